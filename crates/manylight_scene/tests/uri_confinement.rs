//! Buffer and image URIs resolve only inside the glTF file's folder.
//!
//! Each test builds a small glTF in a fresh temporary folder next to a "secret" file outside
//! it, then checks that every way of naming a file outside the folder (absolute paths, `..`,
//! percent-encoded `..`, Windows drive and UNC forms, `file:` URIs, symlinks) and every
//! non-regular file (device, FIFO) is refused with a typed error naming the glTF file, without
//! hanging or reading more than the declared `byteLength`. Every load runs on a worker thread
//! with a timeout, so a regression fails instead of hanging the test run.

use manylight_scene::{LoadOptions, Scene, SceneError, load_gltf};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// Longest a single load may take before the test fails.
const LOAD_TIMEOUT: Duration = Duration::from_secs(30);

/// Vertex positions of the triangle the glTF under test expects.
const GOOD_POSITIONS: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// Vertex positions stored in the secret file outside the asset folder.
const SECRET_POSITIONS: [[f32; 3]; 3] = [[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]];

/// Byte length of a triangle buffer: 3 VEC3 positions, 3 u16 indices, 2 bytes of padding.
const TRIANGLE_BYTES: u64 = 44;

/// A triangle buffer (positions, then indices 0 1 2, padded to 44 bytes).
fn triangle(positions: [[f32; 3]; 3]) -> Vec<u8> {
    let mut bytes: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    for i in [0u16, 1, 2] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes.extend_from_slice(&[0, 0]);
    assert_eq!(bytes.len() as u64, TRIANGLE_BYTES);
    bytes
}

/// A glTF with one triangle whose buffer is `buffer_uri` (`byteLength` 44) and, when
/// `image_uri` is given, a base-colour texture read from it.
fn gltf_json(buffer_uri: &str, image_uri: Option<&str>) -> String {
    let mut root = json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
              "min": [0, 0, 0], "max": [1, 1, 0] },
            { "bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 36 },
            { "buffer": 0, "byteOffset": 36, "byteLength": 6 }
        ],
        "buffers": [{ "byteLength": TRIANGLE_BYTES, "uri": buffer_uri }]
    });
    if let Some(image_uri) = image_uri {
        root["meshes"][0]["primitives"][0]["material"] = json!(0);
        root["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
        root["textures"] = json!([{ "source": 0 }]);
        root["images"] = json!([{ "uri": image_uri }]);
    }
    serde_json::to_string_pretty(&root).expect("serialize glTF")
}

/// A `data:` URI holding the expected triangle.
fn triangle_data_uri() -> String {
    use base64::Engine as _;
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(triangle(GOOD_POSITIONS))
    )
}

/// The 4x4 PNG fixture.
fn png_bytes() -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/png16.png")).expect("png fixture")
}

/// A fresh temporary layout, removed on drop:
///
/// ```text
/// root/secret.bin            triangle with SECRET_POSITIONS
/// root/secret.png            a valid PNG
/// root/sibling/secret.bin    same triangle
/// root/sibling/secret.png    same PNG
/// root/asset/                the glTF file's folder
/// root/asset/sub/            an empty subfolder
/// ```
struct Sandbox {
    root: PathBuf,
}

impl Sandbox {
    fn new(name: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let root = std::env::temp_dir().join(format!("manylight_uri_{}_{n}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("asset/sub")).expect("create asset folder");
        std::fs::create_dir_all(root.join("sibling")).expect("create sibling folder");
        for dir in [root.clone(), root.join("sibling")] {
            std::fs::write(dir.join("secret.bin"), triangle(SECRET_POSITIONS)).expect("write secret");
            std::fs::write(dir.join("secret.png"), png_bytes()).expect("write secret png");
        }
        Self { root }
    }

    /// The glTF file's folder.
    fn asset(&self) -> PathBuf {
        self.root.join("asset")
    }

    /// Writes `scene.gltf` into the asset folder and returns its path.
    fn write_gltf(&self, json: &str) -> PathBuf {
        let path = self.asset().join("scene.gltf");
        std::fs::write(&path, json).expect("write glTF");
        path
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

/// Loads `path` on a worker thread; a load that takes longer than [`LOAD_TIMEOUT`] (a FIFO
/// blocking `open`, an endless device) fails the test instead of hanging it.
fn load(path: &Path) -> Result<Scene, SceneError> {
    let (tx, rx) = std::sync::mpsc::channel();
    let owned = path.to_owned();
    std::thread::spawn(move || {
        let _ = tx.send(load_gltf(&owned, &LoadOptions::default()));
    });
    match rx.recv_timeout(LOAD_TIMEOUT) {
        Ok(result) => result,
        Err(e) => panic!("loading {} did not finish within {LOAD_TIMEOUT:?} ({e})", path.display()),
    }
}

/// The variant name of an error (from its `Debug` form).
fn variant(e: &SceneError) -> String {
    let debug = format!("{e:?}");
    debug.split([' ', '{', '(']).next().unwrap_or_default().to_owned()
}

/// Positions of the first mesh of `scene`.
fn positions(scene: &Scene) -> Vec<[f32; 3]> {
    scene.meshes[0].vertices.iter().map(|v| v.position).collect()
}

/// Where a hostile URI is placed.
#[derive(Clone, Copy, Debug)]
enum Slot {
    Buffer,
    Image,
}

/// Writes a glTF whose buffer or image `uri` is `uri` and checks that loading it fails with
/// `want` (variant name), naming the glTF file and containing every fragment of `fragments`.
fn assert_refused(sandbox: &Sandbox, slot: Slot, uri: &str, want: &str, fragments: &[&str]) {
    let json = match slot {
        Slot::Buffer => gltf_json(uri, None),
        Slot::Image => gltf_json(&triangle_data_uri(), Some(uri)),
    };
    let path = sandbox.write_gltf(&json);
    let err = match load(&path) {
        Ok(scene) => {
            let leaked = match slot {
                Slot::Buffer => format!("vertex positions {:?}", positions(&scene)),
                Slot::Image => format!(
                    "texture {:?}",
                    scene.materials.iter().find_map(|m| m
                        .base_color_texture
                        .as_ref()
                        .map(|t| &t.image)
                        .map(|t| &t.label))
                ),
            };
            panic!("{slot:?} uri `{uri}` loaded ({leaked}) but must be refused");
        }
        Err(e) => e,
    };
    let message = err.to_string();
    assert_eq!(variant(&err), want, "{slot:?} uri `{uri}`: {message}");
    assert!(
        message.contains(&path.display().to_string()),
        "{slot:?} uri `{uri}`: message does not name the glTF file: {message}"
    );
    for fragment in fragments {
        assert!(message.contains(fragment), "{slot:?} uri `{uri}`: message lacks `{fragment}`: {message}");
    }
}

/// Runs [`assert_refused`] for the buffer and the image slot (`secret.bin` in `uri` becomes
/// `secret.png` for the image, so that the file it names would decode).
fn assert_refused_everywhere(sandbox: &Sandbox, uri: &str, want: &str, fragments: &[&str]) {
    assert_refused(sandbox, Slot::Buffer, uri, want, fragments);
    let image_uri = uri.replace("secret.bin", "secret.png");
    assert_refused(sandbox, Slot::Image, &image_uri, want, fragments);
}

#[test]
fn an_absolute_path_outside_the_folder_is_refused() {
    let s = Sandbox::new("absolute");
    let secret = s.root.join("sibling/secret.bin");
    let uri = secret.to_str().expect("utf-8 temp path").replace('\\', "/");
    let reason = if cfg!(windows) { "drive" } else { "absolute path" };
    assert_refused_everywhere(&s, &uri, "UriOutsideFolder", &[reason]);
}

#[test]
fn parent_components_are_refused() {
    let s = Sandbox::new("parent");
    for uri in ["../sibling/secret.bin", "sub/../../secret.bin", "./../secret.bin", "sub/.."] {
        assert_refused_everywhere(&s, uri, "UriOutsideFolder", &["`..`"]);
    }
}

#[test]
fn percent_encoded_parent_components_are_refused() {
    let s = Sandbox::new("percent");
    for uri in ["..%2Fsibling%2Fsecret.bin", "%2E%2E/secret.bin", "sub%2F%2e%2e%2F..%2Fsecret.bin"] {
        assert_refused_everywhere(&s, uri, "UriOutsideFolder", &["`..`"]);
    }
}

#[test]
fn windows_drive_and_unc_paths_are_refused() {
    let s = Sandbox::new("windows");
    for (uri, fragment) in [
        (r"\\host\share\x.bin", "backslash"),
        (r"\\?\C:\x.bin", "backslash"),
        ("C:/x.bin", "drive"),
        (r"C:\x.bin", "drive"),
        ("c:x.bin", "drive"),
        ("C%3A/x.bin", "drive"),
        (r"sub\..\..\secret.bin", "backslash"),
    ] {
        assert_refused_everywhere(&s, uri, "UriOutsideFolder", &[fragment]);
    }
    // A network-path reference (`//host/...`) is a URI pointing to the network.
    assert_refused_everywhere(&s, "//host/share/x.bin", "ExternalUri", &["external URIs are not fetched"]);
}

#[test]
fn schemes_other_than_data_are_refused() {
    let s = Sandbox::new("scheme");
    for uri in ["file:///etc/passwd", "FILE:secret.bin", "ftp://example.com/x.bin", "smb://host/share/x.bin"]
    {
        assert_refused_everywhere(&s, uri, "BadUri", &["unsupported URI scheme"]);
    }
}

#[cfg(unix)]
#[test]
fn dev_zero_is_refused_without_reading_it() {
    let s = Sandbox::new("devzero");
    assert_refused_everywhere(&s, "/dev/zero", "UriOutsideFolder", &["absolute path"]);
}

#[cfg(unix)]
#[test]
fn a_fifo_in_the_folder_is_refused_without_blocking() {
    let s = Sandbox::new("fifo");
    let fifo = s.asset().join("pipe.bin");
    match std::process::Command::new("mkfifo").arg(&fifo).status() {
        Ok(status) => assert!(status.success(), "mkfifo {} failed: {status}", fifo.display()),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => panic!("CI=true but mkfifo fails: {e}"),
        Err(e) => {
            eprintln!("skipping: mkfifo is not available ({e})");
            return;
        }
    }
    assert_refused_everywhere(&s, "pipe.bin", "NotARegularFile", &["pipe.bin", "FIFO"]);
}

#[test]
fn a_directory_is_refused() {
    let s = Sandbox::new("directory");
    assert_refused_everywhere(&s, "sub", "NotARegularFile", &["directory"]);
}

#[cfg(unix)]
#[test]
fn symlinks_that_leave_the_folder_are_refused() {
    let s = Sandbox::new("symlink");
    let asset = s.asset();
    for (link, target) in [
        ("link.bin", s.root.join("sibling/secret.bin")),
        ("link.png", s.root.join("sibling/secret.png")),
        ("relative.bin", PathBuf::from("../secret.bin")),
        ("relative.png", PathBuf::from("../secret.png")),
        ("zero", PathBuf::from("/dev/zero")),
        ("outside", s.root.join("sibling")),
    ] {
        std::os::unix::fs::symlink(&target, asset.join(link)).expect("create symlink");
    }
    for (slot, uri) in [
        (Slot::Buffer, "link.bin"),
        (Slot::Image, "link.png"),
        (Slot::Buffer, "relative.bin"),
        (Slot::Image, "relative.png"),
        (Slot::Buffer, "zero"),
        (Slot::Image, "zero"),
        (Slot::Buffer, "outside/secret.bin"),
        (Slot::Image, "outside/secret.png"),
    ] {
        assert_refused(&s, slot, uri, "UriOutsideFolder", &["resolves outside"]);
    }
}

#[cfg(unix)]
#[test]
fn symlinks_that_stay_inside_the_folder_load() {
    let s = Sandbox::new("inner_symlink");
    let asset = s.asset();
    std::fs::create_dir_all(asset.join("bin")).expect("bin folder");
    std::fs::write(asset.join("bin/data.bin"), triangle(GOOD_POSITIONS)).expect("write buffer");
    std::os::unix::fs::symlink("bin/data.bin", asset.join("alias.bin")).expect("create symlink");
    let path = s.write_gltf(&gltf_json("alias.bin", None));
    let scene = load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(positions(&scene), GOOD_POSITIONS);
}

#[test]
fn a_relative_uri_in_a_subfolder_loads() {
    let s = Sandbox::new("subfolder");
    let asset = s.asset();
    std::fs::create_dir_all(asset.join("bin")).expect("bin folder");
    std::fs::create_dir_all(asset.join("textures")).expect("textures folder");
    std::fs::write(asset.join("bin/data.bin"), triangle(GOOD_POSITIONS)).expect("write buffer");
    std::fs::write(asset.join("bin/my data.bin"), triangle(GOOD_POSITIONS)).expect("write buffer");
    std::fs::write(asset.join("textures/base color.png"), png_bytes()).expect("write png");
    for (buffer, image) in [
        ("bin/data.bin", "textures/base%20color.png"),
        ("./bin/my%20data.bin", "./textures/base color.png"),
        ("bin/./data.bin", "textures/./base%20color.png"),
    ] {
        let path = s.write_gltf(&gltf_json(buffer, Some(image)));
        let scene = load(&path).unwrap_or_else(|e| panic!("buffer `{buffer}`, image `{image}`: {e}"));
        assert_eq!(positions(&scene), GOOD_POSITIONS, "buffer `{buffer}`");
        let texture =
            scene.materials[0].base_color_texture.as_ref().map(|t| &t.image).expect("texture loaded");
        assert_eq!((texture.width, texture.height), (4, 4), "image `{image}`");
    }
}

#[test]
fn a_buffer_file_longer_than_its_byte_length_loads() {
    let s = Sandbox::new("longer");
    let mut bytes = triangle(GOOD_POSITIONS);
    bytes.extend(std::iter::repeat_n(0xAB, 1000));
    std::fs::write(s.asset().join("data.bin"), bytes).expect("write buffer");
    let path = s.write_gltf(&gltf_json("data.bin", None));
    let scene = load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(positions(&scene), GOOD_POSITIONS);
}

/// A sparse 1 TiB buffer file whose first 44 bytes are the triangle: only `byteLength` bytes
/// may be read (reading the whole file would exhaust memory or run into the timeout).
#[cfg(unix)]
#[test]
fn only_byte_length_bytes_of_a_buffer_file_are_read() {
    let s = Sandbox::new("sparse");
    let file = s.asset().join("huge.bin");
    std::fs::write(&file, triangle(GOOD_POSITIONS)).expect("write buffer");
    let handle = std::fs::OpenOptions::new().write(true).open(&file).expect("open buffer");
    if let Err(e) = handle.set_len(1 << 40) {
        eprintln!("skipping: the temporary file system cannot hold a sparse 1 TiB file ({e})");
        return;
    }
    drop(handle);
    let path = s.write_gltf(&gltf_json("huge.bin", None));
    let scene = load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(positions(&scene), GOOD_POSITIONS);
}

/// A sparse image file just over the 256 MiB limit is refused from its size, unread.
#[cfg(unix)]
#[test]
fn an_image_file_over_the_limit_is_refused() {
    let s = Sandbox::new("big_image");
    let file = s.asset().join("big.png");
    std::fs::write(&file, png_bytes()).expect("write png");
    let handle = std::fs::OpenOptions::new().write(true).open(&file).expect("open png");
    handle.set_len((256 << 20) + 1).expect("grow png");
    drop(handle);
    assert_refused(&s, Slot::Image, "big.png", "ReferencedFileTooLarge", &["big.png", "256 MiB"]);
}

#[test]
fn a_buffer_file_shorter_than_its_byte_length_is_refused() {
    let s = Sandbox::new("shorter");
    std::fs::write(s.asset().join("data.bin"), &triangle(GOOD_POSITIONS)[..20]).expect("write buffer");
    let path = s.write_gltf(&gltf_json("data.bin", None));
    let err = load(&path).expect_err("a 20-byte file for a 44-byte buffer");
    let message = err.to_string();
    assert_eq!(variant(&err), "BadBuffer", "{message}");
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert!(message.contains("data.bin") && message.contains("byteLength is 44"), "{message}");
}

#[test]
fn a_missing_file_in_the_folder_names_it() {
    let s = Sandbox::new("missing");
    assert_refused_everywhere(&s, "bin/absent.bin", "ReferencedFile", &["absent.bin"]);
}

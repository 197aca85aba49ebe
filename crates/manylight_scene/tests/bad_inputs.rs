//! Every malformed file of `tests/data/bad_gltf` must fail with the expected typed error that
//! names the file, and never reach the panic fallback (`SceneError::Internal`).

use manylight_scene::{LoadOptions, SceneError, load_gltf};
use std::path::{Path, PathBuf};

/// The repository's `tests/data/bad_gltf` folder.
fn bad_dir() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/bad_gltf")).to_path_buf()
}

/// Short name of an error variant, for comparing with the table below.
fn variant(e: &SceneError) -> &'static str {
    match e {
        SceneError::UnknownSpec { .. } => "UnknownSpec",
        SceneError::Io { .. } => "Io",
        SceneError::Empty { .. } => "Empty",
        SceneError::Json { .. } => "Json",
        SceneError::Glb { .. } => "Glb",
        SceneError::UnsupportedExtension { .. } => "UnsupportedExtension",
        SceneError::MissingReference { .. } => "MissingReference",
        SceneError::ExternalUri { .. } => "ExternalUri",
        SceneError::BadUri { .. } => "BadUri",
        SceneError::ReferencedFile { .. } => "ReferencedFile",
        SceneError::UriOutsideFolder { .. } => "UriOutsideFolder",
        SceneError::NotARegularFile { .. } => "NotARegularFile",
        SceneError::ReferencedFileTooLarge { .. } => "ReferencedFileTooLarge",
        SceneError::BadBuffer { .. } => "BadBuffer",
        SceneError::ViewOutOfRange { .. } => "ViewOutOfRange",
        SceneError::AccessorOutOfRange { .. } => "AccessorOutOfRange",
        SceneError::AccessorType { .. } => "AccessorType",
        SceneError::BadAccessor { .. } => "BadAccessor",
        SceneError::BadPrimitive { .. } => "BadPrimitive",
        SceneError::Mesh { .. } => "Mesh",
        SceneError::UnsupportedImage { .. } => "UnsupportedImage",
        SceneError::ImageDecode { .. } => "ImageDecode",
        SceneError::TextureTooLarge { .. } => "TextureTooLarge",
        SceneError::OverBudget { .. } => "OverBudget",
        SceneError::NonFiniteTransform { .. } => "NonFiniteTransform",
        SceneError::NodeHierarchy { .. } => "NodeHierarchy",
        SceneError::BadLight { .. } => "BadLight",
        SceneError::BadCamera { .. } => "BadCamera",
        SceneError::Invalid { .. } => "Invalid",
        SceneError::Internal { .. } => "Internal",
    }
}

/// File name, expected variant, and a fragment the message must contain.
const EXPECTED: &[(&str, &str, &str)] = &[
    ("empty.gltf", "Empty", "file is empty"),
    ("invalid_json.gltf", "Json", "invalid glTF JSON"),
    ("not_gltf.gltf", "Json", "asset"),
    ("truncated.glb", "Glb", "truncated"),
    ("bad_chunk_length.glb", "Glb", "declares"),
    ("glb_without_bin.glb", "BadBuffer", "no GLB binary chunk"),
    ("missing_buffer.gltf", "ReferencedFile", "does_not_exist.bin"),
    ("short_buffer.gltf", "BadBuffer", "byteLength is 44"),
    ("bad_base64.gltf", "BadUri", "base64"),
    ("http_uri.gltf", "ExternalUri", "external URIs are not fetched"),
    ("view_out_of_range.gltf", "ViewOutOfRange", "buffer view 0"),
    ("accessor_out_of_range.gltf", "AccessorOutOfRange", "accessor 0 reads past the end of buffer view 0"),
    ("stride_too_small.gltf", "BadAccessor", "byteStride 4"),
    ("wrong_component_type.gltf", "AccessorType", "UNSIGNED_BYTE"),
    ("position_vec2.gltf", "AccessorType", "VEC2"),
    ("index_out_of_range.gltf", "Mesh", "index 7"),
    ("nan_position.gltf", "Mesh", "non-finite"),
    ("missing_reference.gltf", "MissingReference", "mesh 5"),
    ("node_cycle.gltf", "NodeHierarchy", "reached twice"),
    ("draco_required.gltf", "UnsupportedExtension", "KHR_draco_mesh_compression"),
    ("nan_transform.gltf", "NonFiniteTransform", "node 0"),
    ("inf_matrix.gltf", "NonFiniteTransform", "node 0"),
    ("nan_light.gltf", "BadLight", "intensity"),
    ("negative_light.gltf", "BadLight", "intensity -5"),
    ("negative_light_color.gltf", "BadLight", "color"),
    ("zero_light_range.gltf", "BadLight", "range"),
    ("spot_inner_wider_than_outer.gltf", "BadLight", "inner 0.8 and outer 0.5"),
    ("bad_camera.gltf", "BadCamera", "yfov"),
    ("missing_image.gltf", "ReferencedFile", "missing.png"),
    ("unsupported_image.gltf", "UnsupportedImage", "image/gif"),
    ("webp_mime.gltf", "UnsupportedImage", "image/webp"),
    ("garbage_image.gltf", "UnsupportedImage", "unrecognised"),
    ("corrupt_png.gltf", "ImageDecode", "image 0"),
    ("https_image.gltf", "ExternalUri", "https://example.com"),
    ("huge_texture.gltf", "TextureTooLarge", "20000x20000"),
    ("too_many_instances.gltf", "OverBudget", "needs 1001000 instances, over the limit of 1000000"),
    ("zero_filled_accessor.gltf", "OverBudget", "needs 22369620 vertices, over the limit of 16000000"),
    ("deep_node_chain.gltf", "OverBudget", "node 1024 needs 1025 levels of node nesting"),
    ("huge_buffer.gltf", "OverBudget", "buffer 0 needs 1099511627776 bytes of buffers"),
    ("fractional_count.gltf", "Json", "1.5"),
    ("bad_percent_data_uri.gltf", "BadUri", "invalid percent escape"),
    ("uriless_buffer_read.gltf", "BadBuffer", "buffer 1: has no uri and the file has no GLB binary chunk"),
    ("glb_second_buffer_without_uri.glb", "BadBuffer", "buffer view 1 reads it"),
    ("animation_without_target.gltf", "Json", "target"),
    ("missing_default_scene.gltf", "MissingReference", "scene 1"),
    ("quantized_unsigned_normal.gltf", "AccessorType", "normalized UNSIGNED_BYTE"),
];

#[test]
fn every_bad_file_fails_with_its_typed_error() {
    let dir = bad_dir();
    let mut seen = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("tests/data/bad_gltf exists") {
        let path = entry.expect("dir entry").path();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !matches!(ext, "gltf" | "glb") {
            continue;
        }
        let name = path.file_name().and_then(|n| n.to_str()).expect("utf-8 name").to_owned();
        let (_, want, fragment) = EXPECTED
            .iter()
            .find(|(n, _, _)| *n == name)
            .unwrap_or_else(|| panic!("{name} is not listed in EXPECTED (add it and to README.md)"));
        let err = match load_gltf(&path, &LoadOptions::default()) {
            Ok(_) => panic!("{name} loaded but must fail"),
            Err(e) => e,
        };
        let message = err.to_string();
        assert_eq!(variant(&err), *want, "{name}: {message}");
        assert!(
            message.contains(&path.display().to_string()),
            "{name}: message does not name the file: {message}"
        );
        assert!(message.contains(fragment), "{name}: message lacks `{fragment}`: {message}");
        seen.push(name);
    }
    for (name, _, _) in EXPECTED {
        assert!(seen.iter().any(|s| s == name), "{name} is listed but missing from {}", dir.display());
    }
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let path = bad_dir().join("no_such_file.gltf");
    let err = load_gltf(&path, &LoadOptions::default()).expect_err("missing file");
    assert_eq!(variant(&err), "Io");
    assert!(err.to_string().contains("no_such_file.gltf"));
}

#[test]
fn a_directory_is_an_io_error() {
    let err = load_gltf(&bad_dir(), &LoadOptions::default()).expect_err("a directory");
    assert_eq!(variant(&err), "Io");
}

#[test]
fn the_texture_limit_is_configurable() {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/png16.gltf"));
    let err =
        load_gltf(path, &LoadOptions { max_texture_size: 2, ..LoadOptions::default() }).expect_err("4x4 > 2");
    assert_eq!(variant(&err), "TextureTooLarge");
    assert!(err.to_string().contains("4x4"));
    // Or downscaled to fit, when the options say so.
    let options = LoadOptions {
        max_texture_size: 2,
        oversized_textures: manylight_scene::OversizedTextures::Downscale,
        ..LoadOptions::default()
    };
    let scene = load_gltf(path, &options).expect("downscaled");
    let textures: Vec<_> =
        scene.materials.iter().filter_map(|m| m.base_color_texture.as_ref().map(|t| &t.image)).collect();
    assert!(!textures.is_empty());
    for t in textures {
        assert_eq!((t.width, t.height), (2, 2), "{}", t.label);
        assert_eq!(t.rgba8.len(), 2 * 2 * 4);
    }
}

/// Truncating a valid file at every length must give an error (or a scene), never a panic.
#[test]
fn every_truncation_of_a_valid_file_is_handled() {
    let dir = std::env::temp_dir().join(format!("manylight_scene_trunc_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for src in ["png16.gltf", "features.gltf"] {
        let full = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(src))
            .expect("fixture");
        std::fs::copy(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/png16.png"),
            dir.join("png16.png"),
        )
        .expect("copy png");
        for len in (0..full.len()).step_by(7) {
            let path = dir.join(src);
            std::fs::write(&path, &full[..len]).expect("write");
            if let Err(e) = load_gltf(&path, &LoadOptions::default()) {
                assert_ne!(variant(&e), "Internal", "{src} cut at {len}: {e}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Corrupting any single byte of a valid GLB (header, JSON, binary chunk, embedded PNG) must
/// give an error or a scene, never a panic or a hang.
#[test]
fn single_byte_corruptions_of_a_glb_are_handled() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/triangle.glb");
    let full = std::fs::read(&src).expect("fixture");
    let dir = std::env::temp_dir().join(format!("manylight_scene_flip_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("flipped.glb");
    let mut errors = 0;
    // One mask per byte, cycling, keeps the test fast (writing the file dominates).
    for i in 0..full.len() {
        let mask = [0xFFu8, 0x80, 0x01][i % 3];
        let mut bytes = full.clone();
        bytes[i] ^= mask;
        std::fs::write(&path, &bytes).expect("write");
        if let Err(e) = load_gltf(&path, &LoadOptions::default()) {
            assert_ne!(variant(&e), "Internal", "byte {i} ^ {mask:#x}: {e}");
            errors += 1;
        }
    }
    assert!(errors > 0);
    let _ = std::fs::remove_dir_all(&dir);
}

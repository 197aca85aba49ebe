//! glTF 2.0 loading (`.gltf` with external or `data:` buffers and images, and `.glb`).
//!
//! The loader never trusts the file:
//! 1. The container is split by hand (GLB header and chunk lengths are checked against the
//!    file size) and the JSON is parsed without `gltf`'s validation; every index is looked up
//!    with a bounds check that turns into a [`SceneError::MissingReference`].
//! 2. Buffers are loaded from the GLB chunk, `data:` URIs or local files (never the network);
//!    of a file only `byteLength` bytes are read. Views and accessors are range-checked
//!    before reading.
//!
//!    A buffer or image `uri` is either a base64 `data:` URI or a relative path that stays
//!    inside the glTF file's folder: after percent-decoding it may not be absolute, contain a
//!    `..` component, a Windows drive letter or a backslash (UNC paths), or use any other
//!    scheme (`http:`, `file:`, ...); its canonical path must lie under the folder's, so a
//!    symlink pointing outside is refused too. Only regular files are read (never a FIFO,
//!    device or directory), image files up to 256 MiB ([`SceneError::UriOutsideFolder`],
//!    [`SceneError::NotARegularFile`], [`SceneError::ReferencedFileTooLarge`]).
//! 3. The node tree of the chosen scene is walked iteratively, rejecting cycles and
//!    non-finite transforms; each mesh primitive, material and image is converted once and
//!    shared.
//! 4. The whole load runs under `catch_unwind`, so even a loader bug cannot take the caller
//!    down ([`SceneError::Internal`]).

mod data;
mod materials;
mod nodes;
mod uri;

pub use materials::blinn_phong_from_pbr;

use crate::{Scene, SceneError};
use manylight_core::TextureData;
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Options of [`load_gltf`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Largest accepted texture width or height in pixels; a larger image is an error
    /// ([`SceneError::TextureTooLarge`]), detected from its header before decoding.
    pub max_texture_size: u32,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { max_texture_size: 8192 }
    }
}

/// Extensions whose absence makes the geometry or textures unreadable.
const UNSUPPORTED_REQUIRED: &[&str] = &[
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
];

/// Loads a `.gltf` or `.glb` file into a [`Scene`].
///
/// Every malformed input is reported as a [`SceneError`] naming the file; nothing is fetched
/// over the network and no file outside the glTF file's folder is read.
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let start = std::time::Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load_inner(path, options)));
    let scene = match result {
        Ok(r) => r?,
        Err(payload) => {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic with a non-string payload".into());
            tracing::error!(file = %path.display(), %message, "glTF loader panicked");
            return Err(SceneError::Internal { path: path.to_owned(), message });
        }
    };
    tracing::info!(
        file = %path.display(),
        meshes = scene.meshes.len(),
        instances = scene.instances.len(),
        lights = scene.lights.len(),
        cameras = scene.cameras.len(),
        ms = start.elapsed().as_secs_f64() * 1e3,
        "loaded glTF"
    );
    Ok(scene)
}

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>), SceneError> {
    let err = |message: String| SceneError::Glb { path: path.to_owned(), message };
    let u32_at = |at: usize| -> Option<u32> {
        bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let version = u32_at(4)
        .ok_or_else(|| err(format!("file is {} bytes, shorter than the 12-byte header", bytes.len())))?;
    let length = u32_at(8)
        .ok_or_else(|| err(format!("file is {} bytes, shorter than the 12-byte header", bytes.len())))?;
    if version != 2 {
        return Err(err(format!("unsupported GLB version {version}")));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(err(format!("header says {length} bytes but the file has {} (truncated?)", bytes.len())));
    }
    let bytes = &bytes[..length];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let (Some(chunk_len), Some(ty)) = (u32_at(at), bytes.get(at + 4..at + 8)) else {
            return Err(err(format!("chunk header at byte {at} is cut off")));
        };
        let start = at + 8;
        let end = start.checked_add(chunk_len as usize).filter(|&e| e <= bytes.len()).ok_or_else(|| {
            err(format!(
                "chunk at byte {at} declares {chunk_len} bytes but only {} remain",
                bytes.len() - start
            ))
        })?;
        match ty {
            b"JSON" if json.is_none() && at == 12 => json = Some(&bytes[start..end]),
            b"BIN\0" if json.is_some() && bin.is_none() => bin = Some(&bytes[start..end]),
            b"JSON" | b"BIN\0" => return Err(err(format!("unexpected chunk at byte {at}"))),
            _ => {} // unknown chunks are skipped, as the spec asks
        }
        // Chunk lengths include their padding, so the next chunk starts right here (as the
        // `gltf` crate reads it too).
        at = end;
    }
    let json = json.ok_or_else(|| err("first chunk is not a JSON chunk".into()))?;
    Ok((json, bin))
}

fn load_inner(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(SceneError::Empty { path: path.to_owned() });
    }
    let (json_bytes, glb_bin) =
        if bytes.starts_with(b"glTF") { split_glb(path, &bytes)? } else { (&bytes[..], None) };
    // A UTF-8 byte-order mark is not valid JSON but harmless; accept it.
    let json_bytes = json_bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json_bytes);
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json_bytes)
        .map_err(|e| SceneError::Json { path: path.to_owned(), message: e.to_string() })?;
    for ext in &root.extensions_required {
        if UNSUPPORTED_REQUIRED.contains(&ext.as_str()) {
            return Err(SceneError::UnsupportedExtension { path: path.to_owned(), extension: ext.clone() });
        }
        if ext != "KHR_lights_punctual" {
            tracing::warn!(file = %path.display(), extension = %ext, "required extension is ignored");
        }
    }
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers = data::load_buffers(path, &base_dir, &root, glb_bin)?;
    let mut ctx = Ctx {
        path,
        base_dir,
        root: &root,
        buffers,
        options,
        textures: HashMap::new(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        scene: Scene {
            name: path
                .file_name()
                .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned()),
            ..Scene::default()
        },
    };
    ctx.walk_scene()?;
    Ok(ctx.scene)
}

/// Everything the loading steps share.
struct Ctx<'a> {
    /// The glTF file (for error messages).
    path: &'a Path,
    /// Folder that URIs resolve in; they may not leave it.
    base_dir: PathBuf,
    /// The parsed, unvalidated JSON.
    root: &'a gltf::json::Root,
    /// Buffer contents, each cut to its `byteLength`.
    buffers: Vec<Cow<'a, [u8]>>,
    /// Limits chosen by the caller.
    options: &'a LoadOptions,
    /// Decoded images by image index.
    textures: HashMap<usize, Arc<TextureData>>,
    /// Scene mesh index by (POSITION, NORMAL, TEXCOORD_0, indices) accessors.
    meshes: HashMap<[Option<usize>; 4], usize>,
    /// Scene material index by glTF material index (`None`: the default material).
    materials: HashMap<Option<usize>, usize>,
    /// The scene being built.
    scene: Scene,
}

impl Ctx<'_> {
    /// `list[index]`, or a [`SceneError::MissingReference`] saying `what` referred to it.
    fn lookup<'l, T>(
        &self,
        list: &'l [T],
        index: usize,
        what: &str,
        kind: &'static str,
    ) -> Result<&'l T, SceneError> {
        list.get(index).ok_or_else(|| SceneError::MissingReference {
            path: self.path.to_owned(),
            what: what.to_owned(),
            kind,
            index,
            count: list.len(),
        })
    }

    /// The file's name, for labels.
    fn file_name(&self) -> String {
        self.path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    }
}

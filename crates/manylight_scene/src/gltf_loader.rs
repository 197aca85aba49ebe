//! glTF 2.0 loading (`.gltf` with external or `data:` buffers and images, and `.glb`).
//!
//! The loader never trusts the file:
//! 1. The file itself is opened without blocking and read only if it is a regular file (never
//!    a FIFO or a device such as `/dev/zero`) within the size budget ([`LoadOptions`]'s
//!    `max_json_bytes` for `.gltf`, `max_glb_bytes` for `.glb`). The container is split by
//!    hand (GLB header and chunk lengths are checked against the file size), the JSON's
//!    values are counted by a scan before it is parsed (`max_json_values`: parsing turns a
//!    few bytes of text into a struct of hundreds), and it is parsed without `gltf`'s
//!    validation (normalised first where the crate's types refuse what the specification
//!    allows, see `normalize.rs`); every index is looked up with a bounds check that turns
//!    into a [`SceneError::MissingReference`].
//! 2. Buffers are loaded from the GLB chunk, `data:` URIs, local files, or the files a caller
//!    fetched beforehand ([`load_gltf_fetched`]; the loader itself never uses the network);
//!    their declared lengths count against `max_buffer_bytes` before each is read, and of a
//!    file only `byteLength` bytes are read. A buffer without `uri` that is not the GLB chunk
//!    is refused only when a buffer view reads it. Views and accessors are range-checked
//!    before reading; `KHR_mesh_quantization` attributes (8- and 16-bit integers) are
//!    dequantised to `f32`.
//!
//!    A buffer or image `uri` is either a `data:` URI (RFC 2397: base64, or percent-encoded
//!    bytes) or a relative path that stays
//!    inside the glTF file's folder: after percent-decoding it may not be absolute, contain a
//!    `..` component, a Windows drive letter or a backslash (UNC paths), or use any other
//!    scheme (`http:`, `file:`, ...); its canonical path must lie under the folder's, so a
//!    symlink pointing outside is refused too. Only regular files are read (never a FIFO,
//!    device or directory), image files up to 256 MiB ([`SceneError::UriOutsideFolder`],
//!    [`SceneError::NotARegularFile`], [`SceneError::ReferencedFileTooLarge`]).
//! 3. The node tree of the chosen scene is walked iteratively, first without creating
//!    anything: cycles, shared children and nesting deeper than `max_node_depth` are refused,
//!    and the instances (nodes × triangle primitives of their meshes) and lights it would
//!    create are counted against `max_instances` and `max_lights`. Then it is walked again,
//!    rejecting non-finite transforms; each mesh primitive and material is converted once
//!    and shared, after its accessor counts were checked against `max_vertices`,
//!    `max_indices` and `max_accessor_bytes`; each image source is decoded once, after its
//!    header was checked against `max_texture_size` and `max_image_bytes`. Generated
//!    tangents count their triangles against `max_tangent_triangles` first, and cost time
//!    linear in them whatever the topology (`MeshData::generate_tangents`).
//! 4. The whole load runs under `catch_unwind`, so even a loader bug cannot take the caller
//!    down ([`SceneError::Internal`]).
//!
//! Every budget that is exceeded is a [`SceneError::OverBudget`] naming the file, what needs
//! how much, the limit and the [`LoadOptions`] field.

mod data;
mod materials;
mod nodes;
mod normalize;
mod uri;

pub use materials::blinn_phong_from_pbr;
pub use uri::{FetchedFiles, ReferencedFile};

use crate::{Scene, SceneError};
use manylight_core::TextureData;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Options of [`load_gltf`]: the largest texture and the budgets a file may use.
///
/// Every budget is checked before the memory it guards is allocated (from a declared count,
/// length or image header), so a small file that declares a huge amount of data is refused
/// cheaply with a [`SceneError::OverBudget`] that names the file, what it needs and the
/// option that limits it. The defaults accept every scene in the repository's `assets/` with
/// a wide margin; lower them for untrusted files, raise them for very large scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Largest texture width or height in pixels; what happens to a larger image is
    /// [`LoadOptions::oversized_textures`]. Set it to the device's limit
    /// (`GpuContext::max_texture_size`) to load only what the renderer can upload. Default 8192.
    pub max_texture_size: u32,
    /// What a texture larger than `max_texture_size` does: refuse the file (the default;
    /// [`SceneError::TextureTooLarge`], detected from the image header before decoding) or
    /// be downscaled to fit.
    pub oversized_textures: OversizedTextures,
    /// Largest size in bytes of a `.gltf` file, and of the JSON chunk of a `.glb` file;
    /// checked against the file's size before it is read. Default 64 MiB.
    pub max_json_bytes: u64,
    /// Most JSON values (objects, arrays, strings, numbers, literals) in the glTF JSON,
    /// counted by a scan of the text before it is parsed. Parsing turns each value into a
    /// typed struct of up to a few hundred bytes (an empty node `{}`, three bytes of text,
    /// takes over 200), so this bounds the parsed document's memory where
    /// `max_json_bytes` alone would not. Default 2 000 000 (real files average 10 to 20
    /// bytes of JSON per value).
    pub max_json_values: u64,
    /// Largest `.glb` file in bytes (header, JSON and binary chunk together); checked against
    /// the file's size before it is read. Default 1 GiB + 64 MiB: room for a JSON chunk of the
    /// default `max_json_bytes` and a binary chunk of the default `max_buffer_bytes`.
    pub max_glb_bytes: u64,
    /// Most bytes of all buffers together (the sum of their `byteLength`s, whether the data
    /// come from the GLB binary chunk, `data:` URIs or files); checked before a buffer is read,
    /// so a file that names the same large file many times is refused. Default 1 GiB.
    pub max_buffer_bytes: u64,
    /// Most bytes of one accessor once unpacked (`count` × element size), whether it reads a
    /// buffer view or is zero-filled (no `bufferView`, e.g. sparse); checked before it is
    /// read. Default 256 MiB.
    pub max_accessor_bytes: u64,
    /// Most vertices of all meshes together; each distinct combination of POSITION, NORMAL,
    /// TEXCOORD_0, TEXCOORD_1, TANGENT and index accessors becomes one mesh, and its POSITION
    /// `count` is checked before any attribute is read. A vertex takes 56 bytes once loaded. Default
    /// 16 000 000.
    pub max_vertices: u64,
    /// Most indices of all meshes together (an unindexed primitive counts one per vertex);
    /// checked before the index accessor is read. Default 48 000 000 (16 million triangles).
    pub max_indices: u64,
    /// Most mesh instances (drawn objects): every triangle primitive of the mesh of every node
    /// in the scene's node tree is one, so 5 000 nodes sharing a mesh of 5 000 primitives
    /// make 25 million. Counted over the node tree before any instance is created.
    /// Default 1 000 000.
    pub max_instances: u64,
    /// Most `KHR_lights_punctual` lights placed by nodes of the scene's node tree; counted
    /// before any light is created. Default 1 000 000.
    pub max_lights: u64,
    /// Deepest node nesting: a root node is at depth 1, its children at depth 2, ...
    /// The node tree is walked without recursion, so depth costs no stack; the limit refuses
    /// degenerate chains whose transforms lose all precision. Default 1024.
    pub max_node_depth: u32,
    /// Most bytes of all decoded images together: each kept image counts as RGBA8 with its
    /// mip chain (width × height × 4 × about 4/3, as the renderer uploads it), and while an
    /// image decodes, what the decode holds at its peak counts too (a 16-bit source in its own
    /// format, 8 bytes a pixel for RGBA, beside its RGBA8 copy; a downscaled copy). Images are
    /// decoded once per distinct source (the same resolved file, the same `data:` URI or the
    /// same buffer view), however many `images` entries name it; each new source is checked
    /// from its header before decoding. Default 1 GiB.
    pub max_image_bytes: u64,
    /// Most triangles of all meshes whose tangents are generated (primitives with a normal
    /// map and `TEXCOORD_0` but no `TANGENT`), counted before each mesh is read or its
    /// tangents generated. Generation uses MikkTSpace where its cost on the mesh's topology
    /// is bounded and per-vertex UV derivatives elsewhere (a fan of hundreds of triangles
    /// around one vertex, one triangle repeated many times: a warning names the mesh; see
    /// `MeshData::generate_tangents`), so its time is linear in the triangles either way; but
    /// MikkTSpace still holds about 400 bytes of temporary memory per triangle and takes
    /// about 3 µs per triangle (one core). Default 4 000 000: at most about 1.6 GB and 12 s
    /// (twice that for the costliest topologies it accepts), 250 times the largest mesh in
    /// the repository's `assets/`, and a quarter of the triangles `max_indices` allows.
    pub max_tangent_triangles: u64,
}

/// What the loader does with an image larger than [`LoadOptions::max_texture_size`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OversizedTextures {
    /// The file is refused with [`SceneError::TextureTooLarge`] (the default).
    #[default]
    Refuse,
    /// The image is decoded and downscaled (aspect kept, triangle filter) so that its larger
    /// side is `max_texture_size`; its decoded size still counts against `max_image_bytes`.
    /// Images whose header declares more than [`MAX_DOWNSCALED_SOURCE`] pixels per side are
    /// still refused.
    Downscale,
}

/// Largest side of an image that [`OversizedTextures::Downscale`] decodes to scale it down.
pub const MAX_DOWNSCALED_SOURCE: u32 = 65_536;

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            max_texture_size: 8192,
            oversized_textures: OversizedTextures::Refuse,
            max_json_bytes: 64 << 20,
            max_json_values: 2_000_000,
            max_glb_bytes: (1 << 30) + (64 << 20),
            max_buffer_bytes: 1 << 30,
            max_accessor_bytes: 256 << 20,
            max_vertices: 16_000_000,
            max_indices: 48_000_000,
            max_instances: 1_000_000,
            max_lights: 1_000_000,
            max_node_depth: 1024,
            max_image_bytes: 1 << 30,
            max_tangent_triangles: 4_000_000,
        }
    }
}

/// Extensions whose absence makes the geometry or textures unreadable.
const UNSUPPORTED_REQUIRED: &[&str] = &[
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
];

/// Extensions the loader implements, so requiring them needs no warning.
const SUPPORTED_REQUIRED: &[&str] =
    &["KHR_lights_punctual", "KHR_mesh_quantization", "KHR_texture_transform"];

/// Loads a `.gltf` or `.glb` file into a [`Scene`].
///
/// Every malformed input is reported as a [`SceneError`] naming the file; nothing is fetched
/// over the network and no file outside the glTF file's folder is read.
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    guarded_load(path, || {
        let bytes = read_scene_file(path, options)?;
        load_inner(path, &bytes, uri::FileSource::Disk, options)
    })
}

/// Loads a `.gltf` or `.glb` file whose bytes and referenced files were fetched beforehand
/// (where there is no file system, as in a browser): `path` is the file's name for messages
/// and the folder its URIs are relative to, `bytes` its contents, `files` what
/// [`referenced_files`] listed. Checked as [`load_gltf`] checks a file on disk; a URI naming a
/// file that `files` lacks is a [`SceneError::ReferencedFile`].
pub fn load_gltf_fetched(
    path: &Path,
    bytes: &[u8],
    files: &FetchedFiles,
    options: &LoadOptions,
) -> Result<Scene, SceneError> {
    guarded_load(path, || {
        check_scene_size(path, bytes, options)?;
        load_inner(path, bytes, uri::FileSource::Fetched(files), options)
    })
}

/// The files that the `.gltf` or `.glb` file with contents `bytes` (named `path`) refers to by
/// relative URIs, each once, for a caller to fetch before [`load_gltf_fetched`]. A URI that
/// would leave the file's folder or names the network is refused here already.
pub fn referenced_files(
    path: &Path,
    bytes: &[u8],
    options: &LoadOptions,
) -> Result<Vec<ReferencedFile>, SceneError> {
    check_scene_size(path, bytes, options)?;
    let parsed = parse_scene_bytes(path, bytes, options)?;
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers =
        parsed.root.buffers.iter().enumerate().map(|(i, b)| (format!("buffer {i}"), b.uri.as_deref()));
    let images = parsed.root.images.iter().enumerate().map(|(i, m)| (format!("image {i}"), m.uri.as_deref()));
    let mut out: Vec<ReferencedFile> = Vec::new();
    for (what, uri) in buffers.chain(images) {
        if let Some(uri) = uri
            && let Some(file) = uri::referenced_file(path, &base_dir, &what, uri)?
            && !out.iter().any(|f| f.name == file.name)
        {
            out.push(file);
        }
    }
    Ok(out)
}

/// Runs `load` under `catch_unwind` (a loader bug becomes [`SceneError::Internal`]) and logs
/// what it loaded.
fn guarded_load(path: &Path, load: impl FnOnce() -> Result<Scene, SceneError>) -> Result<Scene, SceneError> {
    let start = web_time::Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load));
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

/// A [`SceneError::OverBudget`] for file `path`.
fn over_budget(
    path: &Path,
    what: impl Into<String>,
    needed: u64,
    unit: &'static str,
    limit: u64,
    option: &'static str,
) -> SceneError {
    SceneError::OverBudget { path: path.to_owned(), what: what.into(), needed, unit, limit, option }
}

/// Reads the glTF or GLB file itself: only a regular file (a FIFO or device such as
/// `/dev/zero` is refused before a byte is read), and only when its size is within
/// `max_json_bytes` (`.gltf`) or `max_glb_bytes` (a file starting with the GLB magic).
fn read_scene_file(path: &Path, options: &LoadOptions) -> Result<Vec<u8>, SceneError> {
    use std::io::Read as _;
    let io_err = |source| SceneError::Io { path: path.to_owned(), source };
    // Non-blocking on Linux, so opening a FIFO without a writer returns at once.
    let file = uri::open_options().open(path).map_err(io_err)?;
    let meta = file.metadata().map_err(io_err)?;
    if meta.is_dir() {
        return Err(io_err(std::io::Error::from(std::io::ErrorKind::IsADirectory)));
    }
    if !meta.is_file() {
        return Err(SceneError::NotARegularFile {
            path: path.to_owned(),
            what: "the scene file".into(),
            file: path.to_owned(),
            kind: uri::file_kind(meta.file_type()),
        });
    }
    let mut bytes = Vec::new();
    (&file).take(4).read_to_end(&mut bytes).map_err(io_err)?;
    let (limit, option) = size_budget(&bytes, options);
    let too_large = |size: u64| over_budget(path, "the file", size, "bytes", limit, option);
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    // The size is within the budget; a file that grows meanwhile is cut at one byte over it.
    bytes
        .try_reserve_exact(usize::try_from(meta.len()).unwrap_or(usize::MAX))
        .map_err(|_| io_err(std::io::Error::from(std::io::ErrorKind::OutOfMemory)))?;
    (&file)
        .take(limit.saturating_add(1).saturating_sub(bytes.len() as u64))
        .read_to_end(&mut bytes)
        .map_err(io_err)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The budget of a scene file starting with `head`: `max_glb_bytes` for a GLB (its magic),
/// else `max_json_bytes`; with the option's name.
fn size_budget(head: &[u8], options: &LoadOptions) -> (u64, &'static str) {
    if head.starts_with(b"glTF") {
        (options.max_glb_bytes, "max_glb_bytes")
    } else {
        (options.max_json_bytes, "max_json_bytes")
    }
}

/// Refuses scene bytes over their [`size_budget`].
fn check_scene_size(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<(), SceneError> {
    let (limit, option) = size_budget(bytes, options);
    if bytes.len() as u64 > limit {
        return Err(over_budget(path, "the file", bytes.len() as u64, "bytes", limit, option));
    }
    Ok(())
}

/// How many JSON values (objects, arrays, strings including keys, numbers, literals) `json`
/// holds, by a scan that tracks only strings and token boundaries (it does not validate).
fn count_json_values(json: &[u8]) -> u64 {
    let (mut count, mut in_string, mut escaped, mut in_scalar) = (0u64, false, false, false);
    for &b in json {
        if in_string {
            if escaped {
                escaped = false;
            } else if b == b'\\' {
                escaped = true;
            } else if b == b'"' {
                in_string = false;
            }
            continue;
        }
        match b {
            b'"' => {
                count += 1;
                in_string = true;
                in_scalar = false;
            }
            b'{' | b'[' => {
                count += 1;
                in_scalar = false;
            }
            b'}' | b']' | b',' | b':' | b' ' | b'\t' | b'\n' | b'\r' => in_scalar = false,
            _ => {
                if !in_scalar {
                    count += 1;
                    in_scalar = true;
                }
            }
        }
    }
    count
}

/// A scene file's container split and its JSON parsed.
struct ParsedScene<'b> {
    /// The JSON text (without a byte-order mark).
    json: &'b [u8],
    /// `Some(binary chunk)` for a GLB file, `None` for a `.gltf` file.
    glb: Option<Option<&'b [u8]>>,
    /// The parsed, unvalidated JSON.
    root: gltf::json::Root,
}

/// Splits a GLB container and parses the JSON within its budgets.
fn parse_scene_bytes<'b>(
    path: &Path,
    bytes: &'b [u8],
    options: &LoadOptions,
) -> Result<ParsedScene<'b>, SceneError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(SceneError::Empty { path: path.to_owned() });
    }
    let (json_bytes, glb) = if bytes.starts_with(b"glTF") {
        let (json, bin) = split_glb(path, bytes)?;
        (json, Some(bin))
    } else {
        (bytes, None)
    };
    if json_bytes.len() as u64 > options.max_json_bytes {
        let what = "the GLB JSON chunk";
        return Err(over_budget(
            path,
            what,
            json_bytes.len() as u64,
            "bytes",
            options.max_json_bytes,
            "max_json_bytes",
        ));
    }
    let values = count_json_values(json_bytes);
    if values > options.max_json_values {
        return Err(over_budget(
            path,
            "the glTF JSON",
            values,
            "JSON values",
            options.max_json_values,
            "max_json_values",
        ));
    }
    // A UTF-8 byte-order mark is not valid JSON but harmless; accept it.
    let json_bytes = json_bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json_bytes);
    let root = normalize::parse_root(path, json_bytes)?;
    Ok(ParsedScene { json: json_bytes, glb, root })
}

/// Loads the scene file with contents `bytes`, its URIs resolved in `files`.
fn load_inner(
    path: &Path,
    bytes: &[u8],
    files: uri::FileSource<'_>,
    options: &LoadOptions,
) -> Result<Scene, SceneError> {
    let ParsedScene { json: json_bytes, glb, root } = parse_scene_bytes(path, bytes, options)?;
    let material_extensions = materials::material_extensions(path, json_bytes);
    for ext in &root.extensions_required {
        if UNSUPPORTED_REQUIRED.contains(&ext.as_str()) {
            return Err(SceneError::UnsupportedExtension { path: path.to_owned(), extension: ext.clone() });
        }
        if !SUPPORTED_REQUIRED.contains(&ext.as_str()) {
            tracing::warn!(file = %path.display(), extension = %ext, "required extension is ignored");
        }
    }
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers = data::load_buffers(path, &base_dir, files, &root, glb, options)?;
    let mut ctx = Ctx {
        path,
        base_dir,
        files,
        root: &root,
        buffers,
        options,
        textures: HashMap::new(),
        images: HashMap::new(),
        linear: HashMap::new(),
        meshes: HashMap::new(),
        generated_tangents: HashSet::new(),
        materials: HashMap::new(),
        material_extensions,
        used: Used::default(),
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

/// How much of the whole-file budgets the load has used so far.
#[derive(Default)]
struct Used {
    /// Vertices of the scene's meshes.
    vertices: u64,
    /// Indices of the scene's meshes.
    indices: u64,
    /// Bytes of decoded images.
    image_bytes: u64,
    /// Triangles of the meshes whose tangents were generated.
    tangent_triangles: u64,
}

/// Everything the loading steps share.
struct Ctx<'a> {
    /// The glTF file (for error messages).
    path: &'a Path,
    /// Folder that URIs resolve in; they may not leave it.
    base_dir: PathBuf,
    /// Where the files that URIs name are read from.
    files: uri::FileSource<'a>,
    /// The parsed, unvalidated JSON.
    root: &'a gltf::json::Root,
    /// Buffer contents, each cut to its `byteLength` (or why a buffer has none).
    buffers: Vec<data::BufferData<'a>>,
    /// Limits chosen by the caller.
    options: &'a LoadOptions,
    /// Decoded images by image index.
    textures: HashMap<usize, Arc<TextureData>>,
    /// Decoded images by source: `images` entries naming the same source share one decode.
    images: HashMap<materials::ImageSource<'a>, Arc<TextureData>>,
    /// Images read as linear data (metallic-roughness, normal and occlusion maps), by image
    /// index.
    linear: HashMap<usize, Arc<TextureData>>,
    /// Scene mesh index by (POSITION, NORMAL, TEXCOORD_0, TANGENT, indices, TEXCOORD_1) accessors
    /// (`None`: the primitive has no triangles and is skipped).
    meshes: HashMap<[Option<usize>; 6], Option<usize>>,
    /// Scene meshes whose tangents were generated (MikkTSpace), so a mesh shared by many
    /// normal-mapped primitives is processed once.
    generated_tangents: HashSet<usize>,
    /// Scene material index by glTF material index (`None`: the default material).
    materials: HashMap<Option<usize>, usize>,
    /// `KHR_materials_emissive_strength` and `KHR_texture_transform` by glTF material index
    /// (empty when the file uses neither).
    material_extensions: Vec<materials::MaterialExtensions>,
    /// Budget use so far.
    used: Used,
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

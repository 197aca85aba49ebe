//! Typed errors of scene loading and validation. Every variant names the file (or, for
//! generated scenes, the scene name) and says what is wrong with it.

use manylight_core::MeshError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a scene could not be loaded or is not usable.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The scene spec is neither a known generator name nor a `.gltf`/`.glb` path.
    #[error(
        "`{}`: not a scene: expected \"default\", \"sphere-shell\" or a path to a .gltf/.glb file",
        .path.display()
    )]
    UnknownSpec {
        /// The spec as given.
        path: PathBuf,
    },
    /// The file (or a file it names) could not be read.
    #[error("`{}`: cannot read file: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The file has no bytes.
    #[error("`{}`: file is empty", .path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The glTF JSON does not parse or does not have the glTF structure.
    #[error("`{}`: invalid glTF JSON: {message}", .path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// What the JSON parser said (with line and column).
        message: String,
    },
    /// The binary glTF container is malformed (truncated, wrong chunk lengths, ...).
    #[error("`{}`: invalid GLB: {message}", .path.display())]
    Glb {
        /// The file.
        path: PathBuf,
        /// What is wrong with the container.
        message: String,
    },
    /// The file requires a glTF extension this loader cannot honour.
    #[error("`{}`: requires unsupported extension {extension}", .path.display())]
    UnsupportedExtension {
        /// The file.
        path: PathBuf,
        /// The extension name.
        extension: String,
    },
    /// An object refers to another object by an index that does not exist.
    #[error("`{}`: {what} refers to {kind} {index}, but the file has {count}", .path.display())]
    MissingReference {
        /// The file.
        path: PathBuf,
        /// The referring object, e.g. "mesh 2 primitive 0".
        what: String,
        /// The kind of object referred to, e.g. "accessor".
        kind: &'static str,
        /// The missing index.
        index: usize,
        /// How many objects of that kind the file has.
        count: usize,
    },
    /// A buffer or image URI points to the network; it is never fetched.
    #[error("`{}`: {what}: external URIs are not fetched: `{uri}`", .path.display())]
    ExternalUri {
        /// The file.
        path: PathBuf,
        /// The object with the URI, e.g. "buffer 0".
        what: String,
        /// The URI.
        uri: String,
    },
    /// A buffer or image URI is malformed or uses an unsupported scheme.
    #[error("`{}`: {what}: bad URI `{uri}`: {reason}", .path.display())]
    BadUri {
        /// The file.
        path: PathBuf,
        /// The object with the URI.
        what: String,
        /// The URI (shortened when long).
        uri: String,
        /// What is wrong.
        reason: String,
    },
    /// A file named by a buffer or image URI could not be read.
    #[error("`{}`: {what}: cannot read `{}`: {source}", .path.display(), .file.display())]
    ReferencedFile {
        /// The glTF file.
        path: PathBuf,
        /// The object with the URI, e.g. "image 3".
        what: String,
        /// The resolved file path.
        file: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A buffer or image URI names a file outside the glTF file's folder (absolute path, `..`
    /// component, Windows drive or UNC path, or a symlink pointing outside); it is not read.
    #[error(
        "`{}`: {what}: URI `{uri}` reaches outside the folder `{}`: {reason}",
        .path.display(),
        .folder.display()
    )]
    UriOutsideFolder {
        /// The glTF file.
        path: PathBuf,
        /// The object with the URI, e.g. "buffer 0".
        what: String,
        /// The URI (shortened when long).
        uri: String,
        /// The folder URIs resolve in (the glTF file's folder).
        folder: PathBuf,
        /// How the URI leaves the folder.
        reason: String,
    },
    /// A file named by a buffer or image URI is not a regular file (directory, FIFO, device, ...).
    #[error("`{}`: {what}: `{}` is a {kind}, not a regular file", .path.display(), .file.display())]
    NotARegularFile {
        /// The glTF file.
        path: PathBuf,
        /// The object with the URI, e.g. "image 3".
        what: String,
        /// The resolved file path.
        file: PathBuf,
        /// What it is instead, e.g. "FIFO (named pipe)".
        kind: &'static str,
    },
    /// A file named by an image URI is larger than the loader reads.
    #[error(
        "`{}`: {what}: `{}` is {size} bytes, over the limit of {} MiB for image files",
        .path.display(),
        .file.display(),
        .limit >> 20
    )]
    ReferencedFileTooLarge {
        /// The glTF file.
        path: PathBuf,
        /// The object with the URI, e.g. "image 3".
        what: String,
        /// The resolved file path.
        file: PathBuf,
        /// Its size in bytes.
        size: u64,
        /// The limit in bytes.
        limit: u64,
    },
    /// A buffer has fewer bytes than its declared `byteLength`, or has no data at all.
    #[error("`{}`: buffer {buffer}: {problem}", .path.display())]
    BadBuffer {
        /// The file.
        path: PathBuf,
        /// Buffer index.
        buffer: usize,
        /// What is wrong.
        problem: String,
    },
    /// A buffer view reaches outside its buffer.
    #[error(
        "`{}`: buffer view {view} (offset {offset}, length {length}) lies outside buffer {buffer} ({buffer_len} bytes)",
        .path.display()
    )]
    ViewOutOfRange {
        /// The file.
        path: PathBuf,
        /// Buffer view index.
        view: usize,
        /// Its byte offset.
        offset: u64,
        /// Its byte length.
        length: u64,
        /// The buffer it reads.
        buffer: usize,
        /// The buffer's actual length.
        buffer_len: u64,
    },
    /// An accessor reads past the end of its buffer view.
    #[error(
        "`{}`: accessor {accessor} reads past the end of buffer view {view} (needs {needed} bytes, the view has {length})",
        .path.display()
    )]
    AccessorOutOfRange {
        /// The file.
        path: PathBuf,
        /// Accessor index.
        accessor: usize,
        /// Buffer view index.
        view: usize,
        /// Bytes the accessor needs from the start of the view.
        needed: u64,
        /// The view's length.
        length: u64,
    },
    /// An accessor has a type or component type its use does not allow.
    #[error("`{}`: accessor {accessor} used as {usage} is {found}, expected {expected}", .path.display())]
    AccessorType {
        /// The file.
        path: PathBuf,
        /// Accessor index.
        accessor: usize,
        /// How it is used, e.g. "POSITION".
        usage: String,
        /// What it is, e.g. "VEC2 of UNSIGNED_BYTE".
        found: String,
        /// What that use needs.
        expected: &'static str,
    },
    /// An accessor is malformed in some other way (bad stride, bad sparse data, ...).
    #[error("`{}`: accessor {accessor}: {problem}", .path.display())]
    BadAccessor {
        /// The file.
        path: PathBuf,
        /// Accessor index.
        accessor: usize,
        /// What is wrong.
        problem: String,
    },
    /// A mesh primitive is malformed (attribute counts differ, ...).
    #[error("`{}`: mesh {mesh} primitive {primitive}: {problem}", .path.display())]
    BadPrimitive {
        /// The file.
        path: PathBuf,
        /// Mesh index.
        mesh: usize,
        /// Primitive index in the mesh.
        primitive: usize,
        /// What is wrong.
        problem: String,
    },
    /// A mesh primitive's data fails mesh validation (index out of range, NaN position, ...).
    #[error("`{}`: mesh {mesh} primitive {primitive}: {source}", .path.display())]
    Mesh {
        /// The file.
        path: PathBuf,
        /// Mesh index.
        mesh: usize,
        /// Primitive index in the mesh.
        primitive: usize,
        /// The mesh validation error.
        #[source]
        source: MeshError,
    },
    /// An image is in a format the loader does not decode.
    #[error("`{}`: image {image}: unsupported image format ({format}); PNG and JPEG are supported", .path.display())]
    UnsupportedImage {
        /// The file.
        path: PathBuf,
        /// Image index.
        image: usize,
        /// The format found (MIME type or detected format).
        format: String,
    },
    /// An image could not be decoded.
    #[error("`{}`: image {image} cannot be decoded: {message}", .path.display())]
    ImageDecode {
        /// The file.
        path: PathBuf,
        /// Image index.
        image: usize,
        /// What the decoder said.
        message: String,
    },
    /// An image is larger than `LoadOptions::max_texture_size` along a side.
    #[error(
        "`{}`: image {image} is {width}x{height}, larger than the limit of {max} pixels per side",
        .path.display()
    )]
    TextureTooLarge {
        /// The file.
        path: PathBuf,
        /// Image index.
        image: usize,
        /// Declared width.
        width: u32,
        /// Declared height.
        height: u32,
        /// The limit.
        max: u32,
    },
    /// The file needs more of a resource than a [`LoadOptions`](crate::LoadOptions) budget
    /// allows (instances, vertices, decoded image bytes, ...). Detected from declared counts,
    /// lengths and image headers before the memory is allocated.
    #[error(
        "`{}`: {what} needs {needed} {unit}, over the limit of {limit} (LoadOptions::{option})",
        .path.display()
    )]
    OverBudget {
        /// The file.
        path: PathBuf,
        /// What needs it, e.g. "the node tree" or "accessor 3".
        what: String,
        /// How much it needs (with what was already used, for budgets over the whole file).
        needed: u64,
        /// The unit of `needed` and `limit`, e.g. "instances" or "bytes".
        unit: &'static str,
        /// The limit.
        limit: u64,
        /// The [`LoadOptions`](crate::LoadOptions) field that sets the limit.
        option: &'static str,
    },
    /// A node's local or world transform has NaN or infinite entries.
    #[error("`{}`: node {node} has a non-finite transform", .path.display())]
    NonFiniteTransform {
        /// The file.
        path: PathBuf,
        /// Node index.
        node: usize,
    },
    /// The node hierarchy is not a set of trees (a node is reached twice).
    #[error("`{}`: node {node} is reached twice in the node hierarchy (cycle or shared child)", .path.display())]
    NodeHierarchy {
        /// The file.
        path: PathBuf,
        /// Node index.
        node: usize,
    },
    /// A `KHR_lights_punctual` light has unusable parameters.
    #[error("`{}`: light {light}: {problem}", .path.display())]
    BadLight {
        /// The file.
        path: PathBuf,
        /// Light index.
        light: usize,
        /// What is wrong.
        problem: String,
    },
    /// A camera has unusable parameters.
    #[error("`{}`: camera {camera}: {problem}", .path.display())]
    BadCamera {
        /// The file.
        path: PathBuf,
        /// Camera index.
        camera: usize,
        /// What is wrong.
        problem: String,
    },
    /// A loaded or generated scene fails `Scene::validate`.
    #[error("`{}`: invalid scene: {problem}", .path.display())]
    Invalid {
        /// The file or scene name.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// The loader panicked; this is a bug in the loader, not in the file.
    #[error("`{}`: internal error while loading (loader bug): {message}", .path.display())]
    Internal {
        /// The file.
        path: PathBuf,
        /// The panic message.
        message: String,
    },
}

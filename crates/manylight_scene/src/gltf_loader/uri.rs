//! Buffer and image URIs: `data:` URIs are decoded; any other URI must name a regular file
//! inside the glTF file's folder.
//!
//! Confinement is checked on the text and on the file system:
//! 1. After percent-decoding, the URI must be a relative path made of plain names: no scheme
//!    other than `data:` (network URIs are never fetched), no absolute path, no `..`
//!    component, no Windows drive letter, backslash or UNC form.
//! 2. The joined path is canonicalized and must stay under the canonicalized folder, which
//!    also refuses symlinks that point outside it.
//! 3. Only regular files are opened: the type is checked before opening and again on the
//!    opened handle, which is opened non-blocking on Linux so that a FIFO swapped in between
//!    cannot stall the load. On unix the opened file must be the one that was checked; on
//!    Linux its real path (from `/proc/self/fd`) must still lie in the folder.
//!
//! Callers learn the file's size before reading and read at most what they need
//! ([`LocalFile::read_prefix`]).
//!
//! A load from [`FetchedFiles`] (a page fetched what the file refers to) passes the same text
//! checks and then looks the relative path up among the fetched files instead of the disk.

use crate::SceneError;
use base64::Engine as _;
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Where the bytes named by a `uri` come from.
pub(super) enum UriSource {
    /// The bytes themselves: a decoded `data:` URI payload, or a fetched file's copy.
    Bytes { bytes: Vec<u8> },
    /// An opened regular file inside the glTF file's folder.
    File(LocalFile),
}

/// The files a glTF file refers to, fetched before the load (where there is no file system,
/// as in a browser): each keyed by its [`ReferencedFile::name`]. Filled from what
/// [`referenced_files`](super::referenced_files) lists and read by
/// [`load_gltf_fetched`](super::load_gltf_fetched).
#[derive(Clone, Debug, Default)]
pub struct FetchedFiles {
    files: HashMap<String, Vec<u8>>,
}

impl FetchedFiles {
    /// No files.
    pub fn new() -> FetchedFiles {
        FetchedFiles::default()
    }

    /// Adds (or replaces) the file named `name` (a [`ReferencedFile::name`]).
    pub fn insert(&mut self, name: impl Into<String>, bytes: Vec<u8>) {
        self.files.insert(name.into(), bytes);
    }

    /// How many files there are.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

/// A file a glTF file refers to by a relative URI (not a `data:` URI), which a caller without
/// a file system fetches before [`load_gltf_fetched`](super::load_gltf_fetched).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReferencedFile {
    /// The URI as the file writes it (percent-encoded), to resolve against the glTF file's
    /// own URL.
    pub uri: String,
    /// The path it names inside the glTF file's folder, `/`-separated and percent-decoded: the
    /// key of [`FetchedFiles`].
    pub name: String,
}

/// Where the files that URIs name are read from.
#[derive(Clone, Copy)]
pub(super) enum FileSource<'a> {
    /// The glTF file's folder on disk.
    Disk,
    /// Files fetched before the load.
    Fetched(&'a FetchedFiles),
}

/// A regular file inside the glTF file's folder, opened and checked, not yet read.
pub(super) struct LocalFile {
    /// Its canonical path.
    pub(super) path: PathBuf,
    /// Its size in bytes when it was opened.
    pub(super) size: u64,
    handle: File,
}

impl LocalFile {
    /// Reads at most the first `limit` bytes (fewer when the file is shorter).
    pub(super) fn read_prefix(self, gltf: &Path, what: &str, limit: u64) -> Result<Vec<u8>, SceneError> {
        let io_err = |source| SceneError::ReferencedFile {
            path: gltf.to_owned(),
            what: what.to_owned(),
            file: self.path.clone(),
            source,
        };
        // The capacity is bounded by the file's actual size; a size the allocator cannot
        // provide is an error, not an abort.
        let expected = usize::try_from(limit.min(self.size)).unwrap_or(usize::MAX);
        let mut bytes = Vec::new();
        bytes
            .try_reserve_exact(expected)
            .map_err(|_| io_err(std::io::Error::from(std::io::ErrorKind::OutOfMemory)))?;
        (&self.handle).take(limit).read_to_end(&mut bytes).map_err(io_err)?;
        Ok(bytes)
    }
}

/// Shortens long URIs (e.g. `data:` URIs) for error messages.
fn short_uri(uri: &str) -> String {
    if uri.len() <= 80 {
        return uri.to_owned();
    }
    let cut = (0..=77).rev().find(|&i| uri.is_char_boundary(i)).unwrap_or(0);
    format!("{}...", &uri[..cut])
}

/// Decodes the `%XX` escapes of URI text, refusing a `%` that is not followed by two hex
/// digits (the `percent-encoding` crate passes such a `%` through unchanged).
fn percent_decode_strict(text: &str) -> Option<std::borrow::Cow<'_, [u8]>> {
    let bytes = text.as_bytes();
    let escapes_ok = (0..bytes.len())
        .filter(|&i| bytes[i] == b'%')
        .all(|i| bytes.get(i + 1..i + 3).is_some_and(|hex| hex.iter().all(u8::is_ascii_hexdigit)));
    escapes_ok.then(|| percent_encoding::percent_decode(bytes).into())
}

/// Decodes `%XX` escapes of a relative URI reference (the result must be UTF-8).
fn percent_decode(uri: &str) -> Option<String> {
    String::from_utf8(percent_decode_strict(uri)?.into_owned()).ok()
}

/// Whether `uri` is a `data:` URI (the scheme is case-insensitive).
pub(super) fn is_data_uri(uri: &str) -> bool {
    uri.get(..5).is_some_and(|s| s.eq_ignore_ascii_case("data:"))
}

/// `(header, data)` of `data:` URI `uri`: the text before and after the first `,`; `None` for
/// another URI or one without a `,`.
pub(super) fn split_data_uri(uri: &str) -> Option<(&str, &str)> {
    if !is_data_uri(uri) {
        return None;
    }
    uri[5..].split_once(',')
}

/// The bytes of `data:` URI `uri` (RFC 2397): `data:[<mediatype>][;base64],<data>`, where
/// `<data>` is percent-encoded URI text, decoded as base64 when the header ends in `;base64`.
fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let (header, payload) = split_data_uri(uri).ok_or("data URI without ','")?;
    let base64 = header.rsplit_once(';').is_some_and(|(_, last)| last.eq_ignore_ascii_case("base64"));
    let payload = percent_decode_strict(payload)
        .ok_or("invalid percent escape in the data (`%` must be followed by two hex digits)")?;
    if !base64 {
        return Ok(payload.into_owned());
    }
    let payload = payload.trim_ascii_end();
    base64::engine::general_purpose::STANDARD.decode(payload).map_err(|e| format!("invalid base64: {e}"))
}

/// Whether `s` starts with a Windows drive letter (`C:`).
fn has_drive_letter(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() >= 2 && b[0].is_ascii_alphabetic() && b[1] == b':'
}

/// The relative path named by a percent-decoded URI, or why it would leave the folder.
///
/// Only `/` separates components; empty and `.` components are dropped, every other one must
/// be a plain name on this platform.
fn relative_path(decoded: &str) -> Result<PathBuf, String> {
    if decoded.starts_with('/') {
        return Err("it is an absolute path".into());
    }
    if has_drive_letter(decoded) {
        return Err("it is a Windows drive path".into());
    }
    if decoded.contains('\\') {
        return Err("it contains a backslash (a Windows path separator or UNC path)".into());
    }
    let mut out = PathBuf::new();
    for part in decoded.split('/') {
        match part {
            "" | "." => {}
            ".." => return Err("it has a `..` component".into()),
            _ => {
                // On Windows a component such as `C:` parses as a prefix, not a name.
                let mut components = Path::new(part).components();
                match (components.next(), components.next()) {
                    (Some(Component::Normal(_)), None) => out.push(part),
                    _ => return Err(format!("its component `{part}` is not a plain file name")),
                }
            }
        }
    }
    Ok(out)
}

/// A readable name for a file type that is not a regular file.
pub(super) fn file_kind(ty: std::fs::FileType) -> &'static str {
    if ty.is_dir() {
        return "directory";
    }
    if ty.is_symlink() {
        return "symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ty.is_fifo() {
            return "FIFO (named pipe)";
        }
        if ty.is_char_device() {
            return "character device";
        }
        if ty.is_block_device() {
            return "block device";
        }
        if ty.is_socket() {
            return "socket";
        }
    }
    "special file"
}

/// `O_NONBLOCK` on Linux targets whose value is the generic `0o4000` (opening a FIFO with it
/// returns at once instead of waiting for a writer; reads of regular files ignore it); no extra
/// open flags where `O_NONBLOCK`'s value is not the generic one.
#[cfg(unix)]
const OPEN_FLAGS: i32 = if cfg!(all(
    any(target_os = "linux", target_os = "android"),
    any(
        target_arch = "x86",
        target_arch = "x86_64",
        target_arch = "arm",
        target_arch = "aarch64",
        target_arch = "riscv32",
        target_arch = "riscv64",
        target_arch = "loongarch64",
        target_arch = "powerpc",
        target_arch = "powerpc64",
        target_arch = "s390x"
    )
)) {
    0o4000
} else {
    0
};

/// Read-only, and on unix with [`OPEN_FLAGS`].
pub(super) fn open_options() -> std::fs::OpenOptions {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(OPEN_FLAGS);
    }
    options
}

/// Interprets a buffer or image URI of glTF file `path`: `data:` URIs are decoded,
/// `http(s)://` and other schemes are refused (nothing is ever fetched), anything else must
/// name a regular file inside `base_dir`, which is opened (see the module documentation).
pub(super) fn resolve_uri(
    path: &Path,
    base_dir: &Path,
    files: FileSource<'_>,
    what: &str,
    uri: &str,
) -> Result<UriSource, SceneError> {
    let relative = match check_uri(path, base_dir, what, uri)? {
        CheckedUri::Data(bytes) => return Ok(UriSource::Bytes { bytes }),
        CheckedUri::Relative(relative) => relative,
    };
    let io_err = |file: &Path, source| SceneError::ReferencedFile {
        path: path.to_owned(),
        what: what.to_owned(),
        file: file.to_owned(),
        source,
    };
    let base_dir = if base_dir.as_os_str().is_empty() { Path::new(".") } else { base_dir };
    let joined = base_dir.join(&relative);
    let fetched = match files {
        FileSource::Fetched(fetched) => fetched,
        FileSource::Disk => {
            let folder = base_dir.canonicalize().map_err(|e| io_err(base_dir, e))?;
            let file = joined.canonicalize().map_err(|e| io_err(&joined, e))?;
            if !file.starts_with(&folder) {
                let reason = format!("it resolves outside the folder (symlink) to `{}`", file.display());
                return Err(outside(path, base_dir, what, uri, reason));
            }
            return open_regular(path, what, file, &folder).map(UriSource::File).map_err(|e| match e {
                OpenError::Outside(reason) => outside(path, base_dir, what, uri, reason),
                OpenError::Scene(e) => e,
            });
        }
    };
    match fetched.files.get(&fetched_name(&relative)) {
        Some(bytes) => Ok(UriSource::Bytes { bytes: bytes.clone() }),
        None => {
            let missing =
                std::io::Error::new(std::io::ErrorKind::NotFound, "it was not among the fetched files");
            Err(io_err(&joined, missing))
        }
    }
}

/// The key of [`FetchedFiles`] for a checked relative path: its components joined by `/`.
fn fetched_name(relative: &Path) -> String {
    let parts: Vec<_> = relative.components().map(|c| c.as_os_str().to_string_lossy()).collect();
    parts.join("/")
}

/// A URI that passed the text checks.
pub(super) enum CheckedUri {
    /// A `data:` URI's decoded bytes.
    Data(Vec<u8>),
    /// A relative path made of plain names (percent-decoded), inside the glTF file's folder.
    Relative(PathBuf),
}

/// The error for a URI that names something outside `base_dir`.
fn outside(path: &Path, base_dir: &Path, what: &str, uri: &str, reason: String) -> SceneError {
    SceneError::UriOutsideFolder {
        path: path.to_owned(),
        what: what.to_owned(),
        uri: short_uri(uri),
        folder: base_dir.to_owned(),
        reason,
    }
}

/// The [`ReferencedFile`] that `uri` names, `None` for a `data:` URI; refused as
/// [`resolve_uri`] refuses it.
pub(super) fn referenced_file(
    path: &Path,
    base_dir: &Path,
    what: &str,
    uri: &str,
) -> Result<Option<ReferencedFile>, SceneError> {
    if is_data_uri(uri) {
        return Ok(None);
    }
    match check_uri(path, base_dir, what, uri)? {
        CheckedUri::Data(_) => Ok(None),
        CheckedUri::Relative(relative) => {
            Ok(Some(ReferencedFile { uri: uri.to_owned(), name: fetched_name(&relative) }))
        }
    }
}

/// Checks the text of a buffer or image URI: a `data:` URI is decoded, a network URI or any
/// other scheme is refused, anything else must be a relative path of plain names.
fn check_uri(path: &Path, base_dir: &Path, what: &str, uri: &str) -> Result<CheckedUri, SceneError> {
    let bad = |reason: &str| SceneError::BadUri {
        path: path.to_owned(),
        what: what.to_owned(),
        uri: short_uri(uri),
        reason: reason.to_owned(),
    };
    let base_dir = if base_dir.as_os_str().is_empty() { Path::new(".") } else { base_dir };
    let outside = |reason: String| outside(path, base_dir, what, uri, reason);
    let lower = uri.get(..8).unwrap_or(uri).to_ascii_lowercase();
    if lower.starts_with("http://") || lower.starts_with("https://") || uri.starts_with("//") {
        return Err(SceneError::ExternalUri {
            path: path.to_owned(),
            what: what.to_owned(),
            uri: short_uri(uri),
        });
    }
    if is_data_uri(uri) {
        return decode_data_uri(uri).map(CheckedUri::Data).map_err(|reason| bad(&reason));
    }
    // A scheme is letters/digits/+/-/. before the first ':' that comes before any '/'; a
    // single letter there is a Windows drive.
    if let Some(colon) = uri.find(':') {
        let scheme = &uri[..colon];
        if has_drive_letter(uri) {
            return Err(outside("it is a Windows drive path".into()));
        }
        let looks_like_scheme =
            !scheme.is_empty() && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
        if looks_like_scheme {
            return Err(bad(&format!("unsupported URI scheme `{scheme}:`")));
        }
    }
    if uri.is_empty() {
        return Err(bad("empty URI"));
    }
    let decoded = percent_decode(uri).ok_or_else(|| bad("invalid percent escape"))?;
    if decoded.contains('\0') {
        return Err(bad("NUL byte in path"));
    }
    relative_path(&decoded).map(CheckedUri::Relative).map_err(outside)
}

/// Why [`open_regular`] refused a file.
enum OpenError {
    /// The opened file is not the checked one inside the folder.
    #[cfg_attr(not(unix), allow(dead_code))]
    Outside(String),
    /// Any other refusal, already typed.
    Scene(SceneError),
}

/// Opens `file` (canonical, inside the canonical `folder`) if it is a regular file.
fn open_regular(gltf: &Path, what: &str, file: PathBuf, folder: &Path) -> Result<LocalFile, OpenError> {
    let io_err = |file: &Path, source| {
        OpenError::Scene(SceneError::ReferencedFile {
            path: gltf.to_owned(),
            what: what.to_owned(),
            file: file.to_owned(),
            source,
        })
    };
    let not_regular = |file: &Path, ty| {
        OpenError::Scene(SceneError::NotARegularFile {
            path: gltf.to_owned(),
            what: what.to_owned(),
            file: file.to_owned(),
            kind: file_kind(ty),
        })
    };
    // The canonical path has no symlinks left; checking without following one means a FIFO or
    // device is refused before `open` could block on it or read from it.
    let before = std::fs::symlink_metadata(&file).map_err(|e| io_err(&file, e))?;
    if !before.is_file() {
        return Err(not_regular(&file, before.file_type()));
    }
    let handle = open_options().open(&file).map_err(|e| io_err(&file, e))?;
    // The file may have been replaced between the check and the open: check the handle.
    let meta = handle.metadata().map_err(|e| io_err(&file, e))?;
    if !meta.is_file() {
        return Err(not_regular(&file, meta.file_type()));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if (meta.dev(), meta.ino()) != (before.dev(), before.ino()) {
            return Err(OpenError::Outside(format!("`{}` was replaced while it was opened", file.display())));
        }
    }
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        // A folder on the way may have been swapped for a symlink after canonicalization; the
        // kernel knows where the opened file really is. Without `/proc` this check is skipped.
        if let Ok(real) = std::fs::read_link(format!("/proc/self/fd/{}", handle.as_raw_fd()))
            && !real.starts_with(folder)
        {
            return Err(OpenError::Outside(format!("the opened file is `{}`", real.display())));
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = folder;
    Ok(LocalFile { path: file, size: meta.len(), handle })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_relative_paths_are_kept() {
        assert_eq!(relative_path("bin/data.bin"), Ok(PathBuf::from("bin").join("data.bin")));
        assert_eq!(relative_path("./a//b/./c.png"), Ok(PathBuf::from("a").join("b").join("c.png")));
        assert_eq!(relative_path("x/a:b.png").is_err(), cfg!(windows));
    }

    #[test]
    fn escaping_paths_are_refused() {
        for p in ["/etc/passwd", "../x", "a/../../x", "a/..", "C:/x", "c:x", r"\\host\share\x", r"a\..\x"] {
            assert!(relative_path(p).is_err(), "{p}");
        }
    }

    /// Where `O_NONBLOCK` is known, opening a FIFO without a writer returns at once.
    #[cfg(target_os = "linux")]
    #[test]
    fn opening_a_fifo_does_not_block() {
        if OPEN_FLAGS == 0 {
            return;
        }
        let dir = std::env::temp_dir().join(format!("manylight_scene_fifo_open_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let fifo = dir.join("pipe");
        let _ = std::fs::remove_file(&fifo);
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().expect("run mkfifo");
        assert!(status.success());
        let (tx, rx) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || {
            let _ = tx.send(open_options().open(&path).map(|f| f.metadata().map(|m| m.file_type())));
        });
        let opened = rx.recv_timeout(std::time::Duration::from_secs(10)).expect("open returns at once");
        let ty = opened.expect("open").expect("metadata");
        assert_eq!(file_kind(ty), "FIFO (named pipe)");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn data_uris_follow_rfc_2397() {
        assert_eq!(decode_data_uri("data:,a%20b%00"), Ok(b"a b\0".to_vec()));
        assert_eq!(decode_data_uri("data:application/octet-stream,%FF%fe"), Ok(vec![0xFF, 0xFE]));
        assert_eq!(decode_data_uri("data:;base64,QUI%3D"), Ok(b"AB".to_vec()));
        assert_eq!(decode_data_uri("data:text/plain;charset=US-ASCII;BASE64,QUI="), Ok(b"AB".to_vec()));
        // `base64` as the media type is not the `;base64` flag.
        assert_eq!(decode_data_uri("data:base64,QUI="), Ok(b"QUI=".to_vec()));
        for bad in ["data:,%zz", "data:,%4", "data:,100%", "data:;base64,@@@@", "data:abc"] {
            assert!(decode_data_uri(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn percent_escapes_are_decoded() {
        assert_eq!(percent_decode("a%20b%2F..").as_deref(), Some("a b/.."));
        assert_eq!(percent_decode("%zz"), None);
        assert_eq!(percent_decode("%4"), None);
    }
}

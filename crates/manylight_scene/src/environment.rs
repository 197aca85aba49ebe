//! HDR environments from files: Radiance `.hdr` and OpenEXR `.exr` equirectangular panoramas,
//! decoded into [`EquirectImage`]s the renderer can upload.
//!
//! Steps of [`decode_environment`], each refusing a bad file with an [`EnvironmentError`] that
//! names it:
//! 1. The format comes from the bytes, not the name: only Radiance and OpenEXR signatures pass.
//! 2. The header alone gives the size, checked before any pixel is decoded: large enough to be
//!    an environment, twice as wide as high (a full latitude-longitude panorama), within the
//!    [`EnvironmentBudget`]. The budget is also handed to the decoder as `image::Limits`, so a
//!    header claiming 65,536 texels across is refused without allocating for them.
//! 3. The pixels are decoded as linear RGB `f32` (an EXR alpha channel is dropped).
//! 4. Texels the GPU cannot store are clamped and counted ([`sanitize_radiance`]): NaN and
//!    negative channels become 0, infinite and larger ones [`MAX_RADIANCE`].

use image::{DynamicImage, ImageDecoder, ImageError, ImageFormat, ImageReader, Limits};
use manylight_core::environment::EquirectImage;
use std::io::Cursor;
use std::path::PathBuf;
use thiserror::Error;

/// Largest radiance an environment texel keeps: the largest finite `f16`, the GPU's texel
/// format. Brighter texels (the sun in some panoramas) are clamped to it.
pub const MAX_RADIANCE: f32 = 65504.0;
/// Smallest width an environment may have, in texels.
pub const MIN_ENVIRONMENT_WIDTH: u32 = 8;
/// Smallest height an environment may have, in texels.
pub const MIN_ENVIRONMENT_HEIGHT: u32 = 4;

/// How large an environment a decoder may accept: protects against files whose header claims
/// more texels than the machine (or a browser tab) can hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EnvironmentBudget {
    /// Widest panorama accepted, in texels.
    pub max_width: u32,
    /// Highest panorama accepted, in texels.
    pub max_height: u32,
    /// Most bytes the decoded pixels may take (4-channel `f32` for an EXR with alpha, 3-channel
    /// otherwise); a file read from disk may not exceed it either. Peak memory is a small
    /// multiple of it: the conversion to [`EquirectImage`] holds a second copy for a moment,
    /// and the OpenEXR decoder a copy of its own.
    pub max_bytes: u64,
}

impl Default for EnvironmentBudget {
    /// 8192 x 4096 texels (the largest panoramas commonly published), and the bytes those take
    /// as 4-channel `f32`: 512 MiB.
    fn default() -> EnvironmentBudget {
        EnvironmentBudget { max_width: 8192, max_height: 4096, max_bytes: 8192 * 4096 * 16 }
    }
}

impl EnvironmentBudget {
    /// The budget as the `image` crate's decoder limits.
    fn limits(&self) -> Limits {
        let mut limits = Limits::default();
        limits.max_image_width = Some(self.max_width);
        limits.max_image_height = Some(self.max_height);
        limits.max_alloc = Some(self.max_bytes);
        limits
    }
}

/// A decoded environment and what had to be repaired in it.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedEnvironment {
    /// The panorama, every texel finite and in `0..=MAX_RADIANCE`.
    pub image: EquirectImage,
    /// How many texels had a NaN, negative, infinite or too large channel (see
    /// [`sanitize_radiance`]).
    pub clamped_texels: u64,
}

/// Why an environment file was refused. Every message names the file.
#[derive(Debug, Error)]
pub enum EnvironmentError {
    /// The file could not be read.
    #[error("`{}`: cannot read environment file: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The bytes are not a Radiance or OpenEXR image.
    #[error("`{name}`: not an HDR panorama: {found}; expected a Radiance .hdr or OpenEXR .exr file")]
    NotHdr {
        /// The file.
        name: String,
        /// What the bytes are instead (an image format, or that none was recognised).
        found: String,
    },
    /// The file ends before its pixels do.
    #[error("`{name}`: truncated {format} file: it ends before its pixels do")]
    Truncated {
        /// The file.
        name: String,
        /// `"Radiance HDR"` or `"OpenEXR"`.
        format: &'static str,
    },
    /// The header or the pixel data is malformed.
    #[error("`{name}`: corrupt {format} file: {message}")]
    Corrupt {
        /// The file.
        name: String,
        /// `"Radiance HDR"` or `"OpenEXR"`.
        format: &'static str,
        /// What the decoder said.
        message: String,
    },
    /// Too few texels to light anything with.
    #[error(
        "`{name}`: {width}x{height} texels is too small for an environment \
         (at least {MIN_ENVIRONMENT_WIDTH}x{MIN_ENVIRONMENT_HEIGHT})"
    )]
    TooSmall {
        /// The file.
        name: String,
        /// Width in the header.
        width: u32,
        /// Height in the header.
        height: u32,
    },
    /// Not twice as wide as high, so not a full equirectangular panorama.
    #[error(
        "`{name}`: {width}x{height} texels is not an equirectangular panorama \
         (its width must be twice its height)"
    )]
    NotEquirectangular {
        /// The file.
        name: String,
        /// Width in the header.
        width: u32,
        /// Height in the header.
        height: u32,
    },
    /// Wider or higher than the budget allows.
    #[error("`{name}`: {width}x{height} texels exceeds the environment budget of {max_width}x{max_height}")]
    TooLarge {
        /// The file.
        name: String,
        /// Width in the header.
        width: u32,
        /// Height in the header.
        height: u32,
        /// The budget's width.
        max_width: u32,
        /// The budget's height.
        max_height: u32,
    },
    /// Decoding would allocate more bytes than the budget allows.
    #[error("`{name}`: needs {needed} bytes, over the environment budget of {max_bytes} bytes")]
    OverMemoryBudget {
        /// The file.
        name: String,
        /// Bytes the decoded pixels (or the file) take.
        needed: u64,
        /// The budget's bytes.
        max_bytes: u64,
    },
}

/// Decodes an equirectangular HDR panorama from the bytes of a Radiance `.hdr` or OpenEXR
/// `.exr` file, named `name` in errors and logs, within `budget` (see the module documentation
/// for the steps).
pub fn decode_environment(
    bytes: &[u8],
    name: &str,
    budget: &EnvironmentBudget,
) -> Result<DecodedEnvironment, EnvironmentError> {
    let format = hdr_format(bytes, name)?;
    // Reading the header (and an EXR's offset tables) allocates at most about the file's own
    // size, whatever size the header claims.
    let mut decoder = ImageReader::with_format(Cursor::new(bytes), format)
        .into_decoder()
        .map_err(|e| decode_error(name, format, e))?;
    let (width, height) = decoder.dimensions();
    check_dimensions(name, width, height, budget)?;
    let needed = decoder.total_bytes();
    let over_budget =
        || EnvironmentError::OverMemoryBudget { name: name.to_owned(), needed, max_bytes: budget.max_bytes };
    if needed > budget.max_bytes {
        return Err(over_budget());
    }
    let decoded_within_budget = |e| match e {
        ImageError::Limits(_) => over_budget(),
        e => decode_error(name, format, e),
    };
    decoder.set_limits(budget.limits()).map_err(decoded_within_budget)?;
    let pixels = DynamicImage::from_decoder(decoder).map_err(decoded_within_budget)?;
    let decoded = sanitize_image(pixels);
    if decoded.clamped_texels > 0 {
        tracing::warn!(
            "`{name}`: {} texels were NaN, negative or above {MAX_RADIANCE} and were clamped",
            decoded.clamped_texels
        );
    }
    Ok(decoded)
}

/// Reads and decodes the environment file at `path` ([`decode_environment`]). A file larger
/// than the budget's bytes is refused before it is read.
#[cfg(not(target_arch = "wasm32"))]
pub fn load_environment(
    path: &std::path::Path,
    budget: &EnvironmentBudget,
) -> Result<DecodedEnvironment, EnvironmentError> {
    let io_error = |source| EnvironmentError::Io { path: path.to_owned(), source };
    let name = path.display().to_string();
    let len = std::fs::metadata(path).map_err(io_error)?.len();
    if len > budget.max_bytes {
        return Err(EnvironmentError::OverMemoryBudget { name, needed: len, max_bytes: budget.max_bytes });
    }
    let bytes = std::fs::read(path).map_err(io_error)?;
    decode_environment(&bytes, &name, budget)
}

/// One texel made storable: NaN and negative channels become 0, infinite and larger ones
/// [`MAX_RADIANCE`] (and -0 becomes +0). Returns the texel and whether a channel changed.
pub fn sanitize_radiance(texel: [f32; 3]) -> ([f32; 3], bool) {
    let mut clamped = false;
    let out = texel.map(|c| {
        clamped |= !(0.0..=MAX_RADIANCE).contains(&c);
        if c > 0.0 { c.min(MAX_RADIANCE) } else { 0.0 }
    });
    (out, clamped)
}

/// The format of `bytes` if it is one an environment can be, otherwise why not.
fn hdr_format(bytes: &[u8], name: &str) -> Result<ImageFormat, EnvironmentError> {
    let not_hdr = |found: String| EnvironmentError::NotHdr { name: name.to_owned(), found };
    if bytes.is_empty() {
        return Err(not_hdr("the file is empty".to_owned()));
    }
    match image::guess_format(bytes) {
        Ok(format @ (ImageFormat::Hdr | ImageFormat::OpenExr)) => Ok(format),
        Ok(other) => Err(not_hdr(format!("it is a {other:?} image, which has no high dynamic range"))),
        Err(_) => Err(not_hdr("no image signature recognised".to_owned())),
    }
}

/// The size checks, in the order a reader wants them: too small, too large, wrong shape.
fn check_dimensions(
    name: &str,
    width: u32,
    height: u32,
    budget: &EnvironmentBudget,
) -> Result<(), EnvironmentError> {
    let name = name.to_owned();
    if width < MIN_ENVIRONMENT_WIDTH || height < MIN_ENVIRONMENT_HEIGHT {
        return Err(EnvironmentError::TooSmall { name, width, height });
    }
    if width > budget.max_width || height > budget.max_height {
        let (max_width, max_height) = (budget.max_width, budget.max_height);
        return Err(EnvironmentError::TooLarge { name, width, height, max_width, max_height });
    }
    if !is_equirectangular(width, height) {
        return Err(EnvironmentError::NotEquirectangular { name, width, height });
    }
    Ok(())
}

/// Whether `width` is twice `height`, give or take 2 % (published panoramas are sometimes a
/// texel or two off).
fn is_equirectangular(width: u32, height: u32) -> bool {
    let twice = 2 * u64::from(height);
    u64::from(width).abs_diff(twice) <= twice / 50
}

/// The `image` crate's error as ours: running out of bytes is truncation, anything else is
/// corruption.
fn decode_error(name: &str, format: ImageFormat, error: ImageError) -> EnvironmentError {
    let name = name.to_owned();
    let format = format_name(format);
    if is_truncation(&error) {
        EnvironmentError::Truncated { name, format }
    } else {
        EnvironmentError::Corrupt { name, format, message: error.to_string() }
    }
}

/// Whether the decoder ran out of bytes. Radiance pixels report it as an I/O error; a Radiance
/// header and OpenEXR only say so in their messages ("EOF in header", "reference to missing
/// bytes"), which the tests pin for both formats.
fn is_truncation(error: &ImageError) -> bool {
    if let ImageError::IoError(e) = error {
        return e.kind() == std::io::ErrorKind::UnexpectedEof;
    }
    let message = error.to_string().to_ascii_lowercase();
    ["eof in", "missing bytes", "unexpected end"].iter().any(|m| message.contains(m))
}

/// Human name of a format this module decodes.
fn format_name(format: ImageFormat) -> &'static str {
    match format {
        ImageFormat::OpenExr => "OpenEXR",
        _ => "Radiance HDR",
    }
}

/// Decoded pixels as a sanitized panorama.
fn sanitize_image(pixels: DynamicImage) -> DecodedEnvironment {
    let rgb = pixels.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let mut clamped_texels = 0;
    let texels = rgb
        .into_raw()
        .chunks_exact(3)
        .map(|c| {
            let (texel, clamped) = sanitize_radiance([c[0], c[1], c[2]]);
            clamped_texels += u64::from(clamped);
            texel
        })
        .collect();
    DecodedEnvironment { image: EquirectImage { width, height, texels }, clamped_texels }
}

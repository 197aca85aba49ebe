//! Image error metrics: NVIDIA FLIP (through `nv-flip`, as the wgpu project uses) between a
//! reference and a test image, summarised by its mean and high percentiles; and measures over
//! HDR luminance (linear radiance before tone mapping): the light a frame's shadows get wrong
//! ([`light_error`]) and how much a still frame changes from one frame to the next
//! ([`flicker`]).

use thiserror::Error;

/// Summary of a FLIP error map (each pixel's error is in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipStats {
    /// Mean error.
    pub mean: f32,
    /// 95th percentile.
    pub p95: f32,
    /// 99th percentile.
    pub p99: f32,
    /// Largest error.
    pub max: f32,
}

/// The two images cannot be compared.
#[derive(Debug, Error, PartialEq)]
pub enum CompareError {
    /// Sizes differ.
    #[error("image sizes differ: reference {0}x{1}, test {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// A buffer is not `width * height * 4` bytes.
    #[error("buffer of {0} bytes is not a {1}x{2} RGBA8 image")]
    BadBuffer(usize, u32, u32),
}

fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// FLIP between two sRGB RGBA8 images (alpha ignored). Returns the statistics and the error
/// map coloured with the magma palette as RGB8 (for writing a diff image).
pub fn flip_compare(
    size: (u32, u32),
    reference_rgba: &[u8],
    test_size: (u32, u32),
    test_rgba: &[u8],
) -> Result<(FlipStats, Vec<u8>), CompareError> {
    let (w, h) = size;
    if size != test_size {
        return Err(CompareError::SizeMismatch(w, h, test_size.0, test_size.1));
    }
    for buf in [reference_rgba, test_rgba] {
        if buf.len() != (w as usize) * (h as usize) * 4 {
            return Err(CompareError::BadBuffer(buf.len(), w, h));
        }
    }
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference_rgba));
    let test = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test_rgba));
    let error_map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mut pool = nv_flip::FlipPool::from_image(&error_map);
    let stats = FlipStats {
        mean: pool.mean(),
        p95: pool.get_percentile(0.95, false),
        p99: pool.get_percentile(0.99, false),
        max: pool.max_value(),
    };
    let diff = error_map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    Ok((stats, diff))
}

/// Rec. 709 (sRGB primaries) luminance weights of linear red, green and blue; they sum to 1.
pub const REC709_LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// HDR data that cannot be measured.
#[derive(Debug, Error, PartialEq)]
pub enum LuminanceError {
    /// A buffer of channel values is not whole RGBA pixels.
    #[error("{0} channel values are not whole RGBA pixels (4 channels each)")]
    NotRgba(usize),
    /// Two luminance buffers of one measure hold different pixel counts.
    #[error("the {what} image has {len} pixels, the {against} image {expected}")]
    SizeMismatch {
        /// The buffer that differs.
        what: &'static str,
        /// Its pixel count.
        len: usize,
        /// The buffer it is measured against.
        against: &'static str,
        /// That buffer's pixel count.
        expected: usize,
    },
}

/// An IEEE 754 half-precision float (its bits, as an `Rgba16Float` texture stores them) as an
/// `f32`: exact for every value, subnormals, infinities and NaN included.
pub fn f16_to_f32(bits: u16) -> f32 {
    let negative = bits & 0x8000 != 0;
    let exponent = u32::from((bits >> 10) & 0x1f);
    let mantissa = u32::from(bits & 0x3ff);
    let magnitude = match exponent {
        // Zero and subnormals: mantissa × 2⁻²⁴ (exact in f32).
        0 => mantissa as f32 * (1.0 / 16_777_216.0),
        // Infinity (mantissa 0) or NaN.
        0x1f => f32::from_bits(0x7f80_0000 | (mantissa << 13)),
        // Normal: rebias the exponent from 15 to 127, widen the mantissa from 10 to 23 bits.
        e => f32::from_bits(((e + 112) << 23) | (mantissa << 13)),
    };
    if negative { -magnitude } else { magnitude }
}

/// The Rec. 709 luminance of one linear RGB pixel as the tone map shows it: a pixel with a
/// non-finite channel is black, negative channels count as 0.
fn pixel_luminance(r: f32, g: f32, b: f32) -> f32 {
    if !(r.is_finite() && g.is_finite() && b.is_finite()) {
        return 0.0;
    }
    let [wr, wg, wb] = REC709_LUMINANCE;
    wr * r.max(0.0) + wg * g.max(0.0) + wb * b.max(0.0)
}

/// Per-pixel Rec. 709 luminance of linear RGBA `f32` data (alpha ignored; a pixel with a
/// non-finite channel counts as black and negative channels as 0, as the tone map shows them).
pub fn luminance_rgba_f32(rgba: &[f32]) -> Result<Vec<f32>, LuminanceError> {
    if !rgba.len().is_multiple_of(4) {
        return Err(LuminanceError::NotRgba(rgba.len()));
    }
    Ok(rgba.chunks_exact(4).map(|p| pixel_luminance(p[0], p[1], p[2])).collect())
}

/// Per-pixel Rec. 709 luminance of linear RGBA half-float data (the bits of an `Rgba16Float`
/// image, such as the renderer's HDR target), as [`luminance_rgba_f32`].
pub fn luminance_rgba_f16(rgba: &[u16]) -> Result<Vec<f32>, LuminanceError> {
    if !rgba.len().is_multiple_of(4) {
        return Err(LuminanceError::NotRgba(rgba.len()));
    }
    Ok(rgba
        .chunks_exact(4)
        .map(|p| pixel_luminance(f16_to_f32(p[0]), f16_to_f32(p[1]), f16_to_f32(p[2])))
        .collect())
}

/// Refuses `buffer` (named `what`) when its pixel count differs from `against`'s.
fn same_size(
    what: &'static str,
    buffer: &[f32],
    against: &'static str,
    other: &[f32],
) -> Result<(), LuminanceError> {
    if buffer.len() == other.len() {
        return Ok(());
    }
    Err(LuminanceError::SizeMismatch { what, len: buffer.len(), against, expected: other.len() })
}

/// `numerator / denominator`, where a zero denominator gives 0 when the numerator is 0 too
/// (nothing to measure, nothing wrong) and infinity otherwise (an error against no light).
fn relative(numerator: f64, denominator: f64) -> f64 {
    if denominator > 0.0 {
        numerator / denominator
    } else if numerator == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// The light a frame's shadows get wrong, relative to the light its shadows act on:
/// `Σ |shadowed − reference| / Σ unshadowed` over the pixels of three per-pixel luminance
/// buffers of one frame (HDR, before tone mapping): `shadowed` as rendered, `reference` with
/// exact visibility, `unshadowed` with shadows disabled.
///
/// 0 is exact; a shadow test that darkens or lights every pixel wrongly by its whole light
/// scores 1. When the unshadowed frame has no light at all the result is 0 if the shadowed
/// frame matches the reference and infinity if it does not. Buffers of different pixel counts
/// are refused.
pub fn light_error(shadowed: &[f32], reference: &[f32], unshadowed: &[f32]) -> Result<f64, LuminanceError> {
    same_size("reference", reference, "shadowed", shadowed)?;
    same_size("unshadowed", unshadowed, "shadowed", shadowed)?;
    let wrong: f64 = shadowed.iter().zip(reference).map(|(&s, &r)| f64::from((s - r).abs())).sum();
    let light: f64 = unshadowed.iter().map(|&u| f64::from(u)).sum();
    Ok(relative(wrong, light))
}

/// How much a frame changes from the one before it with nothing in the scene moving:
/// `mean |frame − previous| / mean frame` over two per-pixel luminance buffers (HDR, before
/// tone mapping). 0 for a deterministic renderer; a stochastic technique's noise that differs
/// from frame to frame shows here. When `frame` has no light at all the result is 0 if
/// `previous` has none either and infinity if it has. Buffers of different pixel counts are
/// refused.
pub fn flicker(frame: &[f32], previous: &[f32]) -> Result<f64, LuminanceError> {
    same_size("previous", previous, "frame", frame)?;
    let change: f64 = frame.iter().zip(previous).map(|(&a, &b)| f64::from((a - b).abs())).sum();
    let light: f64 = frame.iter().map(|&l| f64::from(l)).sum();
    // Both means are over the same pixel count, which cancels.
    Ok(relative(change, light))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_zero_error() {
        let img: Vec<u8> = (0..16 * 16 * 4).map(|i| (i * 7 % 256) as u8).collect();
        let (s, diff) = flip_compare((16, 16), &img, (16, 16), &img).unwrap();
        // FLIP's pool reports the smallest normal float rather than exact zero.
        assert!(s.mean <= f32::MIN_POSITIVE && s.max <= f32::MIN_POSITIVE, "{s:?}");
        assert_eq!(diff.len(), 16 * 16 * 3);
    }

    #[test]
    fn black_versus_white_is_a_large_error() {
        let black = vec![0u8; 8 * 8 * 4];
        let white = vec![255u8; 8 * 8 * 4];
        let (s, _) = flip_compare((8, 8), &black, (8, 8), &white).unwrap();
        assert!(s.mean > 0.5, "{s:?}");
    }

    #[test]
    fn size_mismatch_is_an_error() {
        assert!(matches!(
            flip_compare((2, 2), &[0; 16], (1, 1), &[0; 4]),
            Err(CompareError::SizeMismatch(2, 2, 1, 1))
        ));
        assert!(matches!(
            flip_compare((2, 2), &[0; 15], (2, 2), &[0; 16]),
            Err(CompareError::BadBuffer(15, 2, 2))
        ));
    }

    #[test]
    fn half_floats_decode_exactly() {
        assert_eq!(f16_to_f32(0x0000), 0.0);
        assert!(f16_to_f32(0x8000).is_sign_negative() && f16_to_f32(0x8000) == 0.0);
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3800), 0.5);
        // 1 + 1/1024: the smallest step above 1.
        assert_eq!(f16_to_f32(0x3c01), 1.0 + 1.0 / 1024.0);
        // The largest half, 65504 = (2 − 2⁻¹⁰) × 2¹⁵.
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        // The smallest subnormal, 2⁻²⁴, and the largest, (1023/1024) × 2⁻¹⁴.
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x03ff), 1023.0 * 2f32.powi(-24));
        // The smallest normal, 2⁻¹⁴.
        assert_eq!(f16_to_f32(0x0400), 2f32.powi(-14));
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert_eq!(f16_to_f32(0xfc00), f32::NEG_INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn luminance_weighs_linear_channels_by_rec709() {
        let rgba = [
            1.0,
            0.0,
            0.0,
            1.0, // red: 0.2126
            0.0,
            1.0,
            0.0,
            0.0, // green: 0.7152
            0.0,
            0.0,
            2.0,
            1.0, // blue ×2: 0.1444
            0.5,
            0.5,
            0.5,
            1.0, // grey: the weights sum to 1
            -1.0,
            1.0,
            0.0,
            1.0, // a negative channel counts as 0
            f32::NAN,
            1.0,
            1.0,
            1.0, // non-finite: black
            1.0,
            f32::INFINITY,
            1.0,
            1.0, // non-finite: black
        ];
        let l = luminance_rgba_f32(&rgba).unwrap();
        let expected = [0.2126, 0.7152, 0.1444, 0.5, 0.7152, 0.0, 0.0];
        assert_eq!(l.len(), expected.len());
        for (got, want) in l.iter().zip(expected) {
            assert!((got - want).abs() < 1e-6, "{l:?}");
        }
        // The same pixels as halves: 1.0 = 0x3c00, 2.0 = 0x4000, 0.5 = 0x3800.
        let half = [0x3c00, 0, 0, 0x3c00, 0, 0x3c00, 0, 0, 0, 0, 0x4000, 0x3c00, 0x3800, 0x3800, 0x3800, 0];
        let lh = luminance_rgba_f16(&half).unwrap();
        for (got, want) in lh.iter().zip(expected) {
            assert!((got - want).abs() < 1e-6, "{lh:?}");
        }
        assert_eq!(luminance_rgba_f32(&[]), Ok(vec![]));
        assert_eq!(luminance_rgba_f32(&[1.0; 6]), Err(LuminanceError::NotRgba(6)));
        assert_eq!(luminance_rgba_f16(&[0; 3]), Err(LuminanceError::NotRgba(3)));
    }

    #[test]
    fn light_error_is_the_wrong_light_over_the_unshadowed_light() {
        // |0.5 − 0.5| + |2 − 1.5| + |0 − 0.25| = 0.75 of 1 + 2 + 1 = 4.
        let e = light_error(&[0.5, 2.0, 0.0], &[0.5, 1.5, 0.25], &[1.0, 2.0, 1.0]).unwrap();
        assert!((e - 0.1875).abs() < 1e-12, "{e}");
        // Exact shadows: 0.
        assert_eq!(light_error(&[0.3, 1.0], &[0.3, 1.0], &[1.0, 1.0]), Ok(0.0));
        // Every pixel's light shadowed where it is lit: 1.
        assert_eq!(light_error(&[0.0, 0.0], &[1.0, 2.0], &[1.0, 2.0]), Ok(1.0));
        // Errors of opposite sign do not cancel: 1 + 1 of 4.
        assert_eq!(light_error(&[0.0, 2.0], &[1.0, 1.0], &[2.0, 2.0]), Ok(0.5));
    }

    #[test]
    fn light_error_without_light_is_defined() {
        assert_eq!(light_error(&[0.0; 3], &[0.0; 3], &[0.0; 3]), Ok(0.0));
        assert_eq!(light_error(&[], &[], &[]), Ok(0.0));
        assert_eq!(light_error(&[0.5, 0.0], &[0.0, 0.0], &[0.0, 0.0]), Ok(f64::INFINITY));
    }

    #[test]
    fn light_error_refuses_buffers_of_other_sizes() {
        assert_eq!(
            light_error(&[0.0; 4], &[0.0; 3], &[0.0; 4]),
            Err(LuminanceError::SizeMismatch { what: "reference", len: 3, against: "shadowed", expected: 4 })
        );
        assert_eq!(
            light_error(&[0.0; 4], &[0.0; 4], &[0.0; 5]),
            Err(LuminanceError::SizeMismatch {
                what: "unshadowed",
                len: 5,
                against: "shadowed",
                expected: 4
            })
        );
    }

    #[test]
    fn flicker_is_the_mean_change_over_the_mean_light() {
        // Mean |Δ| = (0 + 1) / 2 = 0.5 over mean luminance (1 + 3) / 2 = 2.
        assert_eq!(flicker(&[1.0, 3.0], &[1.0, 2.0]), Ok(0.25));
        // A still frame rendered twice alike: 0.
        assert_eq!(flicker(&[0.2, 0.7, 1.5], &[0.2, 0.7, 1.5]), Ok(0.0));
        // Changes of opposite sign do not cancel: (1 + 1) / 2 over (1 + 1) / 2.
        assert_eq!(flicker(&[0.0, 2.0], &[1.0, 1.0]), Ok(1.0));
    }

    #[test]
    fn flicker_without_light_is_defined_and_sizes_must_match() {
        assert_eq!(flicker(&[0.0, 0.0], &[0.0, 0.0]), Ok(0.0));
        assert_eq!(flicker(&[], &[]), Ok(0.0));
        assert_eq!(flicker(&[0.0, 0.0], &[1.0, 0.0]), Ok(f64::INFINITY));
        assert_eq!(
            flicker(&[1.0; 2], &[1.0; 3]),
            Err(LuminanceError::SizeMismatch { what: "previous", len: 3, against: "frame", expected: 2 })
        );
    }
}

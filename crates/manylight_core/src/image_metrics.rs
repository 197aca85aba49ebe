//! Image error metrics: NVIDIA FLIP (through `nv-flip`, as the wgpu project uses) between a
//! reference and a test image, summarised by its mean and high percentiles.

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
}

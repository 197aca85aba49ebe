//! The tone map on the CPU: the twin of `shaders/tonemap.wgsl` (exposure, then the ACES filmic
//! curve of Narkowicz 2015), and the sRGB encoding an `*Srgb` target applies, for CPU reference
//! images.

use glam::Vec3;

/// The ACES filmic fit (Narkowicz 2015), saturated to 0..1.
pub fn aces_fitted(x: Vec3) -> Vec3 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// The sRGB transfer function of a linear value in 0..1.
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 { v * 12.92 } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

/// An HDR colour as the tone-map pass writes it into an RGBA8 sRGB target.
pub fn tonemap_to_srgb8(hdr: Vec3, exposure: f32) -> [u8; 4] {
    let safe = if hdr.is_finite() { hdr.max(Vec3::ZERO) } else { Vec3::ZERO };
    let mapped = aces_fitted(safe * exposure);
    let q = |v: f32| (linear_to_srgb(v) * 255.0 + 0.5).clamp(0.0, 255.0) as u8;
    [q(mapped.x), q(mapped.y), q(mapped.z), 255]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn black_stays_black_and_bright_saturates() {
        assert_eq!(tonemap_to_srgb8(Vec3::ZERO, 1.0), [0, 0, 0, 255]);
        assert_eq!(tonemap_to_srgb8(Vec3::splat(1.0e4), 1.0), [255, 255, 255, 255]);
        assert_eq!(tonemap_to_srgb8(Vec3::splat(f32::NAN), 1.0), [0, 0, 0, 255]);
    }

    #[test]
    fn the_curve_is_monotonic() {
        let mut last = -1.0;
        for i in 0..1000 {
            let y = aces_fitted(Vec3::splat(i as f32 * 0.01)).x;
            assert!(y >= last);
            last = y;
        }
    }
}

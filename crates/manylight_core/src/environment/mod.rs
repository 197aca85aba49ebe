//! Image-based lighting without a GPU: the equirectangular environment the renderer uploads,
//! and the CPU references its split-sum approximation is measured against.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// An equirectangular (latitude-longitude) HDR panorama in linear RGB, as the renderer
/// uploads it. Row 0 is the zenith (+Y); the centre column looks along -Z (Bevy's forward);
/// [`equirect_uv`] and [`equirect_direction`] give the mapping, which `shaders/environment.wgsl`
/// repeats.
///
/// Every texel is finite and non-negative: decoders clamp what is not and count it.
#[derive(Clone, Debug, PartialEq)]
pub struct EquirectImage {
    /// Width in texels (twice the height for a full panorama).
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Linear RGB radiance, row-major from the top row.
    pub texels: Vec<[f32; 3]>,
}

/// Where unit direction `d` lands in an equirectangular image: u in 0..1 from left to right
/// (0.5 looks along -Z, 0.75 along +X), v in 0..1 from the zenith down.
pub fn equirect_uv(d: Vec3) -> Vec2 {
    let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u, v)
}

/// The unit direction at `uv` of an equirectangular image (the inverse of [`equirect_uv`]).
pub fn equirect_direction(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_and_direction_are_inverse() {
        for &(u, v) in &[(0.5, 0.5), (0.75, 0.5), (0.1, 0.2), (0.9, 0.8), (0.3, 0.6)] {
            let uv = Vec2::new(u, v);
            let back = equirect_uv(equirect_direction(uv));
            assert!((back - uv).abs().max_element() < 1e-5, "{uv} -> {back}");
        }
        assert!((equirect_direction(Vec2::new(0.5, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
        assert!((equirect_direction(Vec2::new(0.75, 0.5)) - Vec3::X).length() < 1e-6);
        assert!((equirect_direction(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
    }
}

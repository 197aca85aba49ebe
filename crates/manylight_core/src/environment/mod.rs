//! Image-based lighting without a GPU: the equirectangular environment the renderer uploads,
//! and the CPU references its split-sum approximation is measured against.
//!
//! - [`EquirectImage`], its direction mapping and [`sample_equirect`]: the environment as
//!   radiance per direction.
//! - [`reference`](mod@reference): the Monte-Carlo integral of the environment against the renderer's PBR
//!   BRDF, the ground truth.
//! - [`split_sum`]: what the GPU precomputes and shades with (prefiltered specular, irradiance,
//!   the GGX lookup table), computed without caches, so tests and reports can compare the two.
//! - [`ggx`] and [`sequence`]: the sampling both are built from.

pub mod ggx;
pub mod reference;
pub mod sequence;
pub mod split_sum;

pub use reference::reference_radiance;
pub use split_sum::{
    SplitSumSamples, diffuse_fresnel, ggx_lut, irradiance, prefiltered_specular, split_sum_radiance,
};

use crate::brdf::{PBR_DIELECTRIC_F0, SurfaceParams};
use crate::material::ShadingModel;
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

impl EquirectImage {
    /// A `width` x `height` panorama whose texels hold `radiance` of the direction through each
    /// texel's centre: analytic test environments and constant ones.
    pub fn from_fn(width: u32, height: u32, radiance: impl Fn(Vec3) -> [f32; 3]) -> EquirectImage {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let uv = Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
                radiance(equirect_direction(uv))
            })
            .collect();
        EquirectImage { width, height, texels }
    }

    /// The texel at column `x`, row `y`, or black outside the image or its texel list.
    fn texel(&self, x: u32, y: u32) -> Vec3 {
        let index = y as usize * self.width as usize + x as usize;
        match self.texels.get(index) {
            Some(&t) if x < self.width => Vec3::from(t),
            _ => Vec3::ZERO,
        }
    }
}

/// Radiance arriving from direction `d` (any length): the bilinear interpolation of the four
/// texel centres around it, texel `(i, j)`'s centre at `((i + 0.5) / width, (j + 0.5) / height)`,
/// wrapping across the left/right seam and clamped at the poles' rows (as a GPU sampler with
/// repeat U and clamp-to-edge V does). Black for a zero or non-finite `d` or an empty image.
pub fn sample_equirect(env: &EquirectImage, d: Vec3) -> Vec3 {
    let Some(d) = d.try_normalize() else { return Vec3::ZERO };
    if env.width == 0 || env.height == 0 {
        return Vec3::ZERO;
    }
    let uv = equirect_uv(d);
    let x = uv.x * env.width as f32 - 0.5;
    let y = (uv.y * env.height as f32 - 0.5).clamp(0.0, (env.height - 1) as f32);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |i: f32| i.rem_euclid(env.width as f32) as u32 % env.width;
    let (x0, x1) = (wrap(x0), wrap(x0 + 1.0));
    let y0 = y0 as u32;
    let y1 = (y0 + 1).min(env.height - 1);
    let top = env.texel(x0, y0).lerp(env.texel(x1, y0), fx);
    let bottom = env.texel(x0, y1).lerp(env.texel(x1, y1), fx);
    top.lerp(bottom, fy)
}

/// The PBR material parameters the environment integrals need (the rest of
/// [`SurfaceParams`] is the normal, passed apart, and other models' parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PbrSurface {
    /// Linear base colour.
    pub albedo: Vec3,
    /// Metalness, clamped to 0..1 where used.
    pub metallic: f32,
    /// Perceptual roughness, clamped to [`crate::brdf::PBR_MIN_ROUGHNESS`]..1 where used.
    pub roughness: f32,
}

impl PbrSurface {
    /// Reflectance at normal incidence: `lerp(0.04, albedo, metallic)`.
    pub fn f0(&self) -> Vec3 {
        Vec3::splat(PBR_DIELECTRIC_F0).lerp(self.albedo, self.metallic.clamp(0.0, 1.0))
    }

    /// The Lambert lobe's colour: `albedo (1 - metallic)`.
    pub fn diffuse_color(&self) -> Vec3 {
        self.albedo * (1.0 - self.metallic.clamp(0.0, 1.0))
    }

    /// GGX `alpha = roughness^2`, with roughness clamped as the renderer clamps it.
    pub fn alpha(&self) -> f32 {
        ggx::alpha(self.roughness)
    }

    /// The renderer's [`SurfaceParams`] for this material at unit `normal`.
    pub fn surface_params(&self, normal: Vec3) -> SurfaceParams {
        SurfaceParams {
            albedo: self.albedo,
            normal,
            shininess: 1.0,
            specular: 0.0,
            metallic: self.metallic,
            roughness: self.roughness,
            model: ShadingModel::Pbr,
        }
    }
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
mod integral_tests;

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

    /// A 4 x 2 image whose texel `(x, y)` holds `(x, y, 1)`.
    fn ramp() -> EquirectImage {
        let texels = (0..2).flat_map(|y| (0..4).map(move |x| [x as f32, y as f32, 1.0])).collect();
        EquirectImage { width: 4, height: 2, texels }
    }

    #[test]
    fn sampling_at_a_texel_centre_returns_the_texel() {
        let env = ramp();
        for (x, y) in [(0, 0), (1, 0), (2, 1), (3, 1)] {
            let uv = Vec2::new((x as f32 + 0.5) / 4.0, (y as f32 + 0.5) / 2.0);
            let c = sample_equirect(&env, equirect_direction(uv));
            assert!((c - Vec3::new(x as f32, y as f32, 1.0)).length() < 1e-4, "({x}, {y}): {c}");
        }
    }

    #[test]
    fn sampling_wraps_across_the_seam_and_clamps_at_the_poles() {
        let env = ramp();
        // u = 0 lies halfway between column 3's centre and column 0's (wrapped).
        let seam = sample_equirect(&env, equirect_direction(Vec2::new(0.0, 0.25)));
        assert!((seam - Vec3::new(1.5, 0.0, 1.0)).length() < 1e-4, "{seam}");
        // Above the first row's centres only the first row contributes.
        let zenith = sample_equirect(&env, Vec3::Y);
        assert!(zenith.y.abs() < 1e-6 && zenith.is_finite(), "{zenith}");
        let nadir = sample_equirect(&env, Vec3::NEG_Y);
        assert!((nadir.y - 1.0).abs() < 1e-6, "{nadir}");
    }

    #[test]
    fn sampling_degenerate_inputs_is_black() {
        let env = ramp();
        assert_eq!(sample_equirect(&env, Vec3::ZERO), Vec3::ZERO);
        assert_eq!(sample_equirect(&env, Vec3::new(f32::NAN, 1.0, 0.0)), Vec3::ZERO);
        let empty = EquirectImage { width: 0, height: 0, texels: Vec::new() };
        assert_eq!(sample_equirect(&empty, Vec3::X), Vec3::ZERO);
        // A texel list shorter than the size says reads as black, not out of bounds.
        let short = EquirectImage { width: 4, height: 2, texels: vec![[1.0; 3]; 3] };
        assert!(sample_equirect(&short, Vec3::NEG_Y).is_finite());
    }

    #[test]
    fn from_fn_puts_each_texels_direction_through_its_centre() {
        let env = EquirectImage::from_fn(8, 4, |d| d.to_array());
        for (i, t) in env.texels.iter().enumerate() {
            let (x, y) = ((i % 8) as f32, (i / 8) as f32);
            let d = equirect_direction(Vec2::new((x + 0.5) / 8.0, (y + 0.5) / 4.0));
            assert!((Vec3::from(*t) - d).length() < 1e-6);
        }
    }
}

//! The split-sum approximation (Karis 2013, "Real Shading in Unreal Engine 4") as the GPU
//! computes it, without its caches (cubemap texels, mip levels, lookup-table cells): what the
//! GPU's output converges to as those grow, and a twin for its tests.
//!
//! The integral of [`super::reference`](mod@super::reference) is split into factors that can
//! be precomputed:
//!
//! ```text
//! specular ~ prefiltered_specular(r, roughness) * (f0 * scale(n.v, roughness) + bias(n.v, roughness))
//! diffuse  ~ c_diff * (1 - f0) * diffuse_fresnel(n.v) * irradiance(n)
//! ```
//!
//! - `prefiltered_specular` averages the environment over the GGX lobe about the mirror
//!   direction `r`, assuming `n = v = r` (the lobe's shape at normal incidence).
//! - `(scale, bias)` ([`ggx_lut`]) is the BRDF's specular integral against a white environment,
//!   split by Schlick's Fresnel `F = f0 (1 - (1 - v.h)^5) + (1 - v.h)^5` into the part that
//!   multiplies `f0` and the part that does not.
//! - The renderer's diffuse lobe is `(1 - F) c_diff / pi`, and `1 - F = (1 - f0)(1 - (1 - v.h)^5)`;
//!   its Fresnel factor averaged over the cosine lobe is [`diffuse_fresnel`], which depends on
//!   `n.v` alone (the half vector does not depend on roughness) and stays within 0.975..1. With
//!   it every factor is exact for a constant environment, where the split-sum then equals the
//!   reference; a shader that weights the diffuse term otherwise must change this twin too.
//!
//! Every function takes its sample count, so reports can sweep it; points are unscrambled
//! Hammersley sets, as a prefilter shader uses.

use super::sequence::{TangentFrame, cosine_hemisphere, hammersley};
use super::{EquirectImage, PbrSurface, ggx, sample_equirect};
use crate::brdf::PBR_MIN_N_DOT_V;
use glam::Vec3;

/// Sample counts of the three precomputed factors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitSumSamples {
    /// Per [`ggx_lut`] entry (and [`diffuse_fresnel`]).
    pub lut: u32,
    /// Per [`prefiltered_specular`] direction.
    pub specular: u32,
    /// Per [`irradiance`] direction.
    pub irradiance: u32,
}

impl Default for SplitSumSamples {
    /// 1,024 each, the glTF Sample Viewer's prefilter count.
    fn default() -> SplitSumSamples {
        SplitSumSamples { lut: 1024, specular: 1024, irradiance: 1024 }
    }
}

/// The GGX lookup table's entry `(scale, bias)` at `n_dot_v` and perceptual `roughness`: the
/// renderer's specular lobe reflects `f0 * scale + bias` of a white environment.
///
/// With `h` drawn from [`ggx::sample_ndf`] and `l = reflect(-v, h)`, the density of `l` is
/// `D (n.h) / (4 v.h)`, so the estimator of `integral F D V (n.l) dl` is
/// `F * G_vis` with `G_vis = 4 V (n.l) (v.h) / (n.h)`, `V` the renderer's visibility
/// ([`ggx::visibility`]). Splitting `F` by `Fc = (1 - v.h)^5`:
/// `scale = mean((1 - Fc) G_vis)`, `bias = mean(Fc G_vis)`.
pub fn ggx_lut(n_dot_v: f32, roughness: f32, samples: u32) -> (f32, f32) {
    let n_dot_v = n_dot_v.clamp(PBR_MIN_N_DOT_V, 1.0);
    let a2 = ggx::alpha(roughness).powi(2);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let (mut scale, mut bias) = (0.0, 0.0);
    for i in 0..samples {
        let h = ggx::sample_ndf(hammersley(i, samples), a2);
        let v_dot_h = v.dot(h);
        let n_dot_l = 2.0 * v_dot_h * h.z - v.z;
        if n_dot_l <= 0.0 || v_dot_h <= 0.0 {
            continue;
        }
        let g_vis = 4.0 * ggx::visibility(n_dot_l, n_dot_v, a2) * n_dot_l * v_dot_h / h.z;
        let fc = (1.0 - v_dot_h).powi(5);
        scale += (1.0 - fc) * g_vis;
        bias += fc * g_vis;
    }
    let n = samples.max(1) as f32;
    (scale / n, bias / n)
}

/// The Fresnel factor of the renderer's diffuse lobe, averaged over cosine-distributed light
/// directions at `n_dot_v`: `(1 / pi) integral (1 - (1 - v.h)^5) (n.l) dl`. The diffuse term
/// reflects `c_diff (1 - f0)` times this of the irradiance. Near 1 at normal incidence, lower
/// at grazing views.
pub fn diffuse_fresnel(n_dot_v: f32, samples: u32) -> f32 {
    let n_dot_v = n_dot_v.clamp(PBR_MIN_N_DOT_V, 1.0);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let mut sum = 0.0;
    for i in 0..samples {
        let l = cosine_hemisphere(hammersley(i, samples));
        let v_dot_h = v.dot((v + l).normalize_or(Vec3::Z)).clamp(0.0, 1.0);
        sum += 1.0 - (1.0 - v_dot_h).powi(5);
    }
    sum / samples.max(1) as f32
}

/// The environment averaged over the GGX lobe of perceptual `roughness` about unit mirror
/// direction `r`, each direction weighted by `n.l` with `n = v = r` (Karis's
/// `PrefilterEnvMap`). A constant environment prefilters to itself.
pub fn prefiltered_specular(env: &EquirectImage, r: Vec3, roughness: f32, samples: u32) -> Vec3 {
    let Some(n) = r.try_normalize() else { return Vec3::ZERO };
    let frame = TangentFrame::new(n);
    let a2 = ggx::alpha(roughness).powi(2);
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
    for i in 0..samples {
        let h = ggx::sample_ndf(hammersley(i, samples), a2);
        let n_dot_l = 2.0 * h.z * h.z - 1.0;
        if n_dot_l > 0.0 {
            let l = Vec3::new(2.0 * h.z * h.x, 2.0 * h.z * h.y, n_dot_l);
            sum += sample_equirect(env, frame.to_world(l)) * n_dot_l;
            weight += n_dot_l;
        }
    }
    if weight > 0.0 { sum / weight } else { sample_equirect(env, n) }
}

/// Irradiance at unit normal `n` divided by pi, `(1 / pi) integral L_env(l) (n.l) dl`, by
/// cosine-distributed samples: a Lambert surface of colour `c` reflects `c` times this. A
/// constant environment gives its radiance.
pub fn irradiance(env: &EquirectImage, n: Vec3, samples: u32) -> Vec3 {
    let Some(n) = n.try_normalize() else { return Vec3::ZERO };
    let frame = TangentFrame::new(n);
    let mut sum = Vec3::ZERO;
    for i in 0..samples {
        sum += sample_equirect(env, frame.to_world(cosine_hemisphere(hammersley(i, samples))));
    }
    sum / samples.max(1) as f32
}

/// The split-sum estimate of what [`super::reference_radiance`] computes: the environment's
/// radiance reflected towards unit `v` by `surface` at unit normal `n` (see the module
/// documentation for the factors).
pub fn split_sum_radiance(
    env: &EquirectImage,
    n: Vec3,
    v: Vec3,
    surface: &PbrSurface,
    samples: SplitSumSamples,
) -> Vec3 {
    let Some(n) = n.try_normalize() else { return Vec3::ZERO };
    let v = v.try_normalize().unwrap_or(n);
    let n_dot_v = n.dot(v).max(PBR_MIN_N_DOT_V);
    let r = 2.0 * n.dot(v) * n - v;
    let f0 = surface.f0();
    let (scale, bias) = ggx_lut(n_dot_v, surface.roughness, samples.lut);
    let specular = prefiltered_specular(env, r, surface.roughness, samples.specular) * (f0 * scale + bias);
    let diffuse_weight = surface.diffuse_color() * (Vec3::ONE - f0) * diffuse_fresnel(n_dot_v, samples.lut);
    specular + diffuse_weight * irradiance(env, n, samples.irradiance)
}

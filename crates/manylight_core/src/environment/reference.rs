//! The ground truth for image-based lighting: the radiance a PBR surface reflects of an
//! environment, `L_o(v) = integral over l of L_env(l) f(l, v) (n.l)`, by Monte-Carlo
//! integration against the renderer's BRDF ([`crate::brdf::pbr_point_light`]'s formula, term
//! for term from [`ggx`]).
//!
//! Steps, per estimate:
//! 1. Each iteration draws two light directions: one reflected about a GGX half vector drawn
//!    from the normals visible from `v` ([`ggx::sample_vndf`]), which finds the specular lobe,
//!    and one cosine-distributed ([`sequence::cosine_hemisphere`]), which finds the diffuse lobe.
//! 2. Each direction contributes `L_env(l) f(l, v) (n.l) / (pdf_ggx(l) + pdf_cosine(l))`: the
//!    balance heuristic of multiple importance sampling with one sample per technique, unbiased
//!    whatever the roughness, and never dividing by a density near zero where the integrand
//!    is not (the cosine density covers the whole hemisphere).
//! 3. The points come from a scrambled Hammersley set ([`sequence::Scramble`]) seeded by the
//!    caller, so an estimate is deterministic and neighbouring pixels' errors are independent.
//!
//! The BRDF is evaluated in the tangent frame, where [`ggx::distribution`] stays accurate for
//! the smoothest lobes the renderer shades; a view below the horizon is moved onto it (the
//! renderer clamps `n.v` there), since sampling visible normals needs a view above the surface.

use super::sequence::{self, Scramble, TangentFrame};
use super::{EquirectImage, PbrSurface, ggx, sample_equirect};
use crate::brdf::PBR_MIN_N_DOT_V;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Reflected radiance of `env` towards `v` (unit, towards the eye) at a surface with unit
/// normal `n` and material `surface`, estimated from `2 * samples` directions (see the module
/// documentation); `seed` picks the scramble, a pixel index for example. Black for zero
/// samples or a zero normal.
pub fn reference_radiance(
    env: &EquirectImage,
    n: Vec3,
    v: Vec3,
    surface: &PbrSurface,
    samples: u32,
    seed: u64,
) -> Vec3 {
    let Some(n) = n.try_normalize() else { return Vec3::ZERO };
    if samples == 0 {
        return Vec3::ZERO;
    }
    let v = v.try_normalize().unwrap_or(n);
    let estimator = Estimator::new(env, n, v, surface);
    let specular_points = Scramble::from_seed(seed);
    let diffuse_points = Scramble::from_seed(seed ^ 0x5bd1_e995_0000_0001);
    let mut sum = Vec3::ZERO;
    for i in 0..samples {
        sum += estimator.contribution(estimator.specular_direction(specular_points.hammersley(i, samples)));
        sum += estimator.contribution(sequence::cosine_hemisphere(diffuse_points.hammersley(i, samples)));
    }
    sum / samples as f32
}

/// What every sample of one estimate shares; directions are local to `frame`.
struct Estimator<'a> {
    env: &'a EquirectImage,
    frame: TangentFrame,
    /// The view, above the horizon.
    v: Vec3,
    a2: f32,
    alpha: f32,
    f0: Vec3,
    diffuse_color: Vec3,
}

impl<'a> Estimator<'a> {
    fn new(env: &'a EquirectImage, n: Vec3, v: Vec3, surface: &PbrSurface) -> Estimator<'a> {
        let frame = TangentFrame::new(n);
        let alpha = surface.alpha();
        Estimator {
            env,
            frame,
            v: view_above_horizon(frame.to_local(v)),
            a2: alpha * alpha,
            alpha,
            f0: surface.f0(),
            diffuse_color: surface.diffuse_color(),
        }
    }

    /// A light direction reflected about a visible GGX normal drawn with `xi`.
    fn specular_direction(&self, xi: Vec2) -> Vec3 {
        let h = ggx::sample_vndf(xi, self.v, self.alpha);
        2.0 * self.v.dot(h) * h - self.v
    }

    /// `L_env(l) f(l, v) (n.l)` over the sum of both techniques' densities at `l`.
    fn contribution(&self, l: Vec3) -> Vec3 {
        if l.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (self.v + l).normalize();
        let pdf = ggx::pdf_vndf_reflected(h, self.v.z, self.a2) + l.z * FRAC_1_PI;
        sample_equirect(self.env, self.frame.to_world(l)) * self.brdf_cos(l, h) / pdf
    }

    /// The renderer's BRDF times `n.l` for light from `l` with half vector `h`
    /// (`((1 - F) c_diff / pi + F D V) n.l`).
    fn brdf_cos(&self, l: Vec3, h: Vec3) -> Vec3 {
        let fc = (1.0 - self.v.dot(h).clamp(0.0, 1.0)).powi(5);
        let fresnel = self.f0 + (Vec3::ONE - self.f0) * fc;
        let specular = ggx::distribution(h, self.a2) * ggx::visibility(l.z, self.v.z, self.a2);
        ((Vec3::ONE - fresnel) * self.diffuse_color * FRAC_1_PI + fresnel * specular) * l.z
    }
}

/// `v` (local, unit) if it is at least [`PBR_MIN_N_DOT_V`] above the horizon, otherwise the
/// direction at that elevation with the same azimuth.
fn view_above_horizon(v: Vec3) -> Vec3 {
    if v.z >= PBR_MIN_N_DOT_V {
        return v;
    }
    let azimuth = Vec3::new(v.x, v.y, 0.0).normalize_or(Vec3::X);
    let z = PBR_MIN_N_DOT_V;
    azimuth * (1.0 - z * z).sqrt() + Vec3::new(0.0, 0.0, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::pbr_point_light;

    /// The estimator's BRDF is the renderer's, on both sides of a tilted frame.
    #[test]
    fn the_estimators_brdf_is_the_renderers() {
        let env = EquirectImage::from_fn(8, 4, |_| [1.0; 3]);
        let n = Vec3::new(0.2, 0.9, -0.3).normalize();
        let surface = PbrSurface { albedo: Vec3::new(0.7, 0.4, 0.9), metallic: 0.4, roughness: 0.35 };
        let frame = TangentFrame::new(n);
        let v = frame.to_world(Vec3::new(0.6, -0.2, 0.77).normalize());
        let e = Estimator::new(&env, n, v, &surface);
        for l_local in [Vec3::new(-0.5, 0.3, 0.81), Vec3::new(0.1, 0.1, 0.99), Vec3::new(0.9, 0.0, 0.2)] {
            let l_local = l_local.normalize();
            let l = frame.to_world(l_local);
            let ours = e.brdf_cos(l_local, (e.v + l_local).normalize());
            let renderer = pbr_point_light(&surface.surface_params(n), n.dot(l), v, l);
            assert!(
                (ours - renderer).abs().max_element() < 1e-5 * renderer.max_element(),
                "{ours} vs {renderer}"
            );
        }
    }

    #[test]
    fn a_view_below_the_horizon_is_lifted_onto_it() {
        let v = view_above_horizon(Vec3::new(0.6, 0.0, -0.8));
        assert!((v.length() - 1.0).abs() < 1e-6 && v.z == PBR_MIN_N_DOT_V && v.x > 0.99, "{v}");
        let straight_down = view_above_horizon(Vec3::NEG_Z);
        assert!(straight_down.is_finite() && straight_down.z > 0.0);
    }
}

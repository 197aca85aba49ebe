//! The GGX (Trowbridge-Reitz) terms of [`crate::brdf`]'s PBR model, separated so that the
//! environment integrals can importance-sample them, and the two ways of sampling them.
//!
//! `a2` is `alpha^2` with `alpha = roughness^2`, roughness already clamped to
//! [`crate::brdf::PBR_MIN_ROUGHNESS`]. Directions are in a tangent frame with the normal on +Z.
//! A test checks that `F * D * V * n.l` plus the diffuse lobe equals
//! [`crate::brdf::pbr_point_light`], so the two cannot drift apart.

use crate::brdf::PBR_MIN_ROUGHNESS;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// GGX `alpha = roughness^2` of perceptual `roughness`, clamped to
/// [`PBR_MIN_ROUGHNESS`]..1 as the renderer clamps it.
pub fn alpha(roughness: f32) -> f32 {
    let roughness = roughness.clamp(PBR_MIN_ROUGHNESS, 1.0);
    roughness * roughness
}

/// The GGX normal distribution `D(h) = a2 / (pi ((n.h)^2 (a2 - 1) + 1)^2)` of unit half vector
/// `h` (local, `h.z = n.h >= 0`). The bracket is computed as `(h.x^2 + h.y^2) + a2 (h.z)^2`, the
/// same value without `1 - (n.h)^2`'s cancellation, which in `f32` perturbs `D` by percents
/// near the peak of the smoothest lobes (`a2 ~ 4e-6`) and would bias the integrals there.
pub fn distribution(h: Vec3, a2: f32) -> f32 {
    let d = (h.x * h.x + h.y * h.y) + a2 * h.z * h.z;
    a2 / (PI * d * d)
}

/// `n.x + sqrt(a2 + (1 - a2) (n.x)^2)`: the denominator of Smith's GGX masking term for one
/// direction, `G1(x) = 2 n.x / smith_denominator(n.x)`.
fn smith_denominator(n_dot_x: f32, a2: f32) -> f32 {
    n_dot_x + (a2 + (1.0 - a2) * n_dot_x * n_dot_x).sqrt()
}

/// Smith's GGX masking term of one direction, `G1(x) = 2 n.x / (n.x + sqrt(a2 + (1 - a2) (n.x)^2))`.
pub fn smith_g1(n_dot_x: f32, a2: f32) -> f32 {
    2.0 * n_dot_x / smith_denominator(n_dot_x, a2)
}

/// The visibility term `V = G / (4 n.l n.v)` exactly as [`crate::brdf::pbr_point_light`]
/// computes it: `1 / ((n.l + sqrt(a2 + (1 - a2) (n.l)^2)) (n.v + sqrt(a2 + (1 - a2) (n.v)^2)))`,
/// which is the separable Smith form `G1(l) G1(v) / (4 n.l n.v)`.
pub fn visibility(n_dot_l: f32, n_dot_v: f32, a2: f32) -> f32 {
    1.0 / (smith_denominator(n_dot_l, a2) * smith_denominator(n_dot_v, a2))
}

/// A half vector drawn from the GGX distribution of normals, `pdf(h) = D(h) n.h`, from `xi` in
/// `[0, 1)^2` (Walter et al. 2007; Karis 2013's `ImportanceSampleGGX`).
pub fn sample_ndf(xi: Vec2, a2: f32) -> Vec3 {
    let phi = TAU * xi.x;
    let cos_theta = ((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y)).max(0.0).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Density over light directions `l = reflect(-v, h)` when `h` comes from [`sample_ndf`]:
/// `D(h) n.h / (4 v.h)` (the Jacobian of the reflection is `1 / (4 v.h)`); `h` local and unit.
pub fn pdf_ndf_reflected(h: Vec3, v_dot_h: f32, a2: f32) -> f32 {
    distribution(h, a2) * h.z / (4.0 * v_dot_h.max(1e-8))
}

/// A half vector drawn from the GGX distribution of normals visible from `v` (unit, local,
/// `v.z > 0`), from `xi` in `[0, 1)^2` (Heitz 2018, "Sampling the GGX Distribution of Visible
/// Normals"). Fewer reflected directions fall below the horizon than with [`sample_ndf`],
/// which matters at grazing views.
pub fn sample_vndf(xi: Vec2, v: Vec3, alpha: f32) -> Vec3 {
    // 1. Stretch the view into the configuration where the distribution is a unit hemisphere.
    let vh = Vec3::new(alpha * v.x, alpha * v.y, v.z).normalize();
    // 2. An orthonormal basis about it.
    let len_sq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len_sq > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len_sq.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    // 3. A uniform point on the projected disc, warped to the visible half of it.
    let r = xi.x.sqrt();
    let phi = TAU * xi.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    // 4. Lift onto the hemisphere, then unstretch.
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize_or(Vec3::Z)
}

/// Density over light directions `l = reflect(-v, h)` when `h` comes from [`sample_vndf`]:
/// `G1(v) D(h) / (4 n.v)`, written as `D(h) / (2 (n.v + sqrt(a2 + (1 - a2) (n.v)^2)))` so that
/// it stays finite as `n.v` goes to zero; `h` local and unit.
pub fn pdf_vndf_reflected(h: Vec3, n_dot_v: f32, a2: f32) -> f32 {
    distribution(h, a2) / (2.0 * smith_denominator(n_dot_v, a2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{PBR_DIELECTRIC_F0, SurfaceParams, pbr_point_light};
    use crate::environment::sequence::hammersley;
    use crate::material::ShadingModel;

    #[test]
    fn the_terms_rebuild_the_renderers_brdf() {
        let albedo = Vec3::new(0.8, 0.5, 0.2);
        let (metallic, roughness) = (0.3, 0.4);
        let s = SurfaceParams {
            albedo,
            normal: Vec3::Z,
            shininess: 1.0,
            specular: 0.0,
            metallic,
            roughness,
            model: ShadingModel::Pbr,
        };
        let a2 = roughness.powi(4);
        let v = Vec3::new(0.5, 0.1, 0.7).normalize();
        let l = Vec3::new(-0.3, 0.4, 0.6).normalize();
        let h = (v + l).normalize();
        let f0 = Vec3::splat(PBR_DIELECTRIC_F0).lerp(albedo, metallic);
        let fresnel = f0 + (Vec3::ONE - f0) * (1.0 - v.dot(h)).powi(5);
        let specular = fresnel * distribution(h, a2) * visibility(l.z, v.z, a2);
        let diffuse = (Vec3::ONE - fresnel) * albedo * (1.0 - metallic) / PI;
        let expected = (specular + diffuse) * l.z;
        let actual = pbr_point_light(&s, l.z, v, l);
        assert!((expected - actual).abs().max_element() < 1e-6, "{expected} vs {actual}");
    }

    /// The microfacets' projected area is one: the integral of `D(h) n.h` over the hemisphere,
    /// by stratified uniform samples of `cos(theta)`, so [`sample_ndf`]'s density is normalised.
    #[test]
    fn the_ndf_is_normalised() {
        for roughness in [0.2f32, 0.5, 1.0] {
            let a2 = roughness.powi(4);
            let n = 1 << 16;
            let mut sum = 0.0;
            for i in 0..n {
                let xi = hammersley(i, n);
                let cos_theta = xi.y;
                let h = Vec3::new((1.0 - cos_theta * cos_theta).sqrt(), 0.0, cos_theta);
                sum += distribution(h, a2) * cos_theta * TAU;
            }
            let area = sum / n as f32;
            assert!((area - 1.0).abs() < 0.02, "roughness {roughness}: {area}");
        }
    }

    /// Each sampler with its density estimates the same integral, the specular albedo `D V n.l`
    /// over light directions: a wrong density would bias one of them.
    #[test]
    fn vndf_and_ndf_sampling_estimate_the_same_integral() {
        for (roughness, n_dot_v) in [(0.3f32, 0.9f32), (0.7, 0.3), (1.0, 0.05)] {
            let alpha = roughness * roughness;
            let a2 = alpha * alpha;
            let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
            let n = 1 << 14;
            let (mut by_vndf, mut by_ndf) = (0.0, 0.0);
            for i in 0..n {
                let xi = hammersley(i, n);
                for (h, vndf) in [(sample_vndf(xi, v, alpha), true), (sample_ndf(xi, a2), false)] {
                    let l = 2.0 * v.dot(h) * h - v;
                    if l.z <= 0.0 || v.dot(h) <= 0.0 {
                        continue;
                    }
                    let f = distribution(h, a2) * visibility(l.z, n_dot_v, a2) * l.z;
                    if vndf {
                        by_vndf += f / pdf_vndf_reflected(h, n_dot_v, a2);
                    } else {
                        by_ndf += f / pdf_ndf_reflected(h, v.dot(h), a2);
                    }
                }
            }
            let (by_vndf, by_ndf) = (by_vndf / n as f32, by_ndf / n as f32);
            assert!(
                (by_vndf - by_ndf).abs() < 0.01 * by_ndf.max(0.1),
                "roughness {roughness}, n.v {n_dot_v}: VNDF {by_vndf}, NDF {by_ndf}"
            );
        }
    }
}

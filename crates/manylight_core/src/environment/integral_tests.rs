//! The environment integrals checked against each other and against brute-force quadrature:
//! the reference, the split-sum factors, and the split-sum against the reference.

use super::sequence::{TangentFrame, hammersley};
use super::*;
use crate::brdf::pbr_point_light;
use proptest::prelude::*;
use std::f32::consts::TAU;

/// A constant environment of radiance `rgb`.
fn constant(rgb: [f32; 3]) -> EquirectImage {
    EquirectImage::from_fn(16, 8, |_| [rgb[0], rgb[1], rgb[2]])
}

/// A sky whose radiance is the sine of the elevation above the horizon, black below it.
fn sky() -> EquirectImage {
    EquirectImage::from_fn(256, 128, |d| [d.y.max(0.0); 3])
}

/// A unit view at `n_dot_v` from unit `n`.
fn view_at(n: Vec3, n_dot_v: f32) -> Vec3 {
    let frame = TangentFrame::new(n);
    frame.to_world(Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v))
}

/// `integral f(l) dl` over the hemisphere about `n` by `count` stratified uniform samples.
fn hemisphere_quadrature(n: Vec3, count: u32, f: impl Fn(Vec3) -> Vec3) -> Vec3 {
    let frame = TangentFrame::new(n);
    let mut sum = Vec3::ZERO;
    for i in 0..count {
        let xi = hammersley(i, count);
        let (z, phi) = (xi.x, TAU * xi.y);
        let r = (1.0 - z * z).max(0.0).sqrt();
        sum += f(frame.to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z)));
    }
    sum * TAU / count as f32
}

/// The reflected radiance by brute force: the renderer's BRDF against `env` over the hemisphere.
fn brute_force(env: &EquirectImage, n: Vec3, v: Vec3, surface: &PbrSurface) -> Vec3 {
    let params = surface.surface_params(n);
    hemisphere_quadrature(n, 1 << 16, |l| {
        let n_dot_l = n.dot(l);
        if n_dot_l <= 0.0 {
            return Vec3::ZERO;
        }
        sample_equirect(env, l) * pbr_point_light(&params, n_dot_l, v, l)
    })
}

/// Relative difference of `a` from `b`, against `b`'s largest channel.
fn relative_error(a: Vec3, b: Vec3) -> f32 {
    (a - b).abs().max_element() / b.max_element().max(1e-6)
}

fn surface(metallic: f32, roughness: f32) -> PbrSurface {
    PbrSurface { albedo: Vec3::new(0.9, 0.6, 0.3), metallic, roughness }
}

const TILTED_NORMAL: Vec3 = Vec3::new(0.267_261_24, 0.801_783_7, 0.534_522_5);

#[test]
fn a_constant_environment_prefilters_and_irradiates_to_itself() {
    let rgb = [0.3, 1.0, 2.0];
    let env = constant(rgb);
    for d in [Vec3::Y, Vec3::NEG_Z, TILTED_NORMAL] {
        for roughness in [0.0, 0.1, 0.5, 1.0] {
            let p = prefiltered_specular(&env, d, roughness, 256);
            assert!(relative_error(p, Vec3::from(rgb)) < 1e-5, "{d}, roughness {roughness}: {p}");
        }
        let e = irradiance(&env, d, 256);
        assert!(relative_error(e, Vec3::from(rgb)) < 1e-5, "{d}: {e}");
    }
}

/// The diffuse estimator against closed forms: `(1 / pi) integral max(0, y) (n.l) dl` is 2/3
/// facing up, 2 / (3 pi) facing the horizon and 0 facing down.
#[test]
fn the_irradiance_of_a_sky_matches_its_closed_form() {
    let env = sky();
    let up = irradiance(&env, Vec3::Y, 4096).x;
    let side = irradiance(&env, Vec3::X, 4096).x;
    let down = irradiance(&env, Vec3::NEG_Y, 4096).x;
    assert!((up - 2.0 / 3.0).abs() < 0.005, "up {up}");
    assert!((side - 2.0 / (3.0 * PI)).abs() < 0.005, "side {side}");
    assert!(down.abs() < 1e-3, "down {down}");
}

#[test]
fn a_smooth_prefilter_is_the_mirror_direction() {
    let env = sky();
    for r in [Vec3::Y, TILTED_NORMAL, Vec3::new(0.6, 0.3, -0.74).normalize()] {
        let p = prefiltered_specular(&env, r, 0.0, 256);
        assert!((p - sample_equirect(&env, r)).abs().max_element() < 0.01, "{r}: {p}");
    }
}

/// `(scale, bias)` against brute-force quadrature of the renderer's BRDF: a metal of colour 1
/// reflects `scale + bias` of a white environment, a metal of colour 0 reflects `bias`.
#[test]
fn the_lut_matches_brute_force_quadrature() {
    let env = constant([1.0; 3]);
    for roughness in [0.3, 0.6, 1.0] {
        for n_dot_v in [0.2, 0.5, 1.0] {
            let (scale, bias) = ggx_lut(n_dot_v, roughness, 4096);
            let v = view_at(Vec3::Y, n_dot_v);
            let white = PbrSurface { albedo: Vec3::ONE, metallic: 1.0, roughness };
            let black = PbrSurface { albedo: Vec3::ZERO, ..white };
            let total = brute_force(&env, Vec3::Y, v, &white).x;
            let fresnel_only = brute_force(&env, Vec3::Y, v, &black).x;
            let context = format!("roughness {roughness}, n.v {n_dot_v}: ({scale}, {bias})");
            assert!((scale + bias - total).abs() < 0.01 * total, "{context} vs total {total}");
            assert!((bias - fresnel_only).abs() < 0.002 + 0.02 * bias, "{context} vs bias {fresnel_only}");
        }
    }
}

#[test]
fn the_lut_is_in_range_and_behaves_like_a_single_scattering_ggx() {
    for roughness in [0.045, 0.1, 0.3, 0.6, 1.0] {
        for n_dot_v in [0.0, 0.05, 0.2, 0.5, 0.8, 1.0] {
            let (scale, bias) = ggx_lut(n_dot_v, roughness, 1024);
            assert!(scale >= 0.0 && bias >= 0.0, "roughness {roughness}, n.v {n_dot_v}: ({scale}, {bias})");
            assert!(scale + bias <= 1.001, "roughness {roughness}, n.v {n_dot_v}: ({scale}, {bias})");
        }
        // Fresnel's grazing brightening: bias grows towards grazing views.
        assert!(ggx_lut(0.2, roughness, 1024).1 > ggx_lut(1.0, roughness, 1024).1);
    }
    // A mirror reflects everything at normal incidence, bias (1 - v.h)^5 = 0 there.
    let (scale, bias) = ggx_lut(1.0, 0.045, 1024);
    assert!(scale > 0.99 && bias < 1e-3, "({scale}, {bias})");
    // At roughness 1 and normal incidence D = 1 / pi and V = 1 / (2 (1 + n.l)), so a white
    // metal reflects integral (n.l)^2 / (2 pi (1 + n.l)) dl = 1 - ln 2: single scattering loses
    // the light that masking blocks.
    let (scale, bias) = ggx_lut(1.0, 1.0, 4096);
    assert!((scale + bias - (1.0 - 2f32.ln())).abs() < 0.003, "({scale}, {bias})");
}

#[test]
fn the_diffuse_fresnel_is_one_at_normal_incidence_and_drops_at_grazing() {
    let at = |n_dot_v| diffuse_fresnel(n_dot_v, 4096);
    assert!(at(1.0) > 0.99 && at(1.0) <= 1.0, "{}", at(1.0));
    assert!(
        at(1.0) > at(0.5) && at(0.5) > at(0.2) && at(0.2) > at(0.0),
        "{} {} {}",
        at(0.5),
        at(0.2),
        at(0.0)
    );
    assert!(at(0.0) > 0.5, "{}", at(0.0));
}

/// Multiple importance sampling is unbiased: the reference equals brute-force quadrature of the
/// same BRDF, for a constant environment and a varying one, at a tilted normal.
#[test]
fn the_reference_matches_brute_force_quadrature() {
    for env in [constant([1.0; 3]), sky()] {
        for (metallic, roughness) in [(0.0, 0.3), (0.0, 1.0), (1.0, 0.3), (1.0, 0.7), (0.5, 0.5)] {
            for n_dot_v in [0.2, 0.6, 1.0] {
                let s = surface(metallic, roughness);
                let v = view_at(TILTED_NORMAL, n_dot_v);
                let expected = brute_force(&env, TILTED_NORMAL, v, &s);
                let actual = reference_radiance(&env, TILTED_NORMAL, v, &s, 4096, 7);
                let err = relative_error(actual, expected);
                assert!(
                    err < 0.01,
                    "metallic {metallic}, roughness {roughness}, n.v {n_dot_v}: {actual} vs {expected}"
                );
            }
        }
    }
}

/// For a constant environment every split-sum factor is exact, so the split-sum equals the
/// reference, down to the smoothest surfaces the renderer shades.
#[test]
fn the_split_sum_equals_the_reference_for_a_constant_environment() {
    let env = constant([1.0; 3]);
    for metallic in [0.0, 1.0] {
        for roughness in [0.045, 0.1, 0.3, 0.6, 1.0] {
            for n_dot_v in [0.2, 0.5, 1.0] {
                let s = surface(metallic, roughness);
                let v = view_at(TILTED_NORMAL, n_dot_v);
                let reference = reference_radiance(&env, TILTED_NORMAL, v, &s, 4096, 11);
                let split = split_sum_radiance(&env, TILTED_NORMAL, v, &s, SplitSumSamples::default());
                assert!(
                    relative_error(split, reference) < 0.02,
                    "metallic {metallic}, roughness {roughness}, n.v {n_dot_v}: {split} vs {reference}"
                );
            }
        }
    }
}

#[test]
fn the_reference_is_deterministic_and_seeds_agree() {
    let env = sky();
    let s = surface(0.0, 0.4);
    let v = view_at(TILTED_NORMAL, 0.7);
    let a = reference_radiance(&env, TILTED_NORMAL, v, &s, 1024, 1);
    assert_eq!(a, reference_radiance(&env, TILTED_NORMAL, v, &s, 1024, 1));
    let b = reference_radiance(&env, TILTED_NORMAL, v, &s, 1024, 2);
    assert!(a != b && relative_error(a, b) < 0.02, "{a} vs {b}");
}

/// A random environment of `width` x `height` texels in `0..scale` from `seed`.
fn random_environment(seed: u64, scale: f32) -> EquirectImage {
    let mut state = seed | 1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32 * scale
    };
    let texels = (0..32).map(|_| [next(), next(), next()]).collect();
    EquirectImage { width: 8, height: 4, texels }
}

fn unit(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z).normalize_or(Vec3::Y)
}

proptest! {
    /// Finite and non-negative for any normal, view (back-facing and grazing included),
    /// material (out-of-range metallic and roughness included) and environment.
    #[test]
    fn the_integrals_are_finite_and_non_negative(
        seed in any::<u64>(), scale in 0.0f32..65504.0,
        nx in -1.0f32..1.0, ny in -1.0f32..1.0, nz in -1.0f32..1.0,
        vx in -1.0f32..1.0, vy in -1.0f32..1.0, vz in -1.0f32..1.0,
        metallic in -0.5f32..1.5, roughness in -0.5f32..1.5,
        r in 0.0f32..1.0, g in 0.0f32..1.0, b in 0.0f32..1.0,
    ) {
        let env = random_environment(seed, scale);
        let (n, v) = (unit(nx, ny, nz), unit(vx, vy, vz));
        let s = PbrSurface { albedo: Vec3::new(r, g, b), metallic, roughness };
        let samples = SplitSumSamples { lut: 32, specular: 32, irradiance: 32 };
        for c in [
            reference_radiance(&env, n, v, &s, 32, seed),
            split_sum_radiance(&env, n, v, &s, samples),
            prefiltered_specular(&env, v, roughness, 32),
            irradiance(&env, n, 32),
        ] {
            prop_assert!(c.is_finite() && c.min_element() >= 0.0, "{c}");
        }
        let (lut_scale, lut_bias) = ggx_lut(n.dot(v), roughness, 32);
        prop_assert!(lut_scale.is_finite() && lut_bias.is_finite());
    }
}

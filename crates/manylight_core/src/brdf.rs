//! The shading models on the CPU: the twin of `shaders/common/brdf.wgsl`, with the same
//! operations in the same order, for tests and CPU reference images.
//!
//! [`ShadingModel::Pbr`] is glTF 2.0 metallic-roughness (the specification's Appendix B):
//! Trowbridge-Reitz (GGX) distribution, separable Smith visibility (G1(l) G1(v) / (4 n.l n.v),
//! as the specification writes it), Schlick Fresnel and a Lambert diffuse lobe, with the energy
//! split by metallic:
//!
//! ```text
//! c_diff = lerp(base, 0, metallic)         f0 = lerp(0.04, base, metallic)    a = roughness^2
//! F = f0 + (1 - f0) (1 - v.h)^5
//! D = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2)
//! V = 1 / ((n.l + sqrt(a^2 + (1 - a^2)(n.l)^2)) (n.v + sqrt(a^2 + (1 - a^2)(n.v)^2)))
//! radiance = ((1 - F) c_diff / pi + F D V) * light * attenuation * cone * n.l
//! ```
//!
//! The other models are this renderer's own: Lambert (`albedo * n.l`, no `1/pi`), Blinn-Phong
//! (Lambert plus `specular * (n.h)^shininess * n.l`) and toon. Every model multiplies by the
//! distance attenuation and a spot light's angular falloff (`cone`, [`crate::spot`]; 1 for a
//! point light).

use crate::attenuation::attenuation;
use crate::material::{ShadingModel, TOON_BANDS, TOON_RIM_STRENGTH};
use crate::spot::spot_attenuation;
use glam::Vec3;

/// Smallest roughness the PBR model shades with: below it the GGX lobe of a point light is
/// narrower than a pixel and its peak overflows f16 G-buffer and HDR targets. Shared with WGSL.
pub const PBR_MIN_ROUGHNESS: f32 = 0.045;
/// Smallest `n.v` the PBR model uses: interpolated normals face slightly away from the camera at
/// silhouettes, where `n.v` is zero or negative. Shared with WGSL.
pub const PBR_MIN_N_DOT_V: f32 = 1.0e-4;
/// Reflectance at normal incidence of a glTF dielectric (index of refraction 1.5).
pub const PBR_DIELECTRIC_F0: f32 = 0.04;

/// What a shading model needs of a surface point (WGSL: `SurfaceParams`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParams {
    /// Linear base colour (albedo).
    pub albedo: Vec3,
    /// Unit world-space normal, facing the camera's side.
    pub normal: Vec3,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Blinn-Phong specular strength.
    pub specular: f32,
    /// PBR metalness, 0..1.
    pub metallic: f32,
    /// PBR perceptual roughness, [`PBR_MIN_ROUGHNESS`]..1.
    pub roughness: f32,
    /// The model.
    pub model: ShadingModel,
}

/// A point light as the shading sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLightSample {
    /// World position.
    pub position: Vec3,
    /// Radius where the attenuation reaches zero.
    pub radius: f32,
    /// Linear colour times intensity.
    pub color: Vec3,
    /// Unit direction of a spot light's axis (zero for a point light).
    pub spot_direction: Vec3,
    /// Scale of the angular falloff (`crate::spot::SpotCone::scale_offset`; 0 for a point light).
    pub spot_scale: f32,
    /// Offset of the angular falloff (1 for a point light).
    pub spot_offset: f32,
}

impl PointLightSample {
    /// A point light (no cone).
    pub fn point(position: Vec3, radius: f32, color: Vec3) -> PointLightSample {
        PointLightSample {
            position,
            radius,
            color,
            spot_direction: Vec3::ZERO,
            spot_scale: 0.0,
            spot_offset: 1.0,
        }
    }

    /// A spot light with `cone`.
    pub fn spot(position: Vec3, radius: f32, color: Vec3, cone: &crate::spot::SpotCone) -> PointLightSample {
        let (spot_scale, spot_offset) = cone.scale_offset();
        let spot_direction = cone.sanitized().direction;
        PointLightSample { position, radius, color, spot_direction, spot_scale, spot_offset }
    }
}

/// Radiance that `light` adds at `position` seen from `view_dir` (unit, towards the eye).
pub fn shade_point_light(
    s: &SurfaceParams,
    position: Vec3,
    view_dir: Vec3,
    light: &PointLightSample,
) -> Vec3 {
    let to_light = light.position - position;
    let distance = to_light.length();
    let att = attenuation(distance, light.radius);
    if att <= 0.0 {
        return Vec3::ZERO;
    }
    let l = to_light / distance.max(1e-6);
    let cone = spot_attenuation(light.spot_direction.dot(-l), light.spot_scale, light.spot_offset);
    reflected(s, l, view_dir) * light.color * (att * cone)
}

/// What a surface reflects towards `view_dir` of unit light arriving from unit direction `l`
/// (towards the light): the model's BRDF times n.l (WGSL: `reflected`). Point, spot and
/// directional lights multiply it by their colour, then their falloff.
pub fn reflected(s: &SurfaceParams, l: Vec3, view_dir: Vec3) -> Vec3 {
    let n_dot_l = s.normal.dot(l).max(0.0);
    match s.model {
        ShadingModel::Toon => toon_point_light(s, n_dot_l, view_dir, l),
        ShadingModel::Pbr => {
            if n_dot_l <= 0.0 {
                return Vec3::ZERO;
            }
            pbr_point_light(s, n_dot_l, view_dir, l)
        }
        ShadingModel::Lambert | ShadingModel::BlinnPhong => {
            let mut result = s.albedo * n_dot_l;
            if s.model == ShadingModel::BlinnPhong && n_dot_l > 0.0 {
                let h = (l + view_dir).normalize();
                let n_dot_h = s.normal.dot(h).max(0.0);
                result += Vec3::splat(s.specular * n_dot_h.powf(s.shininess) * n_dot_l);
            }
            result
        }
    }
}

/// Radiance a directional light of `radiance` (colour × illuminance) travelling along unit
/// `direction` adds, seen from `view_dir` (WGSL: the loop of `shade_directional_lights`).
pub fn shade_directional_light(s: &SurfaceParams, direction: Vec3, view_dir: Vec3, radiance: Vec3) -> Vec3 {
    reflected(s, -direction, view_dir) * radiance
}

/// Toon shading of one light (WGSL: `toon_point_light`).
fn toon_point_light(s: &SurfaceParams, n_dot_l: f32, view_dir: Vec3, l: Vec3) -> Vec3 {
    let bands = TOON_BANDS as f32;
    let band = (n_dot_l * bands - 0.5).ceil() / bands;
    let n_dot_v = s.normal.dot(view_dir).max(0.0);
    let rim = (1.0 - n_dot_v).powf(4.0) * smoothstep(-0.2, 0.1, s.normal.dot(l));
    s.albedo * band + s.albedo * (TOON_RIM_STRENGTH * rim)
}

/// WGSL's `smoothstep`.
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The metallic-roughness BRDF times `n.l` for a light in direction `l` (`n_dot_l > 0`)
/// (WGSL: `pbr_point_light`).
pub fn pbr_point_light(s: &SurfaceParams, n_dot_l: f32, view_dir: Vec3, l: Vec3) -> Vec3 {
    let metallic = s.metallic.clamp(0.0, 1.0);
    let roughness = s.roughness.clamp(PBR_MIN_ROUGHNESS, 1.0);
    let a = roughness * roughness;
    let a2 = a * a;
    let hv = l + view_dir;
    let hl = hv.length();
    let h = if hl > 0.0 { hv / hl } else { s.normal };
    let n_dot_v = s.normal.dot(view_dir).max(PBR_MIN_N_DOT_V);
    let n_dot_h = s.normal.dot(h).max(0.0);
    let v_dot_h = view_dir.dot(h).clamp(0.0, 1.0);
    let f0 = Vec3::splat(PBR_DIELECTRIC_F0).lerp(s.albedo, metallic);
    let c_diff = s.albedo * (1.0 - metallic);
    let x = 1.0 - v_dot_h;
    let x2 = x * x;
    let fresnel = f0 + (Vec3::ONE - f0) * (x2 * x2 * x);
    let d_denom = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    let d = a2 / (std::f32::consts::PI * d_denom * d_denom);
    let vis_l = n_dot_l + (a2 + (1.0 - a2) * n_dot_l * n_dot_l).sqrt();
    let vis_v = n_dot_v + (a2 + (1.0 - a2) * n_dot_v * n_dot_v).sqrt();
    let vis = 1.0 / (vis_l * vis_v);
    let diffuse = (Vec3::ONE - fresnel) * c_diff * std::f32::consts::FRAC_1_PI;
    let specular = fresnel * (d * vis);
    (diffuse + specular) * n_dot_l
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn surface(metallic: f32, roughness: f32) -> SurfaceParams {
        SurfaceParams {
            albedo: Vec3::new(0.9, 0.6, 0.3),
            normal: Vec3::Y,
            shininess: 32.0,
            specular: 0.25,
            metallic,
            roughness,
            model: ShadingModel::Pbr,
        }
    }

    /// Directional albedo of the BRDF for a unit irradiance from `l` seen from `v`, by
    /// integrating over the hemisphere of `v` with a white furnace: a white, fully rough
    /// dielectric reflects at most all the light it receives.
    #[test]
    fn white_furnace_reflects_no_more_than_it_receives() {
        for (metallic, roughness) in [(0.0, 1.0), (1.0, 1.0), (1.0, 0.5), (0.0, 0.3), (1.0, 0.3)] {
            let mut s = surface(metallic, roughness);
            s.albedo = Vec3::ONE;
            let l = Vec3::new(0.3, 0.8, 0.1).normalize();
            // Reflected radiance integrated over outgoing directions (uniform sphere samples).
            let n = 200_000;
            let mut sum = Vec3::ZERO;
            let mut state = 0x9e37_79b9_u32;
            let mut rnd = || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                state as f32 / u32::MAX as f32
            };
            for _ in 0..n {
                let z = rnd();
                let phi = rnd() * std::f32::consts::TAU;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let v = Vec3::new(r * phi.cos(), z, r * phi.sin());
                let n_dot_l = s.normal.dot(l);
                // BRDF * cos(l) * cos(v), over the hemisphere (pdf 1 / 2pi).
                sum += pbr_point_light(&s, n_dot_l, v, l) / n_dot_l * v.y * std::f32::consts::TAU;
            }
            let albedo = sum / n as f32;
            assert!(
                albedo.max_element() <= 1.02,
                "metallic {metallic}, roughness {roughness}: reflects {albedo} of the light"
            );
            assert!(albedo.min_element() > 0.3, "metallic {metallic}, roughness {roughness}: {albedo}");
        }
    }

    #[test]
    fn a_dielectric_is_lambert_over_pi_plus_a_specular_lobe() {
        // Light and view straight above a rough dielectric: F = 0.04, almost all diffuse.
        let s = surface(0.0, 1.0);
        let c = pbr_point_light(&s, 1.0, Vec3::Y, Vec3::Y);
        let diffuse = s.albedo * 0.96 / std::f32::consts::PI;
        // D = 1/pi, V = 1/4 at a = 1: specular 0.04 / (4 pi).
        let specular = 0.04 / (4.0 * std::f32::consts::PI);
        assert!((c - diffuse - Vec3::splat(specular)).abs().max_element() < 1e-6, "{c}");
    }

    #[test]
    fn a_metal_has_no_diffuse_and_reflects_its_colour() {
        let s = surface(1.0, 1.0);
        let c = pbr_point_light(&s, 1.0, Vec3::Y, Vec3::Y);
        let expected = s.albedo / (4.0 * std::f32::consts::PI);
        assert!((c - expected).abs().max_element() < 1e-6, "{c} vs {expected}");
    }

    #[test]
    fn smoother_surfaces_have_a_brighter_narrower_highlight() {
        let l = Vec3::new(0.0, 1.0, 1.0).normalize();
        let mirror = Vec3::new(0.0, 1.0, -1.0).normalize();
        let off = Vec3::new(0.5, 1.0, -1.0).normalize();
        let nl = l.y;
        let peak = |r| pbr_point_light(&surface(1.0, r), nl, mirror, l).x;
        let side = |r| pbr_point_light(&surface(1.0, r), nl, off, l).x;
        assert!(peak(0.2) > peak(0.5) && peak(0.5) > peak(0.9));
        assert!(side(0.2) / peak(0.2) < side(0.9) / peak(0.9));
    }

    proptest! {
        /// Finite and non-negative for every direction, metallic and roughness, roughness 0
        /// and grazing or back-facing views included.
        #[test]
        fn pbr_is_finite_and_non_negative(
            lx in -1.0f32..1.0, ly in 0.0f32..1.0, lz in -1.0f32..1.0,
            vx in -1.0f32..1.0, vy in -1.0f32..1.0, vz in -1.0f32..1.0,
            metallic in -0.5f32..1.5, roughness in -0.5f32..1.5,
        ) {
            let l = Vec3::new(lx, ly, lz).normalize_or(Vec3::Y);
            let v = Vec3::new(vx, vy, vz).normalize_or(Vec3::Y);
            let s = surface(metallic, roughness);
            let light = PointLightSample::point(l * 2.0, 10.0, Vec3::splat(100.0));
            let c = shade_point_light(&s, Vec3::ZERO, v, &light);
            prop_assert!(c.is_finite() && c.min_element() >= 0.0, "{c}");
        }
    }
}

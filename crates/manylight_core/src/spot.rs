//! Spot lights: the cone's angular falloff (glTF `KHR_lights_punctual`) and the sphere that
//! bounds what the cone can light, which the cluster build culls with.
//!
//! A spot light is a point light whose contribution is also multiplied by
//! `saturate(cos_angle * scale + offset)^2`, where `cos_angle` is the cosine between the spot's
//! axis and the direction from the light to the surface; `scale` and `offset` come from the
//! inner and outer cone angles ([`SpotCone::scale_offset`]). A point light is the same
//! expression with `scale = 0`, `offset = 1`, so the shaders have no branch for the kind of
//! light (`shade_reached_light` in `shaders/common/brdf.wgsl` and [`crate::brdf`]).

use glam::Vec3;

/// The shape of the light a point-like light sends out: every direction, or a cone (glTF's
/// `point` and `spot`; the sun is a light of its own type). Code that treats the shapes
/// differently matches on it whole, so a new shape fails to compile wherever it must be
/// handled.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LightShape {
    /// Light in every direction, within the light's range.
    #[default]
    Point,
    /// Light inside a cone, within the light's range.
    Spot(SpotCone),
}

impl LightShape {
    /// The sphere `(centre, radius)` that holds every point a light of this shape at
    /// `position` lights within `range`: the range's sphere, or the smaller one around a spot
    /// light's cone ([`SpotCone::bounding_sphere`]).
    pub fn bounding_sphere(&self, position: Vec3, range: f32) -> (Vec3, f32) {
        match self {
            LightShape::Point => (position, range),
            LightShape::Spot(cone) => cone.bounding_sphere(position, range),
        }
    }

    /// `(axis, scale, offset)` of the angular falloff `saturate(cos · scale + offset)²` the
    /// shaders apply: a point light has no axis, scale 0 and offset 1 (1 in every direction).
    pub fn falloff(&self) -> (Vec3, f32, f32) {
        match self {
            LightShape::Point => (Vec3::ZERO, 0.0, 1.0),
            LightShape::Spot(cone) => {
                let (scale, offset) = cone.scale_offset();
                (cone.sanitized().direction, scale, offset)
            }
        }
    }

    /// The angular falloff towards `direction` (from the light; need not be unit): 1 for a
    /// point light, [`spot_attenuation`] of the cone for a spot light.
    pub fn attenuation(&self, direction: Vec3) -> f32 {
        let (axis, scale, offset) = self.falloff();
        match self {
            LightShape::Point => 1.0,
            LightShape::Spot(_) => spot_attenuation(axis.dot(direction.normalize_or_zero()), scale, offset),
        }
    }
}

/// The cone of a spot light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotCone {
    /// Unit direction the light points to, in world space (a glTF spot points down its node's
    /// local -Z).
    pub direction: Vec3,
    /// Angle from the axis, in radians, inside which the light is at full strength.
    pub inner_angle: f32,
    /// Angle from the axis, in radians, beyond which the light is exactly zero (at most π/2).
    pub outer_angle: f32,
}

/// The smallest `cos(inner) - cos(outer)` the falloff divides by (glTF's sample value).
pub const MIN_CONE_COSINE_SPAN: f32 = 0.001;

impl SpotCone {
    /// The cone with non-finite or out-of-range parameters made usable: a zero or non-finite
    /// direction points down -Z, the outer angle lies in `[0, π/2]` and the inner one in
    /// `[0, outer]`.
    pub fn sanitized(self) -> SpotCone {
        let direction = self.direction.try_normalize().unwrap_or(Vec3::NEG_Z);
        let angle = |a: f32, max: f32| if a.is_finite() { a.clamp(0.0, max) } else { max };
        let outer_angle = angle(self.outer_angle, std::f32::consts::FRAC_PI_2);
        let inner_angle = angle(self.inner_angle, outer_angle);
        SpotCone { direction, inner_angle, outer_angle }
    }

    /// `(scale, offset)` of the angular falloff, as the glTF specification computes them:
    /// `scale = 1 / max(cos(inner) - cos(outer), 0.001)`, `offset = -cos(outer) * scale`.
    pub fn scale_offset(&self) -> (f32, f32) {
        let c = self.sanitized();
        let (cos_inner, cos_outer) = (c.inner_angle.cos(), c.outer_angle.cos());
        let scale = 1.0 / (cos_inner - cos_outer).max(MIN_CONE_COSINE_SPAN);
        (scale, -cos_outer * scale)
    }

    /// The sphere `(centre, radius)` that holds every point the cone lights within `range` of
    /// `position` (a spherical sector): for a half-angle θ up to 45° the sphere through the
    /// apex and the rim (centre at `range / (2 cos θ)` along the axis), for wider cones the
    /// sphere around the rim's circle (centre at `range · cos θ`, radius `range · sin θ`). The
    /// radius is widened by one part in 10⁵ so that rounding never leaves a lit point outside.
    pub fn bounding_sphere(&self, position: Vec3, range: f32) -> (Vec3, f32) {
        let c = self.sanitized();
        let (sin, cos) = c.outer_angle.sin_cos();
        let (along, radius) = if cos >= std::f32::consts::FRAC_1_SQRT_2 {
            let r = range / (2.0 * cos);
            (r, r)
        } else {
            (range * cos, range * sin)
        };
        // Never larger than the point light's own sphere.
        if radius >= range {
            return (position, range);
        }
        (position + c.direction * along, radius * (1.0 + 1e-5))
    }
}

/// The angular falloff of a light at cosine `cos_angle` from its axis:
/// `saturate(cos_angle * scale + offset)^2` (1 everywhere for a point light's `(0, 1)`).
#[inline]
pub fn spot_attenuation(cos_angle: f32, scale: f32, offset: f32) -> f32 {
    let t = (cos_angle * scale + offset).clamp(0.0, 1.0);
    t * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn cone(outer: f32) -> SpotCone {
        SpotCone {
            direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
            inner_angle: outer * 0.5,
            outer_angle: outer,
        }
    }

    #[test]
    fn full_inside_the_inner_cone_and_zero_outside_the_outer() {
        let c = cone(0.6);
        let (scale, offset) = c.scale_offset();
        assert_eq!(spot_attenuation(1.0, scale, offset), 1.0);
        assert_eq!(spot_attenuation(0.29f32.cos(), scale, offset), 1.0);
        assert_eq!(spot_attenuation(0.61f32.cos(), scale, offset), 0.0);
        assert_eq!(spot_attenuation(-1.0, scale, offset), 0.0);
        let mid = spot_attenuation(0.45f32.cos(), scale, offset);
        assert!(mid > 0.0 && mid < 1.0, "{mid}");
        // A point light's (0, 1) is 1 in every direction.
        assert_eq!(spot_attenuation(-1.0, 0.0, 1.0), 1.0);
    }

    #[test]
    fn equal_angles_and_bad_input_stay_finite() {
        let hard = SpotCone { direction: Vec3::Z, inner_angle: 0.5, outer_angle: 0.5 };
        let (scale, offset) = hard.scale_offset();
        assert!(scale.is_finite() && offset.is_finite());
        let bad = SpotCone { direction: Vec3::ZERO, inner_angle: f32::NAN, outer_angle: f32::INFINITY };
        let s = bad.sanitized();
        assert_eq!(s.direction, Vec3::NEG_Z);
        assert_eq!(s.outer_angle, std::f32::consts::FRAC_PI_2);
        let (scale, offset) = bad.scale_offset();
        assert!(scale.is_finite() && offset.is_finite());
        let (centre, radius) = bad.bounding_sphere(Vec3::ONE, 2.0);
        assert!(centre.is_finite() && radius.is_finite());
    }

    #[test]
    fn a_narrow_cone_has_a_much_smaller_sphere() {
        let (_, r) = cone(0.2).bounding_sphere(Vec3::ZERO, 10.0);
        assert!(r < 5.2, "{r}");
        let (c, r) = cone(1.5).bounding_sphere(Vec3::ZERO, 10.0);
        assert!(r < 10.0 && r > 9.9, "{c} {r}");
    }

    proptest! {
        /// Every point the cone lights (angular falloff > 0, within the range) lies in the
        /// bounding sphere, whatever the angles.
        #[test]
        fn the_bounding_sphere_holds_every_lit_point(
            outer in 0.0f32..std::f32::consts::FRAC_PI_2,
            inner_fraction in 0.0f32..1.0,
            range in 0.01f32..1000.0,
            u in -1.0f32..1.0,
            v in 0.0f32..std::f32::consts::TAU,
            t in 0.0f32..1.0,
        ) {
            let c = SpotCone { direction: Vec3::new(0.2, 0.9, -0.4).normalize(), inner_angle: outer * inner_fraction, outer_angle: outer };
            let position = Vec3::new(3.0, -2.0, 7.0);
            let (scale, offset) = c.scale_offset();
            // A direction on the unit sphere and a distance within the range.
            let d = Vec3::new((1.0 - u * u).sqrt() * v.cos(), (1.0 - u * u).sqrt() * v.sin(), u);
            let p = position + d * (range * t);
            let lit = spot_attenuation(d.dot(c.direction), scale, offset) > 0.0;
            let (centre, radius) = c.bounding_sphere(position, range);
            prop_assert!(!lit || (p - centre).length() <= radius, "{p} outside ({centre}, {radius})");
        }
    }
}

//! Lights in one place: what kind a light is, what it can reach, how it is packed for the
//! shaders, and which lights the frame's buffers hold. The light buffer holds the frame's
//! point and spot lights in order, an invalid one as an inert zeroed light that reaches
//! nothing ([`buffered_lights`] yields the valid ones); the view uniform the first
//! [`MAX_DIRECTIONAL_LIGHTS`] valid directional lights ([`viewed_directional_lights`]); a
//! light's index there is its index everywhere (cluster lists, the shadow table, probes).
//! Clustering culls with [`bounding_sphere`], the shaders read [`gpu_point_light`]'s fields
//! through `shaders/common/lights.wgsl` (its twin: the same packing and attenuation), and the
//! shadows take their lights from the same two functions, so a new light kind or a new reach
//! is made here once.

use crate::gpu_types::{GpuDirectionalLight, GpuLightMotion, GpuPointLight, MAX_DIRECTIONAL_LIGHTS};
use crate::snapshot::{ExtractedDirectionalLight, ExtractedPointLight, PointLights};
use glam::Vec3;

/// The kinds of light the renderer draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightKind {
    /// Light from a point in every direction, within a range.
    Point,
    /// Light from a point inside a cone, within a range.
    Spot,
    /// Light travelling one way everywhere (the sun).
    Directional,
}

impl LightKind {
    /// The kind of a point or spot light.
    pub fn of(light: &ExtractedPointLight) -> LightKind {
        if light.spot.is_some() { LightKind::Spot } else { LightKind::Point }
    }
}

/// The sphere (centre, radius) that holds every point `light` can reach: its range around it,
/// or the smaller sphere around a spot light's cone ([`manylight_core::SpotCone::bounding_sphere`]).
pub fn bounding_sphere(light: &ExtractedPointLight) -> (Vec3, f32) {
    match (LightKind::of(light), &light.spot) {
        (LightKind::Spot, Some(cone)) => cone.bounding_sphere(light.position, light.radius),
        _ => (light.position, light.radius),
    }
}

/// `light` as the shaders read it (`GpuPointLight` in `shaders/common/lights.wgsl`): a point
/// light has no direction, falloff scale 0 and offset 1 (1 everywhere).
pub fn gpu_point_light(light: &ExtractedPointLight) -> GpuPointLight {
    let (direction, scale, offset) = match &light.spot {
        Some(cone) => {
            let (scale, offset) = cone.scale_offset();
            (cone.sanitized().direction, scale, offset)
        }
        None => (Vec3::ZERO, 0.0, 1.0),
    };
    GpuPointLight {
        position_radius: light.position.extend(light.radius).to_array(),
        color: (light.color * light.intensity).extend(offset).to_array(),
        spot: direction.extend(scale).to_array(),
    }
}

/// `light`'s animation as the light animation pass reads it, its angles taken at `epoch`
/// seconds ([`manylight_core::AnimatedLight::angles_at`], in f64): the pass adds
/// `speed × (t − epoch)` to each, so the GPU's f32 keeps its precision as long as `t` stays
/// near the epoch ([`crate::animation::EPOCH_SPAN_SECS`]). Zeroed (the pass leaves the light as
/// uploaded) for a light without an animation or an invalid one.
pub fn gpu_light_motion(light: &ExtractedPointLight, epoch: f32) -> GpuLightMotion {
    let Some(a) = light.animation.as_deref().filter(|_| light.is_valid()) else {
        return bytemuck::Zeroable::zeroed();
    };
    let [orbit, bob, drift, flicker, flicker2] = a.rates().map(|r| r.speed);
    let angles = a.angles_at(epoch);
    GpuLightMotion {
        center: a.center.to_array(),
        orbit_radius: a.orbit_radius,
        color: a.color.to_array(),
        bob_amplitude: a.bob_amplitude,
        speeds: [orbit, bob, drift, flicker],
        angles: [angles.orbit, angles.bob, angles.drift, angles.flicker],
        flicker2_speed: flicker2,
        flicker2_angle: angles.flicker2,
        epoch,
        intensity: light.intensity,
        animated: 1,
        pad: [0; 3],
    }
}

/// `light` as the view uniform holds it.
pub fn gpu_directional_light(light: &ExtractedDirectionalLight) -> GpuDirectionalLight {
    GpuDirectionalLight {
        direction: light.direction.normalize().extend(0.0).to_array(),
        color: (light.color * light.illuminance).extend(0.0).to_array(),
    }
}

/// The box around everything the light buffer's lights can reach (each light's range around
/// its position or around the box an animated light moves in, which holds a spot light's smaller sphere too), kept as the lights are
/// packed: what slicing a projection without a far plane needs ([`LightReach::farthest`]),
/// without visiting the lights again for each view.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightReach {
    /// The box's (minimum, maximum) corners, `None` while no light was added.
    bounds: Option<(Vec3, Vec3)>,
}

impl LightReach {
    /// Adds what `light` can reach.
    pub fn add(&mut self, light: &ExtractedPointLight) {
        let r = Vec3::splat(light.radius);
        let (lo, hi) = light.position_bounds();
        self.merge(&LightReach { bounds: Some((lo - r, hi + r)) });
    }

    /// Adds what `other` covers.
    pub fn merge(&mut self, other: &LightReach) {
        if let Some((lo, hi)) = other.bounds {
            self.bounds = Some(match self.bounds {
                Some((min, max)) => (min.min(lo), max.max(hi)),
                None => (lo, hi),
            });
        }
    }

    /// The farthest view distance (along −Z of `view_from_world`) any light can reach, at
    /// least that of every light's own sphere (`manylight_core::cluster::farthest_reach`); 0
    /// when there is no light. The farthest corner of the box: a sphere's farthest point along
    /// any direction lies in its own box.
    pub fn farthest(&self, view_from_world: &glam::Mat4) -> f32 {
        let Some((min, max)) = self.bounds else { return 0.0 };
        (0..8)
            .map(|corner| {
                let pick = |bit: u32, lo: f32, hi: f32| if corner & bit == 0 { lo } else { hi };
                let p = Vec3::new(pick(1, min.x, max.x), pick(2, min.y, max.y), pick(4, min.z, max.z));
                -view_from_world.transform_point3(p).z
            })
            .filter(|d| d.is_finite())
            .fold(0.0, f32::max)
    }
}

/// The valid lights of the light buffer, with their index in it (their position in `lights`).
pub fn buffered_lights(lights: &PointLights) -> impl Iterator<Item = (u32, &ExtractedPointLight)> {
    lights.iter().enumerate().filter(|(_, l)| l.is_valid()).map(|(i, l)| (i as u32, l))
}

/// `light` as the light buffer holds it: packed ([`gpu_point_light`]), or zeroed when it is
/// invalid (radius 0: no list keeps it and it adds nothing where a loop meets it).
pub fn buffered_light(light: &ExtractedPointLight) -> GpuPointLight {
    if light.is_valid() { gpu_point_light(light) } else { bytemuck::Zeroable::zeroed() }
}

/// The directional lights the view uniform holds, with their index in it: the first
/// [`MAX_DIRECTIONAL_LIGHTS`] valid ones.
pub fn viewed_directional_lights(
    lights: &[ExtractedDirectionalLight],
) -> impl Iterator<Item = (u32, &ExtractedDirectionalLight)> {
    lights
        .iter()
        .filter(|l| l.is_valid())
        .take(MAX_DIRECTIONAL_LIGHTS as usize)
        .enumerate()
        .map(|(i, l)| (i as u32, l))
}

#[cfg(test)]
mod tests {
    use super::*;
    use manylight_core::SpotCone;

    fn light(spot: Option<SpotCone>) -> ExtractedPointLight {
        ExtractedPointLight {
            position: Vec3::new(1.0, 2.0, 3.0),
            color: Vec3::ONE,
            intensity: 2.0,
            radius: 4.0,
            spot,
            shadow: None,
            animation: None,
        }
    }

    #[test]
    fn a_light_knows_its_kind_reach_and_packing() {
        let point = light(None);
        assert_eq!(LightKind::of(&point), LightKind::Point);
        assert_eq!(bounding_sphere(&point), (point.position, 4.0));
        let packed = gpu_point_light(&point);
        assert_eq!(packed.position_radius, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(packed.color, [2.0, 2.0, 2.0, 1.0], "a point light's falloff offset is 1");
        assert_eq!(packed.spot, [0.0; 4]);
        let cone = SpotCone { direction: Vec3::NEG_Y, inner_angle: 0.2, outer_angle: 0.4 };
        let spot = light(Some(cone));
        assert_eq!(LightKind::of(&spot), LightKind::Spot);
        let (_, r) = bounding_sphere(&spot);
        assert!(r < 4.0, "a narrow cone's sphere is smaller than the range: {r}");
        assert_eq!(gpu_point_light(&spot).spot[1], -1.0);
    }

    #[test]
    fn the_reach_box_covers_every_lights_farthest_point() {
        let view =
            glam::Mat4::from_rotation_y(0.4) * glam::Mat4::from_translation(Vec3::new(-3.0, -1.0, -9.0));
        let mut lights = vec![light(None); 3];
        lights[1].position = Vec3::new(-5.0, 2.0, -20.0);
        lights[2].radius = 0.5;
        let mut reach = LightReach::default();
        assert_eq!(reach.farthest(&view), 0.0);
        lights.iter().for_each(|l| reach.add(l));
        let exact = manylight_core::cluster::farthest_reach(manylight_core::cluster::to_view_space(
            view,
            lights.iter().map(|l| (l.position, l.radius)),
        ));
        let bound = reach.farthest(&view);
        assert!(bound >= exact && bound <= exact + 2.0 * 4.0 * 3f32.sqrt(), "{bound} vs {exact}");
    }

    #[test]
    fn buffers_hold_every_light_in_order() {
        let mut lights = vec![light(None); 4];
        lights[1].position = Vec3::NAN;
        assert_eq!(buffered_light(&lights[1]).position_radius, [0.0; 4]);
        let held: Vec<u32> = buffered_lights(&lights.into()).map(|(i, _)| i).collect();
        assert_eq!(held, [0, 2, 3], "an invalid light keeps its index");
        let sun = ExtractedDirectionalLight {
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            illuminance: 1.0,
            shadow: None,
        };
        let mut suns = vec![sun; MAX_DIRECTIONAL_LIGHTS as usize + 2];
        suns[0].direction = Vec3::ZERO;
        assert_eq!(viewed_directional_lights(&suns).count(), MAX_DIRECTIONAL_LIGHTS as usize);
        assert_eq!(gpu_directional_light(&sun).direction, [0.0, -1.0, 0.0, 0.0]);
    }
}

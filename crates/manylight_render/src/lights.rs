//! Lights in one place: the point, spot and directional lights a frame is rendered from
//! ([`ExtractedPointLight`], [`ExtractedDirectionalLight`]) and the list that holds the first
//! in chunks shared between frames ([`PointLights`]); what kind a light is, what it can reach,
//! how it is packed for the shaders, and which lights the frame's buffers hold. The light
//! buffer holds the frame's point and spot lights in order, an invalid one as an inert zeroed
//! light that reaches nothing ([`buffered_lights`] yields the valid ones); the view uniform the
//! first [`MAX_DIRECTIONAL_LIGHTS`] valid directional lights ([`viewed_directional_lights`]); a
//! light's index there is its index everywhere (cluster lists, the shadow table, probes).
//! Clustering culls with [`bounding_sphere`], the shaders read [`gpu_point_light`]'s fields
//! through `shaders/common/lights.wgsl` (its twin: the same packing and attenuation), and the
//! shadows take their lights from the same two functions, so a new light kind or a new reach
//! is made here once.

use crate::gpu_types::{GpuDirectionalLight, GpuLightMotion, GpuPointLight, MAX_DIRECTIONAL_LIGHTS};
use crate::settings::CascadeShadowConfig;
use glam::Vec3;
pub use manylight_core::LightShape;
use std::sync::Arc;

/// One point light.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtractedPointLight {
    /// World position.
    pub position: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Luminous intensity in candela, multiplying `color`.
    pub intensity: f32,
    /// Radius of influence (contribution is exactly 0 at and beyond it).
    pub radius: f32,
    /// Every direction (a point light) or a cone (a spot light).
    pub shape: LightShape,
    /// The light casts shadows, with these biases (`None`: it lights through everything).
    pub shadow: Option<ShadowBias>,
    /// The light moves and flickers on the GPU (`None`: it stays as extracted): each frame a
    /// compute pass writes its position and colour at
    /// [`FrameSnapshot::elapsed_secs`](crate::snapshot::FrameSnapshot::elapsed_secs) into the
    /// light buffer (`shaders/light_animation.wgsl`), so its motion costs the CPU nothing.
    /// `position` and `color` are then unused; `intensity`, `radius` and `shape` still apply.
    pub animation: Option<Arc<manylight_core::AnimatedLight>>,
}

/// How a light's shadow test keeps a surface from shadowing itself (Bevy's
/// `shadow_depth_bias` and `shadow_normal_bias`): the shaded point moves `normal` texels of the
/// light's shadow map off the surface towards the light, and `depth` world units nearer to
/// it along the ray. Larger values remove acne and detach shadows from their casters
/// (peter-panning).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowBias {
    /// World units along the ray from the light.
    pub depth: f32,
    /// Texels of the shadow map at the shaded point, along the surface normal.
    pub normal: f32,
}

impl ShadowBias {
    /// Bevy's defaults for a light of `shape` (`PointLight`'s or `SpotLight`'s).
    pub fn for_shape(shape: LightShape) -> ShadowBias {
        match shape {
            LightShape::Point => ShadowBias::POINT,
            LightShape::Spot(_) => ShadowBias::SPOT,
        }
    }

    /// Bevy's `PointLight` defaults.
    pub const POINT: ShadowBias = ShadowBias { depth: 0.08, normal: 0.6 };
    /// Bevy's `SpotLight` defaults.
    pub const SPOT: ShadowBias = ShadowBias { depth: 0.02, normal: 1.8 };
    /// Bevy's `DirectionalLight` defaults.
    pub const DIRECTIONAL: ShadowBias = ShadowBias { depth: 0.02, normal: 1.8 };

    /// True when both biases are finite and not negative.
    pub fn is_valid(&self) -> bool {
        self.depth.is_finite() && self.normal.is_finite() && self.depth >= 0.0 && self.normal >= 0.0
    }
}

impl Default for ShadowBias {
    fn default() -> Self {
        ShadowBias::POINT
    }
}

impl ExtractedPointLight {
    /// A point light (no cone, no shadow, no animation).
    pub fn point(position: Vec3, color: Vec3, intensity: f32, radius: f32) -> ExtractedPointLight {
        ExtractedPointLight {
            position,
            color,
            intensity,
            radius,
            shape: LightShape::Point,
            shadow: None,
            animation: None,
        }
    }

    /// True when every parameter is finite, the radius and intensity are not negative, and the
    /// emitted colour (`color × intensity`) does not overflow to infinity; for an animated
    /// light, also the box its orbit and bob stay in, and its base colour with twice the room.
    pub fn is_valid(&self) -> bool {
        self.position.is_finite()
            && self.color.is_finite()
            && self.intensity.is_finite()
            && (self.color * self.intensity).is_finite()
            && self.radius.is_finite()
            && self.radius >= 0.0
            && self.intensity >= 0.0
            && self.shadow.is_none_or(|b| b.is_valid())
            && self
                .animation
                .as_deref()
                .is_none_or(|a| a.position_bounds().is_some() && (a.color * self.intensity * 2.0).is_finite())
    }

    /// The box holding the light's position at every time: its position, or the box its
    /// animation stays in.
    pub fn position_bounds(&self) -> (Vec3, Vec3) {
        self.animation.as_deref().and_then(|a| a.position_bounds()).unwrap_or((self.position, self.position))
    }
}

/// A directional light as extracted for rendering: light travelling along `direction`
/// everywhere (the sun).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedDirectionalLight {
    /// Unit direction the light travels, from the light into the scene.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Illuminance (lux in glTF), multiplying `color`.
    pub illuminance: f32,
    /// The light casts shadows (`None`: it lights through everything).
    pub shadow: Option<DirectionalShadow>,
}

/// A directional light's shadow: its biases (the normal bias in texels of the cascade at the
/// point) and how its cascades split the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalShadow {
    /// Depth and normal bias.
    pub bias: ShadowBias,
    /// The cascades.
    pub cascades: CascadeShadowConfig,
}

impl Default for DirectionalShadow {
    fn default() -> Self {
        DirectionalShadow { bias: ShadowBias::DIRECTIONAL, cascades: Default::default() }
    }
}

impl ExtractedDirectionalLight {
    /// True when every parameter is finite, the direction is not zero, the illuminance is not
    /// negative and `color × illuminance` does not overflow.
    pub fn is_valid(&self) -> bool {
        self.direction.is_finite()
            && self.direction.length_squared() > 0.0
            && self.color.is_finite()
            && self.illuminance.is_finite()
            && self.illuminance >= 0.0
            && (self.color * self.illuminance).is_finite()
    }
}

/// Lights in each chunk of a [`PointLights`] list (the last chunk may hold fewer).
pub const LIGHT_CHUNK: usize = 1024;

/// The point and spot lights of a frame, in chunks of [`LIGHT_CHUNK`] shared between frames
/// (`Arc`): extraction copies a chunk only when one of its lights changed, and the renderer
/// packs and uploads only the lights of chunks that are not the ones it uploaded before. A
/// light's index is its position in the list, which is its index in the light buffer, the
/// lists and the shadow table (an invalid light keeps its place there, lighting nothing).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointLights {
    chunks: Vec<Arc<LightChunk>>,
    len: usize,
}

/// [`LIGHT_CHUNK`] consecutive lights of a [`PointLights`] list, and how many of them cast
/// shadows or animate on the GPU (so a frame finds them without visiting the others).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightChunk {
    lights: Vec<ExtractedPointLight>,
    shadowed: usize,
    animated: usize,
}

impl LightChunk {
    /// The chunk's lights.
    pub fn lights(&self) -> &[ExtractedPointLight] {
        &self.lights
    }

    /// How many of them cast shadows.
    pub fn shadowed(&self) -> usize {
        self.shadowed
    }

    /// How many of them animate on the GPU ([`ExtractedPointLight::animation`]).
    pub fn animated(&self) -> usize {
        self.animated
    }

    fn recount(&mut self) {
        self.shadowed = self.lights.iter().filter(|l| l.shadow.is_some()).count();
        self.animated = self.lights.iter().filter(|l| l.animation.is_some()).count();
    }

    /// Counts `light` in (`add`) or out.
    fn count(&mut self, light: &ExtractedPointLight, add: bool) {
        let (shadowed, animated) =
            (usize::from(light.shadow.is_some()), usize::from(light.animation.is_some()));
        if add {
            self.shadowed += shadowed;
            self.animated += animated;
        } else {
            self.shadowed -= shadowed;
            self.animated -= animated;
        }
    }
}

impl PointLights {
    /// An empty list.
    pub fn new() -> PointLights {
        PointLights::default()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is no light.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The chunks, in order: light `i` is light `i % LIGHT_CHUNK` of chunk `i / LIGHT_CHUNK`.
    pub fn chunks(&self) -> &[Arc<LightChunk>] {
        &self.chunks
    }

    /// Light `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&ExtractedPointLight> {
        self.chunks.get(i / LIGHT_CHUNK).and_then(|c| c.lights.get(i % LIGHT_CHUNK))
    }

    /// Every light, in order.
    pub fn iter(&self) -> impl Iterator<Item = &ExtractedPointLight> {
        self.chunks.iter().flat_map(|c| c.lights.iter())
    }

    /// How many lights animate on the GPU (one visit per chunk).
    pub fn animated(&self) -> usize {
        self.chunks.iter().map(|c| c.animated).sum()
    }

    /// The lights that cast shadows, with their index, visiting only the chunks that hold some.
    pub fn shadowed(&self) -> impl Iterator<Item = (usize, &ExtractedPointLight)> {
        self.chunks.iter().enumerate().filter(|(_, c)| c.shadowed > 0).flat_map(|(k, c)| {
            c.lights
                .iter()
                .enumerate()
                .filter(|(_, l)| l.shadow.is_some())
                .map(move |(i, l)| (k * LIGHT_CHUNK + i, l))
        })
    }

    /// Adds a light at the end.
    pub fn push(&mut self, light: ExtractedPointLight) {
        if self.len.is_multiple_of(LIGHT_CHUNK) {
            let lights = Vec::with_capacity(LIGHT_CHUNK);
            self.chunks.push(Arc::new(LightChunk { lights, shadowed: 0, animated: 0 }));
        }
        let chunk = Arc::make_mut(self.chunks.last_mut().expect("a chunk with room"));
        chunk.count(&light, true);
        chunk.lights.push(light);
        self.len += 1;
    }

    /// Replaces light `i` (copying its chunk if another frame still holds it); false when
    /// there is no light `i`. A light equal to the one there leaves the chunk shared.
    pub fn set(&mut self, i: usize, light: ExtractedPointLight) -> bool {
        let Some(chunk) = self.chunks.get_mut(i / LIGHT_CHUNK) else { return false };
        match chunk.lights.get(i % LIGHT_CHUNK) {
            None => false,
            Some(old) if *old == light => true,
            Some(_) => {
                let chunk = Arc::make_mut(chunk);
                chunk.count(&light, true);
                let old = std::mem::replace(&mut chunk.lights[i % LIGHT_CHUNK], light);
                chunk.count(&old, false);
                true
            }
        }
    }

    /// Removes the last light and returns it.
    pub fn pop(&mut self) -> Option<ExtractedPointLight> {
        let chunk = self.chunks.last_mut()?;
        let light = Arc::make_mut(chunk).lights.pop();
        if chunk.lights.is_empty() {
            self.chunks.pop();
        } else if let Some(light) = &light {
            Arc::make_mut(chunk).count(light, false);
        }
        self.len -= usize::from(light.is_some());
        light
    }

    /// Changes every light with `f`, in place.
    pub fn update(&mut self, mut f: impl FnMut(&mut ExtractedPointLight)) {
        for chunk in &mut self.chunks {
            let chunk = Arc::make_mut(chunk);
            chunk.lights.iter_mut().for_each(&mut f);
            chunk.recount();
        }
    }
}

impl FromIterator<ExtractedPointLight> for PointLights {
    fn from_iter<I: IntoIterator<Item = ExtractedPointLight>>(lights: I) -> PointLights {
        let mut list = PointLights::new();
        lights.into_iter().for_each(|l| list.push(l));
        list
    }
}

impl From<Vec<ExtractedPointLight>> for PointLights {
    fn from(lights: Vec<ExtractedPointLight>) -> PointLights {
        lights.into_iter().collect()
    }
}

impl<'a> IntoIterator for &'a PointLights {
    type Item = &'a ExtractedPointLight;
    type IntoIter = Box<dyn Iterator<Item = &'a ExtractedPointLight> + 'a>;
    fn into_iter(self) -> Self::IntoIter {
        Box::new(self.iter())
    }
}

impl std::ops::Index<usize> for PointLights {
    type Output = ExtractedPointLight;
    fn index(&self, i: usize) -> &ExtractedPointLight {
        self.get(i).unwrap_or_else(|| panic!("light {i} of {}", self.len))
    }
}

/// The sphere (centre, radius) that holds every point `light` can reach: its range around it,
/// or the smaller sphere around a spot light's cone ([`LightShape::bounding_sphere`]).
pub fn bounding_sphere(light: &ExtractedPointLight) -> (Vec3, f32) {
    light.shape.bounding_sphere(light.position, light.radius)
}

/// `light` as the shaders read it (`GpuPointLight` in `shaders/common/lights.wgsl`): a point
/// light has no direction, falloff scale 0 and offset 1 (1 everywhere).
pub fn gpu_point_light(light: &ExtractedPointLight) -> GpuPointLight {
    let (direction, scale, offset) = light.shape.falloff();
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
        // w: whether it casts, read by the shadow rays (the maps have their own table).
        direction: light
            .direction
            .normalize()
            .extend(if light.shadow.is_some() { 1.0 } else { 0.0 })
            .to_array(),
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

/// A frame's directional lights as the view uniform carries them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewedDirectionalLights {
    /// The first [`MAX_DIRECTIONAL_LIGHTS`] valid ones, packed; the rest zeroed.
    pub packed: [GpuDirectionalLight; MAX_DIRECTIONAL_LIGHTS as usize],
    /// How many of `packed` are lights.
    pub count: u32,
    /// Valid lights past [`MAX_DIRECTIONAL_LIGHTS`], not drawn.
    pub dropped: u32,
    /// Lights refused for invalid parameters.
    pub invalid: u32,
}

/// `lights` packed for the view uniform ([`viewed_directional_lights`], [`gpu_directional_light`]).
pub fn pack_directional_lights(lights: &[ExtractedDirectionalLight]) -> ViewedDirectionalLights {
    let mut packed = [GpuDirectionalLight::default(); MAX_DIRECTIONAL_LIGHTS as usize];
    let mut count = 0;
    for (i, l) in viewed_directional_lights(lights) {
        packed[i as usize] = gpu_directional_light(l);
        count += 1;
    }
    let valid = lights.iter().filter(|l| l.is_valid()).count() as u32;
    ViewedDirectionalLights { packed, count, dropped: valid - count, invalid: lights.len() as u32 - valid }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(shape: LightShape) -> ExtractedPointLight {
        ExtractedPointLight {
            position: Vec3::new(1.0, 2.0, 3.0),
            color: Vec3::ONE,
            intensity: 2.0,
            radius: 4.0,
            shape,
            shadow: None,
            animation: None,
        }
    }

    #[test]
    fn a_light_knows_its_reach_packing_and_bias_by_shape() {
        let point = light(LightShape::Point);
        assert_eq!(bounding_sphere(&point), (point.position, 4.0));
        assert_eq!(ShadowBias::for_shape(point.shape), ShadowBias::POINT);
        let packed = gpu_point_light(&point);
        assert_eq!(packed.position_radius, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(packed.color, [2.0, 2.0, 2.0, 1.0], "a point light's falloff offset is 1");
        assert_eq!(packed.spot, [0.0; 4]);
        let cone = manylight_core::SpotCone { direction: Vec3::NEG_Y, inner_angle: 0.2, outer_angle: 0.4 };
        let spot = light(LightShape::Spot(cone));
        assert_eq!(ShadowBias::for_shape(spot.shape), ShadowBias::SPOT);
        let (_, r) = bounding_sphere(&spot);
        assert!(r < 4.0, "a narrow cone's sphere is smaller than the range: {r}");
        assert_eq!(gpu_point_light(&spot).spot[1], -1.0);
    }

    #[test]
    fn the_reach_box_covers_every_lights_farthest_point() {
        let view =
            glam::Mat4::from_rotation_y(0.4) * glam::Mat4::from_translation(Vec3::new(-3.0, -1.0, -9.0));
        let mut lights = vec![light(LightShape::Point); 3];
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
        let mut lights = vec![light(LightShape::Point); 4];
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

    /// Each chunk counts its shadowed and animated lights through every change, so a frame
    /// finds them (and knows whether any light animates) from one count per chunk.
    #[test]
    fn light_chunks_count_their_shadowed_and_animated_lights() {
        let plain = ExtractedPointLight {
            position: Vec3::ZERO,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: 1.0,
            shape: LightShape::Point,
            shadow: None,
            animation: None,
        };
        let motion = manylight_core::AnimatedLight {
            center: Vec3::ONE,
            orbit_radius: 1.0,
            orbit_speed: 0.5,
            phase: 0.0,
            bob_amplitude: 0.2,
            bob_speed: 1.0,
            color: Vec3::ONE,
            flicker_speed: 1.0,
            intensity: 1.0,
            radius: 1.0,
        };
        let animated = ExtractedPointLight { animation: Some(Arc::new(motion)), ..plain.clone() };
        let shadowed = ExtractedPointLight { shadow: Some(ShadowBias::POINT), ..plain.clone() };
        let mut lights: PointLights = (0..LIGHT_CHUNK + 10).map(|_| plain.clone()).collect();
        let recount = |l: &PointLights| {
            let animated = l.iter().filter(|l| l.animation.is_some()).count();
            (l.animated(), l.shadowed().count(), animated, l.iter().filter(|l| l.shadow.is_some()).count())
        };
        assert_eq!(recount(&lights), (0, 0, 0, 0));
        lights.set(3, animated.clone());
        lights.set(LIGHT_CHUNK + 2, animated.clone());
        lights.set(LIGHT_CHUNK + 9, shadowed.clone());
        assert_eq!(recount(&lights), (2, 1, 2, 1));
        lights.set(3, shadowed.clone());
        assert_eq!(recount(&lights), (1, 2, 1, 2));
        assert_eq!(lights.pop(), Some(shadowed));
        lights.push(animated);
        assert_eq!(recount(&lights), (2, 1, 2, 1));
        lights.update(|l| l.animation = None);
        assert_eq!(recount(&lights), (0, 1, 0, 1));
        assert_eq!(lights.chunks().iter().map(|c| c.animated()).sum::<usize>(), 0);
    }
}

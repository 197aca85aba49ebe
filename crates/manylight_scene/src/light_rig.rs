//! Generated lights: an animated rig for filling a scene with many moving coloured lights, and
//! the sphere-shell stress scene (thousands of small lights just inside a large sphere).
//!
//! Everything is deterministic for a seed (a splitmix64 generator, no `rand`), and every
//! position and colour is finite for every finite or non-finite time.

use crate::shapes::{cuboid, uv_sphere};
use crate::{Scene, SceneCamera, SceneInstance, SceneLight};
use glam::{Mat4, Vec3};
use manylight_core::{Aabb, LightCountError, LightLimit, MaterialData, Projection, check_light_count};
use std::f64::consts::TAU;
use std::sync::Arc;

/// Scale of the light radius relative to the mean spacing of the lights (see [`light_rig`]).
/// With `K = 1` a point of the volume lies inside `4/3 π K³ ≈ 4.2` light spheres on average.
pub const RIG_RADIUS_K: f32 = 1.0;

pub use manylight_core::AnimatedLight;

/// `light` at time `t` as a scene light.
pub fn animated_light_at(light: &AnimatedLight, t: f32) -> SceneLight {
    SceneLight {
        position: light.position_at(t),
        color: light.color_at(t),
        intensity: light.intensity,
        radius: light.radius,
        shape: manylight_core::LightShape::Point,
    }
}

/// splitmix64: a tiny, well-mixed deterministic generator (the same sequence on every
/// machine, so scenes built from a seed are reproducible).
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
}

/// Fully saturated-ish colour of hue `h` in [0, 1), saturation `s`, value 1.
fn hsv(h: f32, s: f32) -> Vec3 {
    let h6 = (h.fract() * 6.0).clamp(0.0, 5.999_999);
    let f = h6.fract();
    let (p, q, t) = (1.0 - s, 1.0 - s * f, 1.0 - s * (1.0 - f));
    match h6 as u32 {
        0 => Vec3::new(1.0, t, p),
        1 => Vec3::new(q, 1.0, p),
        2 => Vec3::new(p, 1.0, t),
        3 => Vec3::new(p, q, 1.0),
        4 => Vec3::new(t, p, 1.0),
        _ => Vec3::new(1.0, p, q),
    }
}

/// Intensity (candela) for a light of radius `r`: `0.12 r²`.
///
/// A point sees about 4 lights (see [`RIG_RADIUS_K`]) at a typical distance of 0.6 r, where
/// the windowed inverse-square falloff is about `0.76 / (0.36 r²)`; this intensity makes their
/// sum about 1 lux whatever the radius, so 16 big lights and 4096 small ones light a scene
/// similarly.
pub fn intensity_for_radius(r: f32) -> f32 {
    0.12 * r * r
}

/// `bounds`, or the cube [-1, 1]³ when they are empty or not finite.
fn usable_bounds(bounds: Aabb) -> Aabb {
    let usable =
        !bounds.is_empty() && bounds.min.is_finite() && bounds.max.is_finite() && bounds.size().is_finite();
    if usable { bounds } else { Aabb { min: Vec3::splat(-1.0), max: Vec3::ONE } }
}

/// A model's bounds made into a volume for [`light_rig`] around it: each side at least a
/// quarter of the diagonal, so a flat scene (a single plane) gets lights above it too.
pub fn rig_bounds(bounds: Aabb) -> Aabb {
    let pad = (Vec3::splat(bounds.size().length() * 0.25) - bounds.size()).max(Vec3::ZERO) * 0.5;
    Aabb { min: bounds.min - pad, max: bounds.max + pad }
}

/// `count` animated lights placed deterministically (for `seed`) inside `bounds`.
///
/// Centres are uniform in `bounds` shrunk by 5 % of its size on each side, and orbit and bob
/// amplitudes are limited so every position stays inside that shrunk box at all times. Hues
/// are random and saturated. The radius is
/// `r = clamp(K · (V / count)^(1/3), 0.5, 8)` with `V` the volume of `bounds` and
/// `K` = [`RIG_RADIUS_K`], so the expected number of lights touching a point stays about 4 as
/// `count` grows (until the clamp); the intensity is [`intensity_for_radius`]. An empty or
/// non-finite `bounds` is replaced by the cube [-1, 1]³.
///
/// A `count` past [`manylight_core::MAX_LIGHTS`], or whose lights would not fit the memory
/// available, is refused before anything is allocated.
pub fn light_rig(count: usize, bounds: Aabb, seed: u64) -> Result<Vec<AnimatedLight>, LightCountError> {
    check_count::<AnimatedLight>(count)?;
    let bounds = usable_bounds(bounds);
    let size = bounds.size();
    let inner = Aabb { min: bounds.min + size * 0.05, max: bounds.max - size * 0.05 };
    let volume = (size.x * size.y * size.z).max(1e-6);
    let radius = (RIG_RADIUS_K * (volume / count.max(1) as f32).cbrt()).clamp(0.5, 8.0);
    let intensity = intensity_for_radius(radius);
    let mut rng = SplitMix64(seed ^ 0x6c69_6768_7472_6967);
    Ok((0..count)
        .map(|_| {
            let u = Vec3::new(rng.f32(), rng.f32(), rng.f32());
            let center = inner.min + (inner.max - inner.min) * u;
            let room_xz = (center.x - inner.min.x)
                .min(inner.max.x - center.x)
                .min(center.z - inner.min.z)
                .min(inner.max.z - center.z)
                .max(0.0);
            let room_y = (center.y - inner.min.y).min(inner.max.y - center.y).max(0.0);
            let dir = if rng.f32() < 0.5 { -1.0 } else { 1.0 };
            AnimatedLight {
                center,
                orbit_radius: rng.range(0.2, 1.0) * room_xz.min(3.0),
                orbit_speed: dir * rng.range(0.2, 0.8),
                phase: rng.range(0.0, std::f32::consts::TAU),
                bob_amplitude: rng.f32() * room_y.min(0.5),
                bob_speed: rng.range(0.5, 2.0),
                color: hsv(rng.f32(), rng.range(0.7, 1.0)),
                flicker_speed: rng.range(0.5, 3.0),
                intensity,
                radius,
            }
        })
        .collect())
}

/// Checks `count` lights of type `T` against [`LightLimit::INDICES`] and the memory available.
fn check_count<T>(count: usize) -> Result<(), LightCountError> {
    check_light_count(count, LightLimit::INDICES, std::mem::size_of::<T>() as u64)
}

/// `count` unit directions spread evenly over the sphere: the Fibonacci (golden-angle) lattice,
/// from +y down to -y.
fn fibonacci_sphere(count: usize) -> impl Iterator<Item = Vec3> {
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count).map(move |i| {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
        let ring = (1.0 - y * y).max(0.0).sqrt();
        let theta = (golden_angle * i as f64).rem_euclid(TAU);
        Vec3::new((theta.cos() * ring) as f32, y as f32, (theta.sin() * ring) as f32)
    })
}

/// Radius of the sphere-shell preset's sphere ([`sphere_shell_scene`]; its lights sit just
/// inside).
pub const SHELL_RADIUS: f32 = 50.0;
/// Range of each light of the sphere-shell preset.
pub const SHELL_LIGHT_RANGE: f32 = 0.3;

/// `count` static lights of range `light_range` on a Fibonacci (golden-angle) lattice just
/// inside a sphere of radius `shell_radius` centred on the origin, with random hues.
///
/// Each light sits `min(0.8 · light_range, 1)` inside the sphere: inside the flat faces of the
/// tessellated shell of [`sphere_shell_scene`] (whose faces sag up to ~0.21 below the sphere at
/// r = 50), while its sphere of influence still reaches the shell (for range 0.3 the light is
/// 0.24 inside).
///
/// A `count` past [`manylight_core::MAX_LIGHTS`], or whose lights would not fit the memory
/// available, is refused before anything is allocated.
pub fn sphere_shell_lights(
    count: usize,
    shell_radius: f32,
    light_range: f32,
    seed: u64,
) -> Result<Vec<SceneLight>, LightCountError> {
    check_count::<SceneLight>(count)?;
    let shell = if shell_radius.is_finite() { shell_radius.max(0.0) } else { 0.0 };
    let range = if light_range.is_finite() { light_range.max(0.0) } else { 0.0 };
    let r = shell - (0.8 * range).min(1.0).min(shell);
    let mut rng = SplitMix64(seed ^ 0x7368_656c_6c5f_6c74);
    Ok(fibonacci_sphere(count)
        .map(|dir| SceneLight {
            position: dir * r,
            color: hsv(rng.f32(), rng.range(0.7, 1.0)),
            intensity: intensity_for_radius(range),
            radius: range,
            shape: manylight_core::LightShape::Point,
        })
        .collect())
}

/// `count` static white point lights on a dome around `bounds`, as a model viewer lights a model
/// that brings no lights of its own.
///
/// The lights lie on a Fibonacci (golden-angle) lattice on the sphere of radius `2ρ` about the
/// centre of `bounds` (`ρ` = half its diagonal), each reaching `4ρ` (the whole model from any
/// point of the dome), with `18 ρ² / count` candela each: a surface near the centre facing out
/// then receives about 1 lux from the lights of its side (`count/4π` lights per steradian, each
/// `I · 0.88 / (2ρ)²` with the window at half the range, integrated over the cosine). An empty
/// or non-finite `bounds` is replaced by the cube [-1, 1]³.
///
/// A `count` past [`manylight_core::MAX_LIGHTS`], or whose lights would not fit the memory
/// available, is refused before anything is allocated.
pub fn studio_lights(count: usize, bounds: Aabb) -> Result<Vec<SceneLight>, LightCountError> {
    check_count::<SceneLight>(count)?;
    let bounds = usable_bounds(bounds);
    let rho = (bounds.size().length() * 0.5).max(1e-3);
    let center = bounds.center();
    let intensity = 18.0 * rho * rho / count.max(1) as f32;
    Ok(fibonacci_sphere(count)
        .map(|dir| SceneLight {
            position: center + dir * (2.0 * rho),
            color: Vec3::ONE,
            intensity,
            radius: 4.0 * rho,
            shape: manylight_core::LightShape::Point,
        })
        .collect())
}

/// The sphere-shell stress scene: an inward-facing white sphere of radius 50 (~2200
/// triangles), a 5 × 5 × 5 box at (0, 50, 0), a camera at the origin (45° vertical fov,
/// near 0.1, far 1000) and no lights (add [`sphere_shell_lights`]).
pub fn sphere_shell_scene() -> Scene {
    let white = MaterialData {
        label: "sphere_shell/white".into(),
        base_color: manylight_core::Color::WHITE,
        ..MaterialData::default()
    };
    Scene {
        name: "sphere-shell".into(),
        meshes: vec![
            Arc::new(uv_sphere("sphere_shell/shell", 50.0, 24, 48, true)),
            Arc::new(cuboid("sphere_shell/box", Vec3::splat(5.0), 1.0)),
        ],
        materials: vec![Arc::new(white)],
        instances: vec![
            SceneInstance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            SceneInstance {
                mesh: 1,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, 50.0, 0.0)),
            },
        ],
        lights: Vec::new(),
        directional_lights: Vec::new(),
        cameras: vec![SceneCamera {
            transform: Mat4::IDENTITY,
            projection: Projection::perspective(45f32.to_radians(), 0.1, 1000.0),
        }],
        nodes: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn studio_lights_give_about_one_lux_facing_out() {
        let bounds = Aabb { min: Vec3::new(-3.0, 0.0, -1.0), max: Vec3::new(5.0, 2.0, 1.0) };
        let lights = studio_lights(64, bounds).expect("64 lights");
        let rho = bounds.size().length() * 0.5;
        for l in &lights {
            assert!(((l.position - bounds.center()).length() - 2.0 * rho).abs() < 1e-3 * rho);
            assert!(l.radius >= 3.0 * rho, "reaches the whole model");
        }
        // Illuminance at the centre on surfaces facing along each axis.
        for n in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
            let e: f32 = lights
                .iter()
                .map(|l| {
                    let to = l.position - bounds.center();
                    let cos = n.dot(to.normalize()).max(0.0);
                    l.intensity * manylight_core::attenuation(to.length(), l.radius) * cos
                })
                .sum();
            assert!((0.85..1.15).contains(&e), "{n}: {e} lux");
        }
    }

    #[test]
    fn hsv_is_in_unit_range_and_saturated() {
        for i in 0..100 {
            let c = hsv(i as f32 / 100.0, 1.0);
            assert!(c.min_element() >= 0.0 && c.max_element() <= 1.0);
            assert_eq!(c.max_element(), 1.0);
        }
    }

    #[test]
    fn shell_lights_sit_inside_the_tessellated_shell() {
        let scene = sphere_shell_scene();
        let shell = &scene.meshes[0];
        // The smallest distance of a shell triangle's plane from the centre.
        let mut inscribed = f32::MAX;
        for t in shell.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(shell.vertices[i as usize].position));
            if let Some(n) = (b - a).cross(c - a).try_normalize() {
                inscribed = inscribed.min(n.dot(a).abs());
            }
        }
        for l in sphere_shell_lights(500, 50.0, 0.3, 1).expect("500 lights") {
            let d = l.position.length();
            assert!(d < inscribed, "{d} >= {inscribed}");
            assert!(d + l.radius > inscribed);
        }
    }

    /// Counts no device could hold are refused before anything is allocated (they used to
    /// abort on a 240 GB allocation or panic with "capacity overflow").
    #[test]
    fn impossible_light_counts_are_refused_before_allocation() {
        let bounds = Aabb { min: Vec3::ZERO, max: Vec3::ONE };
        for count in [u32::MAX as usize, usize::MAX] {
            assert!(light_rig(count, bounds, 1).is_err(), "{count}");
            assert!(studio_lights(count, bounds).is_err(), "{count}");
            assert!(sphere_shell_lights(count, 50.0, 0.3, 1).is_err(), "{count}");
        }
    }

    #[test]
    fn shell_scene_is_valid() {
        let s = sphere_shell_scene();
        s.validate().expect("valid");
        let tris = s.meshes[0].triangle_count();
        assert!((1500..3000).contains(&tris), "{tris}");
    }
}

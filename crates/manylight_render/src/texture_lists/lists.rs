//! The CPU side of the texture-list path: the frame's lights at the frame's time, their
//! cluster lists from the CPU assignment, and each packed into the rows of a texture. No GPU.

use crate::gpu_types::GpuPointLight;
use crate::lights::{LightReach, bounding_sphere, buffered_light};
use crate::snapshot::{ExtractedPointLight, PointLights};
use glam::Mat4;
use manylight_core::cluster::{ClusterAssignment, ClusterGrid, CullTest, ViewSphere, assign_lights};

/// Texels of a light in the light texture: `position_radius`, `color`, `spot`.
pub const TEXELS_PER_LIGHT: u32 = 3;

/// The frame's point and spot lights as the light texture holds them, in the order of
/// [`PointLights`] (a light's index is its index everywhere, as in the light buffer).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameLights {
    /// Each light packed ([`buffered_light`]: an invalid one zeroed), an animated one at the
    /// frame's time.
    pub packed: Vec<GpuPointLight>,
    /// The sphere each light can reach (world space; radius 0 for an invalid light).
    pub spheres: Vec<(glam::Vec3, f32)>,
    /// What the valid lights reach, for slicing a projection without a far plane.
    pub reach: LightReach,
    /// Valid lights.
    pub valid: u32,
}

/// `light` as shown at `t` seconds: an animated light at its animation's position and colour
/// (`manylight_core::AnimatedLight`, the CPU twin of `shaders/light_animation.wgsl`).
pub fn light_at(light: &ExtractedPointLight, t: f32) -> ExtractedPointLight {
    let mut shown = light.clone();
    if let Some(a) = light.animation.as_deref() {
        shown.position = a.position_at(t);
        shown.color = a.color_at(t);
    }
    shown
}

impl FrameLights {
    /// The lights of `lights` at `t` seconds.
    pub fn new(lights: &PointLights, t: f32) -> FrameLights {
        let mut out = FrameLights {
            packed: Vec::with_capacity(lights.len()),
            spheres: Vec::with_capacity(lights.len()),
            ..Default::default()
        };
        for light in lights.iter() {
            if !light.is_valid() {
                out.packed.push(buffered_light(light));
                out.spheres.push((glam::Vec3::ZERO, 0.0));
                continue;
            }
            out.reach.add(light);
            out.valid += 1;
            let shown = light_at(light, t);
            out.packed.push(buffered_light(&shown));
            out.spheres.push(bounding_sphere(&shown));
        }
        out
    }

    /// The light texture's texels, `lights_per_row` lights a row, the last row padded with
    /// zeros (at least one row).
    pub fn texels(&self, lights_per_row: u32) -> Vec<[f32; 4]> {
        let texels: Vec<[f32; 4]> =
            self.packed.iter().flat_map(|l| [l.position_radius, l.color, l.spot]).collect();
        padded(&texels, lights_per_row * TEXELS_PER_LIGHT, [0.0; 4])
    }

    /// The cluster lists of a view of `grid` from `view_from_world`, by the CPU assignment
    /// with `test` and `cap` (the same lists the GPU build makes, light for light).
    pub fn assign(
        &self,
        grid: &ClusterGrid,
        view_from_world: &Mat4,
        test: CullTest,
        cap: Option<u32>,
    ) -> ClusterAssignment {
        let spheres: Vec<ViewSphere> =
            manylight_core::cluster::view_spheres(view_from_world, self.spheres.iter().copied());
        assign_lights(grid, &spheres, test, cap)
    }
}

/// Rows of `width` entries that hold `entries` (at least one).
pub fn rows_for(entries: u64, width: u32) -> u32 {
    entries.div_ceil(u64::from(width.max(1))).max(1).min(u64::from(u32::MAX)) as u32
}

/// `data` padded with `fill` to whole rows of `width` (at least one row).
pub fn padded<T: Copy>(data: &[T], width: u32, fill: T) -> Vec<T> {
    // A Vec may hold more than it was asked for: the length is the rows', not the capacity.
    let len = rows_for(data.len() as u64, width) as usize * width.max(1) as usize;
    let mut out = Vec::with_capacity(len);
    out.extend_from_slice(data);
    out.resize(len, fill);
    out
}

/// Counts the pixels the texture-list pass marked as not finite (alpha 0) and makes every
/// pixel opaque again, so the image shows as the tone map's would.
pub fn take_nonfinite(image: &mut image::RgbaImage) -> u32 {
    let mut count = 0;
    for pixel in image.pixels_mut() {
        if pixel[3] == 0 {
            count += 1;
        }
        pixel[3] = 255;
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{UVec2, Vec3};
    use manylight_core::Projection;
    use manylight_core::cluster::GridConfig;

    #[test]
    fn invalid_lights_keep_their_place_and_reach_nothing() {
        let mut lights = PointLights::new();
        lights.push(ExtractedPointLight::point(Vec3::new(0.0, 0.0, -5.0), Vec3::ONE, 10.0, 2.0));
        lights.push(ExtractedPointLight::point(Vec3::new(f32::NAN, 0.0, -5.0), Vec3::ONE, 10.0, 2.0));
        lights.push(ExtractedPointLight::point(Vec3::new(1.0, 0.0, -5.0), Vec3::ONE, 10.0, 2.0));
        let frame = FrameLights::new(&lights, 0.0);
        assert_eq!(frame.valid, 2);
        assert_eq!(frame.packed[1], bytemuck::Zeroable::zeroed());
        assert_eq!(frame.spheres[1].1, 0.0);
        let grid = ClusterGrid::new(UVec2::new(64, 64), &Projection::default(), &GridConfig::default());
        let lists = frame.assign(&grid, &Mat4::IDENTITY, CullTest::Both, None);
        assert!(!lists.indices.is_empty());
        assert!(!lists.indices.contains(&1), "an invalid light is in no list");
    }

    #[test]
    fn animated_lights_are_shown_at_the_frame_time() {
        let rig = manylight_core::AnimatedLight {
            center: Vec3::new(0.0, 1.0, 0.0),
            orbit_radius: 2.0,
            orbit_speed: 0.7,
            phase: 0.3,
            bob_amplitude: 0.5,
            bob_speed: 1.1,
            color: Vec3::new(1.0, 0.5, 0.25),
            flicker_speed: 2.0,
            intensity: 1.0,
            radius: 1.0,
        };
        let rig = std::sync::Arc::new(rig);
        let light = ExtractedPointLight {
            animation: Some(rig.clone()),
            ..ExtractedPointLight::point(Vec3::ZERO, Vec3::ONE, 1.0, 1.0)
        };
        let shown = light_at(&light, 3.5);
        assert_eq!(shown.position, rig.position_at(3.5));
        assert_eq!(shown.color, rig.color_at(3.5));
    }

    #[test]
    fn textures_are_whole_rows() {
        let mut lights = PointLights::new();
        for i in 0..5 {
            lights.push(ExtractedPointLight::point(Vec3::splat(i as f32), Vec3::ONE, 1.0, 1.0));
        }
        let frame = FrameLights::new(&lights, 0.0);
        let texels = frame.texels(2);
        assert_eq!(texels.len(), 3 * 2 * 3);
        assert_eq!(texels[3 * 4], frame.packed[4].position_radius);
        assert_eq!(texels[3 * 5], [0.0; 4]);
        assert_eq!(padded(&[1u32, 2, 3], 2, 0), vec![1, 2, 3, 0]);
        assert_eq!(padded::<u32>(&[], 4, 7), vec![7; 4]);
        assert_eq!(rows_for(0, 8), 1);
    }

    #[test]
    fn nonfinite_pixels_are_counted_and_made_opaque() {
        let mut image = image::RgbaImage::from_pixel(3, 2, image::Rgba([10, 20, 30, 255]));
        image.put_pixel(1, 1, image::Rgba([0, 0, 0, 0]));
        assert_eq!(take_nonfinite(&mut image), 1);
        assert!(image.pixels().all(|p| p[3] == 255));
    }
}

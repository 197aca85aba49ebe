//! Image-based lighting: the environment a camera is lit by ([`EnvironmentMapLight`]), the
//! one it shows behind the geometry ([`Skybox`]), the panoramas they name
//! ([`EnvironmentImages`]) and how finely environments are prefiltered
//! ([`EnvironmentFilter`]).

use glam::Quat;
use manylight_core::environment::EquirectImage;
use std::sync::Arc;

/// Names one panorama of [`EnvironmentImages`] (Bevy names an image with a `Handle<Image>`).
/// A panorama never changes under its handle: a new image is a new handle, and the renderer
/// prefilters each handle once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EnvironmentHandle(u64);

/// The panoramas environments and skyboxes name. With the `bevy` feature it is a resource:
/// an app adds a decoded panorama (`manylight_scene::decode_environment`) and puts the handle
/// on its camera.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::prelude::Resource))]
pub struct EnvironmentImages {
    images: Vec<(EnvironmentHandle, Arc<EquirectImage>)>,
    names: Vec<(EnvironmentHandle, String)>,
    next: u64,
}

impl EnvironmentImages {
    /// Adds a panorama and returns its handle.
    pub fn add(&mut self, image: impl Into<Arc<EquirectImage>>) -> EnvironmentHandle {
        let handle = EnvironmentHandle(self.next);
        self.next += 1;
        self.images.push((handle, image.into()));
        handle
    }

    /// Adds a panorama under a name an overlay can show (its file's, say) and returns its
    /// handle.
    pub fn add_named(
        &mut self,
        name: impl Into<String>,
        image: impl Into<Arc<EquirectImage>>,
    ) -> EnvironmentHandle {
        let handle = self.add(image);
        self.names.push((handle, name.into()));
        handle
    }

    /// The name `handle` was added with, if any.
    pub fn name(&self, handle: EnvironmentHandle) -> Option<&str> {
        self.names.iter().find(|(h, _)| *h == handle).map(|(_, name)| name.as_str())
    }

    /// Puts `image` under a handle of another collection (extraction copies the panoramas a
    /// frame's views name into the frame's snapshot).
    pub fn insert(&mut self, handle: EnvironmentHandle, image: Arc<EquirectImage>) {
        match self.images.iter_mut().find(|(h, _)| *h == handle) {
            Some(entry) => entry.1 = image,
            None => self.images.push((handle, image)),
        }
        self.next = self.next.max(handle.0 + 1);
    }

    /// The panorama of `handle`.
    pub fn get(&self, handle: EnvironmentHandle) -> Option<&Arc<EquirectImage>> {
        self.images.iter().find(|(h, _)| *h == handle).map(|(_, image)| image)
    }

    /// Removes the panorama of `handle` (the renderer frees its maps once no view names it).
    pub fn remove(&mut self, handle: EnvironmentHandle) -> Option<Arc<EquirectImage>> {
        let index = self.images.iter().position(|(h, _)| *h == handle)?;
        self.names.retain(|(h, _)| *h != handle);
        Some(self.images.remove(index).1)
    }

    /// The panoramas, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = (EnvironmentHandle, &Arc<EquirectImage>)> {
        self.images.iter().map(|(h, image)| (*h, image))
    }
}

/// Light from an environment panorama on everything a camera sees (Bevy's
/// `EnvironmentMapLight`): diffuse and specular split-sum image-based lighting, added to the
/// lights in every pipeline. With the `bevy` feature it is a camera component.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct EnvironmentMapLight {
    /// The panorama.
    pub image: EnvironmentHandle,
    /// Multiplies the panorama's radiance (the panorama's values are radiance in the same
    /// units as the lights' output, before exposure).
    pub intensity: f32,
    /// Turns the environment about the world (a panorama's centre looks along -Z).
    pub rotation: Quat,
}

impl EnvironmentMapLight {
    /// The panorama at `intensity` 1, unrotated.
    pub fn new(image: EnvironmentHandle) -> EnvironmentMapLight {
        EnvironmentMapLight { image, intensity: 1.0, rotation: Quat::IDENTITY }
    }
}

/// The panorama drawn behind everything a camera sees (Bevy's `Skybox`), instead of the clear
/// colour. With the `bevy` feature it is a camera component.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::component::Component))]
pub struct Skybox {
    /// The panorama.
    pub image: EnvironmentHandle,
    /// Multiplies the panorama's radiance.
    pub brightness: f32,
    /// Turns the panorama about the world.
    pub rotation: Quat,
}

impl Skybox {
    /// The panorama at `brightness` 1, unrotated.
    pub fn new(image: EnvironmentHandle) -> Skybox {
        Skybox { image, brightness: 1.0, rotation: Quat::IDENTITY }
    }
}

/// How finely an environment is prefiltered when it is loaded: the split-sum's accuracy
/// against its cost (`manylight report` measures both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EnvironmentFilter {
    /// Face size of the source and specular cubes, in texels (a power of two, 16 to 2048).
    pub cube_size: u32,
    /// GGX samples per texel of each specular mip and of the irradiance cube.
    pub samples: u32,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Size of the split-sum lookup table (texels along n.v and along roughness).
    pub lut_size: u32,
}

/// Specular mips of a cube: roughness 0 to 1 in this many steps, at most one per level
/// ([`EnvironmentFilter::specular_mip_roughness`] spaces them).
pub const ENVIRONMENT_SPECULAR_MIPS: u32 = 8;

impl Default for EnvironmentFilter {
    /// 256² faces and 1 024 samples a texel, as the glTF Sample Viewer prefilters; fewer
    /// samples miss small bright features (`manylight environment-accuracy` measures it).
    fn default() -> Self {
        EnvironmentFilter { cube_size: 256, samples: 1024, irradiance_size: 32, lut_size: 128 }
    }
}

impl EnvironmentFilter {
    /// Refuses sizes and counts no environment can be filtered with, naming the field.
    pub fn check_values(&self) -> Result<(), String> {
        if !(16..=2048).contains(&self.cube_size) || !self.cube_size.is_power_of_two() {
            return Err(format!(
                "environment cube_size {} must be a power of two from 16 to 2048",
                self.cube_size
            ));
        }
        if !(1..=65_536).contains(&self.samples) {
            return Err(format!("environment samples {} must be 1 to 65536", self.samples));
        }
        if !(4..=512).contains(&self.irradiance_size) {
            return Err(format!("environment irradiance_size {} must be 4 to 512", self.irradiance_size));
        }
        if !(8..=1024).contains(&self.lut_size) {
            return Err(format!("environment lut_size {} must be 8 to 1024", self.lut_size));
        }
        Ok(())
    }

    /// Mip levels of the specular cube: [`ENVIRONMENT_SPECULAR_MIPS`], fewer for a small cube
    /// (its last face at least 4 texels).
    pub fn specular_mips(&self) -> u32 {
        ENVIRONMENT_SPECULAR_MIPS.min(self.cube_size.ilog2() - 1)
    }

    /// GGX perceptual roughness the specular cube's mip `level` is prefiltered at:
    /// `(level / (mips - 1))²`, so the mips crowd at low roughness, where the lobe's width
    /// changes fastest and a mirror-like surface would otherwise read a much blurrier mip
    /// between its two neighbours (Filament and Unreal space them alike). The shading passes
    /// read the inverse, `environment_specular_lod` in `shaders/common/environment.wgsl`, as
    /// [`EnvironmentFilter::specular_lod`] does here.
    pub fn specular_mip_roughness(&self, level: u32) -> f32 {
        let last = self.specular_mips().saturating_sub(1).max(1) as f32;
        (level as f32 / last).powi(2)
    }

    /// The specular cube's mip level a surface of perceptual `roughness` reads:
    /// `sqrt(roughness) (mips - 1)`, the inverse of
    /// [`EnvironmentFilter::specular_mip_roughness`]. `environment_specular_lod` in
    /// `shaders/common/environment.wgsl` computes the same from `mips - 1` in the view's
    /// `environment.y`.
    pub fn specular_lod(&self, roughness: f32) -> f32 {
        roughness.clamp(0.0, 1.0).sqrt() * self.specular_mips().saturating_sub(1) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every mip's roughness reads back that mip, from mirror (mip 0) to roughness 1 (the
    /// last), for every cube size.
    #[test]
    fn specular_lod_inverts_the_mip_roughness() {
        for cube_size in [16, 64, 256, 2048] {
            let filter = EnvironmentFilter { cube_size, ..EnvironmentFilter::default() };
            let mips = filter.specular_mips();
            assert_eq!(filter.specular_mip_roughness(0), 0.0);
            assert_eq!(filter.specular_mip_roughness(mips - 1), 1.0);
            for level in 0..mips {
                let lod = filter.specular_lod(filter.specular_mip_roughness(level));
                assert!((lod - level as f32).abs() < 1e-4, "cube {cube_size}, mip {level}: lod {lod}");
            }
        }
    }
}

//! Which lights ask for a shadow map this frame, and how large a face each asks for: the size
//! of its sphere on screen, as a power of two in the settings' range. Lights no view sees ask
//! for none; directional lights ask for their cascades at their set size.

use super::ShadowSettings;
use super::frustum::sphere_in_view;
use super::resources::ShadowResources;
use crate::gpu_types::SHADOW_TILE_COLUMNS;
use crate::lights::bounding_sphere;
use crate::snapshot::{ExtractedCamera, ExtractedDirectionalLight, FrameSnapshot};
use glam::{UVec2, Vec3, Vec4};
use manylight_core::ProjectionKind;

/// What a shadow map belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ShadowCaster {
    /// A point or spot light, by its index in the light buffer: six cube faces.
    Point(u32),
    /// A directional light, by its index in the view's directional lights: one tile per
    /// cascade.
    Directional(u32),
}

/// One light's request for a shadow map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRequest {
    /// The light.
    pub caster: ShadowCaster,
    /// Face edge asked for (a power of two).
    pub edge: u32,
    /// Larger is kept first when the atlas is full (the projected size).
    pub importance: f32,
}

/// The radius in pixels of the sphere (`center`, `radius`) in a view through `camera` of
/// `size` pixels; `None` when it has no bound: no camera, or a camera inside the sphere.
pub fn projected_radius(camera: Option<(&ExtractedCamera, UVec2)>, center: Vec3, radius: f32) -> Option<f32> {
    let (camera, size) = camera?;
    let half_height = size.y.max(1) as f32 * 0.5;
    let projection = camera.projection.sanitized();
    match projection.kind {
        ProjectionKind::Orthographic { height } => Some(radius / (0.5 * height) * half_height),
        ProjectionKind::Perspective => {
            let distance = camera.position().distance(center);
            if distance <= radius {
                return None;
            }
            let tangent = radius / (distance * distance - radius * radius).sqrt();
            Some(tangent / (0.5 * projection.fov_y).tan() * half_height)
        }
    }
}

/// `wanted` texels rounded up to a power of two in `lo..=hi`; `hi` when unbounded (`None`) or
/// not finite.
fn edge_for(wanted: Option<f32>, lo: u32, hi: u32) -> u32 {
    match wanted {
        Some(w) if w.is_finite() && w < hi as f32 => {
            (w.max(1.0).ceil() as u32).next_power_of_two().clamp(lo, hi)
        }
        _ => hi,
    }
}

/// The face edge a light with the sphere (`center`, `radius`) asks for in a view through
/// `camera` of `size` pixels: its projected radius in pixels ([`projected_radius`]) times
/// `resolution_scale`, rounded up to a power of two in the settings' range; the largest for a
/// camera inside the sphere or no camera.
pub fn requested_edge(
    settings: &ShadowSettings,
    camera: Option<(&ExtractedCamera, UVec2)>,
    center: Vec3,
    radius: f32,
) -> u32 {
    let wanted = projected_radius(camera, center, radius).map(|p| p * settings.resolution_scale);
    edge_for(wanted, settings.min_face_size, settings.max_face_size)
}

impl ShadowResources {
    /// Asks for a map for every valid point and spot light with a shadow that one of
    /// `frustums` sees, by the light's index in the light buffer (the valid lights in order),
    /// its edge from its size through `camera`; counts the lights no view sees.
    pub(super) fn request_point_maps(
        &mut self,
        snapshot: &FrameSnapshot,
        camera: Option<(&ExtractedCamera, UVec2)>,
        frustums: &[[Vec4; 5]],
    ) {
        let settings = snapshot.settings.shadows;
        self.scratch.requests.clear();
        // The lights with a shadow, found without visiting the chunks that hold none.
        for (k, light) in snapshot.lights.shadowed().map(|(k, l)| (k as u32, l)) {
            if !light.is_valid() || light.radius <= 0.0 {
                continue;
            }
            let (center, radius) = bounding_sphere(light);
            // A light no view sees lights no visible pixel: no map.
            if !sphere_in_view(frustums, center, radius) {
                self.report.unseen_lights += 1;
                continue;
            }
            // The same rounding as the edge, without its range: lights larger on screen first.
            let wanted = projected_radius(camera, center, radius).map(|p| p * settings.resolution_scale);
            let edge = edge_for(wanted, settings.min_face_size, settings.max_face_size);
            let importance = edge_for(wanted, 1, 1 << 30) as f32;
            self.scratch.requests.push(ShadowRequest { caster: ShadowCaster::Point(k), edge, importance });
        }
    }

    /// Asks for the cascades of every casting light of `directional` when the frame has a
    /// view (`has_view`), at their set size (at most a third of `max_atlas`: a block is 3 tiles
    /// wide), kept before any point light when the atlas is full.
    pub(super) fn request_cascades(
        &mut self,
        settings: &ShadowSettings,
        directional: &[&ExtractedDirectionalLight],
        has_view: bool,
        max_atlas: u32,
    ) {
        let widest = 1u32 << (31 - (max_atlas / SHADOW_TILE_COLUMNS).max(1).leading_zeros());
        for (i, light) in directional.iter().enumerate() {
            if light.shadow.is_some() && has_view {
                let edge = settings.cascade_size.max(settings.min_face_size).min(widest);
                let caster = ShadowCaster::Directional(i as u32);
                self.scratch.requests.push(ShadowRequest { caster, edge, importance: f32::MAX });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    #[test]
    fn requested_edges_follow_the_projected_size() {
        let settings = ShadowSettings::default();
        let camera = ExtractedCamera {
            world_from_view: Mat4::IDENTITY,
            projection: Default::default(),
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
            exposure: None,
            environment: None,
            skybox: None,
        };
        let size = UVec2::new(1280, 720);
        let near = requested_edge(&settings, Some((&camera, size)), Vec3::new(0.0, 0.0, -5.0), 1.0);
        let far = requested_edge(&settings, Some((&camera, size)), Vec3::new(0.0, 0.0, -80.0), 1.0);
        assert!(near > far, "{near} vs {far}");
        assert_eq!(far, 16);
        assert_eq!(requested_edge(&settings, Some((&camera, size)), Vec3::ZERO, 1.0), 512, "camera inside");
        assert!(ShadowSettings { min_face_size: 24, ..settings }.check_values().is_err());
        assert!(ShadowSettings { min_face_size: 1024, ..settings }.check_values().is_err());
        assert!(settings.check_values().is_ok());
    }
}

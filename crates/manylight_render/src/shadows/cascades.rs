//! How a directional light's cascade is fitted to its slice of the view: a square around the
//! slice's bounding sphere, snapped to whole texels so it does not shimmer as the camera moves,
//! with a depth range that reaches back to the casters (or the sphere where depth is clamped).

use crate::snapshot::ExtractedCamera;
use glam::{Mat4, Vec3, Vec4};
use manylight_core::{Aabb, ProjectionKind};

/// A slice of the view between two distances along the camera's axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSlice {
    /// Nearer distance.
    pub near: f32,
    /// Further distance.
    pub far: f32,
}

/// A cascade fitted to its slice of the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeFit {
    /// Orthographic along the light: x, y ∈ [-1, 1] over a square that holds the slice's
    /// bounding sphere, z from 1 at the near side (the casters nearest the light, or the
    /// sphere's near side when depth is clamped) to 0 at the sphere's far side (reverse depth,
    /// like the cube faces).
    pub clip_from_world: Mat4,
    /// Width of one of the cascade's texels in world units.
    pub texel: f32,
    /// The depth range in world units.
    pub depth_range: f32,
}

/// Fits a cascade of `edge` texels for light travelling along `direction` to `slice` of the
/// view through `camera` (of aspect `aspect`): the slice's eight corners' bounding sphere, its
/// radius rounded up to 1/16 unit and its centre snapped to whole texels across the light, so
/// the map keeps its size and texel grid as the camera turns and moves (no shimmering edges).
/// Its depth spans the sphere when the shadow pass clamps depth (`casters` is `None`: a caster
/// nearer the light than the sphere is clamped onto its near side and still shadows it, and
/// the depth range stays the sphere's however large the world), else it reaches back to every
/// caster in `casters`.
pub fn fit_cascade(
    camera: &ExtractedCamera,
    aspect: f32,
    slice: ViewSlice,
    direction: Vec3,
    casters: Option<&Aabb>,
    edge: u32,
) -> CascadeFit {
    let projection = camera.projection.sanitized();
    let near = slice.near.max(projection.near);
    let far = slice.far.min(projection.far).max(near);
    let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
    let half_extent = |d: f32| -> (f32, f32) {
        let half_height = match projection.kind {
            ProjectionKind::Perspective => d * (0.5 * projection.fov_y).tan(),
            ProjectionKind::Orthographic { height } => 0.5 * height,
        };
        (half_height * aspect, half_height)
    };
    let mut corners = [Vec3::ZERO; 8];
    for (i, d) in [near, far].into_iter().enumerate() {
        let (w, h) = half_extent(d);
        for (j, (x, y)) in [(-w, -h), (w, -h), (w, h), (-w, h)].into_iter().enumerate() {
            corners[i * 4 + j] = camera.world_from_view.transform_point3(Vec3::new(x, y, -d));
        }
    }
    let center = corners.iter().copied().sum::<Vec3>() / 8.0;
    let radius = corners.iter().map(|c| c.distance(center)).fold(0.0f32, f32::max);
    let radius = ((radius * 16.0).ceil() / 16.0).max(1.0 / 16.0);
    let direction = direction.try_normalize().unwrap_or(Vec3::NEG_Y);
    let up = if direction.y.abs() < 0.99 { Vec3::Y } else { Vec3::X };
    let light_from_world = glam::camera::rh::view::look_to_mat4(Vec3::ZERO, direction, up);
    let texel = 2.0 * radius / edge.max(1) as f32;
    let c = light_from_world.transform_point3(center);
    let (cx, cy) = ((c.x / texel).floor() * texel, (c.y / texel).floor() * texel);
    // Distance along the light is -z in its frame: the sphere spans -c.z ± radius, and the
    // casters nearest the light are at the smallest distance.
    let mut nearest = -c.z - radius;
    if let Some(casters) = casters.filter(|b| !b.is_empty()) {
        let b = casters.transformed(&light_from_world);
        nearest = nearest.min(-b.max.z);
    }
    let farthest = -c.z + radius;
    let range = (farthest - nearest).max(1e-6);
    // Reverse depth: z = (farthest - distance) / range, and distance = -z in the light's frame.
    let scale = Mat4::from_cols(
        Vec4::new(1.0 / radius, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0 / radius, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 1.0 / range, 0.0),
        Vec4::new(-cx / radius, -cy / radius, farthest / range, 1.0),
    );
    CascadeFit { clip_from_world: scale * light_from_world, texel, depth_range: range }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shadows::box_meets_clip;

    /// A cascade holds its whole slice of the view and every caster between it and the light,
    /// and a camera moved by less than a texel moves the cascade's grid by whole texels.
    #[test]
    fn a_cascade_holds_its_slice_and_its_casters_on_a_stable_grid() {
        let camera = |at: Vec3| ExtractedCamera {
            world_from_view: Mat4::from_translation(at) * Mat4::from_rotation_y(0.4),
            projection: manylight_core::Projection::default(),
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
            exposure: None,
            environment: None,
            skybox: None,
        };
        let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
        let casters = Aabb { min: Vec3::new(-50.0, -1.0, -50.0), max: Vec3::new(50.0, 30.0, 50.0) };
        let slice = ViewSlice { near: 2.0, far: 10.0 };
        let cam = camera(Vec3::new(1.0, 2.0, 3.0));
        let fit = fit_cascade(&cam, 16.0 / 9.0, slice, direction, Some(&casters), 1024);
        let inside = |p: Vec3| {
            let c = fit.clip_from_world.transform_point3(p);
            c.x.abs() <= 1.0 + 1e-4 && c.y.abs() <= 1.0 + 1e-4 && (-1e-4..=1.0 + 1e-4).contains(&c.z)
        };
        let (w, h) = ((0.5f32 * 60f32.to_radians()).tan() * 16.0 / 9.0, (0.5f32 * 60f32.to_radians()).tan());
        for d in [2.0, 6.0, 10.0] {
            for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (0.0, 0.0)] {
                let p = cam.world_from_view.transform_point3(Vec3::new(x * w * d, y * h * d, -d));
                assert!(inside(p), "slice point {p} at {d}");
            }
        }
        // A caster high above the slice, towards the light, is still in front of the map (z at
        // most 1); with depth clamped it lies beyond the near side, and is clamped onto it.
        let centre = cam.world_from_view.transform_point3(Vec3::new(0.0, 0.0, -6.0));
        let above = centre - direction * ((29.0 - centre.y) / -direction.y);
        assert!(fit.clip_from_world.transform_point3(above).z <= 1.0 + 1e-4);
        let clamped = fit_cascade(&cam, 16.0 / 9.0, slice, direction, None, 1024);
        assert!(clamped.clip_from_world.transform_point3(above).z > 1.0);
        assert!((clamped.clip_from_world.transform_point3(centre).z - 0.5).abs() < 0.2);
        assert!(clamped.depth_range < fit.depth_range);
        assert!(box_meets_clip(&fit.clip_from_world, &Aabb { min: above - 0.1, max: above + 0.1 }));
        assert!(!box_meets_clip(&fit.clip_from_world, &Aabb { min: centre + 100.0, max: centre + 101.0 }));
        assert!((fit.texel - fit.depth_range).abs() > 0.0 && fit.texel > 0.0);
        // Moved by a third of a texel: same size, the grid shifted by whole texels.
        let moved = fit_cascade(
            &camera(Vec3::new(1.0 + fit.texel / 3.0, 2.0, 3.0)),
            16.0 / 9.0,
            slice,
            direction,
            Some(&casters),
            1024,
        );
        assert_eq!(moved.texel, fit.texel);
        let shift = (moved.clip_from_world.w_axis.x - fit.clip_from_world.w_axis.x) / 2.0 * 1024.0;
        assert!((shift - shift.round()).abs() < 1e-2, "a shift of {shift} texels");
    }
}

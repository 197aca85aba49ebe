//! What a view or a map can see: conservative tests of a light's sphere and its cube faces
//! against the views' frustums, and of a caster's bounds against a light's sphere, a cube face
//! and a cascade. Each may say yes where the exact answer is no, never the reverse.

use super::cube::face_axis;
use crate::snapshot::FrameSnapshot;
use glam::{Mat4, UVec2, Vec3, Vec4};
use manylight_core::Aabb;

/// The planes (`n·p + d ≥ 0` inside) of a reverse-Z view frustum `clip_from_world`: left,
/// right, bottom, top and near. The far plane is left out (it may be at infinity), so the
/// volume is conservative.
pub fn frustum_planes(clip_from_world: &Mat4) -> [Vec4; 5] {
    let m = clip_from_world.transpose();
    let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 - r2]
}

/// The frustums of every view of `snapshot` that shows shadows (each at its rectangle's aspect).
pub fn view_frustums(snapshot: &FrameSnapshot) -> Vec<[Vec4; 5]> {
    snapshot
        .views
        .iter()
        .filter(|v| v.shadows)
        .map(|v| {
            let size = v.rect_in(v.target_size(snapshot.viewport)).size.max(UVec2::ONE);
            frustum_planes(&v.camera.clip_from_world(size))
        })
        .collect()
}

/// True when some point of `points` may lie inside `planes` (false only when all of them are
/// outside one plane: conservative).
fn may_meet(planes: &[Vec4; 5], points: &[Vec3]) -> bool {
    planes.iter().all(|p| points.iter().any(|q| p.truncate().dot(*q) + p.w >= 0.0))
}

/// True when the sphere (`center`, `radius`) may be seen through one of `frustums`.
pub fn sphere_in_view(frustums: &[[Vec4; 5]], center: Vec3, radius: f32) -> bool {
    frustums.iter().any(|planes| {
        planes.iter().all(|p| p.truncate().dot(center) + p.w >= -radius * p.truncate().length())
    })
}

/// True when the part of cube face `face` of a light at `light` with range `radius` may be
/// seen through one of `frustums`: that part lies in the pyramid from the light to the face's
/// square at distance `radius`, tested by its five corners. A face no view sees lights no
/// visible pixel, so it is not drawn.
pub fn face_in_view(frustums: &[[Vec4; 5]], light: Vec3, face: u32, radius: f32) -> bool {
    let (axis, sign) = face_axis(face);
    let (a, b) = (Vec3::AXES[(axis + 1) % 3] * radius, Vec3::AXES[(axis + 2) % 3] * radius);
    let end = light + Vec3::AXES[axis] * sign * radius;
    let corners = [light, end + a + b, end + a - b, end - a + b, end - a - b];
    frustums.iter().any(|planes| may_meet(planes, &corners))
}

/// True when `bounds` meets the sphere (`center`, `radius`).
pub(super) fn sphere_meets_box(center: Vec3, radius: f32, bounds: &Aabb) -> bool {
    if bounds.is_empty() {
        return false;
    }
    let nearest = center.clamp(bounds.min, bounds.max);
    nearest.distance_squared(center) <= radius * radius
}

/// True when `bounds` may meet face `face`'s frustum from `light` (a conservative test against
/// the four planes through the light and the half-space in front of it).
pub fn box_meets_face(light: Vec3, face: u32, bounds: &Aabb) -> bool {
    let (axis, sign) = face_axis(face);
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let (lo, hi) = (bounds.min - light, bounds.max - light);
    // The largest value of n·p over the box.
    let max_over_box = |n: Vec3| -> f32 { (n * lo).max(n * hi).element_sum() };
    let w = Vec3::AXES[axis] * sign;
    let planes = [w, w - Vec3::AXES[a], w + Vec3::AXES[a], w - Vec3::AXES[b], w + Vec3::AXES[b]];
    planes.iter().all(|&n| max_over_box(n) >= 0.0)
}

/// True when `bounds` may meet the box x, y ∈ [-1, 1], z ∈ [0, 1] of the affine (orthographic)
/// projection `clip_from_world`.
pub fn box_meets_clip(clip_from_world: &Mat4, bounds: &Aabb) -> bool {
    if bounds.is_empty() {
        return false;
    }
    let b = bounds.transformed(clip_from_world);
    b.max.x >= -1.0 && b.min.x <= 1.0 && b.max.y >= -1.0 && b.min.y <= 1.0 && b.max.z >= 0.0 && b.min.z <= 1.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu_types::SHADOW_FACES;

    /// Lights and faces no view sees are found (and nothing a view sees is lost).
    #[test]
    fn unseen_lights_and_faces_are_found_conservatively() {
        // A camera at the origin looking down -Z.
        let clip = manylight_core::Projection::default().matrix(1.0);
        let frustums = [frustum_planes(&clip)];
        assert!(sphere_in_view(&frustums, Vec3::new(0.0, 0.0, -10.0), 1.0));
        assert!(!sphere_in_view(&frustums, Vec3::new(0.0, 0.0, 10.0), 1.0), "behind the camera");
        assert!(sphere_in_view(&frustums, Vec3::new(0.0, 0.0, 0.5), 1.0), "around the camera");
        assert!(!sphere_in_view(&frustums, Vec3::new(30.0, 0.0, -10.0), 1.0), "far to the right");
        assert!(!sphere_in_view(&[], Vec3::ZERO, 1.0), "no view sees anything");
        // A light behind the camera: its -Z face looks into the view, its +Z face away.
        let light = Vec3::new(0.0, 0.0, 3.0);
        assert!(face_in_view(&frustums, light, 5, 5.0), "-Z face");
        assert!(!face_in_view(&frustums, light, 4, 5.0), "+Z face");
        // A light inside the view: every face holds seen points.
        assert!((0..SHADOW_FACES).all(|f| face_in_view(&frustums, Vec3::new(0.0, 0.0, -5.0), f, 2.0)));
        // Beside the view, to its left and level with it: only the +X face looks into it.
        let left = Vec3::new(-20.0, 0.0, -10.0);
        let seen: Vec<u32> = (0..SHADOW_FACES).filter(|&f| face_in_view(&frustums, left, f, 30.0)).collect();
        assert!(seen.contains(&0) && !seen.contains(&1), "{seen:?}");
    }
}

//! How a light's cube of six faces projects: the axis each face looks along, its
//! clip-from-world matrix and the reverse depth it stores (the twin of `shadow_face_depth` in
//! `shaders/common/shadows.wgsl`).

use glam::{Mat4, Vec3, Vec4};

/// The faces' near plane as a fraction of the light's range (a point nearer the light than
/// that is never shadowed). Reverse depth keeps float precision at every distance, so the
/// near plane can sit this close: 0.1 mm for a range of 10, 10 cm for a range of 10⁴.
pub const SHADOW_NEAR_FRACTION: f32 = 1e-5;

/// The depth face `f` stores at distance `depth` along its axis: reverse depth, 1 at `near`,
/// 0 at `far`, so a float keeps its precision out to the range (`shadow_face_depth` in
/// `shaders/common/shadows.wgsl`). The atlas is cleared to 0 and keeps the greatest depth
/// (the nearest caster); a point is lit where its depth is at least the stored one.
pub fn face_depth(depth: f32, near: f32, far: f32) -> f32 {
    near * (far - depth) / (depth * (far - near))
}

/// Axis (0 = x) and direction (+1 or -1) face `face` looks along.
pub fn face_axis(face: u32) -> (usize, f32) {
    ((face / 2) as usize % 3, if face.is_multiple_of(2) { 1.0 } else { -1.0 })
}

/// The projection of cube face `face` of a light at `light`: x and y are the coordinates on the
/// next two axes (x on axis + 1, y on axis + 2, modulo 3) over the distance along the face's
/// axis, so the face is x, y ∈ [-w, w]; z / w is [`face_depth`].
pub fn face_clip_from_world(light: Vec3, face: u32, near: f32, far: f32) -> Mat4 {
    let (axis, sign) = face_axis(face);
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let row = |i: usize, s: f32| (Vec3::AXES[i] * s).extend(-s * light[i]);
    let w = row(axis, sign);
    let k = near / (far - near);
    let z = Vec4::W * (k * far) - w * k;
    Mat4::from_cols(row(a, 1.0), row(b, 1.0), z, w).transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu_types::SHADOW_FACES;
    use crate::shadows::box_meets_face;
    use manylight_core::Aabb;

    #[test]
    fn a_face_projects_its_axis_to_the_centre_and_its_edges_to_the_tile() {
        let light = Vec3::new(1.0, 2.0, 3.0);
        let (near, far) = (0.01, 10.0);
        for face in 0..SHADOW_FACES {
            let (axis, sign) = face_axis(face);
            let m = face_clip_from_world(light, face, near, far);
            let ahead = light + Vec3::AXES[axis] * sign * 2.0;
            let c = m * ahead.extend(1.0);
            assert!((c.x / c.w).abs() < 1e-6 && (c.y / c.w).abs() < 1e-6, "face {face}: {c}");
            assert!((c.z / c.w - face_depth(2.0, near, far)).abs() < 1e-6);
            // A point on the next axis at 45° is on the face's edge x = 1.
            let edge = ahead + Vec3::AXES[(axis + 1) % 3] * 2.0;
            let c = m * edge.extend(1.0);
            assert!((c.x / c.w - 1.0).abs() < 1e-6, "face {face}: {c}");
            assert!(box_meets_face(light, face, &Aabb { min: ahead - 0.1, max: ahead + 0.1 }));
            assert!(!box_meets_face(
                light,
                face,
                &Aabb { min: light - ahead + light - 0.1, max: light - ahead + light + 0.1 }
            ));
        }
        assert!((face_depth(near, near, far) - 1.0).abs() < 1e-6);
        assert_eq!(face_depth(far, near, far), 0.0);
    }
}

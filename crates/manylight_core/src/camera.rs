//! Camera projection with reverse-Z (depth 1 at the near plane, 0 at the far plane), which
//! spreads float depth precision evenly in log space and keeps far geometry stable.

use glam::Mat4;

/// Smallest field of view a projection keeps (radians); smaller ones are raised to it.
pub const MIN_FOV_Y: f32 = 1e-6;

/// Largest field of view a projection keeps (radians): the largest `f32` whose half lies below
/// π/2 (`std::f32::consts::PI` rounds above π, and half of it would flip the image).
pub const MAX_FOV_Y: f32 = 3.141_592_5;

/// A perspective projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Vertical field of view in radians, in (0, π).
    pub fov_y: f32,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
}

impl Default for Projection {
    fn default() -> Self {
        Self { fov_y: 60f32.to_radians(), near: 0.1, far: 1000.0 }
    }
}

impl Projection {
    /// Clamps parameters into their valid ranges so the matrix is always finite: a field of view
    /// outside [`MIN_FOV_Y`, `MAX_FOV_Y`] is clamped (NaN or infinite becomes 1 rad), a NaN,
    /// infinite or non-positive near plane becomes 0.1, a near plane so large that no finite
    /// far plane fits beyond it is lowered, and a missing, NaN or too-close far plane becomes
    /// `near × 10⁴` (at most `f32::MAX`).
    pub fn sanitized(self) -> Projection {
        /// Largest near plane that leaves room for a far plane a factor of 2 beyond it.
        const MAX_NEAR: f32 = f32::MAX / 4.0;
        let fov_y = if self.fov_y.is_finite() { self.fov_y.clamp(MIN_FOV_Y, MAX_FOV_Y) } else { 1.0 };
        let near = if self.near.is_finite() && self.near > 0.0 { self.near.min(MAX_NEAR) } else { 0.1 };
        let far = if self.far.is_finite() && self.far > near { self.far } else { (near * 1e4).min(f32::MAX) };
        Projection { fov_y, near, far }
    }

    /// Right-handed, reverse-Z clip-from-view matrix (view looks down -Z; depth in [0, 1],
    /// 1 at `near`, 0 at `far`).
    pub fn matrix(&self, aspect: f32) -> Mat4 {
        let p = self.sanitized();
        let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
        let f = 1.0 / (0.5 * p.fov_y).tan();
        let depth_scale = p.near / (p.far - p.near);
        Mat4::from_cols(
            glam::Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, f, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, depth_scale, -1.0),
            glam::Vec4::new(0.0, 0.0, p.far * depth_scale, 0.0),
        )
    }
}

/// View-space distance (positive, along -Z) for a reverse-Z depth-buffer value.
pub fn linearize_depth_reverse_z(depth: f32, near: f32, far: f32) -> f32 {
    // Reverse-Z maps z_view = -d to depth = near*(far-d)... solved for d:
    // depth = (near * far / d - near) / (far - near)  =>  d = near*far / (depth*(far-near) + near)
    near * far / (depth * (far - near) + near)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    /// Extreme and invalid parameters never give a non-finite matrix: a huge near plane with
    /// no far plane used to make `far` infinite and the depth terms `inf × 0 = NaN`.
    #[test]
    fn extreme_parameters_give_a_finite_matrix() {
        let values = [
            0.0,
            -1.0,
            1e-6,
            0.1,
            1.0,
            1e6,
            1e30,
            f32::MAX / 8.0,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let fovs = [0.0, 1e-6, 1.0, MAX_FOV_Y, std::f32::consts::PI - 1e-6, std::f32::consts::PI, f32::NAN];
        for &near in &values {
            for &far in &values {
                for &fov_y in &fovs {
                    for aspect in [0.0, 1e-6, 16.0 / 9.0, f32::NAN] {
                        let p = Projection { fov_y, near, far };
                        let s = p.sanitized();
                        assert!(s.near > 0.0 && s.far > s.near && s.far.is_finite(), "{p:?} -> {s:?}");
                        let m = p.matrix(aspect);
                        assert!(m.is_finite(), "{p:?} aspect {aspect}: {m:?}");
                        // Never a flipped image: the focal terms stay positive.
                        assert!(m.x_axis.x > 0.0 && m.y_axis.y > 0.0, "{p:?} aspect {aspect}: {m:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn reverse_z_maps_near_to_one_and_far_to_zero() {
        let p = Projection { fov_y: 1.0, near: 0.5, far: 100.0 };
        let m = p.matrix(1.5);
        let n = m * Vec4::new(0.0, 0.0, -0.5, 1.0);
        let f = m * Vec4::new(0.0, 0.0, -100.0, 1.0);
        assert!((n.z / n.w - 1.0).abs() < 1e-6);
        assert!((f.z / f.w).abs() < 1e-6);
        for d in [0.5f32, 1.0, 7.0, 50.0, 100.0] {
            let c = m * Vec4::new(0.0, 0.0, -d, 1.0);
            let lin = linearize_depth_reverse_z(c.z / c.w, 0.5, 100.0);
            assert!((lin - d).abs() / d < 1e-4, "{d} -> {lin}");
        }
    }

    #[test]
    fn bad_parameters_still_give_a_finite_matrix() {
        let p = Projection { fov_y: f32::NAN, near: 0.0, far: -1.0 };
        assert!(p.matrix(0.0).to_cols_array().iter().all(|x| x.is_finite()));
    }
}

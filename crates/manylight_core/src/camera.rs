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
    /// Far plane distance (> near), or `f32::INFINITY` for no far plane: reverse-Z keeps an
    /// infinite projection exact (depth = near / distance), as glTF's infinite cameras are.
    pub far: f32,
}

impl Default for Projection {
    fn default() -> Self {
        Self { fov_y: 60f32.to_radians(), near: 0.1, far: 1000.0 }
    }
}

impl Projection {
    /// A projection without a far plane ([`Projection::far`] is `f32::INFINITY`).
    pub fn infinite(fov_y: f32, near: f32) -> Projection {
        Projection { fov_y, near, far: f32::INFINITY }
    }

    /// Whether the projection has no far plane.
    pub fn is_infinite(&self) -> bool {
        self.far == f32::INFINITY
    }

    /// Clamps parameters into their valid ranges so the matrix is always finite: a field of view
    /// outside [`MIN_FOV_Y`, `MAX_FOV_Y`] is clamped (NaN or infinite becomes 1 rad), and a NaN,
    /// infinite or non-positive near plane becomes 0.1. A far plane that is NaN, not beyond the
    /// near plane, or so close to a huge near plane that the depth terms overflow is dropped:
    /// the projection becomes infinite. `+∞` stays infinite.
    pub fn sanitized(self) -> Projection {
        let fov_y = if self.fov_y.is_finite() { self.fov_y.clamp(MIN_FOV_Y, MAX_FOV_Y) } else { 1.0 };
        let near = if self.near.is_finite() && self.near > 0.0 { self.near } else { 0.1 };
        // `far > near` is false for NaN.
        let far = if self.far > near && depth_terms(near, self.far).1.is_finite() {
            self.far
        } else {
            f32::INFINITY
        };
        Projection { fov_y, near, far }
    }

    /// Right-handed, reverse-Z clip-from-view matrix (view looks down -Z; depth in [0, 1],
    /// 1 at `near`, 0 at `far`; for an infinite projection depth is `near / distance`, 0 only
    /// at infinity).
    pub fn matrix(&self, aspect: f32) -> Mat4 {
        let p = self.sanitized();
        let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
        let f = 1.0 / (0.5 * p.fov_y).tan();
        let (depth_scale, depth_offset) = depth_terms(p.near, p.far);
        Mat4::from_cols(
            glam::Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, f, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, depth_scale, -1.0),
            glam::Vec4::new(0.0, 0.0, depth_offset, 0.0),
        )
    }

    /// `near / far`, 0 for an infinite projection: the one far-plane term that depth
    /// linearisation needs ([`linearize_depth_reverse_z`]), finite in every case.
    pub fn near_over_far(&self) -> f32 {
        let p = self.sanitized();
        p.near / p.far
    }

    /// The projection a cluster grid slices: this one when its far plane is finite, else the
    /// same with its far plane at the farthest view distance a light reaches (`reach`),
    /// rounded up to a power of two so that the grid changes only when the lights move a lot,
    /// and at least twice the near plane. Geometry beyond it lies in the last slice, where no
    /// light reaches, so no light is lost.
    pub fn finite_for(&self, reach: f32) -> Projection {
        let p = self.sanitized();
        if !p.is_infinite() {
            return p;
        }
        let floor = (2.0 * p.near).min(f32::MAX);
        let reach = if reach.is_finite() { reach.max(floor) } else { floor };
        // The next power of two at or above `reach`, if it fits.
        let rounded = 2f32.powi(reach.log2().ceil() as i32);
        let far = if rounded.is_finite() && rounded >= reach { rounded } else { reach };
        Projection { far, ..p }
    }
}

/// `(depth_scale, depth_offset)` of the reverse-Z matrix: depth = (scale · z + offset) / −z.
/// Finite: `near / (far − near)` and `far · near / (far − near)` (the offset overflows when a
/// huge near plane lies just before the far plane); infinite: `0` and `near`.
fn depth_terms(near: f32, far: f32) -> (f32, f32) {
    if far == f32::INFINITY {
        return (0.0, near);
    }
    let scale = near / (far - near);
    (scale, far * scale)
}

/// View-space distance (positive, along −Z) for a reverse-Z depth-buffer value;
/// `far = f32::INFINITY` for an infinite projection (depth 0 then gives `+∞`).
pub fn linearize_depth_reverse_z(depth: f32, near: f32, far: f32) -> f32 {
    // depth = r/(1-r) + near/((1-r) d) with r = near/far, solved for d:
    // d = near / (depth (1 - r) + r), which is near·far / (depth (far - near) + near) when far
    // is finite and near / depth when it is not. The shaders use the same form with `r`
    // precomputed, so no infinity reaches them.
    let r = near / far;
    near / (depth * (1.0 - r) + r)
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
                        assert!(s.near.is_finite() && s.near > 0.0 && s.far > s.near, "{p:?} -> {s:?}");
                        assert!(s.far.is_finite() || s.is_infinite(), "{p:?} -> {s:?}");
                        assert!(s.near_over_far().is_finite(), "{p:?} -> {s:?}");
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

    /// No far plane: depth is `near / distance`, exact to rounding at any distance, and
    /// linearises back; a far plane that is missing, NaN or not beyond near becomes infinite.
    #[test]
    fn an_infinite_projection_keeps_depth_exact_at_any_distance() {
        for near in [1e-6f32, 0.1, 3.0, 1e20] {
            let p = Projection::infinite(1.0, near);
            assert!(p.is_infinite() && p.sanitized() == p);
            assert_eq!(p.near_over_far(), 0.0);
            let m = p.matrix(16.0 / 9.0);
            assert!(m.is_finite(), "{m:?}");
            for k in [1.0f32, 1.5, 10.0, 1e3, 1e6, 1e12, 1e30] {
                let d = near * k;
                if !d.is_finite() {
                    continue;
                }
                let c = m * Vec4::new(0.0, 0.0, -d, 1.0);
                let depth = c.z / c.w;
                assert!(depth > 0.0 && depth <= 1.0, "near {near} d {d}: {depth}");
                assert!((depth * k - 1.0).abs() < 1e-6, "near {near} d {d}: {depth}");
                let lin = linearize_depth_reverse_z(depth, near, f32::INFINITY);
                assert!((lin - d).abs() / d < 1e-6, "near {near} d {d} -> {lin}");
            }
            assert_eq!(linearize_depth_reverse_z(0.0, near, f32::INFINITY), f32::INFINITY);
        }
        for far in [f32::NAN, f32::NEG_INFINITY, 0.0, 0.5, 1.0] {
            assert!(Projection { fov_y: 1.0, near: 1.0, far }.sanitized().is_infinite(), "far {far}");
        }
        // A huge near plane just before the far plane: the depth offset would overflow.
        let tight = Projection { fov_y: 1.0, near: 1e38, far: 1.000_001e38 }.sanitized();
        assert!(tight.is_infinite() && tight.matrix(1.0).is_finite(), "{tight:?}");
        // A finite far plane is kept.
        assert_eq!(Projection::default().sanitized().far, 1000.0);
    }

    /// The finite far plane of an infinite projection covers the farthest light, is a power
    /// of two (so small movements keep the grid), and never falls to the near plane.
    #[test]
    fn finite_for_covers_the_lights_of_an_infinite_projection() {
        let p = Projection::infinite(1.0, 0.1);
        let far = |reach: f32| p.finite_for(reach).far;
        for reach in [0.0f32, 0.15, 0.2, 3.0, 64.0, 65.0, 1e6, 1e38, f32::MAX, f32::INFINITY, f32::NAN] {
            let f = far(reach);
            assert!(f.is_finite() && f >= 0.2, "reach {reach} -> {f}");
            if reach.is_finite() {
                assert!(f >= reach, "reach {reach} -> {f}");
            }
            if reach.is_finite() && reach > 0.2 && reach < 1e38 {
                assert!(f < 2.0 * reach && f.log2().fract() == 0.0, "reach {reach} -> {f}");
            }
        }
        assert_eq!(far(64.0), 64.0);
        assert_eq!(far(64.1), 128.0);
        assert_eq!(p.finite_for(3.0).near, 0.1);
        assert_eq!(Projection::default().finite_for(1e9), Projection::default());
        assert!(Projection::infinite(1.0, f32::MAX).finite_for(0.0).far.is_finite());
    }

    #[test]
    fn bad_parameters_still_give_a_finite_matrix() {
        let p = Projection { fov_y: f32::NAN, near: 0.0, far: -1.0 };
        assert!(p.matrix(0.0).to_cols_array().iter().all(|x| x.is_finite()));
    }
}

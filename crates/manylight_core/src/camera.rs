//! Camera projection with reverse-Z (depth 1 at the near plane, 0 at the far plane), which
//! spreads float depth precision evenly in log space and keeps far geometry stable;
//! perspective or orthographic.

use glam::{Mat4, Vec2, Vec3};

/// Smallest orthographic view height [`Projection::sanitized`] keeps (its half-extent's
/// reciprocal stays finite).
pub const MIN_ORTHOGRAPHIC_HEIGHT: f32 = 1e-30;

/// Largest orthographic view height [`Projection::sanitized`] keeps; taller ones are clamped
/// to it, and the glTF loader refuses cameras whose `ymag` asks for more.
pub const MAX_ORTHOGRAPHIC_HEIGHT: f32 = 1e30;

/// Smallest field of view a projection keeps (radians); smaller ones are raised to it.
pub const MIN_FOV_Y: f32 = 1e-6;

/// Largest field of view a projection keeps (radians): the largest `f32` whose half lies below
/// π/2 (`std::f32::consts::PI` rounds above π, and half of it would flip the image).
pub const MAX_FOV_Y: f32 = 3.141_592_5;

/// Depth range an orthographic projection gets when its far plane is missing, not finite or
/// not beyond the near plane (an orthographic projection needs a finite far plane: its depth
/// is linear).
pub const ORTHOGRAPHIC_FALLBACK_DEPTH: f32 = 1000.0;

/// Perspective or orthographic.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ProjectionKind {
    /// Rays from the camera position through the pixels, with [`Projection::fov_y`].
    #[default]
    Perspective,
    /// Parallel rays: `height` world units fill the view vertically, the width follows the
    /// aspect ratio; [`Projection::fov_y`] is ignored. Depth is linear in view distance.
    Orthographic {
        /// Visible height in world units (> 0).
        height: f32,
    },
}

/// A perspective or orthographic projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Vertical field of view in radians, in (0, π) (perspective only).
    pub fov_y: f32,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near), or `f32::INFINITY` for no far plane: reverse-Z keeps an
    /// infinite projection exact (depth = near / distance), as glTF's infinite cameras are.
    /// An orthographic projection needs a finite one ([`ORTHOGRAPHIC_FALLBACK_DEPTH`]).
    pub far: f32,
    /// Perspective (the default) or orthographic.
    pub kind: ProjectionKind,
}

impl Default for Projection {
    fn default() -> Self {
        Self { fov_y: 60f32.to_radians(), near: 0.1, far: 1000.0, kind: ProjectionKind::Perspective }
    }
}

impl Projection {
    /// A perspective projection.
    pub fn perspective(fov_y: f32, near: f32, far: f32) -> Projection {
        Projection { fov_y, near, far, kind: ProjectionKind::Perspective }
    }

    /// A perspective projection without a far plane ([`Projection::far`] is `f32::INFINITY`).
    pub fn infinite(fov_y: f32, near: f32) -> Projection {
        Projection::perspective(fov_y, near, f32::INFINITY)
    }

    /// An orthographic projection `height` world units tall, from `near` to `far`.
    pub fn orthographic(height: f32, near: f32, far: f32) -> Projection {
        Projection { fov_y: 60f32.to_radians(), near, far, kind: ProjectionKind::Orthographic { height } }
    }

    /// Half the visible width and height in world units for an orthographic projection at
    /// `aspect` (sanitised), `None` for a perspective one.
    pub fn orthographic_half_extent(&self, aspect: f32) -> Option<Vec2> {
        self.sanitized().half_extent_of_sanitized(aspect)
    }

    /// [`Projection::orthographic_half_extent`] of a projection already sanitised.
    fn half_extent_of_sanitized(&self, aspect: f32) -> Option<Vec2> {
        match self.kind {
            ProjectionKind::Orthographic { height } => {
                Some(Vec2::new(0.5 * height * aspect_or_one(aspect), 0.5 * height))
            }
            ProjectionKind::Perspective => None,
        }
    }

    /// Whether the projection is orthographic.
    pub fn is_orthographic(&self) -> bool {
        matches!(self.kind, ProjectionKind::Orthographic { .. })
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
    ///
    /// Orthographic: a height that is NaN or not positive becomes 1, and one outside
    /// [`MIN_ORTHOGRAPHIC_HEIGHT`, `MAX_ORTHOGRAPHIC_HEIGHT`] (`+∞` included) is clamped into
    /// it (an infinite height is clamped, not replaced by 1, which would shrink the view by 38
    /// orders of magnitude without a word), and a far plane
    /// that is missing, infinite, not beyond the near plane or too close to it for the linear
    /// depth scale to be finite becomes `near + ORTHOGRAPHIC_FALLBACK_DEPTH` (or the near
    /// plane is moved back from a far plane at `f32::MAX`).
    pub fn sanitized(self) -> Projection {
        let fov_y = if self.fov_y.is_finite() { self.fov_y.clamp(MIN_FOV_Y, MAX_FOV_Y) } else { 1.0 };
        let near = if self.near.is_finite() && self.near > 0.0 { self.near } else { 0.1 };
        if let ProjectionKind::Orthographic { height } = self.kind {
            let height = if height > 0.0 {
                height.clamp(MIN_ORTHOGRAPHIC_HEIGHT, MAX_ORTHOGRAPHIC_HEIGHT)
            } else {
                1.0 // NaN or not positive
            };
            let fits =
                |near: f32, far: f32| far.is_finite() && far > near && (1.0 / (far - near)).is_finite();
            let (near, far) = if fits(near, self.far) {
                (near, self.far)
            } else if fits(near, near + ORTHOGRAPHIC_FALLBACK_DEPTH) {
                (near, near + ORTHOGRAPHIC_FALLBACK_DEPTH)
            } else {
                // A near plane so large that adding the fallback depth does not change it.
                (near * 0.5, near)
            };
            return Projection { fov_y, near, far, kind: ProjectionKind::Orthographic { height } };
        }
        // `far > near` is false for NaN.
        let far = if self.far > near && depth_terms(near, self.far).1.is_finite() {
            self.far
        } else {
            f32::INFINITY
        };
        Projection { fov_y, near, far, kind: ProjectionKind::Perspective }
    }

    /// Right-handed, reverse-Z clip-from-view matrix (view looks down -Z; depth in [0, 1],
    /// 1 at `near`, 0 at `far`; for an infinite projection depth is `near / distance`, 0 only
    /// at infinity).
    ///
    /// Orthographic: `x / half_width`, `y / half_height`, depth `(far − distance) / (far − near)`
    /// (linear; `w = 1`).
    pub fn matrix(&self, aspect: f32) -> Mat4 {
        let p = self.sanitized();
        let aspect = aspect_or_one(aspect);
        if let Some(half) = p.half_extent_of_sanitized(aspect) {
            let range = p.far - p.near;
            return Mat4::from_cols(
                glam::Vec4::new(1.0 / half.x, 0.0, 0.0, 0.0),
                glam::Vec4::new(0.0, 1.0 / half.y, 0.0, 0.0),
                glam::Vec4::new(0.0, 0.0, 1.0 / range, 0.0),
                glam::Vec4::new(0.0, 0.0, p.far / range, 1.0),
            );
        }
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
    ///
    /// An orthographic projection is always finite (it is returned sanitised).
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

    /// View distance (positive, along −Z) of a reverse-Z depth-buffer value: for a perspective
    /// projection [`linearize_depth_reverse_z`], for an orthographic one the linear map back.
    pub fn linearize_depth(&self, depth: f32) -> f32 {
        self.sanitized().linearize_sanitized(depth)
    }

    /// [`Projection::linearize_depth`] of a projection already sanitised.
    fn linearize_sanitized(&self, depth: f32) -> f32 {
        match self.kind {
            ProjectionKind::Orthographic { .. } => self.far - depth * (self.far - self.near),
            ProjectionKind::Perspective => linearize_depth_reverse_z(depth, self.near, self.far),
        }
    }

    /// The view-space point at normalised device coordinates `ndc` and reverse-Z `depth`, for a
    /// target of `aspect`.
    pub fn view_position(&self, ndc: Vec2, depth: f32, aspect: f32) -> Vec3 {
        let p = self.sanitized();
        let d = p.linearize_sanitized(depth);
        let half = p.half_extent_of_sanitized(aspect).unwrap_or_else(|| {
            let tan_y = (0.5 * p.fov_y).tan();
            Vec2::new(tan_y * aspect_or_one(aspect), tan_y) * d
        });
        (ndc * half).extend(-d)
    }
}

/// `aspect`, or 1 when it is not finite and positive.
fn aspect_or_one(aspect: f32) -> f32 {
    if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 }
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
    /// no far plane must not make `far` infinite and the depth terms `inf × 0 = NaN`.
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
                        let p = Projection::perspective(fov_y, near, far);
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
        let p = Projection::perspective(1.0, 0.5, 100.0);
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
            assert!(Projection::perspective(1.0, 1.0, far).sanitized().is_infinite(), "far {far}");
        }
        // A huge near plane just before the far plane: the depth offset would overflow.
        let tight = Projection::perspective(1.0, 1e38, 1.000_001e38).sanitized();
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
    fn an_infinite_orthographic_height_is_clamped_not_replaced() {
        for (height, kept) in [
            (f32::INFINITY, MAX_ORTHOGRAPHIC_HEIGHT),
            (3e38, MAX_ORTHOGRAPHIC_HEIGHT),
            (1e-40, MIN_ORTHOGRAPHIC_HEIGHT),
            (f32::NAN, 1.0),
            (-2.0, 1.0),
        ] {
            let p = Projection::orthographic(height, 0.1, 100.0).sanitized();
            assert_eq!(p.kind, ProjectionKind::Orthographic { height: kept }, "{height}");
            assert!(p.matrix(1.5).is_finite(), "{height}");
        }
    }

    /// Orthographic: near maps to 1 and far to 0 linearly, x and y by the half-extents at every
    /// distance, and depth linearises back; bad parameters give a finite projection with a
    /// finite far plane.
    #[test]
    fn orthographic_depth_is_linear_and_exact() {
        let p = Projection::orthographic(6.0, 0.5, 40.5);
        assert!(p.is_orthographic() && p.sanitized() == p);
        let aspect = 1.5;
        let m = p.matrix(aspect);
        assert_eq!(p.orthographic_half_extent(aspect), Some(Vec2::new(4.5, 3.0)));
        for (d, depth) in [(0.5f32, 1.0f32), (20.5, 0.5), (40.5, 0.0)] {
            let c = m * Vec4::new(4.5, -3.0, -d, 1.0);
            assert_eq!(c.w, 1.0);
            assert!((c.x - 1.0).abs() < 1e-6 && (c.y + 1.0).abs() < 1e-6, "{c:?}");
            assert!((c.z - depth).abs() < 1e-6, "{d}: {}", c.z);
            assert!((p.linearize_depth(c.z) - d).abs() < 1e-4, "{d}");
            let q = p.view_position(Vec2::new(0.5, -0.25), c.z, aspect);
            assert!(q.abs_diff_eq(Vec3::new(2.25, -0.75, -d), 1e-4), "{q}");
        }
        for (height, near, far) in [
            (f32::NAN, 0.1, 10.0),
            (0.0, 0.1, 10.0),
            (1.0, 0.1, f32::INFINITY),
            (1.0, 5.0, 1.0),
            (1.0, f32::MAX, f32::MAX),
        ] {
            let s = Projection::orthographic(height, near, far).sanitized();
            let ProjectionKind::Orthographic { height: h } = s.kind else { panic!("{s:?}") };
            assert!(h.is_finite() && h > 0.0 && s.far.is_finite() && s.far > s.near && s.near > 0.0, "{s:?}");
            assert!(s.matrix(1.0).is_finite(), "{s:?}");
            assert_eq!(s.finite_for(1e9), s);
        }
    }

    #[test]
    fn bad_parameters_still_give_a_finite_matrix() {
        let p = Projection::perspective(f32::NAN, 0.0, -1.0);
        assert!(p.matrix(0.0).to_cols_array().iter().all(|x| x.is_finite()));
    }
}

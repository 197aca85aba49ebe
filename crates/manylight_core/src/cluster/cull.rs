//! Sphere–cluster tests, written so a WGSL twin can copy them expression for expression.
//!
//! 1. **Reject** spheres that light nothing: radius `<= 0`, non-finite radius or centre.
//! 2. **Inflate** the radius by [`RADIUS_INFLATION`] (`r' = r * 1.00001`): the plane test's dot
//!    products round with an error relative to the radius, and the inflation absorbs it. (The
//!    cluster bounds carry their own margin for the error relative to the cluster's size.)
//! 3. **Test**:
//!    - AABB: `let d = max(max(min - c, c - max), vec3(0)); return dot(d, d) <= r' * r';`
//!    - planes: for each of the six `(n, w)`: `if dot(n, c) + w < -r' { return false; }`
//!
//! Both only ever err towards "touches": the AABB contains the frustum piece, and a sphere that
//! meets the piece is within `r` of every one of its half-spaces.

use super::CullTest;
use glam::{Mat4, Vec3, Vec4};

/// Factor applied to a light's radius before testing (module docs, step 2).
pub const RADIUS_INFLATION: f32 = 1.0 + 1e-5;

/// A light for assignment, in view space. Lights with radius `<= 0` or a non-finite centre or
/// radius touch nothing.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ViewSphere {
    /// Centre in view space.
    pub center: Vec3,
    /// Radius of influence (where attenuation reaches zero).
    pub radius: f32,
}

impl ViewSphere {
    /// Whether the sphere can light anything (module docs, step 1).
    pub fn is_valid(&self) -> bool {
        self.center.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }
}

/// Transforms world-space light positions to view space (`view_from_world`) keeping radii,
/// one at a time (no allocation); [`view_spheres`] collects them.
pub fn to_view_space(
    view_from_world: Mat4,
    lights: impl Iterator<Item = (Vec3, f32)>,
) -> impl Iterator<Item = ViewSphere> {
    lights.map(move |(position, radius)| ViewSphere {
        center: view_from_world.transform_point3(position),
        radius,
    })
}

/// Transforms world-space light positions to view space (`view_from_world`) keeping radii; used
/// by both the CPU and GPU paths.
pub fn view_spheres(view_from_world: &Mat4, lights: impl Iterator<Item = (Vec3, f32)>) -> Vec<ViewSphere> {
    to_view_space(*view_from_world, lights).collect()
}

/// The farthest view distance (along −Z) that any valid sphere reaches, 0 when none does:
/// what [`crate::Projection::finite_for`] needs to slice a projection without a far plane.
pub fn farthest_reach(spheres: impl IntoIterator<Item = ViewSphere>) -> f32 {
    spheres.into_iter().filter(ViewSphere::is_valid).map(|s| -s.center.z + s.radius).fold(0.0, f32::max)
}

/// The radius the tests compare against: `r * RADIUS_INFLATION`.
#[inline]
pub fn inflated_radius(radius: f32) -> f32 {
    radius * RADIUS_INFLATION
}

/// Conservative sphere–box test: true if the sphere (radius inflated) reaches the box `[min,
/// max]`, by closest-point distance
/// (`d = max(max(min - c, c - max), 0); dot(d, d) <= r' * r'`). False for invalid spheres.
#[inline]
pub fn sphere_intersects_aabb(center: Vec3, radius: f32, min: Vec3, max: Vec3) -> bool {
    if !(ViewSphere { center, radius }).is_valid() {
        return false;
    }
    let r = inflated_radius(radius);
    let d = (min - center).max(center - max).max(Vec3::ZERO);
    d.dot(d) <= r * r
}

/// `test` for a sphere against a cluster's AABB `(min, max)` and its six planes: the AABB test,
/// the planes test, or both.
pub fn sphere_passes(test: CullTest, sphere: &ViewSphere, aabb: (Vec3, Vec3), planes: &[Vec4; 6]) -> bool {
    let (c, r) = (sphere.center, sphere.radius);
    match test {
        CullTest::Aabb => sphere_intersects_aabb(c, r, aabb.0, aabb.1),
        CullTest::Planes => sphere_intersects_planes(c, r, planes),
        CullTest::Both => {
            sphere_intersects_aabb(c, r, aabb.0, aabb.1) && sphere_intersects_planes(c, r, planes)
        }
    }
}

/// Conservative plane test: true unless the sphere (radius inflated) lies entirely outside one
/// of the planes (`dot(n, c) + w < -r'`). False for invalid spheres.
#[inline]
pub fn sphere_intersects_planes(center: Vec3, radius: f32, planes: &[Vec4; 6]) -> bool {
    if !(ViewSphere { center, radius }).is_valid() {
        return false;
    }
    let r = inflated_radius(radius);
    for p in planes {
        // Written as `< -r` so a NaN distance (overflow) keeps the light, as in WGSL.
        if p.truncate().dot(center) + p.w < -r {
            return false;
        }
    }
    true
}

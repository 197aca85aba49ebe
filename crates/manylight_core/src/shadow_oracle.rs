//! The exact visibility reference for shadows: does anything block the segment from a surface
//! point to a light?
//!
//! Every shadow technique (maps, screen-space marching, stochastic selection) approximates this
//! answer; the oracle gives it exactly, by casting the segment against every triangle of the
//! scene through a bounding volume hierarchy (`obvhs`'s binary BVH) on the CPU, one light–point
//! pair per ray, in parallel with rayon. It is a reference for measuring shadow error, not a
//! renderer: a 1280×720 frame with four contributing lights a pixel casts about 3.7 million
//! rays.
//!
//! How a pair is decided:
//! 1. The ray starts at the surface point moved off its surface along the normal by
//!    [`surface_offset`] (relative to the point's magnitude, so large worlds keep working), so
//!    the surface does not shadow itself, while a light behind it stays blocked by it.
//! 2. A point or spot light is reached at its position: the ray ends there, less the same
//!    offset, so a light lying on a surface is not hidden by that surface. A directional light
//!    is reached at infinity, against its direction of travel.
//! 3. Any triangle hit in between, from either side, blocks the light.

use crate::mesh::MeshData;
use glam::{Mat4, Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use rayon::prelude::*;

/// Where a light's rays come from, as the oracle sees it (a spot light is its position: its
/// cone decides whether a pair contributes, not whether it is blocked).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSource {
    /// A point or spot light at this world position.
    At(Vec3),
    /// A directional light whose light travels along this (unit or not) world direction.
    Travelling(Vec3),
}

/// One light–point pair to decide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowQuery {
    /// The surface point, in world space.
    pub point: Vec3,
    /// The surface's normal at the point (any length; zero: no offset along it).
    pub normal: Vec3,
    /// The light.
    pub light: LightSource,
}

/// [`surface_offset`] per unit of a point's largest coordinate: 64 float steps.
pub const SURFACE_OFFSET_STEPS: f32 = 64.0 * f32::EPSILON;

/// How far a ray starts off the surface (and ends before a point light) at `point`: 64 float
/// steps of the point's largest coordinate (`f32` positions near `p` are spaced about
/// `|p| · 1.2·10⁻⁷` apart), and never less than 64 steps of 1: 7.6·10⁻⁶ near the origin, 0.076
/// at 10⁴.
pub fn surface_offset(point: Vec3) -> f32 {
    SURFACE_OFFSET_STEPS * point.abs().max_element().max(1.0)
}

/// Where a ray first meets the scene (see [`OccluderSet::first_hit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// The point met, in world space.
    pub point: Vec3,
    /// The unit normal of the triangle met, on the side the ray came from.
    pub normal: Vec3,
    /// Distance along the (unit) ray.
    pub distance: f32,
}

/// The scene's triangles in world space, in a BVH, for exact light–point visibility.
pub struct OccluderSet {
    bvh: Bvh2,
    /// In the BVH's primitive order (no indirection when tracing).
    triangles: Vec<Triangle>,
}

impl OccluderSet {
    /// Builds the set from world-space triangles; triangles with a non-finite corner are left
    /// out (they cannot be hit), degenerate ones kept (they are never hit).
    pub fn new(triangles: impl IntoIterator<Item = [Vec3; 3]>) -> OccluderSet {
        let triangles: Vec<Triangle> = triangles
            .into_iter()
            .filter(|t| t.iter().all(|v| v.is_finite()))
            .map(|[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() })
            .collect();
        if triangles.is_empty() {
            return OccluderSet { bvh: Bvh2::default(), triangles };
        }
        let bvh = build_bvh2_from_tris(
            &triangles,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let triangles = bvh.primitive_indices.iter().map(|&i| triangles[i as usize]).collect();
        OccluderSet { bvh, triangles }
    }

    /// Builds the set from meshes placed by world-from-local transforms (a scene's instances).
    pub fn from_instances<'a>(instances: impl IntoIterator<Item = (&'a MeshData, Mat4)>) -> OccluderSet {
        let mut corners = Vec::new();
        for (mesh, world) in instances {
            corners.extend(mesh.indices.chunks_exact(3).filter_map(|tri| {
                let corner = |i: u32| mesh.vertices.get(i as usize).map(|v| Vec3::from(v.position));
                let [a, b, c] = [corner(tri[0])?, corner(tri[1])?, corner(tri[2])?];
                Some([a, b, c].map(|p| world.transform_point3(p)))
            }));
        }
        OccluderSet::new(corners)
    }

    /// Triangles in the set.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// True when nothing blocks the light from the point (see the module's steps).
    pub fn visible(&self, query: &ShadowQuery) -> bool {
        let Some(ray) = self.ray(query) else { return true };
        if self.triangles.is_empty() {
            return true;
        }
        self.bvh.ray_traverse_miss(ray, |ray, i| hit_distance(&self.triangles[i], ray))
    }

    /// The first triangle the ray from `origin` along `direction` meets (either side), with
    /// its normal turned towards `origin`: a camera ray finds the surface a pixel shows.
    /// `None` when it meets none, or an input is not finite.
    pub fn first_hit(&self, origin: Vec3, direction: Vec3) -> Option<SurfaceHit> {
        let direction = direction.try_normalize()?;
        if self.triangles.is_empty() || !origin.is_finite() {
            return None;
        }
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, f32::INFINITY);
        let mut hit = RayHit::none();
        if !self.bvh.ray_traverse(ray, &mut hit, |ray, i| hit_distance(&self.triangles[i], ray)) {
            return None;
        }
        let tri = &self.triangles[hit.primitive_id as usize];
        let normal = Vec3::from((tri.v1 - tri.v0).cross(tri.v2 - tri.v0)).try_normalize()?;
        let normal = if normal.dot(direction) > 0.0 { -normal } else { normal };
        Some(SurfaceHit { point: origin + direction * hit.t, normal, distance: hit.t })
    }

    /// [`OccluderSet::visible`] for every query, on all cores.
    pub fn visibility(&self, queries: &[ShadowQuery]) -> Vec<bool> {
        queries.par_iter().map(|q| self.visible(q)).collect()
    }

    /// The ray of a query ([`ShadowQuery::segment`]).
    fn ray(&self, query: &ShadowQuery) -> Option<Ray> {
        let (origin, direction, length) = query.segment()?;
        Some(Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, length))
    }
}

impl ShadowQuery {
    /// The segment a shadow ray tests for this pair (see the module's steps): its origin, off
    /// the surface along the normal by [`surface_offset`]; its unit direction towards the
    /// light; and its length (infinite for a directional light). `None` when the point
    /// coincides with the light or an input is not finite (nothing to block). Every tracer of
    /// shadow rays (this oracle, [`crate::ray_bvh`], the shaders) casts this segment.
    pub fn segment(&self) -> Option<(Vec3, Vec3, f32)> {
        let offset = surface_offset(self.point);
        let normal = self.normal.try_normalize().unwrap_or(Vec3::ZERO);
        let (direction, length) = match self.light {
            LightSource::At(position) => {
                let to = position - self.point;
                (to.try_normalize()?, to.length() - offset)
            }
            LightSource::Travelling(direction) => (-direction.try_normalize()?, f32::INFINITY),
        };
        // Off the surface along its normal: a light behind the surface is then blocked by the
        // surface itself, as shading (which gives it no contribution there) agrees.
        let origin = self.point + normal * offset;
        if !origin.is_finite() || length <= 0.0 {
            return None;
        }
        Some((origin, direction, length))
    }
}

/// How far outside a triangle, in barycentric units, a hit still counts: a ray through the
/// edge two triangles share hits both (the plain Möller–Trumbore test can miss both there, and
/// light would leak through the diagonal of a closed box).
pub const EDGE_TOLERANCE: f32 = 1e-6;

/// Distance along `ray` to where it crosses `tri` (either side) within `[tmin, tmax]`, edges
/// included ([`EDGE_TOLERANCE`]); infinity where it does not (Möller–Trumbore).
fn hit_distance(tri: &Triangle, ray: &Ray) -> f32 {
    let (e1, e2) = (tri.v1 - tri.v0, tri.v2 - tri.v0);
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return f32::INFINITY; // parallel or degenerate
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri.v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = ray.direction.dot(q) * inv;
    let inside = u >= -EDGE_TOLERANCE && v >= -EDGE_TOLERANCE && u + v <= 1.0 + EDGE_TOLERANCE;
    let t = e2.dot(q) * inv;
    if inside && t >= ray.tmin && t <= ray.tmax { t } else { f32::INFINITY }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor (y = 0, ±20) and a square plate of half-size 0.5 at height 1 over the origin.
    fn plate_over_floor() -> OccluderSet {
        let quad = |y: f32, h: f32| {
            let [a, b, c, d] = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, z)| Vec3::new(x, y, z));
            [[a, b, c], [a, c, d]]
        };
        OccluderSet::new(quad(0.0, 20.0).into_iter().chain(quad(1.0, 0.5)))
    }

    fn floor_query(x: f32, z: f32, light: LightSource) -> ShadowQuery {
        ShadowQuery { point: Vec3::new(x, 0.0, z), normal: Vec3::Y, light }
    }

    /// The umbra lies where the geometry puts it: a point light at height 2 projects the plate
    /// (height 1) at twice its size, a half-size of 1; light straight down projects it at its
    /// own size. The floor never shadows itself, the plate never shadows its own top.
    #[test]
    fn the_umbra_of_a_plate_is_where_geometry_puts_it() {
        let set = plate_over_floor();
        assert_eq!(set.triangle_count(), 4);
        for (light, half) in [
            (LightSource::At(Vec3::new(0.0, 2.0, 0.0)), 1.0),
            (LightSource::Travelling(Vec3::NEG_Y), 0.5),
            (LightSource::Travelling(Vec3::new(0.0, -3.0, 0.0)), 0.5),
        ] {
            for i in 0..=40 {
                let x = -2.0 + 0.1 * i as f32;
                let q = floor_query(x, 0.03, light);
                if (x.abs() - half).abs() < 0.02 {
                    continue; // on the umbra's edge
                }
                assert_eq!(set.visible(&q), x.abs() > half, "{light:?} at x = {x}");
            }
            let top = ShadowQuery { point: Vec3::new(0.1, 1.0, 0.0), normal: Vec3::Y, light };
            assert!(set.visible(&top), "{light:?}: the plate's top sees the light");
        }
        // A slanted directional light moves the umbra: down and towards +x by 1 per unit of
        // height, the plate's shadow spans x in [0.5, 1.5].
        let slanted = LightSource::Travelling(Vec3::new(1.0, -1.0, 0.0));
        for (x, lit) in [(0.3, true), (0.7, false), (1.3, false), (1.7, true)] {
            assert_eq!(set.visible(&floor_query(x, 0.0, slanted)), lit, "x = {x}");
        }
    }

    /// A camera ray finds the surface it looks at, with the normal facing it.
    #[test]
    fn first_hit_finds_the_nearest_surface() {
        let set = plate_over_floor();
        let down = set.first_hit(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y).expect("the plate");
        assert!((down.point.y - 1.0).abs() < 1e-5 && (down.distance - 2.0).abs() < 1e-5, "{down:?}");
        assert_eq!(down.normal, Vec3::Y);
        let beside = set.first_hit(Vec3::new(2.0, 3.0, 0.0), Vec3::new(0.0, -2.0, 0.0)).expect("the floor");
        assert!(beside.point.abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-5), "{beside:?}");
        let up = set.first_hit(Vec3::new(0.0, 0.5, 0.0), Vec3::Y).expect("the plate's underside");
        assert_eq!(up.normal, Vec3::NEG_Y);
        assert!(set.first_hit(Vec3::new(0.0, 3.0, 0.0), Vec3::Y).is_none());
        assert!(set.first_hit(Vec3::NAN, Vec3::Y).is_none());
    }

    /// A light below the plate's top, touching the floor, inside a closed box, or at the
    /// point itself.
    #[test]
    fn hard_cases_decide_as_geometry_does() {
        let set = plate_over_floor();
        // A light resting on the floor lights the floor beside it (grazing), not through it.
        let on_floor = LightSource::At(Vec3::new(3.0, 0.0, 0.0));
        assert!(set.visible(&floor_query(2.0, 0.0, on_floor)));
        // A light under the plate lights the floor under it.
        let under = LightSource::At(Vec3::new(0.0, 0.5, 0.0));
        assert!(set.visible(&floor_query(0.2, 0.0, under)));
        // ... but not the plate's top.
        let top = ShadowQuery { point: Vec3::new(0.1, 1.0, 0.0), normal: Vec3::Y, light: under };
        assert!(!set.visible(&top));
        // A light at the point: nothing in between.
        let here = LightSource::At(Vec3::new(2.0, 0.0, 0.0));
        assert!(set.visible(&floor_query(2.0, 0.0, here)));
        // A light inside a closed box lights nothing outside it.
        let corners: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) * 2.0 - 1.0)
            .collect();
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        let cube = MeshData::from_attributes(
            "cube",
            &corners,
            None,
            None,
            Some(faces.iter().flat_map(|&[a, b, c, d]| [a, b, c, a, c, d]).collect()),
        )
        .expect("a valid cube");
        let boxed = OccluderSet::from_instances([(&cube, Mat4::from_scale(Vec3::splat(2.0)))]);
        let inside = LightSource::At(Vec3::ZERO);
        for dir in [Vec3::X, Vec3::Y, Vec3::new(-1.0, 0.3, 0.2)] {
            let q = ShadowQuery { point: dir.normalize() * 5.0, normal: -dir, light: inside };
            assert!(!boxed.visible(&q), "{dir}");
        }
        // No occluders, or a non-finite query: visible.
        let empty = OccluderSet::new([]);
        assert!(empty.visible(&floor_query(0.0, 0.0, under)));
        let nan = ShadowQuery { point: Vec3::NAN, normal: Vec3::Y, light: under };
        assert!(set.visible(&nan));
    }

    /// Far from the origin the offset grows with the coordinates: a floor at 10⁴ does not
    /// shadow itself, and the plate's umbra is still where it belongs.
    #[test]
    fn large_coordinates_keep_the_umbra() {
        let shift = Vec3::new(1e4, 0.0, -1e4);
        let quad = |y: f32, h: f32| {
            let [a, b, c, d] = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, z)| Vec3::new(x, y, z) + shift);
            [[a, b, c], [a, c, d]]
        };
        let set = OccluderSet::new(quad(0.0, 20.0).into_iter().chain(quad(1.0, 0.5)));
        let light = LightSource::At(shift + Vec3::new(0.0, 2.0, 0.0));
        let at = |x: f32| ShadowQuery { point: shift + Vec3::new(x, 0.0, 0.0), normal: Vec3::Y, light };
        for (x, lit) in [(0.0, false), (0.5, false), (0.9, false), (1.1, true), (1.5, true), (5.0, true)] {
            assert_eq!(set.visible(&at(x)), lit, "x = {x}");
        }
    }

    /// The BVH answers as testing every triangle does, over random triangles and segments.
    #[test]
    fn the_bvh_agrees_with_testing_every_triangle() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 10.0 - 5.0
        };
        let mut v = || Vec3::new(next(), next(), next());
        let triangles: Vec<[Vec3; 3]> = (0..300)
            .map(|_| {
                let c = v();
                [c, c + v() * 0.2, c + v() * 0.2]
            })
            .collect();
        let set = OccluderSet::new(triangles.iter().copied());
        let all: Vec<Triangle> = triangles
            .iter()
            .map(|&[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() })
            .collect();
        let queries: Vec<ShadowQuery> = (0..2000)
            .map(|_| ShadowQuery { point: v(), normal: Vec3::ZERO, light: LightSource::At(v()) })
            .collect();
        let found = set.visibility(&queries);
        let mut blocked = 0;
        for (q, &visible) in queries.iter().zip(&found) {
            let ray = set.ray(q).expect("a ray");
            let brute = all.iter().all(|t| hit_distance(t, &ray) == f32::INFINITY);
            assert_eq!(visible, brute, "{q:?}");
            blocked += usize::from(!visible);
        }
        assert!(blocked > 100 && blocked < 1900, "a test that exercises both answers: {blocked}");
    }
}

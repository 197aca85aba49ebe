//! The coarse level of the GPU build (level 0): coarse tiles of `span × span` tiles, their
//! bounds, and the test that accepts a superset of what any of their columns accepts; and the
//! extra radius inflation of the tile level, which both levels use.

use glam::{UVec2, Vec3, Vec4};

use super::cull::{ViewSphere, inflated_radius, sphere_intersects_aabb, sphere_intersects_planes};
use super::{ClusterGrid, CullTest};

/// Extra radius inflation of the GPU build's tile level (`TILE_PREFILTER_INFLATION` in
/// `shaders/cluster_build.wgsl`, written into the shader from this constant).
pub const TILE_PREFILTER_INFLATION: f32 = 1.001;

/// Tiles per coarse-tile edge of the build's level 0 for a requested `span` and culling test,
/// or `None` when the build has no coarse level: a span below 2, or the planes test, whose
/// acceptance is not monotone in the tile (a sphere straddling the camera plane can pass a
/// narrow column's side planes and fail a wider column's), so no coarse test is a superset.
pub fn coarse_span(span: u32, test: CullTest) -> Option<u32> {
    (span >= 2 && test != CullTest::Planes).then_some(span)
}

/// Coarse tiles across and down a grid of `tiles` (each axis at least 1).
pub fn coarse_dims(tiles: UVec2, span: u32) -> UVec2 {
    UVec2::new(tiles.x.div_ceil(span.max(1)), tiles.y.div_ceil(span.max(1))).max(UVec2::ONE)
}

/// A coarse tile of the GPU build's level 0: `span × span` tile columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoarseTile {
    /// Lower corner of the box hull of its columns' AABBs.
    pub min: Vec3,
    /// Upper corner of that hull.
    pub max: Vec3,
    /// Its planes in [`ClusterGrid::cluster_planes`] order: the side planes of its outer
    /// columns moved outwards by one more column margin, and its columns' near and far planes.
    pub planes: [Vec4; 6],
    /// The column margin ([`ClusterGrid::cluster_margin`] of the one-slice grid).
    pub margin: f32,
}

/// The coarse tiles of `columns` (a grid of one slice: the build's tile columns), row-major:
/// coarse tile `(cx, cy)` holds columns `x ∈ [cx·span, (cx+1)·span)`, `y ∈ [cy·span,
/// (cy+1)·span)` (clipped to the grid). The hull is computed with `min`/`max` only, so every
/// column's box lies inside its coarse tile's, bit for bit.
pub fn coarse_tiles(columns: &ClusterGrid, span: u32) -> Vec<CoarseTile> {
    let span = span.max(1);
    let tiles = columns.dims.truncate();
    let coarse = coarse_dims(tiles, span);
    let margin = columns.cluster_margin(0);
    let widen = Vec4::new(0.0, 0.0, 0.0, margin);
    let mut out = Vec::with_capacity((coarse.x * coarse.y) as usize);
    for cy in 0..coarse.y {
        for cx in 0..coarse.x {
            let (x0, x1) = (cx * span, ((cx + 1) * span).min(tiles.x) - 1);
            let (y0, y1) = (cy * span, ((cy + 1) * span).min(tiles.y) - 1);
            let mut hull = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let (min, max) = columns.cluster_aabb(x, y, 0);
                    hull = (hull.0.min(min), hull.1.max(max));
                }
            }
            // Left of the first column, right of the last; rows run top down, so the bottom
            // plane is the last row's and the top the first's.
            let [left, _, _, _, near, far] = columns.cluster_planes(x0, y1, 0);
            let [_, right, bottom, _, _, _] = columns.cluster_planes(x1, y1, 0);
            let [_, _, _, top, _, _] = columns.cluster_planes(x0, y0, 0);
            out.push(CoarseTile {
                min: hull.0,
                max: hull.1,
                planes: [left + widen, right + widen, bottom + widen, top + widen, near, far],
                margin,
            });
        }
    }
    out
}

/// Level 0's test (`touches_coarse` in `shaders/cluster_build.wgsl`): the light, radius
/// inflated as for the tile level, must reach the hull box, and, unless `test` is the AABB test,
/// the coarse tile's planes with its radius inflated once more, when its sphere lies wholly in
/// front of the camera by more than `2 × margin`.
///
/// It accepts every light that one of the tile's columns accepts under `test` (the tile level,
/// radius × [`TILE_PREFILTER_INFLATION`]):
/// - AABB: each column's box lies inside the hull, and the per-axis distances are monotone in
///   the box, in floats too;
/// - planes: a side half-space of a column, restricted to depths `≥ 0`, lies inside the coarse
///   tile's on that side (their planes meet at the eye; orthographic: parallel, one inside the
///   other). A sphere whose centre is deeper than its reach is within its reach of the column's
///   half-space at a point of depth `≥ 0`, which is in the coarse half-space; the extra margin
///   covers rounding. Spheres nearer the eye plane can pass a narrow column's side planes and
///   fail a wide one's, so those skip the planes (the near and far planes are the columns'
///   own, but they are skipped with the side planes for simplicity).
pub fn coarse_tile_accepts(tile: &CoarseTile, light: &ViewSphere, test: CullTest) -> bool {
    let r = light.radius * TILE_PREFILTER_INFLATION;
    if !sphere_intersects_aabb(light.center, r, tile.min, tile.max) {
        return false;
    }
    if test == CullTest::Aabb {
        return true;
    }
    let wide = r * TILE_PREFILTER_INFLATION;
    let in_front = -light.center.z > inflated_radius(wide) + 2.0 * tile.margin;
    !in_front || sphere_intersects_planes(light.center, wide, &tile.planes)
}

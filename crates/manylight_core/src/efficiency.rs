//! Culling efficiency of a light assignment for one rendered frame: how many light–pixel pairs
//! the shader evaluates (every light in each pixel's cluster list) against how many of them
//! contribute (the pixel lies strictly inside the light's sphere, where attenuation > 0).
//!
//! 1. reconstruct each covered pixel's view-space position from its pixel centre and the
//!    reverse-Z depth buffer;
//! 2. find its cluster and count the list's lights (evaluated) and those whose sphere contains
//!    the point (contributing);
//! 3. on a sample of pixels, also test every light, to catch a contributing light missing from
//!    the list (must be zero for a conservative assignment).

use crate::Projection;
use crate::cluster::{
    ClusterAssignment, ClusterGrid, CullTest, GridConfig, ViewSphere, ZSlicing, sphere_passes,
};
use glam::{Vec2, Vec3};

/// The result of [`culling_efficiency`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CullingEfficiency {
    /// Pixels covered by geometry.
    pub pixels: u64,
    /// Light–pixel pairs the shader evaluates.
    pub evaluated_pairs: u64,
    /// Light–pixel pairs with a non-zero contribution.
    pub contributing_pairs: u64,
    /// Pixels checked against every light.
    pub sampled_pixels: u64,
    /// Contributing light–pixel pairs missing from the lists on the sampled pixels (a bug if
    /// not zero).
    pub missed_pairs: u64,
}

impl CullingEfficiency {
    /// Evaluated ÷ contributing pairs (1 is perfect; `inf` when nothing contributes).
    pub fn ratio(&self) -> f64 {
        self.evaluated_pairs as f64 / self.contributing_pairs as f64
    }
}

/// Calls `visit(pixel_index, view_position, cluster)` for every pixel covered by geometry (a
/// depth above 0 in a reverse-Z buffer), in row-major order: the view-space position rebuilt
/// from the pixel centre and its depth, and the cluster of `grid` it falls in.
fn for_each_covered_pixel(
    grid: &ClusterGrid,
    projection: &Projection,
    depth: &[f32],
    mut visit: impl FnMut(usize, Vec3, u32),
) {
    let p = projection.sanitized();
    let (w, h) = (grid.viewport.x.max(1), grid.viewport.y.max(1));
    let aspect = w as f32 / h as f32;
    for y in 0..h {
        for x in 0..w {
            let index = (y * w + x) as usize;
            let z = depth.get(index).copied().unwrap_or(0.0);
            if z <= 0.0 || !z.is_finite() {
                continue;
            }
            let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ndc = Vec2::new(px.x / w as f32 * 2.0 - 1.0, 1.0 - px.y / h as f32 * 2.0);
            let q = p.view_position(ndc, z, aspect);
            visit(index, q, grid.cluster_of(px, -q.z));
        }
    }
}

/// True when the view-space point `q` lies strictly inside light `s`'s sphere: the light's
/// contribution there is not zero (its attenuation is zero at and beyond the radius).
fn contributes(s: &ViewSphere, q: Vec3) -> bool {
    s.is_valid() && s.center.distance_squared(q) < s.radius * s.radius
}

/// Measures the efficiency of `assignment` for a frame whose depth buffer (reverse-Z, row-major,
/// `size.x * size.y` values, 0 = background) is `depth`. Every `sample_stride`-th covered
/// pixel is also checked against all lights.
pub fn culling_efficiency(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    sample_stride: usize,
) -> CullingEfficiency {
    let mut out = CullingEfficiency::default();
    for_each_covered_pixel(grid, projection, depth, |_, q, cluster| {
        let list = assignment.lights_of(cluster);
        out.pixels += 1;
        out.evaluated_pairs += list.len() as u64;
        let hits =
            list.iter().filter(|&&l| lights.get(l as usize).is_some_and(|s| contributes(s, q))).count();
        out.contributing_pairs += hits as u64;
        if sample_stride > 0 && (out.pixels as usize).is_multiple_of(sample_stride) {
            out.sampled_pixels += 1;
            let all = lights.iter().filter(|s| contributes(s, q)).count();
            out.missed_pairs += all.saturating_sub(hits) as u64;
        }
    });
    out
}

/// The grid [`exact_pixel_lists`] are over: one-pixel tiles, one linear depth slice.
pub fn pixel_grid(viewport: glam::UVec2, projection: &Projection) -> ClusterGrid {
    let viewport = viewport.max(glam::UVec2::ONE);
    let config =
        GridConfig { dims: Some(viewport.extend(1)), slicing: ZSlicing::Linear, ..GridConfig::default() };
    ClusterGrid::new(viewport, projection, &config)
}

/// The floor of light culling: exact per-pixel light lists for a frame whose depth buffer is
/// `depth` (as for [`culling_efficiency`]), each holding only the lights that contribute at that
/// pixel (the pixel's position strictly inside the light's sphere), in light order.
///
/// The result is an assignment over a grid of one-pixel tiles and one depth slice:
/// `ranges[x + y * width]`, empty for background pixels. The candidates of each pixel are the
/// lights of its cluster in `assignment` (a conservative assignment holds every contributing
/// light, which [`culling_efficiency`]'s sampled check confirms), so building the lists costs a
/// culling-efficiency pass, not pixels × lights.
pub fn exact_pixel_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
) -> ClusterAssignment {
    filtered_pixel_lists(grid, projection, assignment, depth, |l, q| {
        lights.get(l as usize).is_some_and(|s| contributes(s, q))
    })
}

/// Per covered pixel of a frame whose depth buffer is `depth`, the lights of its cluster's list
/// in `assignment` that `keep(light, view_position)` keeps, in list order: an assignment over
/// [`pixel_grid`] (`ranges[x + y * width]`, empty for background pixels, the offsets an
/// exclusive prefix sum of the counts).
fn filtered_pixel_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    depth: &[f32],
    mut keep: impl FnMut(u32, Vec3) -> bool,
) -> ClusterAssignment {
    let pixels = grid.viewport.x.max(1) as usize * grid.viewport.y.max(1) as usize;
    let mut ranges = vec![[0u32; 2]; pixels];
    let mut indices: Vec<u32> = Vec::new();
    for_each_covered_pixel(grid, projection, depth, |index, q, cluster| {
        let offset = indices.len() as u32;
        indices.extend(assignment.lights_of(cluster).iter().copied().filter(|&l| keep(l, q)));
        ranges[index] = [offset, indices.len() as u32 - offset];
    });
    // Background pixels keep offset 0; give them the running offset so the offsets stay an
    // exclusive prefix sum of the counts.
    let mut running = 0u32;
    for r in &mut ranges {
        r[0] = running;
        running += r[1];
    }
    ClusterAssignment { ranges, indices, dropped_pairs: 0, clusters_overflowed: 0 }
}

/// Per cluster, the nearest and farthest view distance of the covered pixels in it;
/// `(inf, -inf)` for a cluster without a pixel.
fn pixel_depth_ranges(grid: &ClusterGrid, projection: &Projection, depth: &[f32]) -> Vec<(f32, f32)> {
    let mut range = vec![(f32::INFINITY, f32::NEG_INFINITY); grid.cluster_count() as usize];
    for_each_covered_pixel(grid, projection, depth, |_, q, cluster| {
        let r = &mut range[cluster as usize];
        *r = (r.0.min(-q.z), r.1.max(-q.z));
    });
    range
}

/// The lists `assignment` would have with **per-cluster depth bounds** (the depth range of the
/// pixels that fall in each cluster, from a depth pre-pass; Olsson et al. 2012): each cluster's
/// bounds cut to its tile between the nearest and farthest of its pixels (widened by the
/// cluster margin), and only the lights of its list that still pass `test` kept; clusters
/// without a pixel keep none. It measures what the technique would save before it is built; it
/// is conservative like the build (a pixel's position lies inside its cluster's cut bounds, so a
/// light containing it passes both tests), which [`culling_efficiency`]'s sampled check
/// confirms.
pub fn depth_bounded_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    test: CullTest,
) -> ClusterAssignment {
    let range = pixel_depth_ranges(grid, projection, depth);
    let mut out = ClusterAssignment { ranges: Vec::with_capacity(range.len()), ..Default::default() };
    for (cluster, &(near, far)) in range.iter().enumerate() {
        let offset = out.indices.len() as u32;
        if near <= far {
            let k = grid.coords(cluster as u32);
            let m = grid.cluster_margin(k.z);
            let (d0, d1) = (
                (near - m).max(grid.slice_boundary(k.z) - m),
                (far + m).min(grid.slice_boundary(k.z + 1) + m),
            );
            let (x0, x1) = grid.x_extent_between(k.x, d0, d1, m);
            let (y0, y1) = grid.y_extent_between(k.y, d0, d1, m);
            let aabb = (Vec3::new(x0, y0, -d1), Vec3::new(x1, y1, -d0));
            let mut planes = grid.cluster_planes(k.x, k.y, k.z);
            planes[4] = glam::Vec4::new(0.0, 0.0, -1.0, -d0);
            planes[5] = glam::Vec4::new(0.0, 0.0, 1.0, d1);
            let keeps = |s: &ViewSphere| sphere_passes(test, s, aabb, &planes);
            let list = assignment.lights_of(cluster as u32);
            out.indices.extend(list.iter().copied().filter(|&l| lights.get(l as usize).is_some_and(keeps)));
        }
        out.ranges.push([offset, out.indices.len() as u32 - offset]);
    }
    out
}

/// The lists tiled deferred lighting shades from (`shaders/tiled_deferred.wgsl`), for a frame
/// whose clusters are tiles (one depth slice): per cluster, the depth range of its pixels split
/// into `cells` equal cells (at most 32), a mask of the cells holding a pixel (2.5D culling,
/// Harada 2012), and the lights of its list whose view-depth interval (centre ± radius) meets
/// an occupied cell. Clusters without a pixel keep none. Conservative: a light reaching a pixel
/// lies within its radius of it along the view axis too.
pub fn depth_masked_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    cells: u32,
) -> ClusterAssignment {
    let cells = cells.clamp(1, 32);
    let count = grid.cluster_count() as usize;
    let range = pixel_depth_ranges(grid, projection, depth);
    let cell = |d: f32, (lo, hi): (f32, f32)| {
        let c = ((d - lo) * (cells as f32 / (hi - lo).max(1e-30))).floor();
        c.clamp(0.0, cells as f32 - 1.0) as u32
    };
    let mut mask = vec![0u32; count];
    for_each_covered_pixel(grid, projection, depth, |_, q, cluster| {
        mask[cluster as usize] |= 1 << cell(-q.z, range[cluster as usize]);
    });
    let mut out = ClusterAssignment { ranges: Vec::with_capacity(count), ..Default::default() };
    for (cluster, (&r, &m)) in range.iter().zip(&mask).enumerate() {
        let offset = out.indices.len() as u32;
        if r.0 <= r.1 {
            let keeps = |s: &ViewSphere| {
                let reach = s.radius * crate::cluster::RADIUS_INFLATION;
                let (lo, hi) = (-s.center.z - reach, -s.center.z + reach);
                if !s.is_valid() || hi < r.0 || lo > r.1 {
                    return false;
                }
                let (first, last) = (cell(lo, r), cell(hi, r));
                let span = (u32::MAX >> (31 - last)) & (u32::MAX << first);
                span & m != 0
            };
            let list = assignment.lights_of(cluster as u32);
            out.indices.extend(list.iter().copied().filter(|&l| lights.get(l as usize).is_some_and(keeps)));
        }
        out.ranges.push([offset, out.indices.len() as u32 - offset]);
    }
    out
}

/// Blocks across and down of `edge`-pixel blocks over `viewport` (the last row and column cut
/// by the viewport); block `(x / edge, y / edge)` holds pixel `(x, y)`, row-major.
pub fn block_dims(viewport: glam::UVec2, edge: u32) -> glam::UVec2 {
    viewport.max(glam::UVec2::ONE).map(|v| v.div_ceil(edge.max(1)))
}

/// How [`refined_lists`] makes its blocks and their boxes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refinement {
    /// Pixels along a block's edge.
    pub edge: u32,
    /// Relative widening of a block's box (see [`refined_lists`]).
    pub slack: f32,
    /// Added to each pixel's distance before `slack` scales it.
    pub offset: f32,
}

/// **Refined light lists** (`shaders/light_refine.wgsl` in the renderer): per block of `edge` ×
/// `edge` pixels ([`block_dims`], row-major; `edge`, `slack` and `offset` from `refinement`), the lights of its pixels' cluster lists (each
/// once, in order of first mention) whose sphere reaches the view-space box around the block's
/// pixel positions, widened on every axis by `slack` × (each pixel's distance + `offset`; the
/// renderer's `offset` is the camera's distance from the world origin). The candidates are the
/// lists of the box of clusters (tiles and slices) its pixels' widened distances fall in, as
/// the renderer takes them. Blocks
/// without a pixel keep none. Conservative: a pixel's position lies in its block's box, so a
/// light containing it reaches the box, and is in its cluster's list.
pub fn refined_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    refinement: Refinement,
) -> ClusterAssignment {
    let Refinement { edge, slack, offset } = refinement;
    let (viewport, edge) = (grid.viewport.max(glam::UVec2::ONE), edge.max(1));
    let dims = block_dims(viewport, edge);
    let count = (dims.x * dims.y) as usize;
    let mut boxes = vec![(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); count];
    // Per block, the box of clusters (tile x, y and slice) its pixels' widened distances fall in.
    let mut cluster_box = vec![(glam::UVec3::MAX, glam::UVec3::ZERO); count];
    for_each_covered_pixel(grid, projection, depth, |index, q, _| {
        let (x, y) = (index as u32 % viewport.x, index as u32 / viewport.x);
        let b = (x / edge + y / edge * dims.x) as usize;
        let s = slack * (q.z.abs() + offset);
        boxes[b] = (boxes[b].0.min(q - s), boxes[b].1.max(q + s));
        let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        for d in [(-q.z - s).max(0.0), -q.z + s] {
            let k = grid.coords(grid.cluster_of(px, d));
            cluster_box[b] = (cluster_box[b].0.min(k), cluster_box[b].1.max(k));
        }
    });
    let clusters: Vec<Vec<u32>> = cluster_box
        .iter()
        .map(|&(lo, hi)| {
            let mut cs = Vec::new();
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        cs.push(grid.index(x, y, z));
                    }
                }
            }
            cs
        })
        .collect();
    let mut out = ClusterAssignment { ranges: Vec::with_capacity(count), ..Default::default() };
    let mut seen = vec![u32::MAX; lights.len()];
    for (b, (&(min, max), cs)) in boxes.iter().zip(&clusters).enumerate() {
        let offset = out.indices.len() as u32;
        for &l in cs.iter().flat_map(|&c| assignment.lights_of(c)) {
            let Some(s) = lights.get(l as usize) else { continue };
            if seen[l as usize] != b as u32
                && crate::cluster::sphere_intersects_aabb(s.center, s.radius, min, max)
            {
                seen[l as usize] = b as u32;
                out.indices.push(l);
            }
        }
        out.ranges.push([offset, out.indices.len() as u32 - offset]);
    }
    out
}

/// The list every pixel shades from when `edge`-pixel blocks have lists of their own
/// (`blocks`, as [`refined_lists`] makes them): its block's, or, for a block whose count is
/// `fallback`, its cluster's in `assignment`. An assignment over [`pixel_grid`] (for
/// [`culling_efficiency`]); background pixels keep none.
pub fn block_lists_per_pixel(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    depth: &[f32],
    edge: u32,
    blocks: &ClusterAssignment,
    fallback: u32,
) -> ClusterAssignment {
    let (viewport, edge) = (grid.viewport.max(glam::UVec2::ONE), edge.max(1));
    let dims = block_dims(viewport, edge);
    // The block lists, then the cluster lists.
    let mut indices = blocks.indices.clone();
    let cluster_base = indices.len() as u32;
    indices.extend_from_slice(&assignment.indices);
    let mut ranges = vec![[0u32; 2]; (viewport.x * viewport.y) as usize];
    for_each_covered_pixel(grid, projection, depth, |index, _, cluster| {
        let (x, y) = (index as u32 % viewport.x, index as u32 / viewport.x);
        let block = blocks.ranges.get((x / edge + y / edge * dims.x) as usize).copied();
        ranges[index] = match block {
            Some(r) if r[1] != fallback => r,
            _ => {
                let r = assignment.ranges.get(cluster as usize).copied().unwrap_or_default();
                [cluster_base + r[0], r[1]]
            }
        };
    });
    ClusterAssignment { ranges, indices, dropped_pairs: 0, clusters_overflowed: 0 }
}

/// The lists **z-binning** (Drobot, "Improved culling for tiled and clustered rendering", 2017)
/// would shade from, for a frame whose clusters are tiles (one depth slice, as Forward+'s): the
/// lights sorted by the view depth of their centre; the depth range from near to far cut into
/// `bins` equal bins, each keeping the first and last sorted light whose depth interval
/// (centre ± radius) meets it; a pixel visits the lights of its tile's list (a bitmask in the
/// technique) whose sorted position lies in its bin's range. Measures what the technique would
/// cut before it is built. Conservative: a light reaching a pixel reaches the pixel's depth, so
/// its bin's range holds it. An assignment over [`pixel_grid`].
pub fn zbinned_lists(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    bins: u32,
) -> ClusterAssignment {
    let bins = bins.max(1);
    let (near, far) = (grid.near, grid.far.max(grid.near * (1.0 + 1e-6)));
    let bin_of =
        |d: f32| (((d - near) / (far - near) * bins as f32).floor().clamp(0.0, bins as f32 - 1.0)) as u32;
    // Sorted position of every light by centre depth.
    let mut order: Vec<u32> = (0..lights.len() as u32).collect();
    order.sort_by(|&a, &b| (-lights[a as usize].center.z).total_cmp(&-lights[b as usize].center.z));
    let mut rank = vec![0u32; lights.len()];
    for (i, &l) in order.iter().enumerate() {
        rank[l as usize] = i as u32;
    }
    // Per bin, the first and last sorted position of a light meeting it.
    let mut range = vec![(u32::MAX, 0u32); bins as usize];
    for (i, &l) in order.iter().enumerate() {
        let s = &lights[l as usize];
        if !s.is_valid() {
            continue;
        }
        let reach = s.radius * crate::cluster::RADIUS_INFLATION;
        let (lo, hi) = (-s.center.z - reach, -s.center.z + reach);
        if hi < near || lo > far {
            continue;
        }
        for b in bin_of(lo)..=bin_of(hi) {
            let r = &mut range[b as usize];
            *r = (r.0.min(i as u32), r.1.max(i as u32));
        }
    }
    filtered_pixel_lists(grid, projection, assignment, depth, |l, q| {
        let (first, last) = range[bin_of(-q.z) as usize];
        let k = rank.get(l as usize).copied().unwrap_or(u32::MAX);
        first <= k && k <= last
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cluster::{CullTest, assign_lights};
    use glam::UVec2;

    /// An 8×4 view (60° wide, near 0.1, far 100) on a grid of 4-px tiles and 4 exponential
    /// slices (boundaries 0.1, 0.56, 3.16, 17.8, 100), and the reverse-Z depth of a point `d`
    /// units ahead.
    fn small_view() -> (ClusterGrid, Projection, impl Fn(f32) -> f32) {
        let size = UVec2::new(8, 4);
        let projection = Projection::perspective(1.0, 0.1, 100.0);
        let grid = ClusterGrid::new(
            size,
            &projection,
            &GridConfig { tile_px: 4, z_slices: 4, ..GridConfig::default() },
        );
        let depth_of = move |d: f32| projection.matrix(2.0).project_point3(glam::Vec3::new(0.0, 0.0, -d)).z;
        (grid, projection, depth_of)
    }

    /// [`small_view`] with one depth slice: its 4-px tiles.
    fn small_tile_view() -> (ClusterGrid, Projection, impl Fn(f32) -> f32) {
        let (grid, projection, depth_of) = small_view();
        let config = GridConfig { tile_px: 4, z_slices: 1, ..GridConfig::default() };
        (ClusterGrid::new(grid.viewport, &projection, &config), projection, depth_of)
    }

    /// Depth bounds cut the lights of a slice that miss the only depth its pixels have: a wall
    /// 4 units away, in a slice from 3.16 to 17.8; a light 8 units away (reaching 6 to 10) is in
    /// the wall's clusters' lists but not in their depth-bounded lists, a light reaching the wall
    /// stays, and no contributing pair is missing.
    #[test]
    fn depth_bounds_drop_lights_that_miss_the_pixels_depth_range() {
        let (grid, projection, depth_of) = small_view();
        let depth = vec![depth_of(4.0); 32];
        let lights = [
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -8.0), radius: 2.0 },
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -5.0), radius: 1.5 },
        ];
        for test in CullTest::ALL {
            let assignment = assign_lights(&grid, &lights, test, None);
            let bounded = depth_bounded_lists(&grid, &projection, &assignment, &lights, &depth, test);
            let wall = grid.cluster_of(glam::Vec2::new(3.5, 1.5), 4.0);
            assert_eq!(assignment.lights_of(wall), [0, 1], "{test:?}");
            assert_eq!(bounded.lights_of(wall), [1], "{test:?}");
            // Clusters without pixels keep nothing; the rest is a subset.
            for c in 0..grid.cluster_count() {
                let (all, kept) = (assignment.lights_of(c), bounded.lights_of(c));
                assert!(kept.iter().all(|l| all.contains(l)), "{test:?}: cluster {c}");
                if grid.coords(c).z != grid.coords(wall).z {
                    assert!(kept.is_empty(), "{test:?}: cluster {c} has no pixel");
                }
            }
            let before = culling_efficiency(&grid, &projection, &assignment, &lights, &depth, 1);
            let after = culling_efficiency(&grid, &projection, &bounded, &lights, &depth, 1);
            assert_eq!(after.missed_pairs, 0, "{test:?}");
            assert_eq!(after.contributing_pairs, before.contributing_pairs, "{test:?}");
            assert!(after.evaluated_pairs < before.evaluated_pairs, "{test:?}: {after:?} vs {before:?}");
        }
    }

    /// A tile whose pixels lie at two depths (a wall at 4 with a post at 12 in its left column):
    /// the 2.5D mask drops a light between them (reaching 7 to 9) that the depth range alone
    /// keeps, keeps lights reaching either surface, and misses no contributing pair.
    #[test]
    fn a_depth_mask_drops_lights_between_a_tiles_surfaces() {
        let (grid, projection, depth_of) = small_tile_view();
        let mut depth = vec![depth_of(12.0); 32];
        for y in 0..4 {
            depth[y * 8] = depth_of(4.0);
        }
        let lights = [
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -8.0), radius: 1.0 },
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -4.5), radius: 1.0 },
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -12.5), radius: 1.0 },
        ];
        let assignment = assign_lights(&grid, &lights, CullTest::Aabb, None);
        let masked = depth_masked_lists(&grid, &projection, &assignment, &lights, &depth, 32);
        let ranged = depth_masked_lists(&grid, &projection, &assignment, &lights, &depth, 1);
        let tile = grid.cluster_of(glam::Vec2::new(0.5, 0.5), 4.0);
        assert!(assignment.lights_of(tile).contains(&0), "{:?}", assignment.lights_of(tile));
        assert!(ranged.lights_of(tile).contains(&0), "one cell is the depth range alone");
        assert!(!masked.lights_of(tile).contains(&0), "{:?}", masked.lights_of(tile));
        for lists in [&masked, &ranged] {
            let e = culling_efficiency(&grid, &projection, lists, &lights, &depth, 1);
            let all = culling_efficiency(&grid, &projection, &assignment, &lights, &depth, 1);
            assert_eq!((e.missed_pairs, e.contributing_pairs), (0, all.contributing_pairs));
        }
    }

    /// Z-binning drops from a pixel's tile list the lights whose depth bin range misses the
    /// pixel's bin: a wall at 4 units, one light reaching it and one 20 units behind it in
    /// the same tiles; nothing that lights a pixel goes missing.
    #[test]
    fn zbinning_drops_lights_outside_the_pixels_depth_bin() {
        let (grid, projection, depth_of) = small_tile_view();
        let depth = vec![depth_of(4.0); 32];
        let lights = [
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -4.5), radius: 1.0 },
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, -24.0), radius: 1.0 },
        ];
        let assignment = assign_lights(&grid, &lights, CullTest::Aabb, None);
        let tile = grid.cluster_of(glam::Vec2::new(3.5, 1.5), 4.0);
        assert_eq!(assignment.lights_of(tile), [0, 1]);
        let binned = zbinned_lists(&grid, &projection, &assignment, &lights, &depth, 100);
        let pixels = pixel_grid(grid.viewport, &projection);
        assert_eq!(binned.lights_of(3 + 8), [0], "pixel (3, 1)");
        let e = culling_efficiency(&pixels, &projection, &binned, &lights, &depth, 1);
        let whole = culling_efficiency(&grid, &projection, &assignment, &lights, &depth, 1);
        assert_eq!((e.missed_pairs, e.contributing_pairs), (0, whole.contributing_pairs));
        assert!(e.evaluated_pairs < whole.evaluated_pairs);
    }

    /// A wall 4 units away filling the 8×4 view, a small light in front of its leftmost pixels:
    /// its 4-px tile's clusters list it for all 16 of their pixels, 2-px blocks only where it
    /// reaches their box, and nothing that lights a pixel is missing, with or without a block
    /// sent back to its cluster lists.
    #[test]
    fn refined_lists_cut_to_the_blocks_a_light_reaches() {
        let (grid, projection, depth_of) = small_view();
        let depth = vec![depth_of(4.0); 32];
        let left = projection.view_position(glam::Vec2::new(-0.875, 0.75), depth_of(4.0), 2.0);
        let lights = [ViewSphere { center: left + glam::Vec3::new(0.0, 0.0, 0.05), radius: 0.2 }];
        let assignment = assign_lights(&grid, &lights, CullTest::Both, None);
        let refinement = Refinement { edge: 2, slack: 1e-5, offset: 0.0 };
        let blocks = refined_lists(&grid, &projection, &assignment, &lights, &depth, refinement);
        assert_eq!(block_dims(grid.viewport, 2), glam::UVec2::new(4, 2));
        assert_eq!(blocks.ranges.len(), 8);
        assert_eq!(blocks.lights_of(0), [0], "the block holding the light's pixel");
        assert!(blocks.lights_of(3).is_empty() && blocks.lights_of(7).is_empty(), "far blocks");
        let pixels = pixel_grid(grid.viewport, &projection);
        let whole = culling_efficiency(&grid, &projection, &assignment, &lights, &depth, 1);
        for fallback_block in [None, Some(0usize)] {
            let mut b = blocks.clone();
            if let Some(i) = fallback_block {
                b.ranges[i][1] = u32::MAX;
            }
            let per_pixel = block_lists_per_pixel(&grid, &projection, &assignment, &depth, 2, &b, u32::MAX);
            let e = culling_efficiency(&pixels, &projection, &per_pixel, &lights, &depth, 1);
            assert_eq!(e.missed_pairs, 0, "{fallback_block:?}");
            assert_eq!(e.contributing_pairs, whole.contributing_pairs);
            assert!(e.contributing_pairs > 0);
            assert!(e.evaluated_pairs < whole.evaluated_pairs, "{e:?} vs {whole:?}");
        }
    }

    /// A wall 4 units away filling an 8×4 view; the left half lit by one light, a light behind
    /// the camera and a radius-0 light lighting nothing.
    #[test]
    fn exact_lists_hold_exactly_the_contributing_lights() {
        let (grid, projection, depth_of) = small_view();
        let mut depth = vec![depth_of(4.0); 32];
        depth[31] = 0.0; // one background pixel
        let left = projection.view_position(glam::Vec2::new(-0.75, 0.0), depth_of(4.0), 2.0);
        let lights = [
            ViewSphere { center: left + glam::Vec3::new(0.0, 0.0, 0.5), radius: 1.0 },
            ViewSphere { center: glam::Vec3::new(0.0, 0.0, 5.0), radius: 2.0 },
            ViewSphere { center: left, radius: 0.0 },
        ];
        let assignment = assign_lights(&grid, &lights, CullTest::Both, None);
        let lists = exact_pixel_lists(&grid, &projection, &assignment, &lights, &depth);
        assert_eq!(lists.ranges.len(), 32);
        let lit: Vec<u32> = (0..32).filter(|&p| lists.lights_of(p) == [0]).collect();
        assert!(!lit.is_empty() && lit.iter().all(|&p| p % 8 < 4), "left pixels lit: {lit:?}");
        assert!(lists.lights_of(31).is_empty(), "background");
        // Offsets are the exclusive prefix sum of the counts.
        let mut running = 0;
        for r in &lists.ranges {
            assert_eq!(r[0], running);
            running += r[1];
        }
        assert_eq!(running as usize, lists.indices.len());
        let pixels = pixel_grid(grid.viewport, &projection);
        let e = culling_efficiency(&pixels, &projection, &lists, &lights, &depth, 1);
        assert_eq!((e.missed_pairs, e.evaluated_pairs), (0, e.contributing_pairs));
        assert_eq!(e.pixels, 31);
    }
}

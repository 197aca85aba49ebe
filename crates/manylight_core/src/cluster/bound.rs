//! Upper bounds on the sizes of a frame's light lists, computed on the CPU before the frame is
//! submitted, so the GPU lists are sized once and can never overflow.
//!
//! 1. **Cluster pairs**: a light can only pass the test for a cluster inside its candidate box
//!    ([`ClusterTables::candidates`]: tile columns × tile rows × slices, conservative by
//!    construction, with slack for rounding). The sum of the boxes' sizes over all lights is at
//!    least the number of (light, cluster) pairs any assignment of this grid accepts, with or
//!    without a cap.
//! 2. **Tile entries**: the first level of the GPU build tests each light against each tile's
//!    whole depth column with the radius inflated by [`TILE_PREFILTER_INFLATION`]; the same
//!    candidate search on the one-slice grid of those columns, with that radius, bounds it.
//! 3. **Longest tile list**: each light's tile-level box adds one to every tile it covers (a
//!    two-dimensional difference array, summed once), so the largest count is at least the
//!    longest per-tile list the build loops over.
//! 4. **Coarse entries**: level 0 of the GPU build tests each light against coarse tiles of
//!    `span × span` tiles ([`coarse_tile_accepts`]), which requires the sphere to reach the box
//!    hull of their columns' AABBs (radius inflated as for the tile level). The hull is the
//!    union of those boxes (they form a full product of overlapping x and y ranges over one z
//!    range), and the test's per-axis distances to it are those to one of the columns, bit for
//!    bit, so a coarse tile accepts a light only if one of its columns' AABBs does: the light's
//!    AABB candidate tiles, counted per coarse tile they meet, bound the coarse lists.
//!    Where the build marks level 0 from the lights' side (`coarse_from_lights`), a light is
//!    kept only in the coarse tiles of its rectangle ([`super::RectGrid::light_tile_rect`]): the coarse
//!    tiles that [`super::RectGrid::light_tile_rect_bound`]'s wider rectangle meets bound those lists
//!    instead, much more tightly (the hull is no filter for deep columns).
//! 5. **Longest coarse list**: the coarse tiles of step 4 are counted per coarse tile with a
//!    difference array as in step 3; level 1 gives each tile as many chunks of candidates as
//!    that count needs (`GpuClusterParams::tile_chunks` in `manylight_render`).
//! 6. A light whose bound rectangle ([`super::RectGrid::light_tile_rect_bound`]) is empty is
//!    left out of steps 1–3: the rectangle holds every tile whose column accepts the light, so
//!    no tile list, and no cluster list (made from the tile lists), holds it. Most lights of a
//!    scene that surrounds the camera are such lights, and the rectangle costs a few
//!    operations.
//! 7. The cost is one candidate search per light and level (two binary searches over the
//!    slices and a few divisions), no per-cluster work: linear in the light count, and spread
//!    over all cores in parts of lights whose sums and difference arrays add up
//!    ([`ListBounder`]).

use glam::{UVec2, Vec3, Vec4};

use super::candidates::ClusterTables;
use super::cull::{ViewSphere, inflated_radius, sphere_intersects_aabb, sphere_intersects_planes};
use super::{ClusterGrid, CullTest};

/// Extra radius inflation of the GPU build's tile level (`TILE_PREFILTER_INFLATION` in
/// `shaders/cluster_build.wgsl`, written into the shader from this constant).
pub const TILE_PREFILTER_INFLATION: f32 = 1.001;

/// Upper bounds of one frame's list sizes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListBounds {
    /// At least the (light, cluster) pairs the cluster level writes.
    pub cluster_pairs: u64,
    /// At least the (light, tile) entries the tile level writes.
    pub tile_entries: u64,
    /// At least the longest per-tile list (the loop length of the build's cluster level).
    pub max_tile_lights: u32,
    /// At least the (light, coarse tile) entries level 0 writes (0 without a coarse level).
    pub coarse_entries: u64,
    /// At least the longest coarse-tile list (the candidates level 1 loops over for each of
    /// its tiles; 0 without a coarse level).
    pub max_coarse_lights: u32,
}

/// How many rectangles cover each cell of a `w × h` grid, the longest count being what is
/// wanted: a two-dimensional difference array, one row and column wider than the grid, summed
/// once. Kept between frames (`reset` reuses its storage), and the arrays of several parts of
/// the lights add up to the array of all of them.
#[derive(Default)]
struct Coverage {
    w: usize,
    h: usize,
    starts: Vec<i64>,
}

impl Coverage {
    /// Empties the array for a grid of `dims` cells.
    fn reset(&mut self, dims: UVec2) {
        (self.w, self.h) = (dims.x as usize + 1, dims.y as usize + 1);
        self.starts.clear();
        self.starts.resize(self.w * self.h, 0);
    }

    /// Adds the cells `[x0, x1] × [y0, y1]`.
    fn add(&mut self, [x0, x1]: [u32; 2], [y0, y1]: [u32; 2]) {
        let w = self.w;
        let (x0, x1) = (x0 as usize, x1 as usize + 1);
        let (y0, y1) = (y0 as usize, y1 as usize + 1);
        self.starts[y0 * w + x0] += 1;
        self.starts[y0 * w + x1] -= 1;
        self.starts[y1 * w + x0] -= 1;
        self.starts[y1 * w + x1] += 1;
    }

    /// Adds the rectangles of `other` (an array of the same grid).
    fn merge(&mut self, other: &Coverage) {
        for (a, b) in self.starts.iter_mut().zip(&other.starts) {
            *a += b;
        }
    }

    /// The largest count of rectangles over one cell (the array holds the counts after).
    fn longest(&mut self) -> u32 {
        let (w, h) = (self.w, self.h);
        // Prefix sums over rows, then columns.
        for y in 0..h {
            for x in 1..w {
                self.starts[y * w + x] += self.starts[y * w + x - 1];
            }
        }
        for y in 1..h {
            for x in 0..w {
                self.starts[y * w + x] += self.starts[(y - 1) * w + x];
            }
        }
        let cells = (0..h.saturating_sub(1)).flat_map(|y| (0..w - 1).map(move |x| y * w + x));
        cells.map(|i| self.starts[i]).max().unwrap_or(0).clamp(0, i64::from(u32::MAX)) as u32
    }
}

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

/// Bounds of the lists that `lights` give in `grid` under `test` (module docs), with a coarse
/// level of `coarse` tiles per edge when [`coarse_span`] gives one, marked from the lights' side
/// when `coarse_from_lights` (each light in the coarse tiles of its rectangle).
///
/// `listed` is cleared and given, in ascending order, the index of every light whose rectangle
/// bound ([`super::RectGrid::light_tile_rect_bound`]) is not empty: the only lights a tile or
/// cluster can list, and the only ones level 0 from the lights' side needs to mark (the bound
/// holds the GPU's rectangle).
///
/// A [`ListBounder`] kept between frames does the same without allocating once its parts have
/// grown, on all cores.
pub fn list_bounds(
    grid: &ClusterGrid,
    lights: &[ViewSphere],
    test: CullTest,
    coarse: Option<u32>,
    coarse_from_lights: bool,
    listed: &mut Vec<u32>,
) -> ListBounds {
    ListBounder::default().bound(grid, lights, test, coarse, coarse_from_lights, listed)
}

/// Lights per part of [`ListBounder::bound`]: each part is bounded on its own, on any core, and
/// the parts' sums and coverage arrays add up (a part costs its coverage arrays' size to merge,
/// a few thousand cells at 1280×720).
pub const BOUND_PART_LIGHTS: usize = 4096;

/// [`list_bounds`] over parts of [`BOUND_PART_LIGHTS`] lights on all cores (rayon's pool), the
/// parts' storage kept from frame to frame. The result is the same, bit for bit: sums and
/// difference arrays add in any order, the longest lists are taken from the merged arrays, and
/// the listed lights are joined in the parts' order.
#[derive(Default)]
pub struct ListBounder {
    parts: Vec<BoundPart>,
}

/// One part's share of a frame's bounds.
#[derive(Default)]
struct BoundPart {
    sums: ListBounds,
    tile_cover: Coverage,
    coarse_cover: Coverage,
    listed: Vec<u32>,
}

/// What every part reads.
struct BoundInputs<'a> {
    clusters: ClusterTables,
    tiles: ClusterTables,
    rects: super::RectGrid,
    test: CullTest,
    coarse: Option<u32>,
    coarse_from_lights: bool,
    lights: &'a [ViewSphere],
}

impl ListBounder {
    /// [`list_bounds`] of `lights`.
    pub fn bound(
        &mut self,
        grid: &ClusterGrid,
        lights: &[ViewSphere],
        test: CullTest,
        coarse: Option<u32>,
        coarse_from_lights: bool,
        listed: &mut Vec<u32>,
    ) -> ListBounds {
        use rayon::prelude::*;
        let columns = ClusterGrid { dims: glam::UVec3::new(grid.dims.x, grid.dims.y, 1), ..*grid };
        let inputs = BoundInputs {
            clusters: ClusterTables::new(grid),
            tiles: ClusterTables::new(&columns),
            rects: super::RectGrid::of(grid),
            test,
            coarse,
            coarse_from_lights,
            lights,
        };
        let parts = lights.len().div_ceil(BOUND_PART_LIGHTS).max(1);
        if self.parts.len() < parts {
            self.parts.resize_with(parts, BoundPart::default);
        }
        let tile_dims = grid.dims.truncate();
        let coarse_dims = coarse.map_or(UVec2::ZERO, |span| super::coarse_dims(tile_dims, span));
        let fill = |(p, part): (usize, &mut BoundPart)| {
            part.tile_cover.reset(tile_dims);
            part.coarse_cover.reset(coarse_dims);
            let first = p * BOUND_PART_LIGHTS;
            let last = (first + BOUND_PART_LIGHTS).min(lights.len());
            part.fill(&inputs, first..last);
        };
        if parts == 1 {
            self.parts.iter_mut().take(1).enumerate().for_each(fill);
        } else {
            self.parts[..parts].par_iter_mut().enumerate().for_each(fill);
        }
        let (head, rest) = self.parts[..parts].split_at_mut(1);
        let all = &mut head[0];
        listed.clear();
        listed.extend_from_slice(&all.listed);
        for part in rest.iter() {
            all.sums.cluster_pairs += part.sums.cluster_pairs;
            all.sums.tile_entries += part.sums.tile_entries;
            all.sums.coarse_entries += part.sums.coarse_entries;
            all.tile_cover.merge(&part.tile_cover);
            all.coarse_cover.merge(&part.coarse_cover);
            listed.extend_from_slice(&part.listed);
        }
        ListBounds {
            max_tile_lights: all.tile_cover.longest(),
            max_coarse_lights: if coarse.is_some() { all.coarse_cover.longest() } else { 0 },
            ..all.sums
        }
    }
}

impl BoundPart {
    /// The bounds of the lights `range` of `inputs.lights` (their sums, coverage and listed
    /// lights; the longest lists are left to the merged arrays).
    fn fill(&mut self, inputs: &BoundInputs<'_>, range: std::ops::Range<usize>) {
        let BoundInputs { clusters, tiles, rects, test, coarse, coarse_from_lights, lights } = inputs;
        let (test, coarse_from_lights) = (*test, *coarse_from_lights);
        self.sums = ListBounds::default();
        self.listed.clear();
        for (index, light) in (range.start as u32..).zip(&lights[range]) {
            // A light no tile's column accepts is in no tile or cluster list: most of a scene's
            // lights when they surround the camera, and the rectangle costs a few operations.
            let rect = rects.light_tile_rect_bound(light.center.extend(light.radius), test);
            let inflated = ViewSphere { radius: light.radius * TILE_PREFILTER_INFLATION, ..*light };
            let tile_box = rect.and_then(|_| tiles.candidates(&inflated, test));
            if let Some(span) = *coarse {
                // The light's tiles (inclusive x and y ranges) whose coarse tiles can list it:
                // those of its rectangle from the lights' side, else those of its AABB
                // candidates (the hull test can take a light no column accepts).
                let reach = if coarse_from_lights {
                    rect.map(|[x0, y0, x1, y1]| ([x0, x1], [y0, y1]))
                } else if test == CullTest::Aabb && rect.is_some() {
                    tile_box.map(|c| (c.x, c.y))
                } else {
                    tiles.candidates(&inflated, CullTest::Aabb).map(|c| (c.x, c.y))
                };
                if let Some((x, y)) = reach {
                    let (x, y) = ([x[0] / span, x[1] / span], [y[0] / span, y[1] / span]);
                    self.sums.coarse_entries += u64::from(x[1] - x[0] + 1) * u64::from(y[1] - y[0] + 1);
                    self.coarse_cover.add(x, y);
                }
            }
            if rect.is_none() {
                continue;
            }
            self.listed.push(index);
            self.sums.cluster_pairs += clusters.candidates(light, test).map_or(0, |c| c.size());
            if let Some(c) = tile_box {
                self.sums.tile_entries += c.size();
                self.tile_cover.add(c.x, c.y);
            }
        }
    }
}

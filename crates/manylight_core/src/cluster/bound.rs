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
//! 4. The cost is one candidate search per light and level (two binary searches over the
//!    slices and a few divisions), no per-cluster work: linear in the light count.

use super::candidates::ClusterTables;
use super::cull::ViewSphere;
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
}

/// Bounds of the lists that `lights` give in `grid` under `test` (module docs).
pub fn list_bounds(grid: &ClusterGrid, lights: &[ViewSphere], test: CullTest) -> ListBounds {
    let clusters = ClusterTables::new(grid);
    let columns = ClusterGrid { dims: glam::UVec3::new(grid.dims.x, grid.dims.y, 1), ..*grid };
    let tiles = ClusterTables::new(&columns);
    let mut bounds = ListBounds::default();
    // Difference array of the tile boxes, one row and column wider than the grid.
    let (w, h) = (grid.dims.x as usize + 1, grid.dims.y as usize + 1);
    let mut starts = vec![0i64; w * h];
    for light in lights {
        bounds.cluster_pairs += clusters.candidates(light, test).map_or(0, |c| c.size());
        let inflated = ViewSphere { radius: light.radius * TILE_PREFILTER_INFLATION, ..*light };
        if let Some(c) = tiles.candidates(&inflated, test) {
            bounds.tile_entries += c.size();
            let (x0, x1) = (c.x[0] as usize, c.x[1] as usize + 1);
            let (y0, y1) = (c.y[0] as usize, c.y[1] as usize + 1);
            starts[y0 * w + x0] += 1;
            starts[y0 * w + x1] -= 1;
            starts[y1 * w + x0] -= 1;
            starts[y1 * w + x1] += 1;
        }
    }
    // Prefix sums over rows, then columns: the count of boxes covering each tile.
    for y in 0..h {
        for x in 1..w {
            starts[y * w + x] += starts[y * w + x - 1];
        }
    }
    for y in 1..h {
        for x in 0..w {
            starts[y * w + x] += starts[(y - 1) * w + x];
        }
    }
    let longest = (0..h - 1).flat_map(|y| (0..w - 1).map(move |x| y * w + x)).map(|i| starts[i]).max();
    bounds.max_tile_lights = longest.unwrap_or(0).clamp(0, i64::from(u32::MAX)) as u32;
    bounds
}

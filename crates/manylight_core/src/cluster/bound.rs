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
//! 3. The cost is one candidate search per light and level (two binary searches over the
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
}

/// Bounds of the lists that `lights` give in `grid` under `test` (module docs).
pub fn list_bounds(grid: &ClusterGrid, lights: &[ViewSphere], test: CullTest) -> ListBounds {
    let clusters = ClusterTables::new(grid);
    let columns = ClusterGrid { dims: glam::UVec3::new(grid.dims.x, grid.dims.y, 1), ..*grid };
    let tiles = ClusterTables::new(&columns);
    let mut bounds = ListBounds::default();
    for light in lights {
        bounds.cluster_pairs += clusters.candidates(light, test).map_or(0, |c| c.size());
        let inflated = ViewSphere { radius: light.radius * TILE_PREFILTER_INFLATION, ..*light };
        bounds.tile_entries += tiles.candidates(&inflated, test).map_or(0, |c| c.size());
    }
    bounds
}

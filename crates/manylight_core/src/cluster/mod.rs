//! Clustered light assignment: the cluster grid (screen tiles × depth slices), conservative
//! sphere–cluster culling tests, and the CPU reference assignment the GPU is checked against.
//!
//! The pieces, in the order a frame uses them:
//!
//! 1. **Grid** ([`ClusterGrid::new`], `grid.rs`): `X × Y` screen tiles of about `tile_px` pixels
//!    times `Z` depth slices, linear or exponential in view distance (Olsson et al. 2012).
//!    Each cluster is a piece of the view frustum; its AABB and its six planes are given in
//!    view space, widened by a small margin ([`ClusterGrid::cluster_margin`]) so float rounding
//!    on either side (CPU or GPU) never loses a light.
//! 2. **Lights to view space** ([`view_spheres`], `cull.rs`): world positions → view space,
//!    radii kept.
//! 3. **Culling test** ([`CullTest`], `cull.rs`): sphere vs cluster AABB (conservative) or
//!    sphere vs the cluster's six planes (tighter, still conservative).
//! 4. **Assignment** ([`assign_lights`], `assign.rs`): count, exclusive prefix sum, fill — the
//!    same three phases as the GPU compute passes — into per-cluster `(offset, count)` ranges
//!    over one light-index list, each list in ascending light order. A per-cluster cap is
//!    optional; what it drops is counted, never silent.
//! 5. **Coarse tiles** ([`coarse_tiles`], `coarse.rs`): the GPU build's level 0, blocks of
//!    tiles whose test ([`coarse_tile_accepts`]) keeps every light any of their columns keeps.
//! 6. **Light rectangles** ([`RectGrid::light_tile_rect`], `rect.rs`): each light's screen rectangle of
//!    tiles, a superset of the tiles and coarse tiles that accept it, so the GPU build's tile
//!    levels run the sphere test only for lights near the tile.
//! 7. **Shading lookup** ([`ClusterGrid::cluster_of`]): pixel + view distance → cluster index.
//! 8. **Measurement** ([`false_positive_counts`], `exact.rs`): how many accepted pairs an exact
//!    sphere–frustum-piece distance rejects.

mod assign;
mod candidates;
mod coarse;
mod cull;
mod exact;
mod grid;
mod rect;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_edge;

pub use assign::{ClusterAssignment, ClusterStats, assign_lights};
pub use coarse::{
    CoarseTile, TILE_PREFILTER_INFLATION, coarse_dims, coarse_span, coarse_tile_accepts, coarse_tiles,
};
pub use cull::{
    RADIUS_INFLATION, ViewSphere, farthest_reach, inflated_radius, sphere_intersects_aabb,
    sphere_intersects_planes, sphere_passes, to_view_space, view_spheres,
};
pub use exact::{false_positive_counts, sphere_touches_cluster_exact};
pub use grid::{CLUSTER_MARGIN, ClusterGrid, GridConfig, MAX_CLUSTERS, MAX_GRID_DIM};
pub use rect::{RECT_MAGNITUDE, RECT_PAD, RECT_SLACK, RectGrid, rect_frustum};

/// How depth slice boundaries are spread between the near and far planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ZSlicing {
    /// Equal thickness in view distance.
    Linear,
    /// Equal ratio `far/near` per slice (`z_k = near · (far/near)^(k/Z)`), so slices keep a
    /// roughly constant aspect in screen space.
    #[default]
    Exponential,
}

impl ZSlicing {
    /// All variants, in `gpu_id` order.
    pub const ALL: [ZSlicing; 2] = [ZSlicing::Linear, ZSlicing::Exponential];

    /// Lower-case name used in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ZSlicing::Linear => "linear",
            ZSlicing::Exponential => "exponential",
        }
    }

    /// Parses a name written by [`ZSlicing::name`] (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The value WGSL receives for this slicing: `Linear` 0, `Exponential` 1.
    pub fn gpu_id(self) -> u32 {
        match self {
            ZSlicing::Linear => 0,
            ZSlicing::Exponential => 1,
        }
    }
}

/// Which sphere–cluster test the assignment uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum CullTest {
    /// Sphere vs the cluster's view-space AABB ([`sphere_intersects_aabb`]).
    Aabb,
    /// Sphere vs the cluster's six planes ([`sphere_intersects_planes`]).
    Planes,
    /// Both tests must accept: the tightest, at the cost of both tests (the default; measured
    /// false-positive rates are in `docs/benchmarks.md`).
    #[default]
    Both,
}

impl CullTest {
    /// All variants.
    pub const ALL: [CullTest; 3] = [CullTest::Aabb, CullTest::Planes, CullTest::Both];

    /// Lower-case name used in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CullTest::Aabb => "aabb",
            CullTest::Planes => "planes",
            CullTest::Both => "both",
        }
    }

    /// Parses a name written by [`CullTest::name`] (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name().eq_ignore_ascii_case(name.trim()))
    }
}

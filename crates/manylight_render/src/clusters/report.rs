//! What a view's cluster build reports, and what tests and measurements read back of it
//! (counters, the lights' view-space spheres, the lists): each read waits for the GPU.

use super::buffers::COUNTER_BYTES;
use super::{ClusterResources, RefinedLists};
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::GpuClusterCounters;
use crate::readback::read_buffer;
use manylight_core::cluster::{ClusterAssignment, ViewSphere};
use serde::Serialize;

/// What the cluster build reported for a frame (in `FrameReport::clusters`). One figure a
/// field, flat, over 15 of them: it is the `clusters` object of `manylight render
/// --stats-json`, read by name by scripts, and every field is one the build counts.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ClusterReport {
    /// Grid size x, y, z.
    pub dims: [u32; 3],
    /// Number of clusters.
    pub clusters: u32,
    /// Lights of the frame (the light buffer's).
    pub lights: u32,
    /// Clusters with at least one light.
    pub non_empty: u32,
    /// Entries in the light-index list.
    pub total_entries: u64,
    /// Largest per-cluster count (before any cap).
    pub max_per_cluster: u32,
    /// Mean entries per cluster.
    pub mean_per_cluster: f64,
    /// Mean entries per non-empty cluster.
    pub mean_per_non_empty: f64,
    /// Light–cluster pairs dropped by the user's cap (0 without a cap).
    pub dropped_pairs: u64,
    /// Clusters that hit the cap.
    pub clusters_overflowed: u32,
    /// Capacity of the index list (entries).
    pub index_capacity: u64,
    /// Entries of the per-tile lists the build filters clusters from.
    pub tile_entries: u64,
    /// Longest per-tile list.
    pub max_per_tile: u32,
    /// Entries of the per-coarse-tile lists the tile lists are filtered from (0 without a
    /// coarse level).
    pub coarse_entries: u64,
    /// Tiles per coarse-tile edge (0: no coarse level).
    pub coarse_span: u32,
    /// Clusters whose list did not fit this frame's lists, which shaded from every light
    /// instead (exact, slower; `gpu_types::LIST_EVERY_LIGHT`): 0 once the lists have grown to
    /// what the frames need.
    pub fallback_clusters: u32,
    /// Capacity of the per-tile lists (entries).
    pub tile_index_capacity: u64,
    /// Capacity of the per-coarse-tile lists (entries).
    pub coarse_index_capacity: u64,
    /// The build ran before the frame, only to count, and the view waited for its counters
    /// (the view's first frame, or the light count more than doubled since the counts the
    /// lists were sized from): the one blocking wait of a view's lists.
    pub counted_first: bool,
    /// Bytes of GPU buffers the cluster build and clustered shading hold (grid bounds, light
    /// spheres, per-tile and per-cluster ranges and index lists, parameters, counters).
    pub buffer_bytes: u64,
    /// Culling test used.
    pub cull_test: String,
    /// Z slicing used.
    pub z_slicing: String,
    /// Levels 0 and 1 of the build ran from the lights' side (each light marks the coarse
    /// tiles of its rectangle, each coarse-list entry the tiles of its coarse tile), not each
    /// (coarse) tile over its candidates; the lists are the same either way.
    pub from_lights: bool,
    /// Invocations of level 0 per coarse tile and of level 1 per tile: chunks of
    /// `TILE_LIGHT_CHUNK` lights, as many as the frame's lights make.
    pub chunks: [u32; 2],
}

impl ClusterReport {
    /// Fills the figures that come from the GPU build's counters.
    pub fn apply_counters(&mut self, c: &GpuClusterCounters) {
        let total = u64::from(c.total_entries);
        self.non_empty = c.non_empty;
        self.total_entries = total;
        self.max_per_cluster = c.max_count;
        self.max_per_tile = c.max_tile_lights;
        self.mean_per_cluster = total as f64 / f64::from(self.clusters.max(1));
        self.mean_per_non_empty = total as f64 / f64::from(c.non_empty.max(1));
        self.dropped_pairs = u64::from(c.dropped_pairs);
        self.clusters_overflowed = c.clusters_overflowed;
        self.tile_entries = u64::from(c.tile_entries);
        self.coarse_entries = u64::from(c.coarse_entries);
        self.fallback_clusters = c.fallback_clusters;
    }
}

impl ClusterResources {
    /// Reads the counters of the last submitted view (waits for the GPU).
    pub fn read_counters(&self, gpu: &GpuContext) -> Result<GpuClusterCounters, RenderError> {
        let bytes = read_buffer(gpu, self.buffers.counters.buffer(), 0, COUNTER_BYTES)?;
        Ok(bytemuck::pod_read_unaligned(&bytes[..std::mem::size_of::<GpuClusterCounters>()]))
    }

    /// Refuses a frame whose pair totals saturated the build's u32 sums.
    pub fn check_saturation(counters: &GpuClusterCounters) -> Result<(), RenderError> {
        use crate::gpu_types::PAIR_COUNT_SATURATED;
        if counters.tile_entries == PAIR_COUNT_SATURATED {
            return Err(RenderError::TooManyPairs { what: "light–tile" });
        }
        if counters.coarse_entries == PAIR_COUNT_SATURATED {
            return Err(RenderError::TooManyPairs { what: "light–coarse-tile" });
        }
        if counters.total_entries == PAIR_COUNT_SATURATED {
            return Err(RenderError::TooManyPairs { what: "light–cluster" });
        }
        Ok(())
    }

    /// The report of a frame from its counters.
    pub fn report(&self, c: &GpuClusterCounters) -> ClusterReport {
        let mut report = ClusterReport {
            dims: [self.grid.dims.x, self.grid.dims.y, self.grid.dims.z],
            clusters: self.params.dims[3],
            lights: self.params.light_count,
            index_capacity: u64::from(self.params.index_capacity),
            tile_index_capacity: u64::from(self.params.tile_index_capacity),
            coarse_index_capacity: u64::from(self.params.coarse_index_capacity),
            counted_first: self.counted_first,
            coarse_span: self.coarse.unwrap_or(0),
            buffer_bytes: self.buffers.bytes(),
            cull_test: self.cull.name().to_string(),
            z_slicing: self.grid.slicing.name().to_string(),
            from_lights: self.from_lights,
            chunks: [self.params.light_chunks, self.params.tile_chunks],
            ..Default::default()
        };
        report.apply_counters(c);
        report
    }

    /// Reads the lights' view-space spheres the last submitted view's build used back (waits for
    /// the GPU): the CPU reference (`manylight_core::cluster::assign_lights`) takes them to
    /// compare lists light for light.
    pub fn read_view_spheres(&self, gpu: &GpuContext) -> Result<Vec<ViewSphere>, RenderError> {
        let n = u64::from(self.params.light_count);
        if n == 0 {
            return Ok(Vec::new());
        }
        let spheres: Vec<[f32; 4]> =
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, self.buffers.spheres.buffer(), 0, n * 16)?);
        Ok(spheres
            .iter()
            .map(|s| ViewSphere { center: glam::Vec3::new(s[0], s[1], s[2]), radius: s[3] })
            .collect())
    }

    /// Reads the refined lists of the last submitted view back (waits for the GPU); `None` when
    /// the view did not refine its lists.
    pub fn read_refined(&self, gpu: &GpuContext) -> Result<Option<RefinedLists>, RenderError> {
        let Some(blocks) = self.refine_blocks else {
            return Ok(None);
        };
        let n = self.refined_blocks();
        let first = u64::from(self.params.refined_first) * 8;
        let mut ranges: Vec<[u32; 2]> =
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, self.buffers.ranges.buffer(), first, n * 8)?);
        let base = u64::from(self.params.index_capacity);
        let indices: Vec<u32> = bytemuck::pod_collect_to_vec(&read_buffer(
            gpu,
            self.buffers.indices.buffer(),
            base * 4,
            self.refined_entries() * 4,
        )?);
        for r in &mut ranges {
            if r[1] != crate::gpu_types::REFINED_FALLBACK {
                r[0] = r[0].saturating_sub(base as u32);
            }
        }
        Ok(Some(RefinedLists { blocks, lists: ClusterAssignment { ranges, indices, ..Default::default() } }))
    }

    /// Reads the GPU's assignment back into the CPU structure (tests compare it with
    /// `manylight_core::cluster::assign_lights`).
    pub fn read_assignment(&self, gpu: &GpuContext) -> Result<ClusterAssignment, RenderError> {
        let count = self.params.dims[3] as u64;
        let ranges_bytes = read_buffer(gpu, self.buffers.ranges.buffer(), 0, count * 8)?;
        let ranges: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&ranges_bytes);
        let counters = self.read_counters(gpu)?;
        // A frame whose lists fell short wrote only what fits.
        let total = u64::from(counters.total_entries.min(self.params.index_capacity));
        let indices: Vec<u32> = if total == 0 {
            Vec::new()
        } else {
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, self.buffers.indices.buffer(), 0, total * 4)?)
        };
        Ok(ClusterAssignment {
            ranges,
            indices,
            dropped_pairs: counters.dropped_pairs as u64,
            clusters_overflowed: counters.clusters_overflowed,
        })
    }
}

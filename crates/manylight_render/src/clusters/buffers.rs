//! The buffers of one view's cluster build and lists. They start small and grow with the grid
//! and the lights (`GrowableBuffer`, whose generation tells the bind groups to follow).

use crate::context::GpuContext;
use crate::gpu_types::{GpuClusterCounters, GpuClusterParams};
use crate::pool::GrowableBuffer;

/// Bytes of the build's counters (`GpuClusterCounters`), before level 0's bits.
pub(super) const COUNTER_BYTES: u64 = std::mem::size_of::<GpuClusterCounters>() as u64;

/// Initial entries of the cluster light-index list (it grows as frames need).
pub const INITIAL_INDEX_CAPACITY: u64 = 1 << 16;
/// Initial entries of the per-tile lists (they grow as frames need).
pub const INITIAL_TILE_INDEX_CAPACITY: u64 = 1 << 12;

/// One view's cluster buffers.
pub struct ClusterBuffers {
    /// The parameters (`GpuClusterParams`): a uniform of the build and the shading passes, a
    /// storage buffer of `cluster_depth` and `light_refine`.
    pub params: wgpu::Buffer,
    /// Per-cluster `(offset, count)`, then (with depth bounds) per-cluster depth ranges
    /// (`shaders/cluster_depth.wgsl`), then (with refined lists) per-block ranges
    /// (`shaders/light_refine.wgsl`).
    pub ranges: GrowableBuffer,
    /// The light-index list: the cluster lists (`GpuClusterParams::index_capacity` entries),
    /// then (with refined lists) `REFINED_LIST_SLOTS` entries per block.
    pub indices: GrowableBuffer,
    /// Each cluster's bounds (`GpuClusterBounds`).
    pub bounds: GrowableBuffer,
    /// The lights' view-space spheres (centre, radius), which the build's first dispatch writes
    /// (`shaders/light_spheres.wgsl`; copied out for the CPU reference in tests).
    pub spheres: GrowableBuffer,
    /// Bounds of the tile columns, then of the coarse tiles.
    pub tile_bounds: GrowableBuffer,
    /// (tile, chunk) ranges, then (coarse tile, chunk) ranges.
    pub tile_ranges: GrowableBuffer,
    /// The per-tile lists (`GpuClusterParams::tile_index_capacity` entries), then the
    /// per-coarse-tile lists.
    pub tile_indices: GrowableBuffer,
    /// The counters (`GpuClusterCounters`), then the bits of levels 0 and 1 when the build sets
    /// them from the lights' side.
    pub counters: GrowableBuffer,
}

impl ClusterBuffers {
    /// Small buffers; they grow as frames need.
    pub fn new(gpu: &GpuContext) -> ClusterBuffers {
        let storage = wgpu::BufferUsages::STORAGE;
        let copy = wgpu::BufferUsages::COPY_SRC;
        // With depth bounds the `cluster_depth` pass clears the depth ranges after the cluster
        // ranges each frame.
        let ranges_usage = storage | copy | wgpu::BufferUsages::COPY_DST;
        ClusterBuffers {
            params: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("cluster_params"),
                size: std::mem::size_of::<GpuClusterParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | storage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            ranges: GrowableBuffer::new(gpu, "cluster_ranges", ranges_usage, 8 * 8192),
            indices: GrowableBuffer::new(gpu, "light_index_list", storage | copy, 4 * INITIAL_INDEX_CAPACITY),
            bounds: GrowableBuffer::new(gpu, "cluster_bounds", storage, 128 * 1024),
            spheres: GrowableBuffer::new(gpu, "light_view_spheres", storage | copy, 16 * 1024),
            tile_bounds: GrowableBuffer::new(gpu, "tile_bounds", storage, 128 * 256),
            tile_ranges: GrowableBuffer::new(gpu, "tile_ranges", storage, 8 * 256),
            tile_indices: GrowableBuffer::new(
                gpu,
                "tile_light_index_list",
                storage,
                4 * INITIAL_TILE_INDEX_CAPACITY,
            ),
            counters: GrowableBuffer::new(gpu, "cluster_counters", storage | copy, COUNTER_BYTES + 4),
        }
    }

    /// The generations of the growable buffers: they change when one is re-created.
    pub fn generations(&self) -> [u64; 8] {
        [
            self.bounds.generation(),
            self.spheres.generation(),
            self.ranges.generation(),
            self.indices.generation(),
            self.tile_bounds.generation(),
            self.tile_ranges.generation(),
            self.tile_indices.generation(),
            self.counters.generation(),
        ]
    }

    /// Bytes of every buffer (capacities, not what this frame filled).
    pub fn bytes(&self) -> u64 {
        let growable = [
            &self.ranges,
            &self.indices,
            &self.bounds,
            &self.spheres,
            &self.tile_bounds,
            &self.tile_ranges,
            &self.tile_indices,
            &self.counters,
        ];
        self.params.size() + growable.iter().map(|b| b.capacity()).sum::<u64>()
    }
}

//! Cluster data on the GPU: the grid's per-cluster bounds, the lights' view-space spheres,
//! the per-cluster `(offset, count)` ranges and the global light-index list, plus the
//! counters the build writes and the renderer reads back each frame.
//!
//! The bounds come from `manylight_core::cluster` (the same numbers the CPU reference uses),
//! so GPU and CPU assignments can be compared light for light.

use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{
    CLUSTER_NO_CAP, COARSE_SCATTER_TILES, CULL_AABB, CULL_BOTH, CULL_PLANES, GpuClusterBounds,
    GpuClusterCounters, GpuClusterParams, LAVAPIPE_LOOP_LIMIT, REFINE_EDGE, REFINED_LIST_SLOTS,
    TILE_LIGHT_CHUNK,
};
use crate::lights::LightReach;
use crate::snapshot::RenderView;
use glam::Mat4;
use manylight_core::Projection;
use manylight_core::cluster::{
    ClusterAssignment, ClusterGrid, CullTest, coarse_dims, coarse_span, coarse_tiles,
};

mod bindings;
mod buffers;
mod report;

pub use bindings::ClusterBindings;
use buffers::COUNTER_BYTES;
pub use buffers::{ClusterBuffers, INITIAL_INDEX_CAPACITY, INITIAL_TILE_INDEX_CAPACITY};
pub use report::ClusterReport;

/// How a view's lists are built beyond the grid and culling test (from its plan:
/// [`PlanInputs::list_options`](crate::plan::PlanInputs::list_options)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListOptions {
    /// The build cuts clusters to their pixels' depth range
    /// (`PlanInputs::bounds_clusters_by_depth`).
    pub depth_bounds: bool,
    /// The `light_refine` pass refines the lists per pixel block
    /// (`PlanInputs::refines_lists`).
    pub refined_lists: bool,
}

/// The refined lists of a frame, read back (`ClusterResources::read_refined`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RefinedLists {
    /// Blocks across and down.
    pub blocks: glam::UVec2,
    /// Per block of `REFINE_EDGE` × `REFINE_EDGE` pixels (row-major) its list, or a count of
    /// `REFINED_FALLBACK` when its pixels shade from their cluster lists.
    pub lists: ClusterAssignment,
}

impl RefinedLists {
    /// The list each pixel of the frame shades from: its block's, or its cluster's in
    /// `clusters` where the block fell back (`efficiency::block_lists_per_pixel`, over
    /// `efficiency::pixel_grid`). `grid`, `projection` and `depth` are the frame's.
    pub fn per_pixel(
        &self,
        grid: &ClusterGrid,
        projection: &Projection,
        clusters: &ClusterAssignment,
        depth: &[f32],
    ) -> ClusterAssignment {
        use crate::gpu_types::REFINED_FALLBACK;
        manylight_core::efficiency::block_lists_per_pixel(
            grid,
            projection,
            clusters,
            depth,
            REFINE_EDGE,
            &self.lists,
            REFINED_FALLBACK,
        )
    }
}

/// GPU buffers and bind groups of the cluster build and of clustered shading.
pub struct ClusterResources {
    /// The grid of the current frame.
    pub grid: ClusterGrid,
    /// The parameters uploaded this frame.
    pub params: GpuClusterParams,
    /// The buffers of the build and of the lists.
    pub buffers: ClusterBuffers,
    /// The layouts and bind groups over [`Self::buffers`].
    pub bindings: ClusterBindings,
    /// What the lists needed in the latest frame whose counters came back.
    needs: Option<ListNeeds>,
    /// The build counted before this frame (`ClusterReport::counted_first`).
    counted_first: bool,
    /// Levels 0 and 1 of the build run from the lights' side this frame (`grid_allows_bits`,
    /// `bits_fit`, `size_bits`).
    from_lights: bool,
    /// The grid and coarse span the uploaded bounds are for.
    bounds_of: Option<(ClusterGrid, Option<u32>)>,
    /// Tiles per coarse-tile edge this frame, `None` without a coarse level.
    coarse: Option<u32>,
    cull: CullTest,
    /// The build cuts clusters to their pixels' depth range this frame.
    depth_bounds: bool,
    /// Blocks across and down of this frame's refined lists, `None` without them.
    refine_blocks: Option<glam::UVec2>,
}

/// Entries a frame's lists needed, from its build's counters (read back without waiting):
/// what the following frames' lists are sized to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListNeeds {
    /// Entries of the cluster lists.
    pub cluster_entries: u64,
    /// Entries of the per-tile lists.
    pub tile_entries: u64,
    /// Entries of the per-coarse-tile lists.
    pub coarse_entries: u64,
    /// The frame's light count.
    pub lights: u32,
    /// The frame's grid, coarse span and culling test: counts made with another grid or test
    /// say little about this frame's.
    pub layout: Option<ListLayout>,
}

/// What shapes a view's lists besides its lights: grid size, coarse span, culling test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ListLayout {
    /// Clusters across, down and deep.
    pub dims: [u32; 3],
    /// Tiles per coarse-tile edge (0: no coarse level).
    pub coarse_span: u32,
    /// The culling test.
    pub cull: CullTest,
}

impl ListNeeds {
    /// What a frame's report says its lists needed.
    pub fn of(report: &ClusterReport) -> ListNeeds {
        let cull = [CullTest::Aabb, CullTest::Planes, CullTest::Both]
            .into_iter()
            .find(|c| c.name() == report.cull_test);
        let layout = cull.map(|cull| ListLayout { dims: report.dims, coarse_span: report.coarse_span, cull });
        let entries = [report.total_entries, report.tile_entries, report.coarse_entries];
        ListNeeds::from_counts(entries, report.lights, layout)
    }

    /// The needs of a frame of `lights` lights and `layout` whose cluster, tile and coarse
    /// lists held `[cluster, tile, coarse]` entries.
    pub fn from_counts(
        [cluster_entries, tile_entries, coarse_entries]: [u64; 3],
        lights: u32,
        layout: Option<ListLayout>,
    ) -> ListNeeds {
        ListNeeds { cluster_entries, tile_entries, coarse_entries, lights, layout }
    }
}

/// Most entries a list level is given before any counts exist where the CPU may not wait for
/// them ([`ClusterResources::size_for_every_light`]): 64 MiB of indices. A frame whose lists
/// need more shades the clusters that do not fit from every light, once.
const MAX_UNCOUNTED_ENTRIES: u64 = 1 << 24;

/// Chunks of [`TILE_LIGHT_CHUNK`] lights that `lights` lights take, at least 1.
fn light_chunks_of(lights: usize) -> u32 {
    u32::try_from(lights).unwrap_or(u32::MAX).div_ceil(TILE_LIGHT_CHUNK).max(1)
}

impl ClusterResources {
    /// Creates the buffers (small; they grow with the grid and the lights).
    pub fn new(gpu: &GpuContext) -> ClusterResources {
        let buffers = ClusterBuffers::new(gpu);
        let bindings = ClusterBindings::new(gpu, &buffers);
        ClusterResources {
            grid: ClusterGrid::new(glam::UVec2::ONE, &Default::default(), &Default::default()),
            params: GpuClusterParams::default(),
            buffers,
            bindings,
            needs: None,
            counted_first: false,
            from_lights: false,
            bounds_of: None,
            coarse: None,
            cull: CullTest::default(),
            depth_bounds: false,
            refine_blocks: None,
        }
    }

    /// Uploads the grid bounds (when the grid changed) and the parameters, sizes the lists from
    /// the counters of the latest frame read back, and zeroes the counters: no light is visited
    /// (the build's first dispatch puts the `light_count` lights of the light buffer in view
    /// space). `reach` bounds what they reach, for a projection without a far plane;
    /// `options`: depth bounds and refined lists, from the view's plan.
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        view: &RenderView,
        view_from_world: &Mat4,
        (light_count, reach): (u32, &LightReach),
        options: ListOptions,
    ) -> Result<(), RenderError> {
        let settings = &view.settings.clusters;
        let depth_bounds = options.depth_bounds;
        self.depth_bounds = depth_bounds;
        self.counted_first = false;
        self.refine_blocks =
            options.refined_lists.then(|| manylight_core::efficiency::block_dims(view.size, REFINE_EDGE));
        let grid_config = settings.grid_for(view.settings.pipeline);
        let projection = Self::finite_projection(view, view_from_world, reach);
        self.grid = ClusterGrid::new(view.size, &projection, &grid_config);
        self.cull = settings.cull;
        self.coarse = coarse_span(settings.coarse_tiles, settings.cull);
        let count = self.grid.cluster_count();
        if self.bounds_of != Some((self.grid, self.coarse)) {
            self.upload_grid_bounds(gpu, view.size, &projection, &grid_config)?;
        }
        // The cluster ranges, then (with depth bounds) the depth ranges of the clusters, then
        // (with refined lists) the blocks' ranges.
        let cluster_ranges = count as u64 * if depth_bounds { 16 } else { 8 };
        self.buffers.ranges.reserve(gpu, cluster_ranges + self.refined_blocks() * 8)?;
        self.buffers.spheres.reserve(gpu, u64::from(light_count.max(1)) * 16)?;
        let chunks = self.size_lists(gpu, light_count)?;
        let cap = settings.cap.unwrap_or(CLUSTER_NO_CAP);
        self.write_params(gpu, view, view_from_world, light_count, cap, chunks)
    }

    /// Uploads the bounds of this frame's grid for a view of `size` pixels: its clusters, its
    /// tile columns and (with a coarse level) its coarse tiles.
    fn upload_grid_bounds(
        &mut self,
        gpu: &GpuContext,
        size: glam::UVec2,
        projection: &Projection,
        grid_config: &manylight_core::cluster::GridConfig,
    ) -> Result<(), RenderError> {
        let dims = self.grid.dims;
        let mut bounds = Vec::with_capacity(self.grid.cluster_count() as usize);
        for z in 0..dims.z {
            for y in 0..dims.y {
                for x in 0..dims.x {
                    let (min, max) = self.grid.cluster_aabb(x, y, z);
                    let planes = self.grid.cluster_planes(x, y, z);
                    bounds.push(GpuClusterBounds {
                        aabb_min: min.extend(0.0).to_array(),
                        aabb_max: max.extend(0.0).to_array(),
                        planes: planes.map(|p| p.to_array()),
                    });
                }
            }
        }
        self.buffers.bounds.write(gpu, bytemuck::cast_slice(&bounds))?;
        // Level 1 of the build: the same tiles with one slice from near to far.
        let tile_grid = ClusterGrid::new(
            size,
            projection,
            &manylight_core::cluster::GridConfig {
                dims: Some(glam::UVec3::new(dims.x, dims.y, 1)),
                ..*grid_config
            },
        );
        let mut tiles = Vec::with_capacity((dims.x * dims.y) as usize);
        for y in 0..dims.y {
            for x in 0..dims.x {
                let (min, max) = tile_grid.cluster_aabb(x, y, 0);
                tiles.push(GpuClusterBounds {
                    aabb_min: min.extend(0.0).to_array(),
                    aabb_max: max.extend(0.0).to_array(),
                    planes: tile_grid.cluster_planes(x, y, 0).map(|p| p.to_array()),
                });
            }
        }
        // Level 0: the coarse tiles after the tiles, the column margin in `aabb_min.w`.
        if let Some(span) = self.coarse {
            tiles.extend(coarse_tiles(&tile_grid, span).into_iter().map(|c| GpuClusterBounds {
                aabb_min: c.min.extend(c.margin).to_array(),
                aabb_max: c.max.extend(0.0).to_array(),
                planes: c.planes.map(|p| p.to_array()),
            }));
        }
        self.buffers.tile_bounds.write(gpu, bytemuck::cast_slice(&tiles))?;
        self.bounds_of = Some((self.grid, self.coarse));
        Ok(())
    }

    /// Sizes the lists and the tile ranges for a frame of `light_count` lights from what the
    /// latest frame read back needed (`needs`; the initial capacities before any), with a
    /// quarter of headroom; returns the light chunks of level 0 and of level 1. A list that
    /// still proves short makes its clusters shade from every light that frame.
    fn size_lists(&mut self, gpu: &GpuContext, light_count: u32) -> Result<[u32; 2], RenderError> {
        let chunks = light_chunks_of(light_count as usize);
        let needs = self.needs.unwrap_or_default();
        // Levels 0 and 1 from the lights' side where the grid allows and their bits fit.
        self.from_lights = self.grid_allows_bits() && self.bits_fit(chunks, needs.coarse_entries);
        // A quarter of headroom: lights that move a little do not grow the lists every frame
        // (growing creates a buffer and rebinds), and the buffers grow in powers of two.
        let bytes =
            |entries: u64, buffer: &crate::pool::GrowableBuffer| (entries.max(1) * 4).min(buffer.max_bytes());
        let with_headroom = |entries: u64, buffer: &crate::pool::GrowableBuffer| {
            if buffer.capacity() >= bytes(entries, buffer) {
                bytes(entries, buffer)
            } else {
                bytes(entries + entries / 4, buffer)
            }
        };
        // The refined lists' slots follow the cluster lists.
        let entries = needs.cluster_entries + self.refined_entries();
        // The tile and coarse-tile lists share a buffer; the spare room is split between them.
        let shared = needs.tile_entries + Self::coarse_room(needs.coarse_entries);
        for (need, buffer) in [(entries, &mut self.buffers.indices), (shared, &mut self.buffers.tile_indices)]
        {
            // Counts read back from a frame (not a counting run, which has no depth bounds)
            // let a list far larger than they need shrink.
            if self.needs.is_some() && !self.counted_first {
                buffer.shrink_to(gpu, bytes(need + need / 4, buffer));
            }
            buffer.reserve(gpu, with_headroom(need, buffer))?;
        }
        // Level 1 runs as many chunks per tile as the longest coarse list can take: all of them
        // (chunks past a tile's list return at once).
        let tiles = self.grid.dims.x as u64 * self.grid.dims.y as u64;
        let coarse_tiles = self.coarse_dims().map_or(0, |d| u64::from(d.x) * u64::from(d.y));
        self.buffers.tile_ranges.reserve(gpu, (tiles + coarse_tiles) * u64::from(chunks) * 8)?;
        Ok([chunks, chunks])
    }

    /// Blocks of this frame's refined lists (0 without them).
    fn refined_blocks(&self) -> u64 {
        self.refine_blocks.map_or(0, |b| u64::from(b.x) * u64::from(b.y))
    }

    /// Entries of the index list this frame's refined lists take, after the cluster lists.
    fn refined_entries(&self) -> u64 {
        self.refined_blocks() * u64::from(REFINED_LIST_SLOTS)
    }

    /// Entries of the index list the cluster lists can take (what the refined lists leave).
    fn cluster_index_capacity(&self) -> u32 {
        (self.buffers.indices.capacity() / 4).saturating_sub(self.refined_entries()).min(u64::from(u32::MAX))
            as u32
    }

    /// Coarse tiles across and down this frame, `None` without a coarse level.
    fn coarse_dims(&self) -> Option<glam::UVec2> {
        self.coarse.map(|span| coarse_dims(self.grid.dims.truncate(), span))
    }

    /// The entries of the tile-lists buffer for the per-tile lists (first) and the
    /// per-coarse-tile lists, from what the lists last needed (`self.needs`): the coarse lists
    /// get what they need and a quarter more
    /// (`coarse_room`; level 1 from the lights' side runs an invocation and keeps a bit per tile
    /// for each of their entries), the tile lists the rest (and the coarse lists what is left
    /// when the buffer could not grow to both).
    fn tile_list_split(&self) -> (u32, u32) {
        let needs = self.needs.unwrap_or_default();
        let (tile_need, coarse_need) = (needs.tile_entries, needs.coarse_entries);
        let total = (self.buffers.tile_indices.capacity() / 4).min(u64::from(u32::MAX));
        let coarse = Self::coarse_room(coarse_need).min(total - tile_need.min(total));
        ((total - coarse) as u32, coarse as u32)
    }

    /// Entries the coarse lists are given for `need`: a quarter more and 256, so lights that
    /// move a little do not change the split every frame.
    fn coarse_room(need: u64) -> u64 {
        need + need / 4 + 256
    }

    /// The view's projection made finite: an infinite projection is sliced up to the farthest
    /// point the lights can reach (`reach`), so nothing beyond it is lit and every light lies
    /// inside the grid.
    fn finite_projection(view: &RenderView, view_from_world: &Mat4, reach: &LightReach) -> Projection {
        view.camera.map(|c| c.projection).unwrap_or_default().finite_for(reach.farthest(view_from_world))
    }

    /// Fills the parameters from this frame's grid, culling test and list capacities, sizes the
    /// bits of levels 0 and 1, uploads the parameters, zeroes the counters and rebinds the
    /// buffers that grew.
    fn write_params(
        &mut self,
        gpu: &GpuContext,
        view: &RenderView,
        view_from_world: &Mat4,
        light_count: u32,
        cap: u32,
        chunks: [u32; 2],
    ) -> Result<(), RenderError> {
        let (near, far) = (self.grid.near, self.grid.far);
        let count_ranges = self.grid.cluster_count() * if self.depth_bounds { 2 } else { 1 };
        let loop_limited = crate::gpu_types::has_loop_limit(&gpu.info);
        self.params = GpuClusterParams {
            dims: [self.grid.dims.x, self.grid.dims.y, self.grid.dims.z, self.grid.cluster_count()],
            viewport: [view.size.x.max(1) as f32, view.size.y.max(1) as f32, near, far],
            light_count,
            cap,
            cull_test: match self.cull {
                CullTest::Aabb => CULL_AABB,
                CullTest::Planes => CULL_PLANES,
                CullTest::Both => CULL_BOTH,
            },
            // The capacities, chunks and `from_lights`: `apply_list_sizes`.
            index_capacity: 0,
            slicing: self.grid.slicing.gpu_id(),
            log_far_over_near: (far / near).ln(),
            tile_index_capacity: 0,
            tile_chunks: 0,
            coarse_dims: self.coarse_dims().unwrap_or(glam::UVec2::ZERO).to_array(),
            coarse_index_capacity: 0,
            coarse_span: self.coarse.unwrap_or(0),
            depth_bounds: u32::from(self.depth_bounds),
            refine_blocks_x: self.refine_blocks.map_or(0, |b| b.x),
            refine_blocks_y: self.refine_blocks.map_or(0, |b| b.y),
            refined_first: count_ranges,
            frustum: manylight_core::cluster::rect_frustum(&self.grid).to_array(),
            light_chunks: 0,
            from_lights: 0,
            loop_limit: if loop_limited { LAVAPIPE_LOOP_LIMIT } else { u32::MAX },
            _pad: 0,
            view_from_world: view_from_world.to_cols_array_2d(),
        };
        self.apply_list_sizes(gpu, chunks)?;
        self.upload_params(gpu, &self.params);
        Ok(())
    }

    /// Puts the lists' sizes (`size_lists`, whose chunks of lights are `[light_chunks,
    /// tile_chunks]`) into the parameters: the cluster, tile and coarse capacities and whether
    /// levels 0 and 1 run from the lights' side; sizes their bits and rebinds the buffers that
    /// grew.
    fn apply_list_sizes(&mut self, gpu: &GpuContext, chunks: [u32; 2]) -> Result<(), RenderError> {
        (self.params.tile_index_capacity, self.params.coarse_index_capacity) = self.tile_list_split();
        self.params.index_capacity = self.cluster_index_capacity();
        self.params.from_lights = u32::from(self.from_lights);
        [self.params.light_chunks, self.params.tile_chunks] = chunks;
        self.size_bits(gpu)?;
        self.bindings.rebind_if_grown(gpu, &self.buffers);
        Ok(())
    }

    /// Uploads `params` and zeroes the counters (before a run of the build).
    fn upload_params(&self, gpu: &GpuContext, params: &GpuClusterParams) {
        gpu.write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(params));
        gpu.write_buffer(
            self.buffers.counters.buffer(),
            0,
            bytemuck::bytes_of(&GpuClusterCounters::default()),
        );
    }

    /// Whether the grid lets levels 0 and 1 of the build run from the lights' side: a coarse
    /// level of at most [`COARSE_SCATTER_TILES`] coarse tiles of at most 64 × 64 tiles (the
    /// loops over them stay short).
    fn grid_allows_bits(&self) -> bool {
        self.coarse.is_some_and(|span| {
            let dims = coarse_dims(self.grid.dims.truncate(), span);
            (1..=COARSE_SCATTER_TILES).contains(&(dims.x * dims.y)) && (2..=64).contains(&span)
        })
    }

    /// Whether the bits of levels 0 and 1 (`bit_bytes`) fit in what the device binds, with as
    /// many coarse-list positions as `coarse_need` gives the coarse lists (`tile_list_split`).
    fn bits_fit(&self, light_chunks: u32, coarse_need: u64) -> bool {
        let span = self.coarse.unwrap_or(0);
        let dims = coarse_dims(self.grid.dims.truncate(), span.max(1));
        let positions = Self::coarse_room(coarse_need);
        COUNTER_BYTES + Self::bit_bytes(dims, span, light_chunks, positions)
            <= self.buffers.counters.max_bytes()
    }

    /// Bytes of the bits of levels 0 and 1: one per (coarse tile, light), then one per (tile of
    /// a coarse tile, position of the coarse lists), each row whole words.
    fn bit_bytes(coarse_dims: glam::UVec2, span: u32, light_chunks: u32, positions: u64) -> u64 {
        let words = |n: u64| n.div_ceil(32) * 4;
        let coarse_tiles = u64::from(coarse_dims.x) * u64::from(coarse_dims.y);
        let level0 = coarse_tiles * u64::from(light_chunks) * words(u64::from(TILE_LIGHT_CHUNK));
        level0 + u64::from(span) * u64::from(span) * words(positions)
    }

    /// Makes room after the counters for this frame's bits of levels 0 and 1 when they run from
    /// the lights' side (`from_lights`), for the coarse lists' present capacity. Bits that do
    /// not fit (the shared buffer had more room for the coarse lists than they asked) send the
    /// levels back to testing each (coarse) tile against its candidates.
    fn size_bits(&mut self, gpu: &GpuContext) -> Result<(), RenderError> {
        if self.from_lights && COUNTER_BYTES + self.params_bit_bytes() > self.buffers.counters.max_bytes() {
            self.from_lights = false;
            self.params.from_lights = 0;
        }
        // The shader's bits array has at least one word.
        let bits = self.coarse_bits().map_or(0, |(_, bytes)| bytes);
        self.buffers.counters.reserve(gpu, COUNTER_BYTES + bits.max(4))?;
        Ok(())
    }

    /// [`Self::bit_bytes`] for this frame's parameters: as many coarse-list positions as the
    /// coarse lists can hold.
    fn params_bit_bytes(&self) -> u64 {
        let p = &self.params;
        let dims = glam::UVec2::from_array(p.coarse_dims);
        Self::bit_bytes(dims, p.coarse_span, p.light_chunks, u64::from(p.coarse_index_capacity))
    }

    /// Uploads per-pixel light lists made outside the renderer (`FrameSnapshot::pixel_light_lists`)
    /// instead of preparing the build: the grid becomes one-pixel tiles with one depth slice
    /// (`manylight_core::efficiency::pixel_grid`), `lists` its ranges and indices. Lists that do
    /// not cover the view's pixels, or that index past the ranges or the lights, are refused.
    pub fn prepare_pixel_lists(
        &mut self,
        gpu: &GpuContext,
        view: &RenderView,
        view_from_world: &Mat4,
        (light_count, reach): (u32, &LightReach),
        lists: &ClusterAssignment,
    ) -> Result<(), RenderError> {
        let projection = Self::finite_projection(view, view_from_world, reach);
        self.grid = manylight_core::efficiency::pixel_grid(view.size, &projection);
        self.cull = view.settings.clusters.cull;
        self.coarse = None;
        let count = self.grid.cluster_count();
        let bad =
            |problem: String| RenderError::UnsupportedSettings(format!("per-pixel light lists: {problem}"));
        if lists.ranges.len() != count as usize {
            return Err(bad(format!("{} ranges for a view of {count} pixels", lists.ranges.len())));
        }
        let entries = lists.indices.len() as u64;
        if let Some(r) = lists.ranges.iter().find(|r| u64::from(r[0]) + u64::from(r[1]) > entries) {
            return Err(bad(format!("a range {r:?} reaches past the {entries} indices")));
        }
        if let Some(l) = lists.indices.iter().find(|&&l| l >= light_count) {
            return Err(bad(format!("light {l} of {light_count} lights")));
        }
        self.buffers.ranges.write(gpu, bytemuck::cast_slice(&lists.ranges))?;
        if lists.indices.is_empty() {
            self.buffers.indices.write(gpu, &[0u8; 4])?;
        } else {
            self.buffers.indices.write(gpu, bytemuck::cast_slice(&lists.indices))?;
        }
        self.depth_bounds = false;
        self.refine_blocks = None;
        self.from_lights = false;
        self.write_params(gpu, view, view_from_world, light_count, CLUSTER_NO_CAP, [1, 1])
    }

    /// The buffer the build writes its counters into (the renderer copies it into the frame's
    /// read-back slot after the view's passes).
    pub fn counters_buffer(&self) -> &wgpu::Buffer {
        self.buffers.counters.buffer()
    }

    /// Where the bits of levels 0 and 1 lie this frame, `(offset, bytes)` in
    /// [`Self::counters_buffer`] (the build clears them first); `None` when those levels test
    /// each (coarse) tile against its candidates.
    pub fn coarse_bits(&self) -> Option<(u64, u64)> {
        self.from_lights.then(|| (COUNTER_BYTES, self.params_bit_bytes()))
    }

    /// Takes what a frame read back needed (its `report`): the following frames' lists are
    /// sized to it. A frame made with another grid or culling test than the counts the lists
    /// were last sized from (one still in flight when the view counted for a new layout) is
    /// passed over.
    pub fn observe(&mut self, report: &ClusterReport) {
        let needs = ListNeeds::of(report);
        if self.needs.is_none_or(|n| n.layout == needs.layout) {
            self.needs = Some(needs);
        }
    }

    /// Whether the lists have no counts to be sized from: no frame of the view was read back
    /// yet, or the light count more than doubled since the one that was (a frame whose lists
    /// fall short shades those clusters from every light, which costs most when the lights are
    /// many). The renderer then runs the build once before the frame, only to count
    /// ([`Self::count_first`]).
    pub fn needs_counting(&self) -> bool {
        self.needs.is_none_or(|n| {
            n.layout != Some(self.layout()) || self.params.light_count > n.lights.saturating_mul(2).max(64)
        })
    }

    /// Sizes the lists for every light in every cluster, tile and coarse tile (at most 2^24
    /// entries a level, and as far as the device's largest binding allows): for a view whose
    /// lists have no counts where the CPU may not wait for a counting run (a browser). The
    /// frame's clusters then hold their lights instead of shading from every light, and the
    /// counts the frame reads back ([`Self::observe`]) size the lists from the next frame on.
    pub fn size_for_every_light(&mut self, gpu: &GpuContext) -> Result<(), RenderError> {
        let lights = u64::from(self.params.light_count);
        let dims = self.grid.dims.as_u64vec3();
        let coarse_tiles = self.coarse_dims().map_or(0, |d| u64::from(d.x) * u64::from(d.y));
        let entries = [dims.x * dims.y * dims.z, dims.x * dims.y, coarse_tiles]
            .map(|n| n.saturating_mul(lights).min(MAX_UNCOUNTED_ENTRIES));
        self.needs = Some(ListNeeds::from_counts(entries, self.params.light_count, Some(self.layout())));
        let chunks = self.size_lists(gpu, self.params.light_count)?;
        self.apply_list_sizes(gpu, chunks)?;
        self.upload_params(gpu, &self.params);
        Ok(())
    }

    /// This frame's [`ListLayout`].
    fn layout(&self) -> ListLayout {
        ListLayout { dims: self.grid.dims.to_array(), coarse_span: self.coarse.unwrap_or(0), cull: self.cull }
    }

    /// Sets the parameters up for a counting run of the build (`counting`: whole slices, no
    /// depth bounds, which the frame has not drawn yet; so at least the counts of the frame)
    /// or back for the frame, and zeroes the counters.
    pub fn count_first(&mut self, gpu: &GpuContext, counting: bool) {
        let mut params = self.params;
        if counting {
            params.depth_bounds = 0;
            self.counted_first = true;
        }
        self.upload_params(gpu, &params);
    }

    /// Sizes the lists again from the counts of a counting run (`counters`); true when they grew
    /// (the counts of a level below a short one are short too, so the build counts again).
    pub fn grow_to_counts(
        &mut self,
        gpu: &GpuContext,
        counters: &GpuClusterCounters,
    ) -> Result<bool, RenderError> {
        let short = counters.total_entries > self.params.index_capacity
            || counters.tile_entries > self.params.tile_index_capacity
            || counters.coarse_entries > self.params.coarse_index_capacity;
        let entries = [counters.total_entries, counters.tile_entries, counters.coarse_entries].map(u64::from);
        self.needs = Some(ListNeeds::from_counts(entries, self.params.light_count, Some(self.layout())));
        if short {
            let chunks = self.size_lists(gpu, self.params.light_count)?;
            self.apply_list_sizes(gpu, chunks)?;
        }
        Ok(short)
    }
}

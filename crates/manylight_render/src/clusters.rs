//! Cluster data on the GPU: the grid's per-cluster bounds, the lights' view-space spheres,
//! the per-cluster `(offset, count)` ranges and the global light-index list, plus the
//! counters the build writes and the renderer reads back each frame.
//!
//! The bounds come from `manylight_core::cluster` (the same numbers the CPU reference uses),
//! so GPU and CPU assignments can be compared light for light.

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{
    CLUSTER_NO_CAP, COARSE_SCATTER_TILES, CULL_AABB, CULL_BOTH, CULL_PLANES, GpuClusterBounds,
    GpuClusterCounters, GpuClusterParams, REFINE_EDGE, REFINED_LIST_SLOTS, TILE_LIGHT_CHUNK,
};
use crate::layouts::{BindGroupDecl, BindingDecl, GroupLayout, SHADING};
use crate::pool::GrowableBuffer;
use crate::readback::read_buffer;
use crate::shaders::ShaderDefs;
use crate::snapshot::RenderView;
use glam::Mat4;
use manylight_core::Projection;
use manylight_core::cluster::{
    ClusterAssignment, ClusterGrid, CullTest, ListBounder, ListBounds, ViewSphere, coarse_dims, coarse_span,
    coarse_tiles, to_view_space,
};
use serde::Serialize;

/// What the cluster build reported for a frame (in `FrameReport::clusters`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ClusterReport {
    /// Grid size x, y, z.
    pub dims: [u32; 3],
    /// Number of clusters.
    pub clusters: u32,
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
    /// Times the lists had to grow after the frame was rendered (each renders it again): 0, since
    /// the CPU bounds size them before submission, unless a bound exceeds what the device binds.
    pub regrows: u32,
    /// The CPU bound the light-index list was sized to (at least `total_entries`).
    pub pair_bound: u64,
    /// The CPU bound the per-tile lists were sized to (at least `tile_entries`).
    pub tile_entry_bound: u64,
    /// The CPU bound the per-coarse-tile lists were sized to (at least `coarse_entries`).
    pub coarse_entry_bound: u64,
    /// CPU milliseconds the list bounds took (before the frame was submitted).
    pub bound_cpu_ms: f64,
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
    /// Invocations of level 0 per coarse tile (chunks of `TILE_LIGHT_CHUNK` lights: of the
    /// listed ones from the lights' side, else of all) and of level 1 per tile (chunks of its
    /// candidates: as many as the longest coarse list can need).
    pub chunks: [u32; 2],
    /// From the lights' side: the lights level 0 marks, those some tile can list (the CPU's
    /// rectangle bound is not empty); 0 per coarse tile.
    pub listed_lights: u32,
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
    }
}

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

const COMPUTE: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// Group 0 of the cluster build (`shaders/cluster_build.wgsl`): the parameters, the cluster
/// bounds and light spheres it reads, the lists it writes, its counters, and the per-tile
/// bounds and lists.
pub static CLUSTER_BUILD_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_build",
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(1, "bounds", COMPUTE),
        BindingDecl::storage(2, "spheres", COMPUTE),
        BindingDecl::storage_rw(3, "ranges", COMPUTE),
        BindingDecl::storage_rw(4, "indices", COMPUTE),
        BindingDecl::storage_rw(5, "build", COMPUTE),
        BindingDecl::storage(6, "tile_bounds", COMPUTE),
        BindingDecl::storage_rw(7, "tile_ranges", COMPUTE),
        BindingDecl::storage_rw(8, "tile_indices", COMPUTE),
    ],
};

/// Group 2 of the passes that shade through the cluster lists (`common/cluster_lists.wgsl`,
/// `tiled_deferred.wgsl`): the parameters, each cluster's range and the light indices.
pub static CLUSTER_LISTS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_lists",
    entries: &[
        BindingDecl::uniform(0, "cluster_params", SHADING),
        BindingDecl::storage(1, "cluster_ranges", SHADING),
        BindingDecl::storage(2, "cluster_indices", SHADING),
    ],
};

/// Group 2 of the `cluster_depth` pass (`shaders/cluster_depth.wgsl`): the parameters, and the
/// ranges buffer, whose per-cluster depth ranges it writes after the cluster ranges.
pub static CLUSTER_DEPTH_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_depth",
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage_rw(1, "cluster_depths", COMPUTE),
    ],
};

/// Group 2 of the `light_refine` pass (`shaders/light_refine.wgsl`): the parameters, the light
/// spheres, and the ranges and index buffers, whose refined part it writes.
pub static LIGHT_REFINE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_refine",
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage(1, "spheres", COMPUTE),
        BindingDecl::storage_rw(2, "ranges", COMPUTE),
        BindingDecl::storage_rw(3, "indices", COMPUTE),
    ],
};

/// GPU buffers and bind groups of the cluster build and of clustered shading.
pub struct ClusterResources {
    /// The grid of the current frame.
    pub grid: ClusterGrid,
    /// The parameters uploaded this frame.
    pub params: GpuClusterParams,
    /// Layout of the build's group 0 ([`CLUSTER_BUILD_GROUP`]).
    pub build_layout: GroupLayout,
    /// Layout of the shading passes' cluster group ([`CLUSTER_LISTS_GROUP`]).
    pub shading_layout: GroupLayout,
    /// Layout of group 2 of the `cluster_depth` pass ([`CLUSTER_DEPTH_GROUP`]).
    pub depth_layout: GroupLayout,
    /// Layout of group 2 of the `light_refine` pass ([`LIGHT_REFINE_GROUP`]).
    pub refine_layout: GroupLayout,
    /// Group 0 of the build.
    pub build_bind_group: wgpu::BindGroup,
    /// The shading group.
    pub shading_bind_group: wgpu::BindGroup,
    /// The params uniform.
    pub params_buffer: wgpu::Buffer,
    /// Per-cluster `(offset, count)`, then (with depth bounds) per-cluster depth ranges
    /// (`shaders/cluster_depth.wgsl`), then (with refined lists) per-block ranges
    /// (`shaders/light_refine.wgsl`).
    pub ranges: GrowableBuffer,
    /// The light-index list: the cluster lists (`GpuClusterParams::index_capacity` entries),
    /// then (with refined lists) `REFINED_LIST_SLOTS` entries per block.
    pub indices: GrowableBuffer,
    bounds: GrowableBuffer,
    /// The lights' view-space spheres (centre, radius).
    pub spheres: GrowableBuffer,
    /// Bounds of the tile columns, then of the coarse tiles.
    tile_bounds: GrowableBuffer,
    /// (tile, chunk) ranges, then (coarse tile, chunk) ranges.
    tile_ranges: GrowableBuffer,
    /// The per-tile lists (`GpuClusterParams::tile_index_capacity` entries), then the
    /// per-coarse-tile lists (`tile_list_split`).
    tile_indices: GrowableBuffer,
    /// The counters (`GpuClusterCounters`), then the bits of levels 0 and 1 when the build sets
    /// them from the lights' side this frame (`coarse_bits`).
    counters: GrowableBuffer,
    /// Levels 0 and 1 of the build run from the lights' side this frame (`grid_allows_bits`,
    /// `bits_fit`, `size_bits`).
    from_lights: bool,
    /// The grid and coarse span the uploaded bounds are for.
    bounds_of: Option<(ClusterGrid, Option<u32>)>,
    /// Tiles per coarse-tile edge this frame, `None` without a coarse level.
    coarse: Option<u32>,
    generations: [u64; 8],
    /// The view-space spheres uploaded this frame (for the CPU reference in tests and stats).
    pub view_spheres: Vec<ViewSphere>,
    /// The lights some tile can list this frame, ascending (`list_bounds`): level 0 from the
    /// lights' side marks these only. Uploaded after the spheres.
    listed: Vec<u32>,
    /// Computes the list bounds on all cores, its parts' storage kept between frames.
    bounder: ListBounder,
    /// What this frame uploads to the spheres buffer: the spheres, then `listed` (four to an
    /// element); kept between frames so that it is not allocated again.
    sphere_upload: Vec<[f32; 4]>,
    /// This frame's CPU bounds of the list sizes, which the lists were sized to before it was
    /// submitted.
    pub bounds_estimate: ListBounds,
    bound_cpu_ms: f64,
    cull: CullTest,
    /// The build cuts clusters to their pixels' depth range this frame.
    depth_bounds: bool,
    /// Blocks across and down of this frame's refined lists, `None` without them.
    refine_blocks: Option<glam::UVec2>,
}

/// Chunks of [`TILE_LIGHT_CHUNK`] lights that `lights` lights take, at least 1.
fn light_chunks_of(lights: usize) -> u32 {
    u32::try_from(lights).unwrap_or(u32::MAX).div_ceil(TILE_LIGHT_CHUNK).max(1)
}

/// Bytes of the build's counters (`GpuClusterCounters`), before level 0's bits.
const COUNTER_BYTES: u64 = std::mem::size_of::<GpuClusterCounters>() as u64;

/// Initial entries of the cluster light-index list (it grows as frames need).
pub const INITIAL_INDEX_CAPACITY: u64 = 1 << 16;
/// Initial entries of the per-tile lists (they grow as frames need).
pub const INITIAL_TILE_INDEX_CAPACITY: u64 = 1 << 12;

impl ClusterResources {
    /// Creates the buffers (small; they grow with the grid and the lights).
    pub fn new(gpu: &GpuContext) -> ClusterResources {
        let device = &gpu.device;
        let defs = ShaderDefs::default();
        let build_layout = CLUSTER_BUILD_GROUP.create_layout(device, defs);
        let shading_layout = CLUSTER_LISTS_GROUP.create_layout(device, defs);
        let depth_layout = CLUSTER_DEPTH_GROUP.create_layout(device, defs);
        let refine_layout = LIGHT_REFINE_GROUP.create_layout(device, defs);
        let params_buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cluster_params"),
            size: std::mem::size_of::<GpuClusterParams>() as u64,
            // Also bound as storage by the `cluster_depth` and `light_refine` passes.
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let storage = wgpu::BufferUsages::STORAGE;
        let copy = wgpu::BufferUsages::COPY_SRC;
        let bounds = GrowableBuffer::new(gpu, "cluster_bounds", storage, 128 * 1024);
        let spheres = GrowableBuffer::new(gpu, "light_view_spheres", storage, 16 * 1024);
        // With depth bounds the `cluster_depth` pass clears the depth ranges after the cluster
        // ranges each frame.
        let ranges = GrowableBuffer::new(
            gpu,
            "cluster_ranges",
            storage | copy | wgpu::BufferUsages::COPY_DST,
            8 * 8192,
        );
        let indices =
            GrowableBuffer::new(gpu, "light_index_list", storage | copy, 4 * INITIAL_INDEX_CAPACITY);
        let tile_bounds = GrowableBuffer::new(gpu, "tile_bounds", storage, 128 * 256);
        let tile_ranges = GrowableBuffer::new(gpu, "tile_ranges", storage, 8 * 256);
        let tile_indices =
            GrowableBuffer::new(gpu, "tile_light_index_list", storage, 4 * INITIAL_TILE_INDEX_CAPACITY);
        let counters = GrowableBuffer::new(gpu, "cluster_counters", storage | copy, COUNTER_BYTES + 4);
        let (build_bind_group, shading_bind_group) = Self::bind_groups(
            gpu,
            &build_layout,
            &shading_layout,
            &params_buffer,
            [&bounds, &spheres, &ranges, &indices, &tile_bounds, &tile_ranges, &tile_indices, &counters],
        );
        ClusterResources {
            grid: ClusterGrid::new(glam::UVec2::ONE, &Default::default(), &Default::default()),
            params: GpuClusterParams::default(),
            build_layout,
            shading_layout,
            depth_layout,
            refine_layout,
            build_bind_group,
            shading_bind_group,
            params_buffer,
            ranges,
            indices,
            bounds,
            spheres,
            tile_bounds,
            tile_ranges,
            tile_indices,
            counters,
            from_lights: false,
            bounds_of: None,
            coarse: None,
            generations: [0; 8],
            view_spheres: Vec::new(),
            listed: Vec::new(),
            bounder: ListBounder::default(),
            sphere_upload: Vec::new(),
            bounds_estimate: ListBounds::default(),
            bound_cpu_ms: 0.0,
            cull: CullTest::default(),
            depth_bounds: false,
            refine_blocks: None,
        }
    }

    fn bind_groups(
        gpu: &GpuContext,
        build_layout: &GroupLayout,
        shading_layout: &GroupLayout,
        params: &wgpu::Buffer,
        [bounds, spheres, ranges, indices, tile_bounds, tile_ranges, tile_indices, counters]: [&GrowableBuffer;
            8],
    ) -> (wgpu::BindGroup, wgpu::BindGroup) {
        let build = build_layout.create_bind_group(
            gpu,
            &[
                params,
                bounds.buffer(),
                spheres.buffer(),
                ranges.buffer(),
                indices.buffer(),
                counters.buffer(),
            ]
            .into_iter()
            .chain([tile_bounds.buffer(), tile_ranges.buffer(), tile_indices.buffer()])
            .map(Binding::Buffer)
            .collect::<Vec<_>>(),
        );
        let shading = shading_layout.create_bind_group(
            gpu,
            &[Binding::Buffer(params), Binding::Buffer(ranges.buffer()), Binding::Buffer(indices.buffer())],
        );
        (build, shading)
    }

    fn rebind_if_grown(&mut self, gpu: &GpuContext) {
        let generations = [
            self.bounds.generation(),
            self.spheres.generation(),
            self.ranges.generation(),
            self.indices.generation(),
            self.tile_bounds.generation(),
            self.tile_ranges.generation(),
            self.tile_indices.generation(),
            self.counters.generation(),
        ];
        if generations != self.generations {
            let (b, s) = Self::bind_groups(
                gpu,
                &self.build_layout,
                &self.shading_layout,
                &self.params_buffer,
                [
                    &self.bounds,
                    &self.spheres,
                    &self.ranges,
                    &self.indices,
                    &self.tile_bounds,
                    &self.tile_ranges,
                    &self.tile_indices,
                    &self.counters,
                ],
            );
            self.build_bind_group = b;
            self.shading_bind_group = s;
            self.generations = generations;
        }
    }

    /// Uploads the grid bounds (when the grid changed), the lights' view-space spheres and the
    /// parameters, and zeroes the counters. `lights` are the (position, radius) pairs in the
    /// order of the light buffer; `options`: depth bounds and refined lists, from the view's
    /// plan.
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        view: &RenderView,
        view_from_world: &Mat4,
        lights: &[(glam::Vec3, f32)],
        options: ListOptions,
    ) -> Result<(), RenderError> {
        let settings = &view.settings.clusters;
        let depth_bounds = options.depth_bounds;
        self.depth_bounds = depth_bounds;
        self.refine_blocks =
            options.refined_lists.then(|| manylight_core::efficiency::block_dims(view.size, REFINE_EDGE));
        let grid_config = settings.grid_for(view.settings.pipeline);
        let projection = self.place_lights(view, view_from_world, lights);
        self.grid = ClusterGrid::new(view.size, &projection, &grid_config);
        self.cull = settings.cull;
        self.coarse = coarse_span(settings.coarse_tiles, settings.cull);
        let count = self.grid.cluster_count();
        if self.bounds_of != Some((self.grid, self.coarse)) {
            let dims = self.grid.dims;
            let mut bounds = Vec::with_capacity(count as usize);
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
            self.bounds.write(gpu, bytemuck::cast_slice(&bounds))?;
            // Level 1 of the build: the same tiles with one slice from near to far.
            let tile_grid = ClusterGrid::new(
                view.size,
                &projection,
                &manylight_core::cluster::GridConfig {
                    dims: Some(glam::UVec3::new(dims.x, dims.y, 1)),
                    ..grid_config
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
            self.tile_bounds.write(gpu, bytemuck::cast_slice(&tiles))?;
            self.bounds_of = Some((self.grid, self.coarse));
        }
        // The cluster ranges, then (with depth bounds) the depth ranges of the clusters, then
        // (with refined lists) the blocks' ranges.
        let cluster_ranges = count as u64 * if depth_bounds { 16 } else { 8 };
        self.ranges.reserve(gpu, cluster_ranges + self.refined_blocks() * 8)?;
        // Lists sized before the frame is submitted, from a CPU bound of what the build can
        // write (`ListBounder`, on all cores): the GPU lists cannot overflow, so the frame is
        // never rendered twice. A bound beyond what the device can bind reserves what it can;
        // then the build's counters decide, after the frame, whether the real lists fit.
        let started = std::time::Instant::now();
        let all_chunks = light_chunks_of(self.view_spheres.len());
        // Levels 0 and 1 from the lights' side where the grid allows and their bits fit (a
        // second bound, of level 0 per coarse tile, when they do not).
        let (cull, coarse) = (settings.cull, self.coarse);
        self.from_lights = self.grid_allows_bits();
        let spheres = &self.view_spheres;
        self.bounds_estimate =
            self.bounder.bound(&self.grid, spheres, cull, coarse, self.from_lights, &mut self.listed);
        if self.from_lights && !self.bits_fit(light_chunks_of(self.listed.len())) {
            self.from_lights = false;
            self.bounds_estimate =
                self.bounder.bound(&self.grid, spheres, cull, coarse, false, &mut self.listed);
        }
        self.bound_cpu_ms = started.elapsed().as_secs_f64() * 1e3;
        // Level 0 from the lights' side runs over the listed lights, per tile over all.
        let light_chunks = if self.from_lights { light_chunks_of(self.listed.len()) } else { all_chunks };
        self.upload_spheres(gpu)?;
        // Level 1 loops over each tile's coarse list (every light without a coarse level) in
        // chunks: as many as the longest list the bound allows, so a coarse list never runs
        // past its tile's last chunk.
        let tile_chunks = match self.coarse {
            Some(_) => {
                self.bounds_estimate.max_coarse_lights.div_ceil(TILE_LIGHT_CHUNK).clamp(1, light_chunks)
            }
            None => light_chunks,
        };
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
        let entries = self.bounds_estimate.cluster_pairs + self.refined_entries();
        self.indices.reserve(gpu, with_headroom(entries, &self.indices))?;
        // The tile and coarse-tile lists share a buffer; the spare room is split between them.
        let (tile_need, coarse_need) =
            (self.bounds_estimate.tile_entries, self.bounds_estimate.coarse_entries);
        self.tile_indices.reserve(gpu, with_headroom(tile_need + coarse_need, &self.tile_indices))?;
        let tiles = self.grid.dims.x as u64 * self.grid.dims.y as u64;
        let coarse_tiles = self.coarse_dims().map_or(0, |d| u64::from(d.x) * u64::from(d.y));
        // Room for level 0's ranges over all lights, should the bits not fit after all (`size_bits`).
        let ranges = tiles * u64::from(tile_chunks) + coarse_tiles * u64::from(all_chunks);
        self.tile_ranges.reserve(gpu, ranges * 8)?;
        let cap = settings.cap.unwrap_or(CLUSTER_NO_CAP);
        let light_count = self.view_spheres.len() as u32;
        self.write_params(gpu, view, light_count, cap, [light_chunks, tile_chunks])
    }

    /// Uploads the view spheres, then the listed lights' indices (their bits, four to a sphere
    /// element: `listed_light` in `shaders/cluster_build.wgsl`).
    fn upload_spheres(&mut self, gpu: &GpuContext) -> Result<(), RenderError> {
        let upload = &mut self.sphere_upload;
        upload.clear();
        upload.extend(self.view_spheres.iter().map(|s| s.center.extend(s.radius).to_array()));
        upload.extend(self.listed.chunks(4).map(|c| {
            let mut four = [0.0f32; 4];
            for (slot, &light) in four.iter_mut().zip(c) {
                *slot = f32::from_bits(light);
            }
            four
        }));
        if upload.is_empty() {
            upload.push([0.0; 4]);
        }
        self.spheres.write(gpu, bytemuck::cast_slice(upload))?;
        Ok(())
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
        (self.indices.capacity() / 4).saturating_sub(self.refined_entries()).min(u64::from(u32::MAX)) as u32
    }

    /// Coarse tiles across and down this frame, `None` without a coarse level.
    fn coarse_dims(&self) -> Option<glam::UVec2> {
        self.coarse.map(|span| coarse_dims(self.grid.dims.truncate(), span))
    }

    /// The entries of the tile-lists buffer for the per-tile lists (first) and the
    /// per-coarse-tile lists: the coarse lists get what they need and a quarter more
    /// (`coarse_room`; level 1 from the lights' side runs an invocation and keeps a bit per tile
    /// for each of their entries), the tile lists the rest (and the coarse lists what is left
    /// when the buffer could not grow to both).
    fn tile_list_split(&self, tile_need: u64, coarse_need: u64) -> (u32, u32) {
        let total = (self.tile_indices.capacity() / 4).min(u64::from(u32::MAX));
        let coarse = Self::coarse_room(coarse_need).min(total - tile_need.min(total));
        ((total - coarse) as u32, coarse as u32)
    }

    /// Entries the coarse lists are given for `need`: a quarter more and 256, so lights that
    /// move a little do not change the split every frame.
    fn coarse_room(need: u64) -> u64 {
        need + need / 4 + 256
    }

    /// Sets the lights' view-space spheres (`lights` in the order of the light buffer) and
    /// returns the view's projection made finite: an infinite projection is sliced up to the
    /// farthest light's reach, so nothing beyond it is lit and every light lies inside the grid.
    fn place_lights(
        &mut self,
        view: &RenderView,
        view_from_world: &Mat4,
        lights: &[(glam::Vec3, f32)],
    ) -> Projection {
        self.view_spheres.clear();
        self.view_spheres.extend(to_view_space(*view_from_world, lights.iter().copied()));
        let reach = manylight_core::cluster::farthest_reach(self.view_spheres.iter().copied());
        view.camera.map(|c| c.projection).unwrap_or_default().finite_for(reach)
    }

    /// Fills the parameters from this frame's grid, culling test and list capacities, sizes the
    /// bits of levels 0 and 1, uploads the parameters, zeroes the counters and rebinds the
    /// buffers that grew.
    fn write_params(
        &mut self,
        gpu: &GpuContext,
        view: &RenderView,
        light_count: u32,
        cap: u32,
        [light_chunks, tile_chunks]: [u32; 2],
    ) -> Result<(), RenderError> {
        let (near, far) = (self.grid.near, self.grid.far);
        let count_ranges = self.grid.cluster_count() * if self.depth_bounds { 2 } else { 1 };
        let (tile_lists, coarse_lists) =
            self.tile_list_split(self.bounds_estimate.tile_entries, self.bounds_estimate.coarse_entries);
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
            index_capacity: self.cluster_index_capacity(),
            slicing: self.grid.slicing.gpu_id(),
            log_far_over_near: (far / near).ln(),
            tile_index_capacity: tile_lists,
            tile_chunks,
            coarse_dims: self.coarse_dims().unwrap_or(glam::UVec2::ZERO).to_array(),
            coarse_index_capacity: coarse_lists,
            coarse_span: self.coarse.unwrap_or(0),
            depth_bounds: u32::from(self.depth_bounds),
            refine_blocks_x: self.refine_blocks.map_or(0, |b| b.x),
            refine_blocks_y: self.refine_blocks.map_or(0, |b| b.y),
            refined_first: count_ranges,
            frustum: manylight_core::cluster::rect_frustum(&self.grid).to_array(),
            light_chunks,
            listed_lights: if self.from_lights { self.listed.len() as u32 } else { 0 },
            _pad: [0; 2],
        };
        self.size_bits(gpu)?;
        gpu.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        gpu.write_buffer(self.counters.buffer(), 0, bytemuck::bytes_of(&GpuClusterCounters::default()));
        self.rebind_if_grown(gpu);
        Ok(())
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
    /// many coarse-list positions as this frame's bound gives the coarse lists
    /// (`tile_list_split`).
    fn bits_fit(&self, light_chunks: u32) -> bool {
        let span = self.coarse.unwrap_or(0);
        let dims = coarse_dims(self.grid.dims.truncate(), span.max(1));
        let positions = Self::coarse_room(self.bounds_estimate.coarse_entries);
        COUNTER_BYTES + Self::bit_bytes(dims, span, light_chunks, positions) <= self.counters.max_bytes()
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
    /// not fit (only when the lists grew past the bound while the frame is checked) send the
    /// levels back to testing each (coarse) tile against its candidates.
    fn size_bits(&mut self, gpu: &GpuContext) -> Result<(), RenderError> {
        if self.from_lights && COUNTER_BYTES + self.params_bit_bytes() > self.counters.max_bytes() {
            // Level 0 per coarse tile loops over all lights.
            self.from_lights = false;
            self.params.light_chunks = light_chunks_of(self.params.light_count as usize);
            self.params.listed_lights = 0;
        }
        // The shader's bits array has at least one word.
        let bits = self.coarse_bits().map_or(0, |(_, bytes)| bytes);
        self.counters.reserve(gpu, COUNTER_BYTES + bits.max(4))?;
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
        lights: &[(glam::Vec3, f32)],
        lists: &ClusterAssignment,
    ) -> Result<(), RenderError> {
        let projection = self.place_lights(view, view_from_world, lights);
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
        if let Some(l) = lists.indices.iter().find(|&&l| l as usize >= lights.len()) {
            return Err(bad(format!("light {l} of {} lights", lights.len())));
        }
        self.ranges.write(gpu, bytemuck::cast_slice(&lists.ranges))?;
        if lists.indices.is_empty() {
            self.indices.write(gpu, &[0u8; 4])?;
        } else {
            self.indices.write(gpu, bytemuck::cast_slice(&lists.indices))?;
        }
        self.bounds_estimate = ListBounds { cluster_pairs: entries, ..ListBounds::default() };
        self.bound_cpu_ms = 0.0;
        self.depth_bounds = false;
        self.refine_blocks = None;
        self.from_lights = false;
        self.write_params(gpu, view, lights.len() as u32, CLUSTER_NO_CAP, [1, 1])
    }

    /// The buffer the build writes its counters into (the renderer copies it into the frame's
    /// read-back slot after the view's passes).
    pub fn counters_buffer(&self) -> &wgpu::Buffer {
        self.counters.buffer()
    }

    /// Where the bits of levels 0 and 1 lie this frame, `(offset, bytes)` in
    /// [`Self::counters_buffer`] (the build clears them first); `None` when those levels test
    /// each (coarse) tile against its candidates.
    pub fn coarse_bits(&self) -> Option<(u64, u64)> {
        self.from_lights.then(|| (COUNTER_BYTES, self.params_bit_bytes()))
    }

    /// Reads the counters of the last submitted view (waits for the GPU).
    pub fn read_counters(&self, gpu: &GpuContext) -> Result<GpuClusterCounters, RenderError> {
        let bytes = read_buffer(gpu, self.counters.buffer(), 0, COUNTER_BYTES)?;
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

    /// True when the index lists are too small for what the frame needed (`counters`).
    pub fn lists_short(&self, counters: &GpuClusterCounters) -> bool {
        let (tiles_short, clusters_short) = self.short_lists(counters);
        tiles_short || clusters_short
    }

    /// Whether the tile-lists buffer (per-tile and per-coarse-tile lists) and the cluster index
    /// list were too small for what the frame needed (`counters`).
    fn short_lists(&self, counters: &GpuClusterCounters) -> (bool, bool) {
        let tiles_short = counters.tile_entries > self.params.tile_index_capacity
            || counters.coarse_entries > self.params.coarse_index_capacity;
        (tiles_short, counters.total_entries > self.params.index_capacity)
    }

    /// True when the index lists were too small for what the frame needed (`counters`); grows
    /// them (to the next power of two, at most the device's binding limit) so the frame can be
    /// rendered again. A list the device cannot bind is refused, naming the limit.
    pub fn grow_if_needed(
        &mut self,
        gpu: &GpuContext,
        counters: &GpuClusterCounters,
    ) -> Result<bool, RenderError> {
        let (tiles_short, clusters_short) = self.short_lists(counters);
        if !tiles_short && !clusters_short {
            return Ok(false);
        }
        if tiles_short {
            let tiles = u64::from(counters.tile_entries.max(self.params.tile_index_capacity));
            let coarse = u64::from(counters.coarse_entries.max(self.params.coarse_index_capacity));
            self.tile_indices.reserve(gpu, (tiles + coarse) * 4)?;
            (self.params.tile_index_capacity, self.params.coarse_index_capacity) =
                self.tile_list_split(tiles, coarse);
            self.size_bits(gpu)?;
        }
        if clusters_short {
            self.indices.reserve(gpu, (counters.total_entries as u64 + self.refined_entries()) * 4)?;
            self.params.index_capacity = self.cluster_index_capacity();
        }
        gpu.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        gpu.write_buffer(self.counters.buffer(), 0, bytemuck::bytes_of(&GpuClusterCounters::default()));
        self.rebind_if_grown(gpu);
        Ok(true)
    }

    /// The report of a frame from its counters.
    pub fn report(&self, c: &GpuClusterCounters, regrows: u32) -> ClusterReport {
        let mut report = ClusterReport {
            dims: [self.grid.dims.x, self.grid.dims.y, self.grid.dims.z],
            clusters: self.params.dims[3],
            index_capacity: self.params.index_capacity as u64,
            regrows,
            pair_bound: self.bounds_estimate.cluster_pairs,
            tile_entry_bound: self.bounds_estimate.tile_entries,
            coarse_entry_bound: self.bounds_estimate.coarse_entries,
            coarse_span: self.coarse.unwrap_or(0),
            bound_cpu_ms: self.bound_cpu_ms,
            buffer_bytes: self.buffer_bytes(),
            cull_test: self.cull.name().to_string(),
            z_slicing: self.grid.slicing.name().to_string(),
            from_lights: self.from_lights,
            chunks: [self.params.light_chunks, self.params.tile_chunks],
            listed_lights: self.params.listed_lights,
            ..Default::default()
        };
        report.apply_counters(c);
        report
    }

    /// True when this frame's lists might not hold what the build writes, which is known
    /// before the frame is submitted: a bound exceeds the capacity the device could give, or,
    /// on a `loop_limited` adapter, the longest tile list could exceed `loop_limit`. Such a
    /// view waits for its counters instead of trusting the bound.
    pub fn bound_can_fail(&self, loop_limited: bool, loop_limit: u32) -> bool {
        self.bounds_estimate.cluster_pairs > u64::from(self.params.index_capacity)
            || self.bounds_estimate.tile_entries > u64::from(self.params.tile_index_capacity)
            || self.bounds_estimate.coarse_entries > u64::from(self.params.coarse_index_capacity)
            || (loop_limited && self.bounds_estimate.max_tile_lights > loop_limit)
    }

    /// Bytes of the GPU buffers held (capacities, not what this frame filled).
    pub fn buffer_bytes(&self) -> u64 {
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
        growable.iter().map(|b| b.capacity()).sum::<u64>() + self.params_buffer.size()
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
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, self.ranges.buffer(), first, n * 8)?);
        let base = u64::from(self.params.index_capacity);
        let indices: Vec<u32> = bytemuck::pod_collect_to_vec(&read_buffer(
            gpu,
            self.indices.buffer(),
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
        let ranges_bytes = read_buffer(gpu, self.ranges.buffer(), 0, count * 8)?;
        let ranges: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&ranges_bytes);
        let counters = self.read_counters(gpu)?;
        let total = counters.total_entries as u64;
        let indices: Vec<u32> = if total == 0 {
            Vec::new()
        } else {
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, self.indices.buffer(), 0, total * 4)?)
        };
        Ok(ClusterAssignment {
            ranges,
            indices,
            dropped_pairs: counters.dropped_pairs as u64,
            clusters_overflowed: counters.clusters_overflowed,
        })
    }
}

//! The `cluster_build` compute pass: per-coarse-tile lists (from each light's rectangle of
//! tiles where their bits fit), per-tile lists from them, then
//! per-cluster lists from those, each by count → prefix sum → fill (see
//! `shaders/cluster_build.wgsl`), producing per-cluster `(offset, count)` ranges into one
//! light-index list.

use super::{CLUSTER_DEPTHS, CLUSTERS};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::layouts::GroupLayout;
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;

/// The cluster build's pipelines: per workgroup size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClusterBuildKey {
    /// Invocations per workgroup.
    pub workgroup_size: u32,
}

impl PipelineKey for ClusterBuildKey {
    type Pipeline = ClusterBuildPipelines;
}

/// The compute pipelines of the build, for one workgroup size: the lights' view-space spheres
/// (`shaders/light_spheres.wgsl`), three per level, and levels 0 and 1 from the lights' side
/// (`light_marks`, `tile_marks` and the `_bits` steps). One field a compute entry point (over
/// 15): the build's steps are dispatched by name in `record`, and a map would hide a missing one.
pub struct ClusterBuildPipelines {
    light_spheres: wgpu::ComputePipeline,
    light_marks: wgpu::ComputePipeline,
    coarse_count_bits: wgpu::ComputePipeline,
    coarse_fill_bits: wgpu::ComputePipeline,
    tile_marks: wgpu::ComputePipeline,
    tile_count_bits: wgpu::ComputePipeline,
    tile_fill_bits: wgpu::ComputePipeline,
    coarse_count: wgpu::ComputePipeline,
    coarse_scan: wgpu::ComputePipeline,
    coarse_fill: wgpu::ComputePipeline,
    tile_count: wgpu::ComputePipeline,
    tile_scan: wgpu::ComputePipeline,
    tile_fill: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    fill: wgpu::ComputePipeline,
}

impl ClusterBuildPipelines {
    fn new(
        device: &wgpu::Device,
        layout: &GroupLayout,
        spheres_layout: &GroupLayout,
        workgroup_size: u32,
    ) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "cluster_build.wgsl")?;
        crate::layouts::check_pipeline("cluster_build.wgsl", &[], &[layout])?;
        let pipeline_layout = crate::layouts::pipeline_layout(device, "cluster_build", &[layout]);
        let spheres_module = crate::shaders::create_module(device, "light_spheres.wgsl")?;
        crate::layouts::check_pipeline("light_spheres.wgsl", &[], &[spheres_layout])?;
        let spheres_pipeline_layout =
            crate::layouts::pipeline_layout(device, "light_spheres", &[spheres_layout]);
        let constants = [("WORKGROUP_SIZE", workgroup_size as f64)];
        let light_spheres = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("light_spheres"),
            layout: Some(&spheres_pipeline_layout),
            module: &spheres_module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        });
        let make = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("cluster_build"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            })
        };
        Ok(ClusterBuildPipelines {
            light_spheres,
            light_marks: make("light_marks"),
            coarse_count_bits: make("coarse_count_bits"),
            coarse_fill_bits: make("coarse_fill_bits"),
            tile_marks: make("tile_marks"),
            tile_count_bits: make("tile_count_bits"),
            tile_fill_bits: make("tile_fill_bits"),
            coarse_count: make("coarse_count"),
            coarse_scan: make("coarse_scan"),
            coarse_fill: make("coarse_fill"),
            tile_count: make("tile_count"),
            tile_scan: make("tile_scan"),
            tile_fill: make("tile_fill"),
            count: make("count"),
            scan: make("scan"),
            fill: make("fill"),
        })
    }
}

/// Assigns the frame's lights to clusters on the GPU.
pub struct ClusterBuildPass {
    /// Invocations per workgroup of the count and fill steps.
    pub workgroup_size: u32,
    /// The cluster level cuts clusters to their pixels' depth range (written by
    /// [`super::ClusterDepthPass`], which then runs first).
    pub depth_bounds: bool,
}

pub use super::common::dispatch_size;

impl NamedPass for ClusterBuildPass {
    const NAME: &'static str = "cluster_build";
}

impl Pass for ClusterBuildPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        if self.depth_bounds { vec![CLUSTER_DEPTHS] } else { Vec::new() }
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTERS]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx.require_clusters("cluster_build")?;
        let wg = self.workgroup_size.clamp(1, 1024);
        let (layout, spheres_layout) = (&clusters.bindings.build_layout, &clusters.bindings.spheres_layout);
        let pipelines = ctx.pipelines.get_or_create(ClusterBuildKey { workgroup_size: wg }, |k| {
            ClusterBuildPipelines::new(&ctx.gpu.device, layout, spheres_layout, k.workgroup_size)
        })?;
        let spheres_group = ctx.bind_group(
            spheres_layout,
            &[
                Binding::Buffer(&clusters.buffers.params),
                Binding::Buffer(ctx.scene.lights.buffer.buffer()),
                Binding::Buffer(clusters.buffers.spheres.buffer()),
            ],
        );
        let max_groups = ctx.gpu.device.limits().max_compute_workgroups_per_dimension;
        let groups = dispatch_size(clusters.params.dims[3], wg, max_groups)?;
        // Levels 0 and 1 run one invocation per (coarse tile or tile, chunk of candidates).
        let p = &clusters.params;
        let entries = |tiles: u64, chunks: u32| {
            u32::try_from(tiles * u64::from(chunks)).map_err(|_| {
                RenderError::UnsupportedSettings(format!(
                    "{tiles} tiles × {chunks} light chunks exceed 2^32 cluster-build invocations"
                ))
            })
        };
        let tiles = u64::from(p.dims[0]) * u64::from(p.dims[1]);
        let tile_groups = dispatch_size(entries(tiles, p.tile_chunks)?, wg, max_groups)?;
        let light_groups = dispatch_size(p.light_count, wg, max_groups)?;
        let position_groups = dispatch_size(p.coarse_index_capacity, wg, max_groups)?;
        let coarse_tiles = u64::from(p.coarse_dims[0]) * u64::from(p.coarse_dims[1]);
        let coarse_groups = dispatch_size(entries(coarse_tiles, p.light_chunks)?, wg, max_groups)?;
        // The bits of levels 0 and 1 start clear (`light_marks` and `tile_marks` only set them).
        if let Some((offset, bytes)) = clusters.coarse_bits() {
            ctx.encoder.clear_buffer(clusters.counters_buffer(), offset, Some(bytes));
        }
        let timestamps = ctx.compute_timestamps(true, true);
        {
            let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cluster_build"),
                timestamp_writes: timestamps,
            });
            // The lights' view-space spheres first, then the build over them.
            pass.set_bind_group(crate::layouts::LIGHT_SPHERES_GROUP.index, &spheres_group, &[]);
            pass.set_pipeline(&pipelines.light_spheres);
            pass.dispatch_workgroups(light_groups[0], light_groups[1], 1);
            pass.set_bind_group(
                crate::layouts::CLUSTER_BUILD_GROUP.index,
                &clusters.bindings.build_group,
                &[],
            );
            // The steps of the build (shaders/cluster_build.wgsl), in order; the scans run as
            // one workgroup.
            // Levels 0 and 1 per (coarse) tile, or from the lights' side where their bits fit.
            let per_tile = [
                (&pipelines.coarse_count, coarse_groups),
                (&pipelines.coarse_scan, [1, 1]),
                (&pipelines.coarse_fill, coarse_groups),
                (&pipelines.tile_count, tile_groups),
                (&pipelines.tile_scan, [1, 1]),
                (&pipelines.tile_fill, tile_groups),
            ];
            let from_lights = [
                (&pipelines.light_marks, light_groups),
                (&pipelines.coarse_count_bits, coarse_groups),
                (&pipelines.coarse_scan, [1, 1]),
                (&pipelines.coarse_fill_bits, coarse_groups),
                (&pipelines.tile_marks, position_groups),
                (&pipelines.tile_count_bits, tile_groups),
                (&pipelines.tile_scan, [1, 1]),
                (&pipelines.tile_fill_bits, tile_groups),
            ];
            let levels = [(&pipelines.count, groups), (&pipelines.scan, [1, 1]), (&pipelines.fill, groups)];
            // Without a coarse level, level 1 alone (every light a candidate).
            let first = match (p.coarse_span > 0, clusters.coarse_bits().is_some()) {
                (false, _) => &per_tile[3..],
                (true, false) => &per_tile[..],
                (true, true) => &from_lights[..],
            };
            for &(pipeline, workgroups) in first.iter().chain(&levels) {
                pass.set_pipeline(pipeline);
                pass.dispatch_workgroups(workgroups[0], workgroups[1], 1);
            }
        }
        Ok(())
    }
}

/// The per-pixel light lists a frame brings (`FrameSnapshot::pixel_light_lists`), uploaded
/// with the view's constants (`ClusterResources::prepare_pixel_lists`). It records no GPU work:
/// it stands in the graph for the cluster build the view skips, as the writer of the lists the
/// shading passes read.
pub struct PixelListsPass;

/// Name of [`PixelListsPass`] in pass lists and reports.
pub const PIXEL_LIGHT_LISTS: &str = "pixel_light_lists";

impl NamedPass for PixelListsPass {
    const NAME: &'static str = PIXEL_LIGHT_LISTS;
}

impl Pass for PixelListsPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTERS]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        ctx.require_clusters("pixel_light_lists").map(|_| ())
    }
}

/// Needed when the view shades with clusters, or shows a view of cluster data: the build, or
/// the lists the frame brings.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.view.needs_clusters(p.has_lights) {
        if p.has_pixel_lists {
            out.push(Box::new(PixelListsPass));
        } else {
            let (workgroup_size, depth_bounds) =
                (p.settings().clusters.workgroup_size, p.bounds_clusters_by_depth());
            out.push(Box::new(ClusterBuildPass { workgroup_size, depth_bounds }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::dispatch_size;

    #[test]
    fn dispatches_split_into_rows_past_the_limit() {
        assert_eq!(dispatch_size(0, 64, 65_535).ok(), Some([1, 1]));
        assert_eq!(dispatch_size(64 * 65_535, 64, 65_535).ok(), Some([65_535, 1]));
        assert_eq!(dispatch_size(64 * 65_535 + 1, 64, 65_535).ok(), Some([65_535, 2]));
        assert_eq!(dispatch_size(1 << 20, 1, 65_535).ok(), Some([65_535, 17]));
        // Every invocation is covered, and the rows are not more than one short of full.
        for (n, wg, max) in [(1_000_003u32, 7u32, 1000u32), (u32::MAX / 2, 2, 65_535), (4, 1, 2)] {
            let [x, y] = dispatch_size(n, wg, max).expect("fits");
            assert!(x <= max && y <= max);
            assert!(u64::from(x) * u64::from(y) * u64::from(wg) >= u64::from(n));
        }
        assert!(dispatch_size(u32::MAX, 1, 1000).is_err());
        assert!(dispatch_size(u32::MAX, 1, 65_535).is_err(), "more than 65 535² workgroups");
    }
}

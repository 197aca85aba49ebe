//! The `cluster_build` compute pass: per-tile lists, then per-cluster lists from them, each by
//! count → prefix sum → fill (see `shaders/cluster_build.wgsl`), producing per-cluster
//! `(offset, count)` ranges into one light-index list.

use super::CLUSTERS;
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName};

/// The six compute pipelines of the build (three per level), for one workgroup size.
pub struct ClusterBuildPipelines {
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
        layout: &wgpu::BindGroupLayout,
        workgroup_size: u32,
    ) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "cluster_build.wgsl")?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cluster_build"),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
        let constants = [("WORKGROUP_SIZE", workgroup_size as f64)];
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
}

impl Pass for ClusterBuildPass {
    fn name(&self) -> &'static str {
        "cluster_build"
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTERS]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters =
            ctx.clusters.ok_or_else(|| RenderError::Graph("cluster_build needs cluster resources".into()))?;
        let wg = self.workgroup_size.clamp(1, 1024);
        let layout = &clusters.build_layout;
        let pipelines = ctx
            .pipelines
            .get_or_create(wg as u64, || ClusterBuildPipelines::new(&ctx.gpu.device, layout, wg))?;
        let groups = clusters.params.dims[3].div_ceil(wg);
        // Level 1 runs one invocation per (tile, chunk of lights).
        let tile_entries = clusters.params.dims[0] * clusters.params.dims[1] * clusters.params.tile_chunks;
        let tile_groups = tile_entries.div_ceil(wg);
        let timestamps = ctx.compute_timestamps(true, true);
        {
            let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cluster_build"),
                timestamp_writes: timestamps,
            });
            pass.set_bind_group(0, &clusters.build_bind_group, &[]);
            // The six steps of the build (shaders/cluster_build.wgsl), in order; the scans run
            // as one workgroup.
            let steps = [
                (&pipelines.tile_count, tile_groups),
                (&pipelines.tile_scan, 1),
                (&pipelines.tile_fill, tile_groups),
                (&pipelines.count, groups),
                (&pipelines.scan, 1),
                (&pipelines.fill, groups),
            ];
            for (pipeline, workgroups) in steps {
                pass.set_pipeline(pipeline);
                pass.dispatch_workgroups(workgroups, 1, 1);
            }
        }
        clusters.copy_counters(ctx.encoder);
        Ok(())
    }
}

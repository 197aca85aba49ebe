//! The `cluster_depth` pass: per-cluster depth bounds (`shaders/cluster_depth.wgsl`). One
//! compute pass over the pixels, after the depth pre-pass or the G-buffer pass and before the
//! cluster build, records for every cluster the range of its pixels' shading distances; the
//! build then cuts each cluster to that range
//! ([`crate::snapshot::ClusterSettings::depth_bounds`]).

use super::gbuffer_layout::{DistancePipeline, DistanceSource};
use super::{CLUSTER_DEPTHS, DEPTH};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;

/// The pipeline key of [`ClusterDepthPass`]: where it reads the shading distances, and which
/// bindings group 0 (the view, which it shares with the shading passes) has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClusterDepthKey {
    /// Where the shading distances come from.
    pub source: DistanceSource,
    /// The defines of the view's group 0 (`SHADOWS`, `ENVIRONMENT`).
    pub view: crate::shaders::ShaderDefs,
}

impl PipelineKey for ClusterDepthKey {
    type Pipeline = DistancePipeline;
}

/// Writes every cluster's pixel depth range after the cluster ranges (zeroed first).
pub struct ClusterDepthPass {
    /// Where the shading distances come from.
    pub source: DistanceSource,
    /// The view's clear colour (the G-buffer read group holds it, as for deferred lighting,
    /// which shares that group's uniform).
    pub clear_color: [f32; 3],
}

impl NamedPass for ClusterDepthPass {
    const NAME: &'static str = "cluster_depth";
}

impl Pass for ClusterDepthPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        self.source.reads()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTER_DEPTHS]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx.require_clusters("cluster_depth")?;
        let scene = ctx.scene;
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(
            ClusterDepthKey { source: self.source, view: scene.view.defs() },
            |k| {
                DistancePipeline::new(
                    device,
                    "cluster_depth.wgsl",
                    "cluster_depth",
                    [&scene.view.layout, &clusters.bindings.depth_layout],
                    k.source,
                )
            },
        )?;
        let source = self.source.bind_group(ctx, &pipeline.source_layout, self.clear_color)?;
        // Zero the depth ranges (no pixel yet), which follow the cluster ranges.
        let ranges = clusters.buffers.ranges.buffer();
        let bytes = u64::from(clusters.params.dims[3]) * 8;
        ctx.encoder.clear_buffer(ranges, bytes, Some(bytes));
        let resources = [Binding::Buffer(&clusters.buffers.params), Binding::Buffer(ranges)];
        let depths = ctx.bind_group(&clusters.bindings.depth_layout, &resources);
        let depth = ctx.texture(DEPTH)?.texture();
        let groups = [depth.width().div_ceil(8), depth.height().div_ceil(8)];
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("cluster_depth"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(crate::layouts::SCENE_GROUP.index, &scene.view.bind_group, &[]);
        pass.set_bind_group(pipeline.source_layout.decl().index, &source, &[]);
        pass.set_bind_group(clusters.bindings.depth_layout.decl().index, &depths, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], 1);
        Ok(())
    }
}

/// Needed when the view bounds its clusters by depth (`PlanInputs::bounds_clusters_by_depth`):
/// from the G-buffer when it is shaded deferred, else from the depth pre-pass.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.bounds_clusters_by_depth() {
        let source = DistanceSource::of(p);
        out.push(Box::new(ClusterDepthPass { source, clear_color: p.settings().clear_color }));
    }
}

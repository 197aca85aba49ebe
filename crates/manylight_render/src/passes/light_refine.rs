//! The `light_refine` pass: refined light lists (`shaders/light_refine.wgsl`). One compute
//! pass after the cluster build keeps, for every block of `REFINE_EDGE` × `REFINE_EDGE`
//! pixels, the lights of its pixels' cluster lists that reach the box around their surface
//! positions; the shading passes read a block's list instead of its pixels' cluster lists
//! ([`crate::snapshot::ClusterSettings::refined_lists`]).

use super::CLUSTERS;
use super::gbuffer_layout::{DistancePipeline, DistanceSource};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::gpu_types::REFINE_GROUP_EDGE;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;

/// The pipeline key of [`LightRefinePass`]: where it reads the shading distances, and which
/// bindings group 0 (the view, which it shares with the shading passes) has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RefineKey {
    /// Where the shading distances come from.
    pub source: DistanceSource,
    /// The defines of the view's group 0 (`SHADOWS`, `ENVIRONMENT`).
    pub view: crate::shaders::ShaderDefs,
}

impl PipelineKey for RefineKey {
    type Pipeline = DistancePipeline;
}

/// Writes every pixel block's refined list and range after the cluster lists and ranges.
pub struct LightRefinePass {
    /// Where the shading distances come from.
    pub source: DistanceSource,
    /// The view's clear colour (the G-buffer read group holds it).
    pub clear_color: [f32; 3],
}

impl NamedPass for LightRefinePass {
    const NAME: &'static str = "light_refine";
}

impl Pass for LightRefinePass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        let mut reads = self.source.reads();
        reads.push(CLUSTERS);
        reads
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![CLUSTERS]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx.require_clusters("light_refine")?;
        let scene = ctx.scene;
        let device = &ctx.gpu.device;
        let pipeline =
            ctx.pipelines.get_or_create(RefineKey { source: self.source, view: scene.view.defs() }, |k| {
                DistancePipeline::new(
                    device,
                    "light_refine.wgsl",
                    "light_refine",
                    [&scene.view.layout, &clusters.bindings.refine_layout],
                    k.source,
                )
            })?;
        let source = self.source.bind_group(ctx, &pipeline.source_layout, self.clear_color)?;
        let lists = ctx.bind_group(
            &clusters.bindings.refine_layout,
            &[
                Binding::Buffer(&clusters.buffers.params),
                Binding::Buffer(clusters.buffers.spheres.buffer()),
                Binding::Buffer(clusters.buffers.ranges.buffer()),
                Binding::Buffer(clusters.buffers.indices.buffer()),
            ],
        );
        let p = &clusters.params;
        // Workgroups of 8 × 8 invocations, each refining REFINE_GROUP_EDGE² blocks.
        let per_workgroup = 8 * REFINE_GROUP_EDGE;
        let groups = [p.refine_blocks_x.div_ceil(per_workgroup), p.refine_blocks_y.div_ceil(per_workgroup)];
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light_refine"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(crate::layouts::SCENE_GROUP.index, &scene.view.bind_group, &[]);
        pass.set_bind_group(pipeline.source_layout.decl().index, &source, &[]);
        pass.set_bind_group(clusters.bindings.refine_layout.decl().index, &lists, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], 1);
        Ok(())
    }
}

/// Needed when the view refines its lists (`PlanInputs::refines_lists`): from the G-buffer when
/// it is shaded deferred, else from the depth pre-pass.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.refines_lists() {
        let source = DistanceSource::of(p);
        out.push(Box::new(LightRefinePass { source, clear_color: p.settings().clear_color }));
    }
}

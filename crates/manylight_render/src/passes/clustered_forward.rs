//! Clustered forward shading (Forward+ when the grid has one slice): each fragment walks its
//! cluster's light list instead of every light.

use super::common::{MeshPipelineDesc, clear_color, color_attachment, mesh_pipeline};
use super::scene_draw::{ScenePipeline, record_scene_pass, variant_pipelines};
use super::{CLUSTERS, DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::GroupLayout;
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT, SurfaceVariant};

/// Clustered shading's pipeline: with or without a depth pre-pass before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClusteredForwardKey {
    /// Depth tested `GreaterEqual` without writes, after the pre-pass.
    pub after_prepass: bool,
    /// Culling and alpha masking.
    pub variant: SurfaceVariant,
}

impl PipelineKey for ClusteredForwardKey {
    type Pipeline = ClusteredForwardPipeline;
}

/// The pipeline of [`ClusteredForwardPass`] (one per depth mode).
pub struct ClusteredForwardPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl ClusteredForwardPipeline {
    fn new(
        device: &wgpu::Device,
        layouts: [&GroupLayout; 3],
        key: &ClusteredForwardKey,
    ) -> Result<Self, RenderError> {
        let after_prepass = key.after_prepass;
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "clustered_forward",
                shader: "clustered_forward.wgsl",
                layouts: &layouts,
                fragment: Some("fs_main"),
                targets: &[HDR_FORMAT],
                // After a pre-pass only the nearest surface passes (reverse-Z: greater-equal).
                depth_write: !after_prepass,
                depth_compare: if after_prepass {
                    wgpu::CompareFunction::GreaterEqual
                } else {
                    wgpu::CompareFunction::Greater
                },
                variant: key.variant,
            },
        )?;
        Ok(ClusteredForwardPipeline { pipeline })
    }
}

impl ScenePipeline for ClusteredForwardPipeline {
    fn render_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
    }
}

/// Shades the scene with per-cluster light lists into [`HDR`].
pub struct ClusteredForwardPass {
    /// Linear clear colour of the HDR target.
    pub clear_color: [f32; 3],
    /// True when a depth pre-pass wrote [`DEPTH`] already.
    pub after_prepass: bool,
    /// Reads the shadow atlas: the frame's lights cast shadows ([`PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl NamedPass for ClusteredForwardPass {
    const NAME: &'static str = "clustered_forward";
}

impl Pass for ClusteredForwardPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        let mut reads = if self.after_prepass { vec![CLUSTERS, DEPTH] } else { vec![CLUSTERS] };
        reads.extend(self.shadows.then_some(super::SHADOW_ATLAS));
        reads
    }
    fn writes(&self) -> Vec<ResourceName> {
        if self.after_prepass { vec![HDR] } else { vec![HDR, DEPTH] }
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let mut specs = vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }];
        if !self.after_prepass {
            specs.push(TextureSpec {
                name: DEPTH,
                format: DEPTH_FORMAT,
                usage: super::DEPTH_USAGE,
                scale: 1.0,
            });
        }
        specs
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let clusters = ctx.require_clusters("clustered_forward")?;
        let layouts = [&scene.view.layout, &scene.assets.material_layout, &clusters.bindings.lists_layout];
        let after = self.after_prepass;
        let pipelines = variant_pipelines(
            ctx,
            |variant| ClusteredForwardKey { after_prepass: after, variant },
            |k| ClusteredForwardPipeline::new(&ctx.gpu.device, layouts, k),
        )?;
        let color = color_attachment(ctx.texture(HDR)?, clear_color(self.clear_color));
        let depth = ctx.texture(DEPTH)?;
        let extra = [&clusters.bindings.lists_group];
        record_scene_pass(ctx, "clustered_forward", &[color], depth, !after, &pipelines, &extra);
        Ok(())
    }
}

/// Needed for Forward+ and clustered forward with lights.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.shades_with_clusters() && !p.shades_deferred() {
        out.push(Box::new(ClusteredForwardPass {
            clear_color: p.settings().clear_color,
            after_prepass: p.runs_depth_prepass(),
            shadows: p.shades_shadows(),
        }));
    }
}

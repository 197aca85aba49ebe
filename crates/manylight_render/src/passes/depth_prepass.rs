//! Depth pre-pass: lays down depth so the lighting pass shades each visible pixel once.

use super::DEPTH;
use super::common::{MeshPipelineDesc, mesh_pipeline};
use super::scene_draw::{ScenePipeline, record_scene_pass, variant_pipelines};
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, SceneResources, SurfaceVariant};

/// The depth pre-pass's pipeline: one per surface variant (alpha-masked ones run a fragment
/// stage that discards, the others none).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthPrepassKey(pub SurfaceVariant);

impl PipelineKey for DepthPrepassKey {
    type Pipeline = DepthPrepassPipeline;
}

/// The pipeline of [`DepthPrepass`].
pub struct DepthPrepassPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl DepthPrepassPipeline {
    fn new(
        device: &wgpu::Device,
        scene: &SceneResources,
        variant: SurfaceVariant,
    ) -> Result<Self, RenderError> {
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "depth_prepass",
                shader: "depth_prepass.wgsl",
                layouts: &[&scene.view_layout, &scene.material_layout],
                fragment: variant.alpha_mask.then_some("fs_mask"),
                targets: &[],
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Greater,
                variant,
            },
        )?;
        Ok(DepthPrepassPipeline { pipeline })
    }
}

impl ScenePipeline for DepthPrepassPipeline {
    fn render_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
    }
}

/// Writes [`DEPTH`] for every drawn instance.
pub struct DepthPrepass;

impl Pass for DepthPrepass {
    fn name(&self) -> &'static str {
        "depth_prepass"
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![DEPTH]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        vec![TextureSpec { name: DEPTH, format: DEPTH_FORMAT, usage: super::DEPTH_USAGE, scale: 1.0 }]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let pipelines = variant_pipelines(ctx, DepthPrepassKey, |k| {
            DepthPrepassPipeline::new(&ctx.gpu.device, scene, k.0)
        })?;
        let depth = ctx.texture(DEPTH)?;
        record_scene_pass(ctx, "depth_prepass", &[], depth, true, &pipelines, &[]);
        Ok(())
    }
}

/// Needed before forward clustered shading that asks for it (Forward+ always), and for the
/// depth debug view.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.runs_depth_prepass() || p.settings().debug_view == crate::snapshot::DebugViewMode::Depth {
        out.push(Box::new(DepthPrepass));
    }
}

//! Depth pre-pass: lays down depth so the lighting pass shades each visible pixel once.

use super::DEPTH;
use super::common::{MeshPipelineDesc, mesh_pipeline};
use super::scene_draw::record_scene_pass;
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, SceneResources};

/// The depth pre-pass's pipeline (there is one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthPrepassKey;

impl PipelineKey for DepthPrepassKey {
    type Pipeline = DepthPrepassPipeline;
}

/// The pipeline of [`DepthPrepass`].
pub struct DepthPrepassPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl DepthPrepassPipeline {
    fn new(device: &wgpu::Device, scene: &SceneResources) -> Result<Self, RenderError> {
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "depth_prepass",
                shader: "depth_prepass.wgsl",
                layouts: &[&scene.view_layout, &scene.material_layout],
                fragment: None,
                targets: &[],
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Greater,
            },
        )?;
        Ok(DepthPrepassPipeline { pipeline })
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
        let pipeline = ctx
            .pipelines
            .get_or_create(DepthPrepassKey, |_| DepthPrepassPipeline::new(&ctx.gpu.device, scene))?;
        let depth = ctx.texture(DEPTH)?;
        record_scene_pass(ctx, "depth_prepass", &[], depth, true, &pipeline.pipeline, &[]);
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

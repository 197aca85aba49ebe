//! Naive forward pass: draws every instance, evaluating every light per fragment, into the
//! HDR target with a reverse-Z depth test.

use super::common::{MeshPipelineDesc, clear_color, color_attachment, mesh_pipeline};
use super::scene_draw::{ScenePipeline, record_scene_pass, variant_pipelines};
use super::{DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT, SceneResources, SurfaceVariant};

/// Naive forward's pipeline: one per surface variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ForwardKey(pub SurfaceVariant);

impl PipelineKey for ForwardKey {
    type Pipeline = ForwardPipeline;
}

/// The pipeline of [`ForwardPass`].
pub struct ForwardPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl ForwardPipeline {
    fn new(
        device: &wgpu::Device,
        scene: &SceneResources,
        variant: SurfaceVariant,
    ) -> Result<Self, RenderError> {
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "forward",
                shader: "forward.wgsl",
                layouts: &[&scene.view.layout, &scene.assets.material_layout],
                fragment: Some("fs_main"),
                targets: &[HDR_FORMAT],
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Greater,
                variant,
            },
        )?;
        Ok(ForwardPipeline { pipeline })
    }
}

impl ScenePipeline for ForwardPipeline {
    fn render_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
    }
}

/// Draws the scene with every light evaluated per fragment.
pub struct ForwardPass {
    /// Linear clear colour of the HDR target.
    pub clear_color: [f32; 3],
    /// Reads the shadow atlas: the frame's lights cast shadows ([`PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl NamedPass for ForwardPass {
    const NAME: &'static str = "forward";
}

impl Pass for ForwardPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        if self.shadows { vec![super::SHADOW_ATLAS] } else { Vec::new() }
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR, DEPTH]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        vec![
            TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 },
            TextureSpec { name: DEPTH, format: DEPTH_FORMAT, usage: super::DEPTH_USAGE, scale: 1.0 },
        ]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let pipelines =
            variant_pipelines(ctx, ForwardKey, |k| ForwardPipeline::new(&ctx.gpu.device, scene, k.0))?;
        let color = color_attachment(ctx.texture(HDR)?, clear_color(self.clear_color));
        let depth = ctx.texture(DEPTH)?;
        record_scene_pass(ctx, "forward", &[color], depth, true, &pipelines, &[]);
        Ok(())
    }
}

/// Needed for naive forward, and for every pipeline when there are no lights to assign (it
/// draws the ambient), unless a debug view replaces the image.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if !p.shades_with_clusters() && !p.shades_deferred() && !p.replaces_shading() {
        out.push(Box::new(ForwardPass {
            clear_color: p.settings().clear_color,
            shadows: p.shades_shadows(),
        }));
    }
}

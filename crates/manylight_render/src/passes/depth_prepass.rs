//! Depth pre-pass: lays down depth so the lighting pass shades each visible pixel once.

use super::common::{MeshPipelineDesc, color_attachment, mesh_pipeline};
use super::scene_draw::{ScenePipeline, record_scene_pass, variant_pipelines};
use super::{DEPTH, SHADING_DISTANCE};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, SceneResources, SurfaceVariant};

/// The depth pre-pass's pipeline: one per surface variant (alpha-masked ones run a fragment
/// stage that discards, the others none) and per whether it writes the shading distance for
/// per-cluster depth bounds and refined light lists (then every variant runs a fragment stage).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthPrepassKey {
    /// Culling and alpha masking.
    pub variant: SurfaceVariant,
    /// Writes [`SHADING_DISTANCE`].
    pub distance: bool,
}

impl PipelineKey for DepthPrepassKey {
    type Pipeline = DepthPrepassPipeline;
}

/// The pipeline of [`DepthPrepass`].
pub struct DepthPrepassPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl DepthPrepassPipeline {
    fn new(device: &wgpu::Device, scene: &SceneResources, key: DepthPrepassKey) -> Result<Self, RenderError> {
        let variant = key.variant;
        let fragment = match (key.distance, variant.alpha_mask) {
            (false, false) => None,
            (false, true) => Some("fs_mask"),
            (true, false) => Some("fs_distance"),
            (true, true) => Some("fs_mask_distance"),
        };
        let targets: &[wgpu::TextureFormat] = if key.distance { &[SHADING_DISTANCE_FORMAT] } else { &[] };
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "depth_prepass",
                shader: "depth_prepass.wgsl",
                layouts: &[&scene.view.layout, &scene.assets.material_layout],
                fragment,
                targets,
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

/// Format of [`SHADING_DISTANCE`].
pub const SHADING_DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Writes [`DEPTH`] for every drawn instance, and with `distance` each pixel's shading distance
/// ([`SHADING_DISTANCE`], for per-cluster depth bounds and refined light lists).
pub struct DepthPrepass {
    /// Also writes [`SHADING_DISTANCE`].
    pub distance: bool,
}

impl NamedPass for DepthPrepass {
    const NAME: &'static str = "depth_prepass";
}

impl Pass for DepthPrepass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        if self.distance { vec![DEPTH, SHADING_DISTANCE] } else { vec![DEPTH] }
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let depth = TextureSpec { name: DEPTH, format: DEPTH_FORMAT, usage: super::DEPTH_USAGE, scale: 1.0 };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let distance =
            TextureSpec { name: SHADING_DISTANCE, format: SHADING_DISTANCE_FORMAT, usage, scale: 1.0 };
        if self.distance { vec![depth, distance] } else { vec![depth] }
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let distance = self.distance;
        let pipelines = variant_pipelines(
            ctx,
            |variant| DepthPrepassKey { variant, distance },
            |k| DepthPrepassPipeline::new(&ctx.gpu.device, scene, *k),
        )?;
        let depth = ctx.texture(DEPTH)?;
        let colors = if distance {
            vec![color_attachment(ctx.texture(SHADING_DISTANCE)?, wgpu::Color::TRANSPARENT)]
        } else {
            Vec::new()
        };
        record_scene_pass(ctx, "depth_prepass", &colors, depth, true, &pipelines, &[]);
        Ok(())
    }
}

/// Needed before forward clustered shading that asks for it (Forward+ always), and for the
/// depth debug view.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.runs_depth_prepass() || p.settings().debug_view == crate::snapshot::DebugViewMode::Depth {
        out.push(Box::new(DepthPrepass { distance: p.prepass_writes_distance() }));
    }
}

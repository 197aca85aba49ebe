//! Tone map: HDR colour × exposure through the ACES fit into the output (sRGB) target.

use super::HDR;
use super::common::{draw_fullscreen, fullscreen_pipeline};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, OUTPUT, Pass, PassContext, ResourceName};
use crate::layouts::{GroupLayout, TONEMAP_GROUP};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;

/// The tone map's pipeline: one per output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TonemapKey {
    /// Format of [`OUTPUT`].
    pub format: wgpu::TextureFormat,
}

impl PipelineKey for TonemapKey {
    type Pipeline = TonemapPipeline;
}

/// The pipeline of [`TonemapPass`] for one output format.
pub struct TonemapPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl TonemapPipeline {
    fn new(device: &wgpu::Device, output: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let layout = TONEMAP_GROUP.create_layout(device, Default::default());
        let pipeline = fullscreen_pipeline(device, "tonemap", "tonemap.wgsl", &[&layout], "fs_main", output)?;
        Ok(TonemapPipeline { pipeline, layout })
    }
}

/// Writes the tone-mapped image to [`OUTPUT`] and counts the pixels whose HDR colour is not
/// finite (shown black) into [`SceneResources::nonfinite`](crate::resources::SceneResources).
pub struct TonemapPass;

impl NamedPass for TonemapPass {
    const NAME: &'static str = "tonemap";
}

impl Pass for TonemapPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![OUTPUT]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let format = ctx.output_format;
        let device = &ctx.gpu.device;
        let pipeline =
            ctx.pipelines.get_or_create(TonemapKey { format }, |k| TonemapPipeline::new(device, k.format))?;
        let bind_group = ctx.bind_group(
            &pipeline.layout,
            &[
                Binding::Buffer(&ctx.scene.view.buffer),
                Binding::Texture(ctx.texture(HDR)?),
                Binding::Buffer(&ctx.scene.nonfinite.counter),
            ],
        );
        let output = ctx.texture(OUTPUT)?;
        ctx.encoder.clear_buffer(&ctx.scene.nonfinite.counter, 0, None);
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(ctx.encoder, "tonemap", output, timestamps, &pipeline.pipeline, &[&bind_group]);
        Ok(())
    }
}

/// Needed unless a debug view replaces the image.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    if p.shows_image() {
        out.push(Box::new(TonemapPass));
    }
}

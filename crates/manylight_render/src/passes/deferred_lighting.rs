//! Clustered deferred lighting: one full-screen pass reads the G-buffer and walks each pixel's
//! cluster list into [`HDR`].

use super::common::{FullscreenPipelineDesc, draw_fullscreen, fullscreen_pipeline_with_defs};
use super::gbuffer_layout::{codec_constants, gbuffer_read_bind_group, gbuffer_read_layout, gbuffer_reads};
use super::{CLUSTERS, HDR};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::GroupLayout;
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::HDR_FORMAT;
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;

/// Deferred lighting's pipelines: per G-buffer layout and normal codec.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DeferredLightingKey {
    /// The G-buffer read.
    pub layout: GBufferLayout,
    /// Its normal codec.
    pub codec: NormalCodec,
    /// The defines of the view's group 0 (`SHADOWS`, `ENVIRONMENT`): its bindings.
    pub view: crate::shaders::ShaderDefs,
}

impl PipelineKey for DeferredLightingKey {
    type Pipeline = DeferredLightingPipeline;
}

/// The pipeline of [`DeferredLightingPass`] for one layout.
pub struct DeferredLightingPipeline {
    pipeline: wgpu::RenderPipeline,
    gbuffer_layout: GroupLayout,
}

impl DeferredLightingPipeline {
    fn new(
        device: &wgpu::Device,
        view_layout: &GroupLayout,
        cluster_layout: &GroupLayout,
        layout: GBufferLayout,
        codec: NormalCodec,
        defs: crate::shaders::ShaderDefs,
    ) -> Result<Self, RenderError> {
        let gbuffer_layout = gbuffer_read_layout(device, layout);
        let layouts = [view_layout, &gbuffer_layout, cluster_layout];
        let constants = codec_constants(codec);
        let pipeline = fullscreen_pipeline_with_defs(
            device,
            &FullscreenPipelineDesc {
                label: "deferred_lighting",
                shader: "deferred_lighting.wgsl",
                layouts: &layouts,
                fragment: "fs_main",
                output: HDR_FORMAT,
                blend: None,
                depth: None,
                constants: &constants,
            },
            defs.with_gbuffer(layout),
        )?;
        Ok(DeferredLightingPipeline { pipeline, gbuffer_layout })
    }
}

/// Lights the G-buffer with the pixels' cluster lists.
pub struct DeferredLightingPass {
    /// The G-buffer layout to read.
    pub layout: GBufferLayout,
    /// Normal codec of the `Packed` and `Compact` layouts.
    pub codec: NormalCodec,
    /// Linear colour of pixels no geometry covers.
    pub clear_color: [f32; 3],
    /// Reads the shadow atlas: the frame's lights cast shadows ([`PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl NamedPass for DeferredLightingPass {
    const NAME: &'static str = "deferred_lighting";
}

impl Pass for DeferredLightingPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        gbuffer_reads(self.layout)
            .chain([CLUSTERS])
            .chain(self.shadows.then_some(super::SHADOW_ATLAS))
            .collect()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx.require_clusters("deferred_lighting")?;
        let device = &ctx.gpu.device;
        let (layout, codec) = (self.layout, self.codec);
        let view_layout = &ctx.scene.view.layout;
        let pipeline = ctx.pipelines.get_or_create(
            DeferredLightingKey { layout, codec, view: ctx.scene.view.defs() },
            |k| {
                let defs = k.view;
                DeferredLightingPipeline::new(
                    device,
                    view_layout,
                    &clusters.bindings.lists_layout,
                    k.layout,
                    k.codec,
                    defs,
                )
            },
        )?;
        let gbuffer = gbuffer_read_bind_group(ctx, &pipeline.gbuffer_layout, layout, self.clear_color)?;
        let hdr = ctx.texture(HDR)?;
        let timestamps = ctx.render_timestamps(true, true);
        let groups = [&ctx.scene.view.bind_group, &gbuffer, &clusters.bindings.lists_group];
        draw_fullscreen(ctx.encoder, "deferred_lighting", hdr, timestamps, &pipeline.pipeline, &groups);
        Ok(())
    }
}

/// Needed for clustered deferred with lights, and for tiled deferred when the frame brings its
/// own per-pixel lists (they are no tiles' lists).
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    use crate::snapshot::PipelineKind;
    let s = p.settings();
    let lit_here = match s.pipeline {
        PipelineKind::ClusteredDeferred => true,
        PipelineKind::TiledDeferred => p.has_pixel_lists,
        _ => false,
    };
    if p.shades_deferred() && lit_here {
        let (layout, codec, clear_color) = (s.gbuffer, s.normal_codec, s.clear_color);
        out.push(Box::new(DeferredLightingPass { layout, codec, clear_color, shadows: p.shades_shadows() }));
    }
}

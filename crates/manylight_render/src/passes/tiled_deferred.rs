//! Tiled deferred lighting in compute (`shaders/tiled_deferred.wgsl`): one workgroup per tile
//! of the light grid cuts the tile's list to its pixels' depths (range and 2.5D mask) in
//! workgroup memory and shades its pixels from it into [`HDR`].

use super::common::compute_pipeline_with_defs;
use super::gbuffer_layout::{codec_constants, gbuffer_read_bind_group, gbuffer_read_layout, gbuffer_reads};
use super::{CLUSTERS, HDR};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::{GroupLayout, TILED_DEFERRED_OUTPUT_GROUP};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::HDR_FORMAT;
use crate::snapshot::{GBufferLayout, PipelineKind};
use manylight_core::codec::NormalCodec;

/// Tiled deferred's pipelines: per G-buffer layout and normal codec.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TiledDeferredKey {
    /// The G-buffer read.
    pub layout: GBufferLayout,
    /// Its normal codec.
    pub codec: NormalCodec,
    /// The defines of the view's group 0 (`SHADOWS`, `ENVIRONMENT`): its bindings.
    pub view: crate::shaders::ShaderDefs,
}

impl PipelineKey for TiledDeferredKey {
    type Pipeline = TiledDeferredPipeline;
}

/// The compute pipeline of [`TiledDeferredPass`] for one layout.
pub struct TiledDeferredPipeline {
    pipeline: wgpu::ComputePipeline,
    gbuffer_layout: GroupLayout,
    output_layout: GroupLayout,
}

impl TiledDeferredPipeline {
    fn new(
        device: &wgpu::Device,
        view_layout: &GroupLayout,
        cluster_layout: &GroupLayout,
        layout: GBufferLayout,
        codec: NormalCodec,
        defs: crate::shaders::ShaderDefs,
    ) -> Result<Self, RenderError> {
        let gbuffer_layout = gbuffer_read_layout(device, layout);
        let output_layout = TILED_DEFERRED_OUTPUT_GROUP.create_layout(device, defs);
        let layouts = [view_layout, &gbuffer_layout, cluster_layout, &output_layout];
        let constants = codec_constants(codec);
        let pipeline = compute_pipeline_with_defs(
            device,
            "tiled_deferred",
            "tiled_deferred.wgsl",
            &layouts,
            "cs_main",
            &constants,
            defs.with_gbuffer(layout),
        )?;
        Ok(TiledDeferredPipeline { pipeline, gbuffer_layout, output_layout })
    }
}

/// Lights the G-buffer tile by tile in compute.
pub struct TiledDeferredPass {
    /// The G-buffer layout to read.
    pub layout: GBufferLayout,
    /// Normal codec of the `Packed` and `Compact` layouts.
    pub codec: NormalCodec,
    /// Linear colour of pixels no geometry covers.
    pub clear_color: [f32; 3],
    /// Reads the shadow atlas: the frame's lights cast shadows ([`PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl NamedPass for TiledDeferredPass {
    const NAME: &'static str = "tiled_deferred";
}

impl Pass for TiledDeferredPass {
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
        // Written by the compute pass; drawn over by the transparent pass; read by post.
        let usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING;
        vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }]
    }
    fn is_compute(&self) -> bool {
        true
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx.require_clusters("tiled_deferred")?;
        let [tiles_x, tiles_y, slices, _] = clusters.params.dims;
        if slices != 1 {
            return Err(RenderError::Graph(format!(
                "tiled_deferred needs a grid of one depth slice, got {slices}"
            )));
        }
        let max = ctx.gpu.device.limits().max_compute_workgroups_per_dimension;
        if tiles_x > max || tiles_y > max {
            return Err(RenderError::UnsupportedSettings(format!(
                "tiled deferred runs a workgroup per tile: {tiles_x}×{tiles_y} tiles exceed \
                 max_compute_workgroups_per_dimension ({max})"
            )));
        }
        let device = &ctx.gpu.device;
        let (layout, codec) = (self.layout, self.codec);
        let view_layout = &ctx.scene.view.layout;
        let pipeline = ctx.pipelines.get_or_create(
            TiledDeferredKey { layout, codec, view: ctx.scene.view.defs() },
            |k| {
                let defs = k.view;
                TiledDeferredPipeline::new(
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
        let output = ctx.bind_group(&pipeline.output_layout, &[Binding::Texture(ctx.texture(HDR)?)]);
        let timestamps = ctx.compute_timestamps(true, true);
        let mut pass = ctx.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tiled_deferred"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipeline.pipeline);
        for (i, group) in [&ctx.scene.view.bind_group, &gbuffer, &clusters.bindings.lists_group, &output]
            .into_iter()
            .enumerate()
        {
            pass.set_bind_group(i as u32, group, &[]);
        }
        pass.dispatch_workgroups(tiles_x, tiles_y, 1);
        Ok(())
    }
}

/// Needed for tiled deferred with lights and tile lists of its own (a frame that brings
/// per-pixel lists is lit by the full-screen deferred pass instead: `deferred_lighting`).
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    let s = p.settings();
    if p.shades_deferred() && s.pipeline == PipelineKind::TiledDeferred && !p.has_pixel_lists {
        let (layout, codec, clear_color) = (s.gbuffer, s.normal_codec, s.clear_color);
        out.push(Box::new(TiledDeferredPass { layout, codec, clear_color, shadows: p.shades_shadows() }));
    }
}

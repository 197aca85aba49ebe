//! Clustered deferred lighting: one full-screen pass reads the G-buffer and walks each pixel's
//! cluster list into [`HDR`].

use super::common::{
    FullscreenPipelineDesc, draw_fullscreen, fullscreen_pipeline_desc, texture_entry, uniform_entry,
};
use super::gbuffer::{codec_constants, fragment_entry, targets, variant_key};
use super::{CLUSTERS, DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::resources::HDR_FORMAT;
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;
use wgpu::util::DeviceExt;

/// The pipeline of [`DeferredLightingPass`] for one layout.
pub struct DeferredLightingPipeline {
    pipeline: wgpu::RenderPipeline,
    gbuffer_layout: wgpu::BindGroupLayout,
}

/// Binding number of each G-buffer target in `shaders/common/gbuffer_read.wgsl`, group 1.
fn binding_of(name: ResourceName) -> u32 {
    match name {
        super::GBUFFER_POSITION => 0,
        super::GBUFFER_NORMAL => 1,
        super::GBUFFER_ALBEDO => 2,
        super::GBUFFER_PACKED_ALBEDO => 6,
        super::GBUFFER_PACKED_POSITION => 7,
        _ => 3,
    }
}

/// Group 1 of `common/gbuffer_read.wgsl` for a layout: its targets, depth and the clear colour.
pub fn gbuffer_read_layout(device: &wgpu::Device, layout: GBufferLayout) -> wgpu::BindGroupLayout {
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = targets(layout)
        .iter()
        .map(|&(name, _)| {
            let sample = if name == super::GBUFFER_COMPACT { wgpu::TextureSampleType::Uint } else { float };
            texture_entry(binding_of(name), sample)
        })
        .collect();
    entries.push(texture_entry(4, wgpu::TextureSampleType::Depth));
    entries.push(uniform_entry(5, wgpu::ShaderStages::FRAGMENT));
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gbuffer_read"),
        entries: &entries,
    })
}

/// A bind group for [`gbuffer_read_layout`]: the frame's G-buffer targets, depth and
/// `clear_color` (linear RGB).
pub fn gbuffer_read_bind_group(
    ctx: &PassContext<'_>,
    bind_group_layout: &wgpu::BindGroupLayout,
    layout: GBufferLayout,
    clear_color: [f32; 3],
) -> Result<wgpu::BindGroup, RenderError> {
    let device = &ctx.gpu.device;
    let [r, g, b] = clear_color;
    let clear = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("gbuffer_clear_color"),
        contents: bytemuck::cast_slice(&[r, g, b, 1.0f32]),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let mut entries = Vec::new();
    for &(name, _) in targets(layout) {
        entries.push(wgpu::BindGroupEntry {
            binding: binding_of(name),
            resource: wgpu::BindingResource::TextureView(ctx.texture(name)?),
        });
    }
    entries.push(wgpu::BindGroupEntry {
        binding: 4,
        resource: wgpu::BindingResource::TextureView(ctx.texture(DEPTH)?),
    });
    entries.push(wgpu::BindGroupEntry { binding: 5, resource: clear.as_entire_binding() });
    Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("gbuffer_read"),
        layout: bind_group_layout,
        entries: &entries,
    }))
}

impl DeferredLightingPipeline {
    fn new(
        device: &wgpu::Device,
        view_layout: &wgpu::BindGroupLayout,
        cluster_layout: &wgpu::BindGroupLayout,
        layout: GBufferLayout,
        codec: NormalCodec,
    ) -> Result<Self, RenderError> {
        let gbuffer_layout = gbuffer_read_layout(device, layout);
        let layouts = [view_layout, &gbuffer_layout, cluster_layout];
        let constants = codec_constants(codec);
        let pipeline = fullscreen_pipeline_desc(
            device,
            &FullscreenPipelineDesc {
                label: "deferred_lighting",
                shader: "deferred_lighting.wgsl",
                layouts: &layouts,
                fragment: fragment_entry(layout),
                output: HDR_FORMAT,
                blend: None,
                depth: None,
                constants: &constants,
            },
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
}

impl Pass for DeferredLightingPass {
    fn name(&self) -> &'static str {
        "deferred_lighting"
    }
    fn reads(&self) -> Vec<ResourceName> {
        targets(self.layout).iter().map(|&(name, _)| name).chain([DEPTH, CLUSTERS]).collect()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters = ctx
            .clusters
            .ok_or_else(|| RenderError::Graph("deferred_lighting needs cluster resources".into()))?;
        let device = &ctx.gpu.device;
        let (layout, codec) = (self.layout, self.codec);
        let view_layout = &ctx.scene.view_layout;
        let pipeline = ctx.pipelines.get_or_create(variant_key(layout, codec), || {
            DeferredLightingPipeline::new(device, view_layout, &clusters.shading_layout, layout, codec)
        })?;
        let gbuffer = gbuffer_read_bind_group(ctx, &pipeline.gbuffer_layout, layout, self.clear_color)?;
        let hdr = ctx.texture(HDR)?;
        let timestamps = ctx.render_timestamps(true, true);
        let groups = [&ctx.scene.view_bind_group, &gbuffer, &clusters.shading_bind_group];
        draw_fullscreen(ctx.encoder, "deferred_lighting", hdr, timestamps, &pipeline.pipeline, &groups);
        Ok(())
    }
}

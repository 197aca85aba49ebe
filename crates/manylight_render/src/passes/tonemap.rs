//! Tone map: HDR colour × exposure through the ACES fit into the output (sRGB) target.

use super::HDR;
use crate::context::RenderError;
use crate::graph::{OUTPUT, Pass, PassContext, ResourceName};
use crate::pipelines::format_key;

/// The pipeline of [`TonemapPass`] for one output format.
pub struct TonemapPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl TonemapPipeline {
    fn new(device: &wgpu::Device, output: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "tonemap.wgsl")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tonemap"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tonemap"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("fullscreen_vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: output,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(TonemapPipeline { pipeline, layout })
    }
}

/// Writes the tone-mapped image to [`OUTPUT`].
pub struct TonemapPass;

impl Pass for TonemapPass {
    fn name(&self) -> &'static str {
        "tonemap"
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
            ctx.pipelines.get_or_create(format_key(format), || TonemapPipeline::new(device, format))?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &pipeline.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ctx.scene.view_buffer.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(ctx.texture(HDR)?),
                },
            ],
        });
        let output = ctx.texture(OUTPUT)?;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: output,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}

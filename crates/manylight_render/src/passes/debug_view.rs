//! Debug view: replaces tone mapping with the per-pixel light count of the pixel's cluster (a
//! heatmap with a legend bar) or the cluster x / y / z index.

use super::{CLUSTERS, DEPTH};
use crate::context::RenderError;
use crate::graph::{OUTPUT, Pass, PassContext, ResourceName};
use crate::pipelines::format_key;
use crate::snapshot::DebugView;
use wgpu::util::DeviceExt;

/// The pipeline of [`DebugViewPass`] for one output format.
pub struct DebugViewPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl DebugViewPipeline {
    fn new(device: &wgpu::Device, output: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "debug_view.wgsl")?;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let uniform = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: fragment,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("debug_view"),
            entries: &[
                uniform(0),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: fragment,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                uniform(2),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: fragment,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                uniform(4),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("debug_view"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("debug_view"),
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
        Ok(DebugViewPipeline { pipeline, layout })
    }
}

/// Writes a debug visualisation to [`OUTPUT`].
pub struct DebugViewPass {
    /// What to show (not `DebugView::None`).
    pub view: DebugView,
    /// Light count drawn as the hottest colour of the heatmap.
    pub heatmap_max: u32,
}

impl Pass for DebugViewPass {
    fn name(&self) -> &'static str {
        "debug_view"
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![DEPTH, CLUSTERS]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![OUTPUT]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let clusters =
            ctx.clusters.ok_or_else(|| RenderError::Graph("debug_view needs cluster resources".into()))?;
        let format = ctx.output_format;
        let device = &ctx.gpu.device;
        let pipeline =
            ctx.pipelines.get_or_create(format_key(format), || DebugViewPipeline::new(device, format))?;
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("debug_view_params"),
            contents: bytemuck::cast_slice(&[self.view.gpu_id(), self.heatmap_max.max(1), 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("debug_view"),
            layout: &pipeline.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ctx.scene.view_buffer.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(ctx.texture(DEPTH)?),
                },
                wgpu::BindGroupEntry { binding: 2, resource: clusters.params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: clusters.ranges.buffer().as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: params.as_entire_binding() },
            ],
        });
        let output = ctx.texture(OUTPUT)?;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("debug_view"),
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

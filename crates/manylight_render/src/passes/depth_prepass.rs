//! Depth pre-pass: lays down depth so the lighting pass shades each visible pixel once.

use super::DEPTH;
use super::forward::{draw_scene, vertex_layout};
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::resources::{DEPTH_FORMAT, SceneResources};

/// The pipeline of [`DepthPrepass`].
pub struct DepthPrepassPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl DepthPrepassPipeline {
    fn new(device: &wgpu::Device, scene: &SceneResources) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "depth_prepass.wgsl")?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth_prepass"),
            bind_group_layouts: &[Some(&scene.view_layout), Some(&scene.material_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth_prepass"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
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
        let pipeline =
            ctx.pipelines.get_or_create(0, || DepthPrepassPipeline::new(&ctx.gpu.device, scene))?;
        let depth = ctx.texture(DEPTH)?;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth_prepass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(0, &scene.view_bind_group, &[]);
        draw_scene(&mut pass, scene);
        Ok(())
    }
}

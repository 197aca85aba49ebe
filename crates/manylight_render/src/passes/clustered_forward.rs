//! Clustered forward shading (Forward+ when the grid has one slice): each fragment walks its
//! cluster's light list instead of every light.

use super::forward::{draw_scene, vertex_layout};
use super::{CLUSTERS, DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT};

/// The pipeline of [`ClusteredForwardPass`] (one per depth mode).
pub struct ClusteredForwardPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl ClusteredForwardPipeline {
    fn new(
        device: &wgpu::Device,
        layouts: [&wgpu::BindGroupLayout; 3],
        after_prepass: bool,
    ) -> Result<Self, RenderError> {
        let module = crate::shaders::create_module(device, "clustered_forward.wgsl")?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("clustered_forward"),
            bind_group_layouts: &layouts.map(Some),
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("clustered_forward"),
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
                // After a pre-pass only the nearest surface passes (reverse-Z: greater-equal).
                depth_write_enabled: Some(!after_prepass),
                depth_compare: Some(if after_prepass {
                    wgpu::CompareFunction::GreaterEqual
                } else {
                    wgpu::CompareFunction::Greater
                }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: HDR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(ClusteredForwardPipeline { pipeline })
    }
}

/// Shades the scene with per-cluster light lists into [`HDR`].
pub struct ClusteredForwardPass {
    /// Linear clear colour of the HDR target.
    pub clear_color: [f32; 3],
    /// True when a depth pre-pass wrote [`DEPTH`] already.
    pub after_prepass: bool,
}

impl Pass for ClusteredForwardPass {
    fn name(&self) -> &'static str {
        "clustered_forward"
    }
    fn reads(&self) -> Vec<ResourceName> {
        if self.after_prepass { vec![CLUSTERS, DEPTH] } else { vec![CLUSTERS] }
    }
    fn writes(&self) -> Vec<ResourceName> {
        if self.after_prepass { vec![HDR] } else { vec![HDR, DEPTH] }
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let mut specs = vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }];
        if !self.after_prepass {
            specs.push(TextureSpec {
                name: DEPTH,
                format: DEPTH_FORMAT,
                usage: super::DEPTH_USAGE,
                scale: 1.0,
            });
        }
        specs
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let clusters = ctx
            .clusters
            .ok_or_else(|| RenderError::Graph("clustered_forward needs cluster resources".into()))?;
        let layouts = [&scene.view_layout, &scene.material_layout, &clusters.shading_layout];
        let after = self.after_prepass;
        let pipeline = ctx
            .pipelines
            .get_or_create(after as u64, || ClusteredForwardPipeline::new(&ctx.gpu.device, layouts, after))?;
        let hdr = ctx.texture(HDR)?;
        let depth = ctx.texture(DEPTH)?;
        let timestamps = ctx.render_timestamps(true, true);
        let [r, g, b] = self.clear_color.map(f64::from);
        let depth_load = if after { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(0.0) };
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("clustered_forward"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(0, &scene.view_bind_group, &[]);
        pass.set_bind_group(2, &clusters.shading_bind_group, &[]);
        draw_scene(&mut pass, scene);
        Ok(())
    }
}

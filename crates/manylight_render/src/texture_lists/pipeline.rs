//! The pipeline of the texture-list path and what it binds: its bind groups, declared once
//! ([`TEXTURE_LISTS_VIEW_GROUP`](crate::layouts::TEXTURE_LISTS_VIEW_GROUP), [`TEXTURE_LISTS_GROUP`](crate::layouts::TEXTURE_LISTS_GROUP); `tests/shaders.rs` checks them against the WGSL), the view
//! uniform, and the per-instance vertex buffer.

use super::textures::ListTexture;
use crate::bindings::Binding;
use crate::context::GpuContext;
use crate::gpu_types::GpuInstance;
use crate::layouts::GroupLayout;
use crate::readback::HEADLESS_FORMAT;
use crate::resources::{DEPTH_FORMAT, SurfaceVariant};

/// The pipeline of draws of `variant`, with the path's `layout` and shader `module`.
pub(super) fn create_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    variant: SurfaceVariant,
) -> wgpu::RenderPipeline {
    let constants = variant.constants();
    let options = || wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 8] = wgpu::vertex_attr_array![
        5 => Float32x4, 6 => Float32x4, 7 => Float32x4, 8 => Float32x4,
        9 => Float32x4, 10 => Float32x4, 11 => Float32x4, 12 => Float32x4
    ];
    let instance_layout = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuInstance>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &INSTANCE_ATTRIBUTES,
    };
    let targets = [Some(wgpu::ColorTargetState {
        format: HEADLESS_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("texture_lists"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: options(),
            buffers: &[Some(crate::passes::common::vertex_layout()), Some(instance_layout)],
        },
        primitive: variant.primitive(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: options(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

pub(super) fn lists_group(
    gpu: &GpuContext,
    layout: &GroupLayout,
    params: &wgpu::Buffer,
    [lights, ranges, indices]: [&ListTexture; 3],
) -> wgpu::BindGroup {
    layout.create_bind_group(
        gpu,
        &[
            Binding::Buffer(params),
            Binding::Texture(lights.view()),
            Binding::Texture(ranges.view()),
            Binding::Texture(indices.view()),
        ],
    )
}

/// A vertex buffer of `count` instances (at least 64: few scenes need it to grow).
pub(super) fn instance_buffer(gpu: &GpuContext, count: usize) -> wgpu::Buffer {
    gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture_lists_instances"),
        size: (count.max(64).next_power_of_two() * std::mem::size_of::<GpuInstance>()) as u64,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

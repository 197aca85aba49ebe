//! Deferred light volumes: after the G-buffer pass, a full-screen ambient/background triangle,
//! then every light drawn as an instanced sphere proxy that adds its light to the pixels it
//! covers (see `shaders/light_volumes.wgsl` for the depth-test rule that lights each pixel once
//! per light, camera inside the sphere and far-plane crossing included).

use super::common::{FullscreenPipelineDesc, fullscreen_pipeline_desc, fullscreen_pipeline_with_defs};
use super::common::{clear_color, color_attachment, draw_fullscreen};
use super::gbuffer_layout::{codec_constants, gbuffer_read_bind_group, gbuffer_read_layout, targets};
use super::{DEPTH, HDR, LIGHT_ACCUM};
use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::{GroupLayout, LIGHT_ACCUM_GROUP, check_pipeline, pipeline_layout};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT};
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;
use manylight_core::icosphere::Icosphere;

/// Subdivision level of the sphere proxy: 320 triangles, at most 4.6 % larger than the sphere.
pub const PROXY_SUBDIVISIONS: u32 = 2;

/// Light volumes' pipelines: per G-buffer layout, normal codec and accumulation format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightVolumesKey {
    /// The G-buffer read.
    pub layout: GBufferLayout,
    /// Its normal codec.
    pub codec: NormalCodec,
    /// Where the lights are summed.
    pub accumulation: wgpu::TextureFormat,
    /// The defines of the view's group 0 (`SHADOWS`, `ENVIRONMENT`): its bindings.
    pub view: crate::shaders::ShaderDefs,
}

impl PipelineKey for LightVolumesKey {
    type Pipeline = LightVolumesPipeline;
}

/// The pipelines and proxy mesh of [`LightVolumesPass`] for one layout and codec.
pub struct LightVolumesPipeline {
    ambient: wgpu::RenderPipeline,
    volume: wgpu::RenderPipeline,
    /// Copies the f32 sum into HDR (only with an f32 accumulation target).
    resolve: Option<(wgpu::RenderPipeline, GroupLayout)>,
    gbuffer_layout: GroupLayout,
    proxy: ProxyMesh,
}

impl LightVolumesPipeline {
    fn new(
        gpu: &GpuContext,
        view_layout: &GroupLayout,
        layout: GBufferLayout,
        codec: NormalCodec,
        accumulation: wgpu::TextureFormat,
        defs: crate::shaders::ShaderDefs,
    ) -> Result<Self, RenderError> {
        let device = &gpu.device;
        let gbuffer_layout = gbuffer_read_layout(device, layout);
        let constants = codec_constants(codec);
        let layouts = [view_layout, &gbuffer_layout];
        // The ambient pass reads no shadows: its shader is composed without them.
        let ambient = fullscreen_pipeline_with_defs(
            device,
            &FullscreenPipelineDesc {
                label: "light_volumes_ambient",
                shader: "light_volumes.wgsl",
                layouts: &layouts,
                fragment: "fs_ambient",
                output: accumulation,
                blend: None,
                depth: read_only_depth(wgpu::CompareFunction::Always),
                constants: &constants,
            },
            crate::shaders::ShaderDefs::default().with_gbuffer(layout),
        )?;
        let volume = volume_pipeline(device, layouts, &constants, accumulation, defs.with_gbuffer(layout))?;
        let resolve = if accumulation != HDR_FORMAT {
            Some(resolve_pipeline(device, layouts, &constants, defs)?)
        } else {
            None
        };
        Ok(LightVolumesPipeline { ambient, volume, resolve, gbuffer_layout, proxy: ProxyMesh::new(gpu) })
    }
}

/// A depth test against the stored surfaces, without writing depth (the shaders read it).
fn read_only_depth(compare: wgpu::CompareFunction) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(false),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    })
}

/// The pipeline that draws each light's proxy (`vs_volume`, `fs_volume`) and adds its light
/// into the `accumulation` target.
fn volume_pipeline(
    device: &wgpu::Device,
    layouts: [&GroupLayout; 2],
    constants: &[(&str, f64)],
    accumulation: wgpu::TextureFormat,
    defs: crate::shaders::ShaderDefs,
) -> Result<wgpu::RenderPipeline, RenderError> {
    check_pipeline("light_volumes.wgsl", &["vs_volume", "fs_volume"], &layouts)?;
    let module = crate::shaders::create_module_with(device, "light_volumes.wgsl", defs)?;
    let layout = pipeline_layout(device, "light_volumes", &layouts);
    let options = || wgpu::PipelineCompilationOptions { constants, ..Default::default() };
    // Back faces only, kept where they lie at or behind the stored surface (reverse-Z:
    // LessEqual). Without depth clamping, back faces beyond the far plane would be clipped
    // and their pixels miss the light, so the depth test is dropped instead.
    let unclipped_depth = device.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL);
    let compare =
        if unclipped_depth { wgpu::CompareFunction::LessEqual } else { wgpu::CompareFunction::Always };
    let additive = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("light_volumes"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_volume"),
            compilation_options: options(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState {
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: Some(wgpu::Face::Front),
            unclipped_depth,
            ..Default::default()
        },
        depth_stencil: read_only_depth(compare),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_volume"),
            compilation_options: options(),
            targets: &[Some(wgpu::ColorTargetState {
                format: accumulation,
                blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    }))
}

/// The pipeline that copies an f32 sum of the lights into HDR (`fs_resolve`), and the layout of
/// its group 2 ([`LIGHT_ACCUM_GROUP`]).
fn resolve_pipeline(
    device: &wgpu::Device,
    [view_layout, gbuffer_layout]: [&GroupLayout; 2],
    constants: &[(&str, f64)],
    defs: crate::shaders::ShaderDefs,
) -> Result<(wgpu::RenderPipeline, GroupLayout), RenderError> {
    let accum_layout = LIGHT_ACCUM_GROUP.create_layout(device, defs);
    let pipeline = fullscreen_pipeline_desc(
        device,
        &FullscreenPipelineDesc {
            label: "light_volumes_resolve",
            shader: "light_volumes.wgsl",
            layouts: &[view_layout, gbuffer_layout, &accum_layout],
            fragment: "fs_resolve",
            output: HDR_FORMAT,
            blend: None,
            depth: None,
            constants,
        },
    )?;
    Ok((pipeline, accum_layout))
}

/// The sphere proxy every light draws: an icosphere around the unit sphere.
struct ProxyMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

impl ProxyMesh {
    fn new(gpu: &GpuContext) -> ProxyMesh {
        let proxy = Icosphere::circumscribing_unit_sphere(PROXY_SUBDIVISIONS);
        let vertices = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("light_volume_proxy_vertices"),
            contents: bytemuck::cast_slice(&proxy.positions.iter().map(|p| p.to_array()).collect::<Vec<_>>()),
            usage: wgpu::BufferUsages::VERTEX,
        });
        // Pad to a multiple of 4 bytes (wgpu's copy alignment) with a repeated index.
        let mut index_data = proxy.indices.clone();
        if index_data.len() % 2 == 1 {
            index_data.push(0);
        }
        let indices = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("light_volume_proxy_indices"),
            contents: bytemuck::cast_slice(&index_data),
            usage: wgpu::BufferUsages::INDEX,
        });
        ProxyMesh { vertices, indices, index_count: proxy.indices.len() as u32 }
    }
}

/// Lights the G-buffer light by light with sphere proxies into [`HDR`].
pub struct LightVolumesPass {
    /// The G-buffer layout to read.
    pub layout: GBufferLayout,
    /// Normal codec of the `Packed` and `Compact` layouts.
    pub codec: NormalCodec,
    /// Linear colour of pixels no geometry covers.
    pub clear_color: [f32; 3],
    /// Format the lights are summed in: [`HDR_FORMAT`] (directly into HDR), or rgba32f where
    /// the device can blend it ([`LightVolumesPass::accumulation_format`]), then copied to HDR.
    pub accumulation: wgpu::TextureFormat,
    /// Reads the shadow atlas: the frame's lights cast shadows
    /// ([`crate::plan::PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl LightVolumesPass {
    /// rgba32f when `device` can blend it, else [`HDR_FORMAT`].
    pub fn accumulation_format(device: &wgpu::Device) -> wgpu::TextureFormat {
        if device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) {
            wgpu::TextureFormat::Rgba32Float
        } else {
            HDR_FORMAT
        }
    }

    fn accumulates_separately(&self) -> bool {
        self.accumulation != HDR_FORMAT
    }
}

impl NamedPass for LightVolumesPass {
    const NAME: &'static str = "light_volumes";
}

impl Pass for LightVolumesPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        let shadows = self.shadows.then_some(super::SHADOW_ATLAS);
        targets(self.layout).iter().map(|t| t.name).chain([DEPTH]).chain(shadows).collect()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let mut specs = vec![TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 }];
        if self.accumulates_separately() {
            specs.push(TextureSpec { name: LIGHT_ACCUM, format: self.accumulation, usage, scale: 1.0 });
        }
        specs
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let (layout, codec, accumulation) = (self.layout, self.codec, self.accumulation);
        let scene = ctx.scene;
        let gpu = ctx.gpu;
        let key = LightVolumesKey { layout, codec, accumulation, view: scene.view.defs() };
        let pipeline = ctx.pipelines.get_or_create(key, |k| {
            let defs = k.view;
            LightVolumesPipeline::new(gpu, &scene.view.layout, k.layout, k.codec, k.accumulation, defs)
        })?;
        let gbuffer = gbuffer_read_bind_group(ctx, &pipeline.gbuffer_layout, layout, self.clear_color)?;
        let hdr = ctx.texture(HDR)?;
        let target = if self.accumulates_separately() { ctx.texture(LIGHT_ACCUM)? } else { hdr };
        let depth = ctx.texture(DEPTH)?;
        let resolve = pipeline.resolve.as_ref().map(|(resolve, accum_layout)| {
            let accum = ctx.bind_group(accum_layout, &[Binding::Texture(target)]);
            (resolve, accum)
        });
        let timestamps = ctx.render_timestamps(true, resolve.is_none());
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("light_volumes"),
            color_attachments: &[color_attachment(target, clear_color(self.clear_color))],
            // Read-only depth: tested against, and sampled by the shaders at the same time.
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(crate::layouts::SCENE_GROUP.index, &scene.view.bind_group, &[]);
        pass.set_bind_group(crate::layouts::GBUFFER_READ_GROUP.index, &gbuffer, &[]);
        pass.set_pipeline(&pipeline.ambient);
        pass.draw(0..3, 0..1);
        if scene.lights.count > 0 {
            pass.set_pipeline(&pipeline.volume);
            pass.set_vertex_buffer(0, pipeline.proxy.vertices.slice(..));
            pass.set_index_buffer(pipeline.proxy.indices.slice(..), wgpu::IndexFormat::Uint16);
            pass.draw_indexed(0..pipeline.proxy.index_count, 0, 0..scene.lights.count);
        }
        drop(pass);
        if let Some((resolve, accum)) = resolve {
            let timestamps = ctx.render_timestamps(false, true);
            let groups = [&scene.view.bind_group, &gbuffer, &accum];
            draw_fullscreen(ctx.encoder, "light_volumes_resolve", hdr, timestamps, resolve, &groups);
        }
        Ok(())
    }
}

/// Needed for deferred light volumes with lights.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    let s = p.settings();
    if p.shades_deferred() && s.pipeline == crate::snapshot::PipelineKind::LightVolumes {
        let (layout, codec, clear_color) = (s.gbuffer, s.normal_codec, s.clear_color);
        out.push(Box::new(LightVolumesPass {
            layout,
            codec,
            clear_color,
            accumulation: p.accumulation,
            shadows: p.shades_shadows(),
        }));
    }
}

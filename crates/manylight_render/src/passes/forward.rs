//! Naive forward pass: draws every instance, evaluating every light per fragment, into the
//! HDR target with a reverse-Z depth test.

use super::common::{MeshPipelineDesc, clear_color, color_attachment, depth_attachment, mesh_pipeline};
use super::{DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{Pass, PassContext, ResourceName, TextureSpec};
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT, SceneResources};
use manylight_core::Vertex;

/// The pipeline of [`ForwardPass`].
pub struct ForwardPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl ForwardPipeline {
    fn new(device: &wgpu::Device, scene: &SceneResources) -> Result<Self, RenderError> {
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "forward",
                shader: "forward.wgsl",
                layouts: &[&scene.view_layout, &scene.material_layout],
                fragment: Some("fs_main"),
                targets: &[HDR_FORMAT],
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Greater,
            },
        )?;
        Ok(ForwardPipeline { pipeline })
    }
}

/// The vertex buffer layout of [`Vertex`].
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRIBUTES: [wgpu::VertexAttribute; 3] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ATTRIBUTES,
    }
}

/// Draws the scene with every light evaluated per fragment.
pub struct ForwardPass {
    /// Linear clear colour of the HDR target.
    pub clear_color: [f32; 3],
}

impl Pass for ForwardPass {
    fn name(&self) -> &'static str {
        "forward"
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR, DEPTH]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        vec![
            TextureSpec { name: HDR, format: HDR_FORMAT, usage, scale: 1.0 },
            TextureSpec { name: DEPTH, format: DEPTH_FORMAT, usage: super::DEPTH_USAGE, scale: 1.0 },
        ]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let pipeline = ctx.pipelines.get_or_create(0, || ForwardPipeline::new(&ctx.gpu.device, scene))?;
        let color = color_attachment(ctx.texture(HDR)?, clear_color(self.clear_color));
        let depth = ctx.texture(DEPTH)?;
        record_scene_pass(ctx, "forward", &[color], depth, true, &pipeline.pipeline, &[]);
        Ok(())
    }
}

/// Records the graph pass as one timed wgpu render pass that draws every scene instance with
/// `pipeline`: group 0 is the view, group 1 each draw's material, `extra` follow from group 2.
/// The depth attachment is cleared when `clear_depth`, else loaded (after a pre-pass).
pub fn record_scene_pass(
    ctx: &mut PassContext<'_>,
    label: &str,
    colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    depth: &wgpu::TextureView,
    clear_depth: bool,
    pipeline: &wgpu::RenderPipeline,
    extra: &[&wgpu::BindGroup],
) {
    let scene = ctx.scene;
    let timestamps = ctx.render_timestamps(true, true);
    let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: colors,
        depth_stencil_attachment: depth_attachment(depth, clear_depth),
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &scene.view_bind_group, &[]);
    for (i, group) in extra.iter().enumerate() {
        pass.set_bind_group(2 + i as u32, *group, &[]);
    }
    draw_scene(&mut pass, scene);
}

/// Issues one indexed draw per scene draw, switching material bind groups (group 1) and
/// vertex/index buffers only when they change.
pub fn draw_scene(pass: &mut wgpu::RenderPass<'_>, scene: &SceneResources) {
    let (mut bound_material, mut bound_mesh) = (usize::MAX, usize::MAX);
    for d in &scene.draws {
        let (Some(mesh), Some(material)) = (scene.mesh(d.mesh), scene.material(d.material)) else {
            continue;
        };
        if d.material != bound_material {
            pass.set_bind_group(1, &material.bind_group, &[]);
            bound_material = d.material;
        }
        if d.mesh != bound_mesh {
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            bound_mesh = d.mesh;
        }
        pass.draw_indexed(0..mesh.index_count, 0, d.instance..d.instance + 1);
    }
}

//! Drawing the scene's instances inside a render pass, shared by every pass that rasterises
//! the scene (forward, clustered forward, depth pre-pass, G-buffer).

use super::common::depth_attachment;
use crate::graph::PassContext;
use crate::resources::SceneResources;

/// Records the graph pass as one timed wgpu render pass that draws every scene instance with
/// `pipeline`: group 0 is the view, group 1 each draw's material, `extra` follow from group 2.
/// The depth attachment is cleared when `clear_depth`, else loaded (after a pre-pass); then the
/// draws run in reverse order (see [`draw_scene`]).
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
    draw_scene(&mut pass, scene, !clear_depth);
}

/// Issues one indexed draw per scene draw, switching material bind groups (group 1) and
/// vertex/index buffers only when they change. `reverse` draws them last to first: a pass after
/// the depth pre-pass tests `GreaterEqual`, so of coplanar surfaces (equal depth) the last
/// drawn wins, where a pass that tests `Greater` keeps the first; drawn in reverse, both keep
/// the same one, and every pipeline shows the same surface (ties are exact in orthographic
/// views, whose depth is linear).
pub fn draw_scene(pass: &mut wgpu::RenderPass<'_>, scene: &SceneResources, reverse: bool) {
    let (mut bound_material, mut bound_mesh) = (usize::MAX, usize::MAX);
    let mut draw = |d: &crate::resources::Draw| {
        let (Some(mesh), Some(material)) = (scene.mesh(d.mesh), scene.material(d.material)) else {
            return;
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
    };
    if reverse {
        scene.draws.iter().rev().for_each(&mut draw);
    } else {
        scene.draws.iter().for_each(&mut draw);
    }
}

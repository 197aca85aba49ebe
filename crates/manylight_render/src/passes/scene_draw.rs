//! Drawing the scene's instances inside a render pass, shared by every pass that rasterises
//! the scene (forward, clustered forward, depth pre-pass, G-buffer).

use super::common::depth_attachment;
use crate::context::RenderError;
use crate::graph::PassContext;
use crate::pipelines::PipelineKey;
use crate::resources::{SceneResources, SurfaceVariant};
use std::sync::Arc;

/// A mesh pass's pipeline object: the wgpu pipeline its draws use.
pub trait ScenePipeline {
    /// The pipeline to draw with.
    fn render_pipeline(&self) -> &wgpu::RenderPipeline;
}

/// A mesh pass's pipeline for each surface variant.
pub type VariantPipelines<P> = Vec<(SurfaceVariant, Arc<P>)>;

/// The pipelines of an opaque mesh pass for every opaque variant the frame draws
/// (`SceneInstances::variants`), each made by `create` on first use. Blended variants get
/// none, so the opaque passes skip their draws.
pub fn variant_pipelines<K: PipelineKey>(
    ctx: &PassContext<'_>,
    key: impl Fn(SurfaceVariant) -> K,
    create: impl Fn(&K) -> Result<K::Pipeline, RenderError>,
) -> Result<VariantPipelines<K::Pipeline>, RenderError> {
    pipelines_where(ctx, |v| !v.blend, key, create)
}

/// [`variant_pipelines`] for the blended variants only (the transparent pass).
pub fn blended_variant_pipelines<K: PipelineKey>(
    ctx: &PassContext<'_>,
    key: impl Fn(SurfaceVariant) -> K,
    create: impl Fn(&K) -> Result<K::Pipeline, RenderError>,
) -> Result<VariantPipelines<K::Pipeline>, RenderError> {
    pipelines_where(ctx, |v| v.blend, key, create)
}

fn pipelines_where<K: PipelineKey>(
    ctx: &PassContext<'_>,
    filter: impl Fn(&SurfaceVariant) -> bool,
    key: impl Fn(SurfaceVariant) -> K,
    create: impl Fn(&K) -> Result<K::Pipeline, RenderError>,
) -> Result<VariantPipelines<K::Pipeline>, RenderError> {
    // Each variant's pipeline has the view's shading model where its material has none, and
    // reads shadows when the frame's lights cast them and the environment when the view has one.
    let global = ctx.scene.view.uniform.shading_model;
    let view = ctx.scene.view.defs();
    let variants = ctx.scene.instances.variants.iter().filter(|v| filter(v));
    variants
        .map(|&v| Ok((v, ctx.pipelines.get_or_create(key(v.resolved(global).with_view(view)), &create)?)))
        .collect()
}

/// Records the graph pass as one timed wgpu render pass that draws every scene instance with
/// the pipeline of its variant in `pipelines`: group 0 is the view, group 1 each draw's
/// material, `extra` follow from group 2.
/// The depth attachment is cleared when `clear_depth`, else loaded (after a pre-pass); then the
/// draws run in reverse order (see [`draw_scene`]).
pub fn record_scene_pass<P: ScenePipeline>(
    ctx: &mut PassContext<'_>,
    label: &str,
    colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    depth: &wgpu::TextureView,
    clear_depth: bool,
    pipelines: &[(SurfaceVariant, Arc<P>)],
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
    pass.set_bind_group(crate::layouts::SCENE_GROUP.index, &scene.view.bind_group, &[]);
    // The pass's own groups follow the material's.
    for (i, group) in extra.iter().enumerate() {
        pass.set_bind_group(crate::layouts::MATERIAL_GROUP.index + 1 + i as u32, *group, &[]);
    }
    draw_scene(&mut pass, scene, pipelines, !clear_depth);
}

/// Issues one indexed draw per scene draw, switching pipelines (by the draw's variant; a draw
/// whose variant has no pipeline in `pipelines` is skipped), material bind groups (group 1)
/// and vertex/index buffers only when they change. `reverse` draws them last to first: a pass after
/// the depth pre-pass tests `GreaterEqual`, so of coplanar surfaces (equal depth) the last
/// drawn wins, where a pass that tests `Greater` keeps the first; drawn in reverse, both keep
/// the same one, and every pipeline shows the same surface (ties are exact in orthographic
/// views, whose depth is linear).
pub fn draw_scene<P: ScenePipeline>(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneResources,
    pipelines: &[(SurfaceVariant, Arc<P>)],
    reverse: bool,
) {
    if reverse {
        draw_in_order(pass, scene, pipelines, scene.instances.draws.iter().rev());
    } else {
        draw_in_order(pass, scene, pipelines, scene.instances.draws.iter());
    }
}

/// Issues `draws` in the order given, as [`draw_scene`] does.
pub fn draw_in_order<'d, P: ScenePipeline>(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneResources,
    pipelines: &[(SurfaceVariant, Arc<P>)],
    draws: impl Iterator<Item = &'d crate::resources::Draw>,
) {
    let (mut bound_material, mut bound_mesh) = (usize::MAX, usize::MAX);
    let mut bound_variant = None;
    let mut draw = |d: &crate::resources::Draw| {
        let (Some(mesh), Some(material)) = (scene.assets.mesh(d.mesh), scene.assets.material(d.material))
        else {
            return;
        };
        if bound_variant != Some(d.variant) {
            let Some((_, pipeline)) = pipelines.iter().find(|(v, _)| *v == d.variant) else {
                return;
            };
            pass.set_pipeline(pipeline.render_pipeline());
            bound_variant = Some(d.variant);
        }
        if d.material != bound_material {
            pass.set_bind_group(crate::layouts::MATERIAL_GROUP.index, &material.bind_group, &[]);
            bound_material = d.material;
        }
        if d.mesh != bound_mesh {
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            bound_mesh = d.mesh;
        }
        pass.draw_indexed(0..mesh.index_count, 0, d.instance..d.instance + 1);
    };
    draws.for_each(&mut draw);
}

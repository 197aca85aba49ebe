//! The shadow pass: draws the casting lights' maps that changed into the shadow atlas
//! ([`crate::shadows`]), one instanced draw per mesh over all (instance, face) pairs. When the
//! atlas keeps other maps, it loads the atlas and first clears the tiles it draws.

use super::SHADOW_ATLAS;
use super::common::vertex_layout;
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::layouts::{GroupLayout, SHADOW_MAPS_GROUP, check_pipeline, pipeline_layout};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::shaders::ShaderDefs;
use crate::shadows::SHADOW_ATLAS_FORMAT;

/// The shadow pass's pipeline: with clip distances where the device has them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShadowMapsKey {
    /// Faces are cut to their tiles by clip distances; otherwise by discarding fragments.
    pub clip_distances: bool,
    /// Depth is clamped, not clipped (`Features::DEPTH_CLIP_CONTROL`): casters nearer the
    /// light than a cascade's near side land on it (pancaking).
    pub clamps_depth: bool,
}

impl PipelineKey for ShadowMapsKey {
    type Pipeline = ShadowMapsPipeline;
}

/// The pipelines of [`ShadowMapsPass`] and the layout of their group 0 (faces, draws,
/// instances).
pub struct ShadowMapsPipeline {
    pipeline: wgpu::RenderPipeline,
    /// Clears the tiles of the faces drawn (`vs_clear`).
    clear: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl ShadowMapsPipeline {
    fn new(device: &wgpu::Device, key: &ShadowMapsKey) -> Result<Self, RenderError> {
        let layout = SHADOW_MAPS_GROUP.create_layout(device, Default::default());
        check_pipeline("shadow_maps.wgsl", &["vs_main", "fs_main", "vs_clear"], &[&layout])?;
        let defs = ShaderDefs { clip_distances: key.clip_distances, ..Default::default() };
        let module = crate::shaders::create_module_with(device, "shadow_maps.wgsl", defs)?;
        let pipeline_layout = pipeline_layout(device, "shadow_maps", &[&layout]);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow_maps"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            // Both sides cast: a single-sided mesh seen from behind by the light still blocks it.
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                unclipped_depth: key.clamps_depth,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_ATLAS_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            // Without clip distances a fragment shader discards what falls outside the tile.
            fragment: (!key.clip_distances).then(|| wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let clear = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow_clear"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_clear"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_ATLAS_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        Ok(ShadowMapsPipeline { pipeline, clear, layout })
    }
}

/// Draws the frame's shadow maps into [`SHADOW_ATLAS`].
pub struct ShadowMapsPass;

impl NamedPass for ShadowMapsPass {
    const NAME: &'static str = "shadow_maps";
}

impl Pass for ShadowMapsPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![SHADOW_ATLAS]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        // The first view of a frame draws its maps; the others read them.
        let Some(shadows) = ctx.shadows.filter(|s| s.active && s.take_pending_draw()) else {
            return Ok(());
        };
        let Some(atlas) = shadows.atlas_view() else {
            return Ok(());
        };
        let key =
            ShadowMapsKey { clip_distances: shadows.clip_distances, clamps_depth: shadows.clamps_depth };
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(key, |k| ShadowMapsPipeline::new(device, k))?;
        let bind_group = ctx.bind_group(
            &pipeline.layout,
            &[
                Binding::Buffer(shadows.faces.buffer()),
                Binding::Buffer(shadows.draws.buffer()),
                Binding::Buffer(ctx.scene.instances.buffer.buffer()),
            ],
        );
        let scene = ctx.scene;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow_maps"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: atlas,
                depth_ops: Some(wgpu::Operations {
                    // Reverse depth: 0 is the far plane, where nothing casts.
                    load: if shadows.clears_tiles { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(0.0) },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(SHADOW_MAPS_GROUP.index, &bind_group, &[]);
        if shadows.clears_tiles {
            pass.set_pipeline(&pipeline.clear);
            pass.draw(0..6, 0..shadows.faces_drawn);
        }
        pass.set_pipeline(&pipeline.pipeline);
        for run in &shadows.mesh_draws {
            let Some(mesh) = scene.assets.mesh(run.mesh) else {
                continue;
            };
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.index_count, 0, run.first..run.first + run.count);
        }
        Ok(())
    }
}

/// Needed when the view shades lights and the frame has a casting light
/// ([`PlanInputs::shades_shadows`]).
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.shades_shadows() {
        out.push(Box::new(ShadowMapsPass));
    }
}

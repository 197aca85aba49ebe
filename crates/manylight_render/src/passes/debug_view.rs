//! Debug view: replaces tone mapping with what explains a frame (`shaders/debug_view.wgsl`).
//! Three families, each its own entry point and bind group layout, so a view binds only what it
//! reads:
//! - cluster views (light-count heatmap with a legend bar, cluster x / y / z index, overflow):
//!   depth + the cluster lists;
//! - depth: the linearised view distance;
//! - surface views (albedo, normal): the Full G-buffer;
//! - shadow views: the atlas (`shadow-atlas`), or the lights and their shadow table
//!   (`shadow-lod`), after a frame planned as without a debug view. A frame without a shadow
//!   map shows the background.

use super::common::{draw_fullscreen, fullscreen_pipeline};
use super::{
    CLUSTERS, DEPTH, GBUFFER_ALBEDO, GBUFFER_EMISSIVE, GBUFFER_NORMAL, GBUFFER_POSITION, SHADOW_ATLAS,
};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, OUTPUT, Pass, PassContext, ResourceName};
use crate::layouts::{
    BindGroupDecl, DEBUG_CLUSTERS_GROUP, DEBUG_DEPTH_GROUP, DEBUG_SHADOW_ATLAS_GROUP, DEBUG_SHADOW_LOD_GROUP,
    DEBUG_SURFACE_GROUP, GroupLayout,
};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::snapshot::DebugViewMode;

/// The data a debug view reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Family {
    Clusters,
    Depth,
    Surface,
    ShadowAtlas,
    ShadowLod,
}

impl Family {
    fn of(mode: DebugViewMode) -> Family {
        if mode == DebugViewMode::ShadowAtlas {
            Family::ShadowAtlas
        } else if mode == DebugViewMode::ShadowLod {
            Family::ShadowLod
        } else if mode.uses_surfaces() {
            Family::Surface
        } else if mode.uses_clusters() {
            Family::Clusters
        } else {
            Family::Depth
        }
    }

    /// The family's bind group and fragment entry point.
    fn group_and_entry(self) -> (&'static BindGroupDecl, &'static str) {
        match self {
            Family::Clusters => (&DEBUG_CLUSTERS_GROUP, "fs_clusters"),
            Family::Depth => (&DEBUG_DEPTH_GROUP, "fs_depth"),
            Family::Surface => (&DEBUG_SURFACE_GROUP, "fs_surface"),
            Family::ShadowAtlas => (&DEBUG_SHADOW_ATLAS_GROUP, "fs_shadow_atlas"),
            Family::ShadowLod => (&DEBUG_SHADOW_LOD_GROUP, "fs_shadow_lod"),
        }
    }
}

/// The debug views' pipelines: per data read and output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct DebugViewKey {
    family: Family,
    format: wgpu::TextureFormat,
}

impl PipelineKey for DebugViewKey {
    type Pipeline = DebugViewPipeline;
}

/// The pipeline of [`DebugViewPass`] for one family and output format.
pub struct DebugViewPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl DebugViewPipeline {
    fn new(device: &wgpu::Device, family: Family, output: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let (group, entry) = family.group_and_entry();
        let layout = group.create_layout(device, Default::default());
        let pipeline =
            fullscreen_pipeline(device, "debug_view", "debug_view.wgsl", &[&layout], entry, output)?;
        Ok(DebugViewPipeline { pipeline, layout })
    }
}

/// Where the depth view's scale ends: at the far plane; without one, where a cluster grid
/// would end (as far as the lights reach, [`manylight_core::Projection::finite_for`]), or at
/// `near × 10⁴` when there is no light.
fn depth_view_far(scene: &crate::resources::SceneResources) -> f32 {
    let (near, near_over_far) = (scene.view.uniform.params.x, scene.view.uniform.params.y);
    if near_over_far > 0.0 {
        return near / near_over_far;
    }
    if scene.lights.count == 0 {
        return near * 1e4;
    }
    let reach = scene.lights.reach.farthest(&scene.view.uniform.view_from_world);
    manylight_core::Projection::infinite(1.0, near).finite_for(reach).far
}

/// Writes a debug visualisation to [`OUTPUT`].
pub struct DebugViewPass {
    /// What to show (not `DebugViewMode::None`).
    pub view: DebugViewMode,
    /// Light count drawn as the hottest colour of the heatmap (and a full cluster of the
    /// overflow view when there is no cap).
    pub heatmap_max: u32,
    /// The frame draws shadow maps ([`PlanInputs::shades_shadows`]): the shadow views read
    /// them; without, they show the background.
    pub shadows: bool,
}

impl NamedPass for DebugViewPass {
    const NAME: &'static str = "debug_view";
}

impl Pass for DebugViewPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        match Family::of(self.view) {
            Family::Clusters => vec![DEPTH, CLUSTERS],
            Family::Depth => vec![DEPTH],
            Family::Surface => {
                vec![DEPTH, GBUFFER_ALBEDO, GBUFFER_NORMAL, GBUFFER_EMISSIVE, GBUFFER_POSITION]
            }
            // After the shadow pass, when the frame has one.
            Family::ShadowAtlas | Family::ShadowLod if self.shadows => vec![DEPTH, SHADOW_ATLAS],
            Family::ShadowAtlas | Family::ShadowLod => Vec::new(),
        }
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![OUTPUT]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let family = Family::of(self.view);
        let shadows = ctx.shadows.filter(|s| s.active && self.shadows);
        if matches!(family, Family::ShadowAtlas | Family::ShadowLod) && shadows.is_none() {
            // No shadow map this frame: the background alone.
            let output = ctx.texture(OUTPUT)?;
            ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("debug_view"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: output,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.02, g: 0.02, b: 0.02, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            return Ok(());
        }
        let format = ctx.output_format;
        let device = &ctx.gpu.device;
        let key = DebugViewKey { family, format };
        let pipeline =
            ctx.pipelines.get_or_create(key, |k| DebugViewPipeline::new(device, k.family, k.format))?;
        let depth_far = depth_view_far(ctx.scene);
        let params = ctx.uniform(&[self.view.gpu_id(), self.heatmap_max.max(1), depth_far.to_bits(), 0]);
        let mut bindings = vec![
            Binding::Buffer(&ctx.scene.view.buffer),
            Binding::Texture(ctx.texture(DEPTH)?),
            Binding::Buffer(&params),
        ];
        match family {
            Family::Clusters => {
                let clusters = ctx.require_clusters("debug_view")?;
                bindings.extend([
                    Binding::Buffer(&clusters.buffers.params),
                    Binding::Buffer(clusters.buffers.ranges.buffer()),
                ]);
            }
            Family::Depth => {}
            Family::Surface => bindings.extend([
                Binding::Texture(ctx.texture(GBUFFER_ALBEDO)?),
                Binding::Texture(ctx.texture(GBUFFER_NORMAL)?),
                Binding::Texture(ctx.texture(GBUFFER_EMISSIVE)?),
                Binding::Texture(ctx.texture(GBUFFER_POSITION)?),
            ]),
            Family::ShadowAtlas => {
                let atlas = shadows.and_then(|s| s.atlas_view()).ok_or_else(|| {
                    RenderError::Graph("shadow-atlas: the frame's shadows have no atlas".into())
                })?;
                bindings.push(Binding::Texture(atlas));
            }
            Family::ShadowLod => {
                let table = shadows
                    .map(|s| s.lights.buffer())
                    .ok_or_else(|| RenderError::Graph("shadow-lod: the frame has no shadow table".into()))?;
                bindings.extend([Binding::Buffer(ctx.scene.lights.buffer.buffer()), Binding::Buffer(table)]);
            }
        }
        let bind_group = ctx.bind_group(&pipeline.layout, &bindings);
        let output = ctx.texture(OUTPUT)?;
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(ctx.encoder, "debug_view", output, timestamps, &pipeline.pipeline, &[&bind_group]);
        Ok(())
    }
}

/// Needed when the view shows a debug view (it replaces the tone map).
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    let s = p.settings();
    if !p.shows_image() {
        out.push(Box::new(DebugViewPass {
            view: s.debug_view,
            heatmap_max: s.debug_heatmap_max,
            shadows: p.shades_shadows(),
        }));
    }
}

//! The transparent pass: blended surfaces (glTF `alphaMode` `BLEND`) drawn after every opaque
//! pass, farthest first, over the shaded image. Depth is tested against the opaque surfaces
//! but not written, and each fragment is lit as forward shading lights it: through the cluster
//! lists where the view built them, else by every light. Planned only when the frame draws a
//! blended material.

use super::common::{MeshPipelineDesc, depth_attachment, mesh_pipeline};
use super::scene_draw::{ScenePipeline, blended_variant_pipelines, draw_in_order};
use super::{CLUSTERS, DEPTH, HDR};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::layouts::GroupLayout;
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{HDR_FORMAT, SurfaceVariant};

/// The transparent pass's pipeline: per blended variant, with or without cluster lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TransparentKey {
    /// Lit through the cluster lists (group 2) rather than by every light.
    pub clustered: bool,
    /// Winding and culling (always a blended variant).
    pub variant: SurfaceVariant,
}

impl PipelineKey for TransparentKey {
    type Pipeline = TransparentPipeline;
}

/// The pipeline of [`TransparentPass`].
pub struct TransparentPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl TransparentPipeline {
    fn new(
        device: &wgpu::Device,
        layouts: &[&GroupLayout],
        key: &TransparentKey,
    ) -> Result<Self, RenderError> {
        let pipeline = mesh_pipeline(
            device,
            &MeshPipelineDesc {
                label: "transparent",
                shader: "transparent.wgsl",
                layouts,
                fragment: Some(if key.clustered { "fs_clusters" } else { "fs_every_light" }),
                targets: &[HDR_FORMAT],
                // Behind nothing opaque, and never hiding what is drawn after it.
                depth_write: false,
                depth_compare: wgpu::CompareFunction::Greater,
                variant: key.variant,
            },
        )?;
        Ok(TransparentPipeline { pipeline })
    }
}

impl ScenePipeline for TransparentPipeline {
    fn render_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
    }
}

/// Draws the blended instances over [`HDR`], farthest first.
pub struct TransparentPass {
    /// Lit through the cluster lists (the view built them) rather than by every light.
    pub clustered: bool,
    /// Reads the shadow atlas: the frame's lights cast shadows ([`PlanInputs::shades_shadows`]).
    pub shadows: bool,
}

impl NamedPass for TransparentPass {
    const NAME: &'static str = "transparent";
}

impl Pass for TransparentPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        let mut reads = if self.clustered { vec![HDR, DEPTH, CLUSTERS] } else { vec![HDR, DEPTH] };
        reads.extend(self.shadows.then_some(super::SHADOW_ATLAS));
        reads
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let clusters = if self.clustered {
            let c = ctx.require_clusters("transparent")?;
            Some(c)
        } else {
            None
        };
        let mut layouts = vec![&scene.view.layout, &scene.assets.material_layout];
        layouts.extend(clusters.map(|c| &c.bindings.lists_layout));
        let clustered = self.clustered;
        let pipelines = blended_variant_pipelines(
            ctx,
            |variant| TransparentKey { clustered, variant },
            |k| TransparentPipeline::new(&ctx.gpu.device, &layouts, k),
        )?;
        let color = ctx.texture(HDR)?;
        let depth = ctx.texture(DEPTH)?;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("transparent"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: depth_attachment(depth, false),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(crate::layouts::SCENE_GROUP.index, &scene.view.bind_group, &[]);
        if let Some(c) = clusters {
            pass.set_bind_group(crate::layouts::CLUSTER_LISTS_GROUP.index, &c.bindings.lists_group, &[]);
        }
        draw_in_order(
            &mut pass,
            scene,
            &pipelines,
            scene.instances.blended.iter().map(|&i| &scene.instances.draws[i]),
        );
        Ok(())
    }
}

/// Needed when the frame draws a blended material and the view shows shaded surfaces.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if p.has_blended && !p.replaces_shading() {
        out.push(Box::new(TransparentPass {
            clustered: p.shades_with_clusters(),
            shadows: p.shades_shadows(),
        }));
    }
}

//! G-buffer pass of clustered deferred: writes each pixel's surface (position or depth,
//! normal, albedo, shading parameters) in the chosen [`GBufferLayout`].

use super::common::{MeshPipelineDesc, color_attachment, mesh_pipeline_with_defs};
use super::gbuffer_layout::{codec_constants, targets};
use super::scene_draw::{ScenePipeline, record_scene_pass, variant_pipelines};
use super::{DEPTH, DEPTH_USAGE};
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, SceneResources, SurfaceVariant};
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;

/// The G-buffer pass's pipelines: per layout and normal codec.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GBufferKey {
    /// The layout written.
    pub layout: GBufferLayout,
    /// Its normal codec.
    pub codec: NormalCodec,
    /// Culling and alpha masking.
    pub variant: SurfaceVariant,
}

impl PipelineKey for GBufferKey {
    type Pipeline = GBufferPipeline;
}

/// The pipeline of [`GBufferPass`] for one layout and codec.
pub struct GBufferPipeline {
    pipeline: wgpu::RenderPipeline,
}

impl GBufferPipeline {
    fn new(device: &wgpu::Device, scene: &SceneResources, key: &GBufferKey) -> Result<Self, RenderError> {
        let GBufferKey { layout, codec, variant } = *key;
        let formats: Vec<wgpu::TextureFormat> = targets(layout).iter().map(|t| t.format).collect();
        let pipeline = mesh_pipeline_with_defs(
            device,
            &MeshPipelineDesc {
                label: "gbuffer",
                shader: "gbuffer.wgsl",
                layouts: &[&scene.view.layout, &scene.assets.material_layout],
                fragment: Some("fs_main"),
                targets: &formats,
                depth_write: true,
                depth_compare: wgpu::CompareFunction::Greater,
                variant,
            },
            &codec_constants(codec),
            variant.defs().with_gbuffer(layout),
        )?;
        Ok(GBufferPipeline { pipeline })
    }
}

impl ScenePipeline for GBufferPipeline {
    fn render_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
    }
}

/// Rasterises the scene into the G-buffer and [`DEPTH`].
pub struct GBufferPass {
    /// The layout.
    pub layout: GBufferLayout,
    /// Normal codec of the `Packed` and `Compact` layouts.
    pub codec: NormalCodec,
}

impl NamedPass for GBufferPass {
    const NAME: &'static str = "gbuffer";
}

impl Pass for GBufferPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        Vec::new()
    }
    fn writes(&self) -> Vec<ResourceName> {
        targets(self.layout).iter().map(|t| t.name).chain([DEPTH]).collect()
    }
    fn creates(&self) -> Vec<TextureSpec> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        targets(self.layout)
            .iter()
            .map(|t| TextureSpec { name: t.name, format: t.format, usage, scale: 1.0 })
            .chain([TextureSpec { name: DEPTH, format: DEPTH_FORMAT, usage: DEPTH_USAGE, scale: 1.0 }])
            .collect()
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let scene = ctx.scene;
        let (layout, codec) = (self.layout, self.codec);
        let pipelines = variant_pipelines(
            ctx,
            |variant| GBufferKey { layout, codec, variant },
            |k| GBufferPipeline::new(&ctx.gpu.device, scene, k),
        )?;
        let views = targets(layout).iter().map(|t| ctx.texture(t.name)).collect::<Result<Vec<_>, _>>()?;
        let depth = ctx.texture(DEPTH)?;
        let attachments: Vec<_> =
            views.iter().map(|view| color_attachment(view, wgpu::Color::TRANSPARENT)).collect();
        record_scene_pass(ctx, "gbuffer", &attachments, depth, true, &pipelines, &[]);
        Ok(())
    }
}

/// Needed for the deferred pipelines with lights (the view's layout), and for the surface
/// debug views (the Full layout) in every pipeline.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    let s = p.settings();
    if p.shows_surfaces() {
        out.push(Box::new(GBufferPass { layout: GBufferLayout::Full, codec: s.normal_codec }));
    } else if p.shades_deferred() {
        out.push(Box::new(GBufferPass { layout: s.gbuffer, codec: s.normal_codec }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes per pixel a layout reports are those of its targets plus 4 of depth.
    #[test]
    fn bytes_per_pixel_match_the_targets() {
        for layout in GBufferLayout::ALL {
            let targets: u32 =
                targets(layout).iter().map(|t| t.format.block_copy_size(None).unwrap_or(0)).sum();
            let depth = DEPTH_FORMAT.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)).unwrap_or(0);
            assert_eq!(layout.bytes_per_pixel(), targets + depth, "{layout:?}");
        }
    }
}

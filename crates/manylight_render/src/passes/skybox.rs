//! Skybox: the camera's panorama behind the geometry, after the opaque shading and before the
//! blended surfaces, where the depth buffer still holds the far plane.

use super::common::{FullscreenPipelineDesc, fullscreen_pipeline_desc};
use super::{DEPTH, HDR};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName};
use crate::layouts::{GroupLayout, SKYBOX_GROUP};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::{DEPTH_FORMAT, HDR_FORMAT};
use crate::settings::{EnvironmentFilter, EnvironmentHandle};

/// The skybox's one pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SkyboxKey;

impl PipelineKey for SkyboxKey {
    type Pipeline = SkyboxPipeline;
}

/// The pipeline of [`SkyboxPass`].
pub struct SkyboxPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl SkyboxPipeline {
    fn new(device: &wgpu::Device) -> Result<Self, RenderError> {
        let layout = SKYBOX_GROUP.create_layout(device, Default::default());
        let pipeline = fullscreen_pipeline_desc(
            device,
            &FullscreenPipelineDesc {
                label: "skybox",
                shader: "skybox.wgsl",
                layouts: &[&layout],
                fragment: "fs_main",
                output: HDR_FORMAT,
                blend: None,
                // The triangle lies on the far plane (reverse-Z 0): "0 >= stored" holds only
                // where no surface was drawn (stored 0). Exact for a constant 0, unlike "equal",
                // which needs the vertex positions to be invariant.
                depth: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(false),
                    depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                constants: &[],
            },
        )?;
        Ok(SkyboxPipeline { pipeline, layout })
    }
}

/// Draws the camera's [`Skybox`](crate::Skybox) where no surface is.
pub struct SkyboxPass {
    /// The panorama.
    pub image: EnvironmentHandle,
    /// How it was prefiltered (its maps are found by both).
    pub filter: EnvironmentFilter,
}

impl NamedPass for SkyboxPass {
    const NAME: &'static str = "skybox";
}

impl Pass for SkyboxPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR, DEPTH]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        // A panorama the snapshot did not hold was counted by the environments' prepare: the
        // clear colour stays.
        let Some((sky, sampler)) = ctx.environments.and_then(|e| e.sky(self.image, self.filter)) else {
            return Ok(());
        };
        let device = &ctx.gpu.device;
        let pipeline = ctx.pipelines.get_or_create(SkyboxKey, |_| SkyboxPipeline::new(device))?;
        let group = ctx.bind_group(
            &pipeline.layout,
            &[Binding::Buffer(&ctx.scene.view.buffer), Binding::Texture(sky), Binding::Sampler(sampler)],
        );
        let hdr = ctx.texture(HDR)?;
        let depth = ctx.texture(DEPTH)?;
        let timestamps = ctx.render_timestamps(true, true);
        let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("skybox"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: hdr,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(SKYBOX_GROUP.index, &group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}

/// Needed when the view's camera has a skybox and the view shows its shaded image.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    let skybox = p.view.camera.and_then(|c| c.skybox);
    if let Some(skybox) = skybox
        .filter(|_| !p.replaces_shading() && p.settings().debug_view == crate::snapshot::DebugViewMode::None)
    {
        out.push(Box::new(SkyboxPass { image: skybox.image, filter: p.settings().environment_filter }));
    }
}

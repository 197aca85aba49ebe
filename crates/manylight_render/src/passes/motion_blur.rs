//! Camera-motion blur (GPU Gems 3, ch. 27): each pixel's world position is rebuilt from depth,
//! projected with last frame's clip-from-world, and the HDR image is averaged along the
//! resulting screen velocity (`shaders/motion_blur.wgsl`): `fs_blur` reads the HDR image and
//! depth and writes the second HDR image, which the passes after it (bloom, tone mapping) read
//! as HDR ([`PassContext::post_process_write`]).
//!
//! The tap count is a pipeline-override constant (one cached pipeline per count): lavapipe
//! compiles a shader whose loop count comes from a uniform again at every draw and keeps every
//! copy (0.84 MB per frame).
//!
//! A pixel that moved less than half a pixel keeps its exact colour. When the whole camera did
//! not move (a still camera, or the first frame, which has no previous matrix) the pass records
//! nothing at all: the image is the unblurred one and costs no GPU time.

use super::common::{FullscreenPipelineDesc, draw_fullscreen, fullscreen_pipeline_desc};
use super::{DEPTH, HDR, post_process_texture};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::{GroupLayout, MOTION_BLUR_GROUP};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::HDR_FORMAT;
pub use crate::settings::MotionBlurSettings;

/// Uniforms of `shaders/motion_blur.wgsl` (`MotionBlurParams`); the tap count is the
/// pipeline's `SAMPLES` override.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MotionBlurParams {
    strength: f32,
    max_pixels: f32,
    _pad: [u32; 2],
}

/// Motion blur's pipelines: one per sample count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct MotionBlurKey {
    samples: u32,
}

impl PipelineKey for MotionBlurKey {
    type Pipeline = MotionBlurPipeline;
}

/// The pipeline of [`MotionBlurPass`] for one tap count.
struct MotionBlurPipeline {
    blur: wgpu::RenderPipeline,
    blur_layout: GroupLayout,
}

impl MotionBlurPipeline {
    fn new(device: &wgpu::Device, samples: u32) -> Result<Self, RenderError> {
        let blur_layout = MOTION_BLUR_GROUP.create_layout(device, Default::default());
        let blur = fullscreen_pipeline_desc(
            device,
            &FullscreenPipelineDesc {
                label: "motion_blur",
                shader: "motion_blur.wgsl",
                layouts: &[&blur_layout],
                fragment: "fs_blur",
                output: HDR_FORMAT,
                blend: None,
                depth: None,
                constants: &[("SAMPLES", f64::from(samples))],
            },
        )?;
        Ok(MotionBlurPipeline { blur, blur_layout })
    }
}

/// Blurs the HDR image along each pixel's camera-motion velocity, in place.
pub struct MotionBlurPass {
    /// Samples, strength, clamp.
    pub settings: MotionBlurSettings,
    /// False when the camera's clip-from-world equals last frame's (or there is no last frame):
    /// nothing moves, nothing is recorded.
    pub camera_moved: bool,
}

impl MotionBlurPass {
    /// The pass for `camera` at `viewport`, with its settings.
    pub fn for_camera(camera: &crate::snapshot::ExtractedCamera, viewport: glam::UVec2) -> Option<Self> {
        let settings = camera.motion_blur?;
        let current = camera.clip_from_world(viewport);
        let camera_moved = camera.prev_clip_from_world.is_some_and(|prev| prev != current);
        Some(MotionBlurPass { settings, camera_moved })
    }
}

impl NamedPass for MotionBlurPass {
    const NAME: &'static str = "motion_blur";
}

impl Pass for MotionBlurPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR, DEPTH]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        vec![post_process_texture()]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        if !self.camera_moved {
            return Ok(());
        }
        let device = &ctx.gpu.device;
        let s = self.settings;
        let samples = s.samples.clamp(2, 64);
        let pipeline = ctx
            .pipelines
            .get_or_create(MotionBlurKey { samples }, |k| MotionBlurPipeline::new(device, k.samples))?;
        let params = MotionBlurParams {
            strength: if s.strength.is_finite() { s.strength.max(0.0) } else { 0.0 },
            max_pixels: if s.max_pixels.is_finite() { s.max_pixels.max(0.0) } else { 0.0 },
            _pad: [0; 2],
        };
        let params = ctx.uniform(&params);
        let depth = ctx.texture(DEPTH)?;
        let target = ctx.post_process_write()?;
        let blur_group = ctx.bind_group(
            &pipeline.blur_layout,
            &[
                Binding::Buffer(&ctx.scene.view.buffer),
                Binding::Buffer(&params),
                Binding::Texture(target.source),
                Binding::Texture(depth),
            ],
        );
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(
            ctx.encoder,
            "motion_blur",
            target.destination,
            timestamps,
            &pipeline.blur,
            &[&blur_group],
        );
        Ok(())
    }
}

/// Needed when the camera has motion blur and no debug view replaces the image.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn crate::graph::Pass>>) {
    if let Some(pass) = p.view.camera.and_then(|c| MotionBlurPass::for_camera(&c, p.view.size))
        && p.shows_image()
    {
        out.push(Box::new(pass));
    }
}

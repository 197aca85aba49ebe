//! Showing frames in a 2D canvas through read-back, for browsers whose WebGPU canvas cannot
//! present: headless Chromium's WebGPU on SwiftShader (machines without a GPU) loses its device
//! as soon as a WebGPU canvas presents a frame. The frame is rendered offscreen, as headless
//! rendering does, copied to the CPU without a wait ([`PendingImage`]) and drawn with
//! `putImageData`, frames later.

use manylight::app::backend::FrameSink;
use manylight::app::render_world::{DeviceLoss, HeadlessRenderer, SinkFrame};
use manylight::render::readback::PendingImage;
use manylight::render::wgpu;
use manylight::render::{FramePlanner, FrameReport, FrameSnapshot, RenderError, RenderTextureId};
use std::sync::{Arc, Mutex};

/// The newest frame read back for display, taken by the page's animation-frame loop.
pub type DisplaySlot = Arc<Mutex<Option<image::RgbaImage>>>;

/// Renders offscreen and reads every frame back for display (one read-back on its way at a
/// time), plus the frame the app asked to capture.
pub struct ReadBackSink {
    renderer: HeadlessRenderer,
    display: DisplaySlot,
    shown: Option<PendingImage>,
    captured: Option<PendingImage>,
}

impl ReadBackSink {
    /// A sink around `renderer` that puts frames to show into `display`.
    pub fn new(renderer: HeadlessRenderer, display: DisplaySlot) -> ReadBackSink {
        ReadBackSink { renderer, display, shown: None, captured: None }
    }
}

impl FrameSink for ReadBackSink {
    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError> {
        let mut frame = self.renderer.render_in_flight(snapshot, false)?;
        let gpu = self.renderer.render_world.gpu();
        if let Some(image) = PendingImage::take_arrived(&mut self.shown, gpu)?
            && let Ok(mut slot) = self.display.lock()
        {
            *slot = Some(image);
        }
        frame.image = PendingImage::take_arrived(&mut self.captured, gpu)?;
        if let Some(target) = self.renderer.target() {
            if self.shown.is_none() {
                self.shown = Some(PendingImage::start(gpu, target.texture())?);
            }
            if readback && self.captured.is_none() {
                self.captured = Some(PendingImage::start(gpu, target.texture())?);
            }
        }
        Ok(frame)
    }

    fn set_stages(&mut self, stages: &Arc<FramePlanner>) {
        self.renderer.set_stages(stages);
    }

    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        self.renderer.drain()
    }

    fn lose_device(&mut self, when: DeviceLoss) {
        self.renderer.lose_device(when);
    }

    fn take_textures(&mut self) -> Vec<(RenderTextureId, image::RgbaImage)> {
        self.renderer.take_textures()
    }

    fn ready(&self) -> bool {
        self.renderer.ready()
    }

    fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        self.renderer.adapter()
    }
}

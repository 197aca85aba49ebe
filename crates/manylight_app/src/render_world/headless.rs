//! Headless rendering: a render world and an offscreen target.

use super::RenderWorld;
use super::recovery::{DeviceSink, SinkFrame, empty_report};
use manylight_render::{FrameReport, FrameSnapshot, GpuContext, HeadlessTarget, RenderError};

/// Headless rendering: a render world plus an offscreen target that follows the snapshot's
/// viewport size.
pub struct HeadlessRenderer {
    /// The render world.
    pub render_world: RenderWorld,
    target: Option<HeadlessTarget>,
}

impl HeadlessRenderer {
    /// Creates a headless GPU context and render world with
    /// [`manylight_render::DEFAULT_FRAMES_IN_FLIGHT`] frames in flight.
    pub fn new() -> Result<HeadlessRenderer, RenderError> {
        Self::with_frames_in_flight(manylight_render::DEFAULT_FRAMES_IN_FLIGHT)
    }

    /// Creates a headless GPU context and render world; at most `frames_in_flight` frames are
    /// submitted and not yet read back.
    ///
    /// The device is requested with a blocking wait, which a browser cannot do: there this
    /// fails with [`RenderError::BlockingWait`]; request a [`GpuContext`] asynchronously
    /// ([`GpuContext::request`]) and use [`HeadlessRenderer::with_context`].
    pub fn with_frames_in_flight(frames_in_flight: u32) -> Result<HeadlessRenderer, RenderError> {
        #[cfg(not(target_arch = "wasm32"))]
        return Ok(Self::with_context(GpuContext::headless()?, frames_in_flight));
        #[cfg(target_arch = "wasm32")]
        {
            let _ = frames_in_flight;
            Err(RenderError::BlockingWait)
        }
    }

    /// The offscreen target the last frame was drawn into (none before the first frame).
    pub fn target(&self) -> Option<&HeadlessTarget> {
        self.target.as_ref()
    }

    /// A headless renderer on a context the caller requested.
    pub fn with_context(gpu: GpuContext, frames_in_flight: u32) -> HeadlessRenderer {
        HeadlessRenderer {
            render_world: RenderWorld::with_frames_in_flight(gpu, frames_in_flight),
            target: None,
        }
    }

    /// Renders a snapshot and waits for it (the reference path for tests and measurements: the
    /// report is complete when this returns); when `readback` is set, returns the image too. A
    /// device found lost is recreated (see [`RenderWorld::recover_device`]); the frame in
    /// which the loss is found renders nothing and says so in
    /// [`FrameReport::device_recoveries`].
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let mut frame = self.render_recovering(snapshot, readback)?;
        frame.reports.extend(self.render_world.take_reports(true)?);
        let report =
            frame.reports.pop().ok_or_else(|| RenderError::Graph("the frame gave no report".into()))?;
        Ok((report, frame.image))
    }

    /// Renders a snapshot without waiting for the GPU (unless `readback` asks for the image):
    /// returns the reports that have arrived, oldest first.
    pub fn render_in_flight(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<SinkFrame, RenderError> {
        self.render_recovering(snapshot, readback)
    }
}

impl DeviceSink for HeadlessRenderer {
    fn gpu(&self) -> &GpuContext {
        self.render_world.gpu()
    }

    fn render_world(&mut self) -> &mut RenderWorld {
        &mut self.render_world
    }

    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError> {
        self.render_world.recover_device(reason, frame, None)?;
        self.target = None;
        Ok(())
    }

    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(Option<FrameReport>, Option<image::RgbaImage>), RenderError> {
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 || !snapshot.views.iter().any(|v| v.camera.is_valid()) {
            // Nothing to look through or at.
            let mut snapshot = snapshot;
            let invalid_cameras = snapshot.reject_invalid_camera();
            let report = FrameReport { invalid_cameras, ..empty_report(&snapshot) };
            return Ok((Some(self.render_world.report_empty(report)), None));
        }
        let gpu = self.render_world.gpu().clone();
        let limit = gpu.device.limits().max_texture_dimension_2d;
        if size.x > limit || size.y > limit {
            return Err(RenderError::TargetTooLarge { width: size.x, height: size.y, limit });
        }
        if self.target.as_ref().map(|t| t.size()) != Some((size.x, size.y)) {
            self.target = Some(HeadlessTarget::new(&gpu, size.x, size.y));
        }
        let Some(target) = self.target.as_ref() else {
            return Err(RenderError::Graph("no headless target".into()));
        };
        let view = target.view().clone();
        let report = self.render_world.render(snapshot, &view, manylight_render::HEADLESS_FORMAT)?;
        let image = if readback { Some(target.read(&gpu)?) } else { None };
        self.render_world.finish_frame(report);
        Ok((None, image))
    }
}

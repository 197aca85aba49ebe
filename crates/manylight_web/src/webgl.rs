//! Rendering on WebGL2, the fallback where `navigator.gpu` gives no adapter (or the page asks
//! for it with `backend=webgl2`): the texture-list path (`manylight::render::texture_lists`:
//! clustered forward with CPU-built lists in textures) as the app's frame sink.
//!
//! Every frame is rendered offscreen and copied to the CPU without a wait (a browser cannot
//! block); when its copy arrives, frames later, the pixels the pass marked as not finite are
//! counted into the frame's report, which is handed to the app only then, and the image goes
//! to the page's display slot (and to the app when it asked for that frame). Natively (tests)
//! the sink waits for each frame, so reports and images come back with their own frame.

use crate::readback_canvas::DisplaySlot;
use manylight::app::backend::FrameSink;
use manylight::app::render_world::SinkFrame;
use manylight::render::readback::PendingImage;
use manylight::render::texture_lists::TextureListRenderer;
use manylight::render::texture_lists::lists::take_nonfinite;
use manylight::render::wgpu;
use manylight::render::{FrameReport, FrameSnapshot, RenderError};
use std::collections::VecDeque;
use std::sync::Mutex;

/// Frames rendered and not yet read back, at most (the app waits for [`FrameSink::ready`]).
pub const MAX_FRAMES_IN_FLIGHT: usize = 2;

/// A frame on its way back: its report, its image copy, and whether the app asked for it.
struct InFlight {
    report: FrameReport,
    image: PendingImage,
    wanted: bool,
}

/// The frames in flight and those that came back, not yet handed to the app.
#[derive(Default)]
struct Queue {
    in_flight: VecDeque<InFlight>,
    reports: Vec<FrameReport>,
    image: Option<image::RgbaImage>,
}

/// The texture-list renderer as a frame sink (module docs).
pub struct TextureListSink {
    renderer: TextureListRenderer,
    display: Option<DisplaySlot>,
    queue: Mutex<Queue>,
    /// The surface whose context the device was found through (the page's WebGL2 canvas),
    /// kept as long as the device.
    _surface: Option<wgpu::Surface<'static>>,
}

impl TextureListSink {
    /// A sink around `renderer` that puts each frame read back into `display`, if given.
    pub fn new(renderer: TextureListRenderer, display: Option<DisplaySlot>) -> TextureListSink {
        TextureListSink { renderer, display, queue: Mutex::new(Queue::default()), _surface: None }
    }

    /// This sink, keeping `surface` (the one its device was found through) alive with it.
    pub fn keeping(mut self, surface: wgpu::Surface<'static>) -> TextureListSink {
        self._surface = Some(surface);
        self
    }

    /// Takes the frames whose copies arrived, in order, into the queue's reports and image.
    fn collect(&self) -> Result<(), RenderError> {
        let gpu = self.renderer.gpu();
        let mut queue =
            self.queue.lock().map_err(|_| RenderError::Readback("the frame queue is poisoned".into()))?;
        while let Some(front) = queue.in_flight.front() {
            let Some(arrived) = front.image.try_take(gpu) else { break };
            let Some(InFlight { mut report, wanted, .. }) = queue.in_flight.pop_front() else { break };
            let mut image = arrived?;
            report.nonfinite_pixels = Some(take_nonfinite(&mut image));
            queue.reports.push(report);
            if wanted {
                queue.image = Some(image.clone());
            }
            if let Some(display) = &self.display
                && let Ok(mut slot) = display.lock()
            {
                *slot = Some(image);
            }
        }
        Ok(())
    }

    /// The reports and the image that came back since the last call.
    fn take_arrived(&self) -> Result<SinkFrame, RenderError> {
        self.collect()?;
        let mut queue =
            self.queue.lock().map_err(|_| RenderError::Readback("the frame queue is poisoned".into()))?;
        Ok(SinkFrame { reports: std::mem::take(&mut queue.reports), image: queue.image.take() })
    }
}

impl FrameSink for TextureListSink {
    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError> {
        let report = self.renderer.render(&snapshot)?;
        let gpu = self.renderer.gpu();
        let target =
            self.renderer.target().ok_or_else(|| RenderError::Readback("no frame was drawn".into()))?;
        let image = PendingImage::start(gpu, target.texture())?;
        if let Ok(mut queue) = self.queue.lock() {
            queue.in_flight.push_back(InFlight { report, image, wanted: readback });
        }
        if gpu.can_block() {
            gpu.wait_idle()?;
        }
        self.take_arrived()
    }

    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        if self.renderer.gpu().can_block() {
            self.renderer.gpu().wait_idle()?;
        }
        Ok(self.take_arrived()?.reports)
    }

    fn ready(&self) -> bool {
        // Polls, so that copies that arrived free their place.
        let _ = self.collect();
        self.queue.lock().is_ok_and(|q| q.in_flight.len() < MAX_FRAMES_IN_FLIGHT)
    }

    fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        Some(&self.renderer.gpu().info)
    }
}

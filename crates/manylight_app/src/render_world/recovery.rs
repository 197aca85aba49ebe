//! Device loss: how many losses the render world takes ([`MAX_DEVICE_LOSSES`] within
//! [`DEVICE_LOSS_WINDOW`] frames), injected losses for tests and the soak run ([`DeviceLoss`]),
//! recreating the device ([`RenderWorld::recover_device`]) and rendering through a loss
//! ([`DeviceSink::render_recovering`]).

use super::{RenderWorld, Stages};
use manylight_render::{FrameReport, FrameSnapshot, GpuContext, PipelineKind, RenderError};

/// The message of a panic payload (`panic!` with a string or a formatted message).
pub(crate) fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}

/// A lost device is recreated at most this many times within [`DEVICE_LOSS_WINDOW`] frames;
/// one more loss ends rendering with [`RenderError::DeviceLost`] instead of a device that keeps
/// dying being recreated forever.
pub const MAX_DEVICE_LOSSES: usize = 3;

/// Frames over which [`MAX_DEVICE_LOSSES`] is counted.
pub const DEVICE_LOSS_WINDOW: u64 = 600;

/// Frames in which the device was lost lately.
#[derive(Default)]
struct LossHistory {
    frames: std::collections::VecDeque<u64>,
}

impl LossHistory {
    /// Counts a loss in `frame`; `Err` when it is one too many.
    fn admit(&mut self, frame: u64, reason: &str) -> Result<(), RenderError> {
        while self.frames.front().is_some_and(|&f| frame.saturating_sub(f) >= DEVICE_LOSS_WINDOW) {
            self.frames.pop_front();
        }
        if self.frames.len() >= MAX_DEVICE_LOSSES {
            return Err(RenderError::DeviceLost {
                reason: reason.to_string(),
                why: format!(
                    "it was lost {} times within {DEVICE_LOSS_WINDOW} frames (MAX_DEVICE_LOSSES is {MAX_DEVICE_LOSSES})",
                    self.frames.len() + 1
                ),
            });
        }
        self.frames.push_back(frame);
        Ok(())
    }
}

/// When an injected device loss happens (fault injection for tests and the soak run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceLoss {
    /// The device is destroyed at once, between frames: the next frame finds it lost before
    /// it starts, recreates it and renders on the new device.
    BetweenFrames,
    /// The device is destroyed during the next frame, after its work was submitted: that
    /// frame's read-back and presentation meet a lost device, the frame is reported with no
    /// passes, and the frame after it renders on a new device.
    InFrame,
    /// The device is destroyed at the start of the next frame, after the check for a lost
    /// device and before the frame uploads its meshes, textures and lights: every buffer and
    /// texture of that frame is created on a lost device. The frame is reported with no
    /// passes, and the frame after it renders on a new device.
    BeforeUploads,
}

/// What the render world keeps about device losses across frames (and across the recreated
/// device).
#[derive(Default)]
pub(super) struct DeviceRecovery {
    losses: LossHistory,
    /// An injected loss waiting for the next frame ([`DeviceLoss::InFrame`] or
    /// [`DeviceLoss::BeforeUploads`]).
    pub(super) lose_in_frame: Option<DeviceLoss>,
    /// Device recoveries not yet counted in a finished frame's report.
    pub(super) recoveries: u32,
}

impl RenderWorld {
    /// Destroys the device as a driver reset would, now or during the next frame.
    pub fn lose_device(&mut self, when: DeviceLoss) {
        match when {
            DeviceLoss::BetweenFrames => self.gpu().device.destroy(),
            DeviceLoss::InFrame | DeviceLoss::BeforeUploads => self.recovery.lose_in_frame = Some(when),
        }
    }

    /// Recreates the device after it was lost (`reason`, found in `frame`): a new device on the
    /// same instance (able to present to `surface`, if given) and a new renderer on it, whose
    /// scene resources, pipelines and cluster buffers are built again from the next snapshot.
    /// Fails with [`RenderError::DeviceLost`] when no device can be created or when the device
    /// was lost more than [`MAX_DEVICE_LOSSES`] times within [`DEVICE_LOSS_WINDOW`] frames.
    pub fn recover_device(
        &mut self,
        reason: String,
        frame: u64,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<(), RenderError> {
        self.recovery.losses.admit(frame, &reason)?;
        let gpu = self
            .gpu()
            .recreate(surface)
            .map_err(|e| RenderError::DeviceLost { reason: reason.clone(), why: e.to_string() })?;
        tracing::warn!("the GPU device was {reason} in frame {frame}; recreated it on `{}`", gpu.info.name);
        let recovery = std::mem::take(&mut self.recovery);
        let frames_in_flight = self.renderer().frames_in_flight();
        let stages = self.world.resource::<Stages>().0.clone();
        *self = RenderWorld::with_frames_in_flight(gpu, frames_in_flight);
        self.world.insert_resource(Stages(stages));
        self.recovery = DeviceRecovery { recoveries: recovery.recoveries + 1, ..recovery };
        Ok(())
    }

    /// `report` with the device recoveries not yet counted in a frame's report. A frame that
    /// rendered nothing is reported this way, at once (nothing of it is on the GPU);
    /// [`RenderWorld::finish_frame`] counts them into the frame it sends in flight.
    pub fn report_empty(&mut self, mut report: FrameReport) -> FrameReport {
        report.device_recoveries += std::mem::take(&mut self.recovery.recoveries);
        report
    }
}

/// What a sink gives back for a frame: the reports that arrived meanwhile (in pipelined use,
/// those of earlier frames), and the frame's image if asked.
#[derive(Debug, Default)]
pub struct SinkFrame {
    /// Complete reports, oldest first.
    pub reports: Vec<FrameReport>,
    /// The frame's image, when read back.
    pub image: Option<image::RgbaImage>,
}

/// A renderer on a device that can be lost: it renders a frame on its device and recreates the
/// device after a loss; [`DeviceSink::render_recovering`] puts the two together.
pub(crate) trait DeviceSink {
    /// The current device.
    fn gpu(&self) -> &GpuContext;
    /// The render world.
    fn render_world(&mut self) -> &mut RenderWorld;
    /// Recreates the device after it was lost (`reason`, found in `frame`).
    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError>;
    /// Renders one frame on the current device and finishes it; `Some` report when the frame
    /// rendered nothing (it is complete at once).
    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(Option<FrameReport>, Option<image::RgbaImage>), RenderError>;

    /// Renders one frame, recreating the device first if it was lost since the last frame, or
    /// after the frame if it was lost during it. That frame's work went to the lost device: it
    /// is reported with no passes, and rendering goes on from the next frame (frames still in
    /// flight on the lost device report nothing). With `readback` the frame's image is read
    /// and every frame in flight is waited for; without, the reports that have arrived are
    /// returned and nothing waits.
    fn render_recovering(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<SinkFrame, RenderError> {
        let frame = snapshot.frame_index;
        if let Some(reason) = self.gpu().lost() {
            self.recover(reason, frame)?;
        }
        let (viewport, pipeline) = (snapshot.viewport, snapshot.settings.pipeline);
        // The frame boundary: a wgpu call that panics because the device was lost during the
        // frame (a third-party pass, a helper outside `GpuContext`) ends the frame here, where
        // the loss can be recovered from; a panic on a device that is not lost goes on
        // unwinding to the caller.
        let rendered = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.render_on_device(snapshot, readback).and_then(|(empty, image)| {
                let mut reports = self.render_world().take_reports(readback)?;
                reports.extend(empty);
                Ok(SinkFrame { reports, image })
            })
        }));
        let result = match rendered {
            Ok(result) => result,
            Err(panic) if self.gpu().lost().is_some() => {
                Err(RenderError::Device(format!("panicked: {}", panic_message(&*panic))))
            }
            Err(panic) => std::panic::resume_unwind(panic),
        };
        match self.gpu().lost() {
            Some(reason) => {
                if let Err(e) = &result {
                    tracing::warn!("frame {frame} failed on the lost device: {e}");
                }
                self.recover(reason, frame)?;
                let lost_frame = report_without_passes(frame, viewport, pipeline);
                let lost_frame = self.render_world().report_empty(lost_frame);
                Ok(SinkFrame { reports: vec![lost_frame], image: None })
            }
            None => result,
        }
    }
}

/// The report of a frame that rendered nothing (zero-sized viewport).
pub fn empty_report(snapshot: &FrameSnapshot) -> FrameReport {
    report_without_passes(snapshot.frame_index, snapshot.viewport, snapshot.settings.pipeline)
}

/// The report of frame `frame_index` of `viewport` that ran no pass.
fn report_without_passes(frame_index: u64, viewport: glam::UVec2, pipeline: PipelineKind) -> FrameReport {
    FrameReport { frame_index, width: viewport.x, height: viewport.y, pipeline, ..Default::default() }
}

//! Hand-off from the main world to the renderer: synchronously on the caller's thread, or
//! pipelined over a bounded crossbeam channel to a render thread (the simulation of frame N+1
//! overlaps the rendering of frame N; the channel holds one frame, so the simulation never runs
//! more than one frame ahead).

use crate::render_world::{DeviceLoss, SinkFrame, panic_message};
use crate::resources::{FrameStats, HeadlessCapture, RenderFailure, RenderedImages};
use bevy_ecs::prelude::*;
use crossbeam_channel::{Receiver, Sender, bounded, unbounded};
use manylight_render::{FramePlanner, FrameReport, FrameSnapshot, RenderError, RenderTextureId};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::thread::JoinHandle;

/// What rendering a frame gives back: the reports of the frames whose GPU figures arrived
/// meanwhile (with frames in flight, earlier frames'; each names its frame), the frame's image
/// if asked, and the images of its render-to-texture cameras.
#[derive(Debug)]
pub struct RenderedFrame {
    /// The frame that was rendered.
    pub frame_index: u64,
    /// Complete reports, oldest first.
    pub reports: Vec<FrameReport>,
    /// The main target's image, when read back.
    pub image: Option<image::RgbaImage>,
    /// The render-to-texture images, by id.
    pub textures: Vec<(RenderTextureId, image::RgbaImage)>,
}

/// A rendered frame, or why rendering stopped.
pub type FrameResult = Result<RenderedFrame, RenderFailed>;

/// Why rendering stopped: sent as a message (`MessageReader<RenderFailed>`) in the update that
/// learns of it, before the app exits with `AppExit::error()`; its text is also kept in
/// [`crate::RenderFailure`].
#[derive(Message, Clone, Debug, thiserror::Error)]
pub enum RenderFailed {
    /// The renderer returned an error (a lost device it could not recreate is
    /// [`RenderError::DeviceLost`]).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The renderer panicked; the message is the panic's.
    #[error("the renderer panicked: {0}")]
    Panic(String),
    /// The render thread ended outside a frame.
    #[error("{0}")]
    Stopped(String),
}

/// Something that renders snapshots: the headless renderer or a window surface.
pub trait FrameSink: Send + Sync + 'static {
    /// Renders one snapshot without waiting for the GPU, unless `readback` asks for its image
    /// (then every frame in flight is waited for); returns the reports that have arrived.
    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError>;

    /// The stages the next frames are planned with (the built-in ones and the app's; each frame
    /// brings them, as an `Arc` that changes only when the app adds a stage). Sinks that plan
    /// no frames ignore them.
    fn set_stages(&mut self, stages: &Arc<FramePlanner>) {
        let _ = stages;
    }

    /// Waits for the frames in flight and returns their reports (at shutdown).
    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        Ok(Vec::new())
    }

    /// Destroys the GPU device, as a driver reset would, at the point `when` says; the renderer
    /// finds it lost and recreates it. For fault-injection tests and the soak run; sinks
    /// without a device ignore it.
    fn lose_device(&mut self, when: DeviceLoss) {
        let _ = when;
    }

    /// The adapter the sink renders with, once it has a device.
    fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        None
    }

    /// Whether the next frame can be rendered without waiting for the GPU (every frame in
    /// flight has a free read-back slot). Where nothing may block (a browser) the app updates
    /// only when its sink is ready.
    fn ready(&self) -> bool {
        true
    }

    /// The images the last frame's render-to-texture cameras drew (none by default).
    fn take_textures(&mut self) -> Vec<(RenderTextureId, image::RgbaImage)> {
        Vec::new()
    }
}

impl FrameSink for crate::render_world::HeadlessRenderer {
    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError> {
        self.render_in_flight(snapshot, readback)
    }

    fn set_stages(&mut self, stages: &Arc<FramePlanner>) {
        self.render_world.set_stages(stages);
    }

    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        self.render_world.take_reports(true)
    }

    fn lose_device(&mut self, when: DeviceLoss) {
        self.render_world.lose_device(when);
    }

    fn take_textures(&mut self) -> Vec<(RenderTextureId, image::RgbaImage)> {
        self.render_world.take_textures()
    }

    fn ready(&self) -> bool {
        self.render_world.renderer().can_begin_frame()
    }

    fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        Some(&self.render_world.gpu().info)
    }
}

/// Renders one frame, turning a panic of the renderer into an error like any other failed
/// frame (the app ends on it; the render thread stops).
fn render_caught(sink: &mut dyn FrameSink, frame: Frame) -> FrameResult {
    let Frame { snapshot, readback, stages } = frame;
    let frame_index = snapshot.frame_index;
    sink.set_stages(&stages);
    match catch_unwind(AssertUnwindSafe(|| sink.render_frame(*snapshot, readback))) {
        Ok(result) => result
            .map(|SinkFrame { reports, image }| RenderedFrame {
                frame_index,
                reports,
                image,
                textures: sink.take_textures(),
            })
            .map_err(RenderFailed::Render),
        Err(payload) => Err(RenderFailed::Panic(panic_message(payload.as_ref()))),
    }
}

/// Waits for the sink's frames in flight; their reports as one result (none: `None`).
fn drain_caught(sink: &mut dyn FrameSink, last_frame: u64) -> Option<FrameResult> {
    match catch_unwind(AssertUnwindSafe(|| sink.drain())) {
        Ok(Ok(reports)) if reports.is_empty() => None,
        Ok(Ok(reports)) => {
            Some(Ok(RenderedFrame { frame_index: last_frame, reports, image: None, textures: Vec::new() }))
        }
        Ok(Err(e)) => Some(Err(RenderFailed::Render(e))),
        Err(payload) => Some(Err(RenderFailed::Panic(panic_message(payload.as_ref())))),
    }
}

/// One frame handed to the renderer.
struct Frame {
    snapshot: Box<FrameSnapshot>,
    /// Its image is read back.
    readback: bool,
    /// The stages it is planned with.
    stages: Arc<FramePlanner>,
}

enum ToRenderThread {
    Frame(Frame),
    LoseDevice(DeviceLoss),
}

/// The render thread: receives snapshots, renders them, sends results back.
pub struct RenderThread {
    frames: Option<Sender<ToRenderThread>>,
    results: Receiver<FrameResult>,
    handle: Option<JoinHandle<()>>,
}

impl RenderThread {
    /// Starts a render thread around `sink`.
    pub fn spawn(mut sink: Box<dyn FrameSink>) -> std::io::Result<RenderThread> {
        let (frame_tx, frame_rx) = bounded::<ToRenderThread>(1);
        let (result_tx, result_rx) = unbounded::<FrameResult>();
        let handle = std::thread::Builder::new().name("manylight-render".into()).spawn(move || {
            // Ends when the sender is dropped (app shut down) or a frame fails; then the frames
            // still in flight are waited for and reported.
            let mut last_frame = 0;
            let mut failed = false;
            while let Ok(message) = frame_rx.recv() {
                let frame = match message {
                    ToRenderThread::Frame(frame) => frame,
                    ToRenderThread::LoseDevice(when) => {
                        sink.lose_device(when);
                        continue;
                    }
                };
                last_frame = frame.snapshot.frame_index;
                let result = render_caught(sink.as_mut(), frame);
                failed = result.is_err();
                if result_tx.send(result).is_err() || failed {
                    break;
                }
            }
            if !failed && let Some(result) = drain_caught(sink.as_mut(), last_frame) {
                let _ = result_tx.send(result);
            }
            tracing::debug!("render thread finished");
        })?;
        Ok(RenderThread { frames: Some(frame_tx), results: result_rx, handle: Some(handle) })
    }

    /// Stops the thread after the frame in flight and waits for it; a panic that ended the
    /// thread comes back as its message.
    pub fn shutdown(&mut self) -> Option<String> {
        self.frames.take();
        self.handle.take().and_then(|h| h.join().err()).map(|payload| {
            let message = format!("the render thread panicked: {}", panic_message(payload.as_ref()));
            tracing::error!("{message}");
            message
        })
    }
}

impl Drop for RenderThread {
    fn drop(&mut self) {
        let _ = self.shutdown();
    }
}

/// How the main world reaches the renderer.
#[derive(Resource)]
pub enum RenderBackend {
    /// No renderer yet (a window backend is created when the window exists).
    Pending,
    /// Render on the calling thread.
    Sync {
        /// The renderer.
        sink: Box<dyn FrameSink>,
        /// Results not yet collected.
        pending: Vec<FrameResult>,
        /// The last frame submitted.
        last_frame: u64,
    },
    /// Render on a render thread.
    Pipelined(RenderThread),
    /// Creating the renderer failed; the message says why.
    Failed(String),
}

/// Whether this platform renders on a thread of its own: everywhere but a browser, whose
/// WebAssembly has no threads (there the synchronous path renders each frame on the caller).
pub const HAS_RENDER_THREAD: bool = cfg!(not(target_arch = "wasm32"));

impl RenderBackend {
    /// The backend for `sink`: pipelined on a render thread when asked and the platform has
    /// threads ([`HAS_RENDER_THREAD`]), synchronous otherwise.
    pub fn start(sink: Box<dyn FrameSink>, pipelined: bool) -> RenderBackend {
        if !(pipelined && HAS_RENDER_THREAD) {
            return RenderBackend::sync(sink);
        }
        match RenderThread::spawn(sink) {
            Ok(t) => RenderBackend::Pipelined(t),
            Err(e) => RenderBackend::Failed(format!("could not start the render thread: {e}")),
        }
    }

    /// Whether a frame submitted now renders without a blocking wait: a synchronous sink with
    /// a free read-back slot, or a render thread (which waits on its own thread). No renderer
    /// yet (the device is still being requested) is not ready.
    pub fn ready(&self) -> bool {
        match self {
            RenderBackend::Sync { sink, .. } => sink.ready(),
            RenderBackend::Pipelined(_) | RenderBackend::Failed(_) => true,
            RenderBackend::Pending => false,
        }
    }

    /// The adapter of a synchronous sink (a render thread keeps its sink to itself: `None`).
    pub fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        match self {
            RenderBackend::Sync { sink, .. } => sink.adapter(),
            _ => None,
        }
    }

    /// Renders on the calling thread through `sink`.
    pub fn sync(sink: Box<dyn FrameSink>) -> RenderBackend {
        RenderBackend::Sync { sink, pending: Vec::new(), last_frame: 0 }
    }

    /// Hands a snapshot over, to be planned with `stages` (renders it now in sync mode).
    pub fn submit(&mut self, snapshot: FrameSnapshot, readback: bool, stages: Arc<FramePlanner>) {
        let frame = Frame { snapshot: Box::new(snapshot), readback, stages };
        match self {
            RenderBackend::Pending => {}
            RenderBackend::Sync { sink, pending, last_frame } => {
                *last_frame = frame.snapshot.frame_index;
                pending.push(render_caught(sink.as_mut(), frame));
            }
            RenderBackend::Pipelined(thread) => {
                let sent =
                    thread.frames.as_ref().is_some_and(|tx| tx.send(ToRenderThread::Frame(frame)).is_ok());
                if !sent {
                    tracing::debug!("render thread has stopped; frame dropped");
                }
            }
            RenderBackend::Failed(_) => {}
        }
    }

    /// Destroys the renderer's GPU device, as a driver reset would, between frames or during
    /// the next one ([`DeviceLoss`]): the renderer finds the device lost, recreates it and
    /// goes on (counted in [`FrameReport::device_recoveries`]). Fault injection for tests and
    /// the soak run.
    pub fn lose_device(&mut self, when: DeviceLoss) {
        match self {
            RenderBackend::Sync { sink, .. } => sink.lose_device(when),
            RenderBackend::Pipelined(thread) => {
                if let Some(tx) = thread.frames.as_ref() {
                    let _ = tx.send(ToRenderThread::LoseDevice(when));
                }
            }
            RenderBackend::Pending | RenderBackend::Failed(_) => {}
        }
    }

    /// Results that arrived since the last call.
    pub fn drain(&mut self) -> Vec<FrameResult> {
        match self {
            RenderBackend::Sync { pending, .. } => std::mem::take(pending),
            RenderBackend::Pipelined(thread) => {
                let mut results: Vec<FrameResult> = thread.results.try_iter().collect();
                // A render thread that ended while frames are still being sent has failed (it
                // panicked, or it stopped after an error already reported above).
                let ended = thread.handle.as_ref().is_some_and(|h| h.is_finished());
                if ended && thread.frames.is_some() && !results.iter().any(|r| r.is_err()) {
                    let message = thread.shutdown();
                    results.push(Err(RenderFailed::Stopped(
                        message.unwrap_or_else(|| "the render thread stopped unexpectedly".into()),
                    )));
                }
                results
            }
            RenderBackend::Failed(message) => {
                let m = std::mem::take(message);
                if m.is_empty() { Vec::new() } else { vec![Err(RenderFailed::Stopped(m))] }
            }
            RenderBackend::Pending => Vec::new(),
        }
    }

    /// Waits for every frame in flight (pipelined mode) and returns their results; a render
    /// thread that panicked adds an error with the panic's message, so a run never ends in a
    /// success with a frame missing.
    pub fn flush(&mut self) -> Vec<FrameResult> {
        let panic = match self {
            RenderBackend::Pipelined(thread) => thread.shutdown(),
            RenderBackend::Sync { sink, pending, last_frame } => {
                if !pending.iter().any(|r| r.is_err())
                    && let Some(result) = drain_caught(sink.as_mut(), *last_frame)
                {
                    pending.push(result);
                }
                None
            }
            _ => None,
        };
        let mut results = self.drain();
        if let Some(message) = panic
            && !results.iter().any(|r| r.is_err())
        {
            results.push(Err(RenderFailed::Stopped(message)));
        }
        results
    }
}

/// Stores finished frames in the world: each report in [`FrameStats`], a read-back image in
/// [`HeadlessCapture`]; a failure goes to [`RenderFailure`] and is sent as a [`RenderFailed`]
/// message. Returns true when a frame failed (the caller ends the app with an error).
pub fn record_results(world: &mut World, results: Vec<FrameResult>) -> bool {
    let mut failed = false;
    for result in results {
        match result {
            Ok(RenderedFrame { frame_index, reports, image, textures }) => {
                if !textures.is_empty()
                    && let Some(mut images) = world.get_resource_mut::<RenderedImages>()
                {
                    for (id, texture) in textures {
                        images.insert(id, frame_index, texture);
                    }
                }
                if let Some(mut stats) = world.get_resource_mut::<FrameStats>() {
                    stats.submitted = stats.submitted.max(frame_index);
                    for report in reports {
                        stats.record(report);
                    }
                }
                if let (Some(image), Some(mut capture)) = (image, world.get_resource_mut::<HeadlessCapture>())
                {
                    capture.image = Some(image);
                }
            }
            Err(failure) => {
                tracing::error!("rendering failed: {failure}");
                world.insert_resource(RenderFailure(Some(failure.to_string())));
                if world.contains_resource::<bevy_ecs::message::Messages<RenderFailed>>() {
                    world.write_message(failure);
                }
                failed = true;
            }
        }
    }
    failed
}

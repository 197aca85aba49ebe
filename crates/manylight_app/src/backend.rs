//! Hand-off from the main world to the renderer: synchronously on the caller's thread, or
//! pipelined over a bounded crossbeam channel to a render thread (the simulation of frame N+1
//! overlaps the rendering of frame N; the channel holds one frame, so the simulation never runs
//! more than one frame ahead).

use bevy_ecs::prelude::*;
use crossbeam_channel::{Receiver, Sender, bounded, unbounded};
use manylight_render::{FrameReport, FrameSnapshot, RenderError};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::thread::JoinHandle;

/// What a rendered frame gives back: its report and, if asked, its image.
pub type FrameResult = Result<(FrameReport, Option<image::RgbaImage>), String>;

/// Something that renders snapshots: the headless renderer or a window surface.
pub trait FrameSink: Send + Sync + 'static {
    /// Renders one snapshot; reads the image back when `readback` is set.
    fn render_frame(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError>;
}

impl FrameSink for crate::render_world::HeadlessRenderer {
    fn render_frame(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        self.render(snapshot, readback)
    }
}

/// The message of a panic payload (`panic!` with a string or a formatted message).
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}

/// Renders one frame, turning a panic of the renderer into an error like any other failed
/// frame (the app ends on it; the render thread stops).
fn render_caught(sink: &mut dyn FrameSink, snapshot: FrameSnapshot, readback: bool) -> FrameResult {
    match catch_unwind(AssertUnwindSafe(|| sink.render_frame(snapshot, readback))) {
        Ok(result) => result.map_err(|e| e.to_string()),
        Err(payload) => Err(format!("the renderer panicked: {}", panic_message(payload.as_ref()))),
    }
}

enum Message {
    Frame(Box<FrameSnapshot>, bool),
}

/// The render thread: receives snapshots, renders them, sends results back.
pub struct RenderThread {
    frames: Option<Sender<Message>>,
    results: Receiver<FrameResult>,
    handle: Option<JoinHandle<()>>,
}

impl RenderThread {
    /// Starts a render thread around `sink`.
    pub fn spawn(mut sink: Box<dyn FrameSink>) -> std::io::Result<RenderThread> {
        let (frame_tx, frame_rx) = bounded::<Message>(1);
        let (result_tx, result_rx) = unbounded::<FrameResult>();
        let handle = std::thread::Builder::new().name("manylight-render".into()).spawn(move || {
            // Ends when the sender is dropped (app shut down) or a frame fails.
            while let Ok(Message::Frame(snapshot, readback)) = frame_rx.recv() {
                let result = render_caught(sink.as_mut(), *snapshot, readback);
                let failed = result.is_err();
                if result_tx.send(result).is_err() || failed {
                    break;
                }
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
    },
    /// Render on a render thread.
    Pipelined(RenderThread),
    /// Creating the renderer failed; the message says why.
    Failed(String),
}

impl RenderBackend {
    /// Hands a snapshot over (renders it now in sync mode).
    pub fn submit(&mut self, snapshot: FrameSnapshot, readback: bool) {
        match self {
            RenderBackend::Pending => {}
            RenderBackend::Sync { sink, pending } => {
                pending.push(render_caught(sink.as_mut(), snapshot, readback));
            }
            RenderBackend::Pipelined(thread) => {
                let sent = thread
                    .frames
                    .as_ref()
                    .is_some_and(|tx| tx.send(Message::Frame(Box::new(snapshot), readback)).is_ok());
                if !sent {
                    tracing::debug!("render thread has stopped; frame dropped");
                }
            }
            RenderBackend::Failed(_) => {}
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
                    results.push(Err(
                        message.unwrap_or_else(|| "the render thread stopped unexpectedly".into())
                    ));
                }
                results
            }
            RenderBackend::Failed(message) => {
                let m = std::mem::take(message);
                if m.is_empty() { Vec::new() } else { vec![Err(m)] }
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
            _ => None,
        };
        let mut results = self.drain();
        if let Some(message) = panic
            && !results.iter().any(|r| r.is_err())
        {
            results.push(Err(message));
        }
        results
    }
}

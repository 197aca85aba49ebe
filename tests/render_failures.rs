//! A panic or an error of the renderer ends the app with that error, in pipelined and
//! synchronous mode alike, also when it happens in the last frame: the headless runner then
//! exits with an error and writes no PNG (never the previous frame's image as a success).

mod support;

use manylight::app::backend::{FrameSink, RenderBackend, RenderThread};
use manylight::app::render_world::{HeadlessRenderer, SinkFrame};
use manylight::app::{FrameStats, RenderFailure};
use manylight::prelude::*;
use manylight::render::{FrameReport, FrameSnapshot, RenderError};
use support::gpu;

const SIZE: UVec2 = UVec2::new(64, 48);

/// How the wrapped renderer fails.
#[derive(Clone, Copy, Debug)]
enum Failure {
    Panic,
    Error,
}

/// The real headless renderer, failing on the `fail_at`-th frame (1-based).
struct FailingSink {
    inner: HeadlessRenderer,
    frames: u32,
    fail_at: u32,
    failure: Failure,
}

impl FrameSink for FailingSink {
    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError> {
        self.frames += 1;
        if self.frames == self.fail_at {
            match self.failure {
                Failure::Panic => panic!("injected renderer panic in frame {}", self.frames),
                Failure::Error => {
                    return Err(RenderError::Readback(format!("injected error in frame {}", self.frames)));
                }
            }
        }
        self.inner.render_frame(snapshot, readback)
    }

    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        self.inner.drain()
    }
}

/// A headless app of `frames` frames writing `out`, whose renderer fails in frame `fail_at`.
fn failing_app(pipelined: bool, frames: u32, fail_at: u32, failure: Failure, out: &std::path::Path) -> App {
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE).with_frames(frames).with_output(out)).add_systems(
        Startup,
        |mut commands: Commands| {
            let scene = default_scene();
            spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
            spawn_light_rig(&mut commands, 8, scene.bounds(), 1).expect("the rig's lights fit");
        },
    );
    let sink = FailingSink { inner: HeadlessRenderer::new().expect("adapter"), frames: 0, fail_at, failure };
    let backend = if pipelined {
        RenderBackend::Pipelined(RenderThread::spawn(Box::new(sink)).expect("render thread"))
    } else {
        RenderBackend::sync(Box::new(sink))
    };
    app.insert_resource(backend);
    app
}

#[test]
fn a_renderer_failure_ends_the_run_with_an_error_and_no_png() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        for failure in [Failure::Panic, Failure::Error] {
            // In the first frame, in the middle, and in the last frame of the run.
            for fail_at in [1, 2, 3] {
                let what = format!("pipelined {pipelined}, {failure:?} in frame {fail_at} of 3");
                let out =
                    support::output_dir().join(format!("failure_{pipelined}_{failure:?}_{fail_at}.png"));
                let _ = std::fs::remove_file(&out);
                let exit = failing_app(pipelined, 3, fail_at, failure, &out).run();
                assert!(exit.is_error(), "{what}: exit {exit:?}");
                assert!(!out.exists(), "{what}: a PNG was written although the frame failed");
            }
        }
    }
}

#[test]
fn the_failure_message_reaches_the_app() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        let out = support::output_dir().join("failure_message.png");
        let mut app = failing_app(pipelined, 4, 2, Failure::Panic, &out);
        manylight::app::headless::finish_plugins(&mut app);
        let mut exited = None;
        for _ in 0..4 {
            app.update();
            if let Some(exit) = app.should_exit() {
                exited = Some(exit);
                break;
            }
        }
        manylight::app::headless::finish_frames(&mut app);
        let message = app.world().resource::<RenderFailure>().0.clone();
        let message = message.unwrap_or_else(|| panic!("pipelined {pipelined}: no RenderFailure"));
        assert!(message.contains("injected renderer panic in frame 2"), "pipelined {pipelined}: {message}");
        // Synchronous mode knows at once; pipelined mode by the next frame's drain.
        if !pipelined {
            assert!(exited.as_ref().is_some_and(AppExit::is_error), "sync: {exited:?}");
        }
        assert!(app.world().resource::<FrameStats>().frames_rendered <= 2);
    }
}

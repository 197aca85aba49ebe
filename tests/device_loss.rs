//! A lost GPU device (driver reset, device removed; here `Device::destroy`) is recreated: the
//! frame in which the loss is found renders nothing and is counted, the next frame renders the
//! same image as before on a new device, in synchronous and pipelined mode, in every pipeline.
//! A device that keeps getting lost ends the app with a typed error (a `RenderFailed` message,
//! then `AppExit::error()`), never a panic, a hang or frames that silently render nothing.

mod support;

use manylight::app::backend::RenderBackend;
use manylight::app::headless::{finish_frames, finish_plugins};
use manylight::app::render_world::{DeviceLoss, MAX_DEVICE_LOSSES};
use manylight::app::{FrameStats, HeadlessCapture, RenderFailed, RenderFailure, RenderSettings};
use manylight::prelude::*;
use manylight::render::{PipelineKind, RenderError};
use support::{STRICT, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(96, 64);

fn app(pipelined: bool, pipeline: PipelineKind) -> App {
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE).with_pipelined(pipelined))
        .insert_resource(RenderSettings { pipeline, ..Default::default() })
        .add_systems(Startup, |mut commands: Commands| {
            let scene = default_scene();
            spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
            // A light rig without animation: every frame shows the same image.
            spawn_light_rig(&mut commands, 64, scene.bounds(), 7);
        });
    finish_plugins(&mut app);
    app
}

/// Runs `frames` frames, destroying the device in or before the frames `lose` lists,
/// then waits for the frames in flight; returns whether the app asked to exit.
fn run(app: &mut App, frames: u64, lose: &[(u64, DeviceLoss)]) -> Option<AppExit> {
    let mut exit = None;
    for f in 0..frames {
        for &(_, when) in lose.iter().filter(|(at, _)| *at == f) {
            app.world_mut().resource_mut::<RenderBackend>().lose_device(when);
        }
        app.update();
        exit = app.should_exit();
        if exit.is_some() {
            break;
        }
    }
    finish_frames(app);
    exit
}

fn captured(app: &App) -> image::RgbaImage {
    app.world().resource::<HeadlessCapture>().image.clone().expect("a captured frame")
}

#[test]
fn a_lost_device_is_recreated_and_the_next_frame_is_the_same_image() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        for pipeline in PipelineKind::ALL {
            let what = format!("pipelined {pipelined}, {}", pipeline.name());
            let mut reference = app(pipelined, pipeline);
            assert!(run(&mut reference, 6, &[]).is_none(), "{what}");
            let mut lossy = app(pipelined, pipeline);
            // Lost between frames 1 and 2 (frame 2 renders on a new device), then during
            // frame 4 (which renders nothing; frame 5 renders on a third device).
            let losses = [(2, DeviceLoss::BetweenFrames), (4, DeviceLoss::InFrame)];
            assert!(run(&mut lossy, 6, &losses).is_none(), "{what}");
            assert!(lossy.world().resource::<RenderFailure>().0.is_none(), "{what}");
            let stats = lossy.world().resource::<FrameStats>();
            assert_eq!(stats.device_recoveries, 2, "{what}: each loss is counted once");
            assert_eq!(stats.frames_rendered, 5, "{what}: only the frame of the in-frame loss is missing");
            let last = stats.last.as_ref().expect("a report");
            assert_eq!(last.device_recoveries, 0, "{what}");
            assert_eq!(last.nonfinite_pixels.unwrap_or(0), 0, "{what}");
            assert_similar(
                &format!("device_loss_{pipelined}_{}", pipeline.name()),
                &captured(&reference),
                &captured(&lossy),
                STRICT,
            );
        }
    }
}

#[test]
fn a_device_lost_again_and_again_ends_the_app_with_a_typed_error() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        let mut app = app(pipelined, PipelineKind::ClusteredForward);
        let losses: Vec<_> = (1..=MAX_DEVICE_LOSSES as u64 + 1).map(|f| (f, DeviceLoss::InFrame)).collect();
        let exit = run(&mut app, MAX_DEVICE_LOSSES as u64 + 3, &losses);
        if !pipelined {
            // Synchronous mode knows at once; pipelined mode when the frames are flushed.
            assert!(exit.as_ref().is_some_and(AppExit::is_error), "sync: {exit:?}");
        }
        let stats = app.world().resource::<FrameStats>();
        assert_eq!(stats.device_recoveries, MAX_DEVICE_LOSSES as u64, "pipelined {pipelined}");
        let failures: Vec<RenderFailed> =
            app.world_mut().resource_mut::<bevy_ecs::message::Messages<RenderFailed>>().drain().collect();
        assert!(
            matches!(failures.as_slice(), [RenderFailed::Render(RenderError::DeviceLost { .. })]),
            "pipelined {pipelined}: {failures:?}"
        );
        let message = app.world().resource::<RenderFailure>().0.clone().unwrap_or_default();
        assert!(message.contains("MAX_DEVICE_LOSSES"), "pipelined {pipelined}: {message}");
    }
}

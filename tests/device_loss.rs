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
            spawn_light_rig(&mut commands, 64, scene.bounds(), 7).expect("the rig's lights fit");
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

/// Runs `frames` frames with the device lost as `losses` says and checks the recovery against a
/// run without losses: no failure, each loss counted once, `rendered` frames rendered, and the
/// last image the same (FLIP within the strict tolerance; `name` names the failure images).
fn assert_recovers(
    name: &str,
    pipelined: bool,
    pipeline: PipelineKind,
    frames: u64,
    losses: &[(u64, DeviceLoss)],
    rendered: u64,
) {
    let what = format!("pipelined {pipelined}, {}", pipeline.name());
    let mut reference = app(pipelined, pipeline);
    assert!(run(&mut reference, frames, &[]).is_none(), "{what}");
    let mut lossy = app(pipelined, pipeline);
    assert!(run(&mut lossy, frames, losses).is_none(), "{what}");
    assert!(lossy.world().resource::<RenderFailure>().0.is_none(), "{what}");
    let stats = lossy.world().resource::<FrameStats>();
    assert_eq!(stats.device_recoveries, losses.len() as u64, "{what}: each loss is counted once");
    assert_eq!(stats.frames_rendered, rendered, "{what}: frames rendered");
    let last = stats.last.as_ref().expect("a report");
    assert_eq!(last.device_recoveries, 0, "{what}");
    assert_eq!(last.nonfinite_pixels.unwrap_or(0), 0, "{what}");
    assert_similar(
        &format!("{name}_{pipelined}_{}", pipeline.name()),
        &captured(&reference),
        &captured(&lossy),
        STRICT,
    );
}

#[test]
fn a_lost_device_is_recreated_and_the_next_frame_is_the_same_image() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        for pipeline in PipelineKind::ALL {
            // Lost between frames 1 and 2 (frame 2 renders on a new device), then during
            // frame 4 (which renders nothing; frame 5 renders on a third device): only the
            // frame of the in-frame loss is missing.
            let losses = [(2, DeviceLoss::BetweenFrames), (4, DeviceLoss::InFrame)];
            assert_recovers("device_loss", pipelined, pipeline, 6, &losses, 5);
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

/// A device lost at the start of a frame, before its uploads: every mesh, texture and light
/// buffer of that frame is created on the lost device (wgpu's `create_buffer_init` panics there).
/// The frame is reported with no passes, and the frames after it render the same image as a
/// run without a loss — in the first frame (everything uploads) and in a later one.
#[test]
fn a_device_lost_before_the_frames_uploads_recovers() {
    let _gpu = gpu();
    for pipelined in [false, true] {
        for pipeline in [PipelineKind::ClusteredForward, PipelineKind::LightVolumes] {
            let losses = [(0, DeviceLoss::BeforeUploads), (2, DeviceLoss::BeforeUploads)];
            assert_recovers("device_loss_uploads", pipelined, pipeline, 5, &losses, 3);
        }
    }
}

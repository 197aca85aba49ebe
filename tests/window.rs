//! Opens a real window (on its own Xvfb server when no display is set) and drives it through
//! [`WindowRequests`]: resizes, a storm of resizes, minimising (0×0), resizing while minimised,
//! restoring, a 1×1 window with bloom and motion blur and back, then closing while a frame is in
//! flight. Checks that every size was really rendered, that no frame had a non-finite pixel,
//! that the frames after the 1×1 ones equal, pixel for pixel, the frame read back before them,
//! that the app exits with success, that nothing panicked and that the render thread is gone
//! when `App::run` returns.
//!
//! winit allows one event loop per process, so everything is one `#[test]`: it drives a
//! pipelined window (render thread) itself, then runs itself again in a child process for a
//! synchronous one (surface on the main thread).
//!
//! Without a display and without `Xvfb` the test says so loudly and passes, unless `CI=true`,
//! where it fails.

mod support;

use manylight::app::backend::RenderBackend;
use manylight::app::render_world::DeviceLoss;
use manylight::app::window::{WindowConfig, WindowRequests};
use manylight::app::{HeadlessCapture, ViewportSize};
use manylight::prelude::*;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Seconds one step of the script may take before the test gives up.
const STEP_TIMEOUT: Duration = Duration::from_secs(20);
/// The whole test aborts after this (a hung event loop must not hang CI).
const WATCHDOG: Duration = Duration::from_secs(150);
/// Set in the child process that runs the synchronous mode.
const MODE_VAR: &str = "MANYLIGHT_WINDOW_TEST_MODE";
/// Updates the app must stay minimised with a 0×0 viewport.
const MINIMISED_UPDATES: u32 = 10;
/// Frames rendered at 1×1 before the window grows again.
const ONE_PIXEL_FRAMES: u32 = 5;
/// Frames read back after the 1×1 ones and compared with the reference.
const COMPARED_FRAMES: u32 = 3;
/// The size the 1×1 steps start from and come back to.
const BACK: (u32, u32) = (320, 240);

/// A unit cube with flat normals (24 vertices).
fn cube() -> MeshData {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let u = Vec3::from_array(std::array::from_fn(|i| if i == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let v = n.cross(u);
            let base = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push((n + u * a + v * b) * 0.5);
                normals.push(n);
            }
            indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    match MeshData::from_attributes("test_cube", &positions, Some(&normals), None, Some(indices)) {
        Ok(m) => m,
        Err(e) => panic!("the test cube is invalid: {e}"),
    }
}

/// A floor, four boxes, eight coloured lights, a camera and a second one drawn over its top-left
/// corner (a viewport copied into the swapchain image).
fn spawn_small_scene(mut commands: Commands) {
    let mesh = Arc::new(cube());
    let material = Arc::new(MaterialData::default());
    let mut floor = Transform::from_xyz(0.0, -0.05, 0.0);
    floor.scale = Vec3::new(8.0, 0.1, 8.0);
    commands.spawn((floor, Mesh3d(mesh.clone()), Material(material.clone())));
    for (x, z) in [(-1.5, -1.5), (1.5, -1.5), (-1.5, 1.5), (1.5, 1.5)] {
        commands.spawn((Transform::from_xyz(x, 0.5, z), Mesh3d(mesh.clone()), Material(material.clone())));
    }
    for i in 0..8 {
        let a = i as f32 / 8.0 * std::f32::consts::TAU;
        let color = Color::linear_rgb(0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin(), 0.6);
        commands.spawn((
            Transform::from_xyz(3.0 * a.cos(), 1.5, 3.0 * a.sin()),
            PointLight { color, intensity: 50.0, range: 6.0, radius: 0.0, ..Default::default() },
        ));
    }
    commands.spawn((Transform::from_xyz(0.0, 4.0, 7.0).looking_at(Vec3::ZERO, Vec3::Y), Camera3d));
    let corner = Viewport { physical_position: UVec2::new(8, 8), physical_size: UVec2::new(64, 48) };
    commands.spawn((
        Transform::from_xyz(0.0, 9.0, 0.1).looking_at(Vec3::ZERO, Vec3::Y),
        Camera3d,
        Camera { order: 1, viewport: Some(corner), ..default() },
    ));
}

/// One step of the script.
#[derive(Clone, Copy, Debug)]
enum Step {
    /// Ask for a size (no waiting).
    Resize(u32, u32),
    /// Ask to minimise or restore (no waiting).
    Minimize(bool),
    /// Wait until a frame of this size was really rendered.
    Rendered(u32, u32),
    /// Wait until the viewport has been 0×0 for [`MINIMISED_UPDATES`] updates.
    StayMinimised,
    /// Put `Bloom` and `MotionBlur` on the camera (`true`) or take them off, and read every
    /// frame back from now on (or stop).
    Post(bool),
    /// Wait until this many more frames with bloom were rendered at this size.
    RenderedFrames(u32, u32, u32),
    /// Keep the next frame read back at [`BACK`] as the reference image.
    CaptureReference,
    /// Wait until [`COMPARED_FRAMES`] frames read back at [`BACK`] were compared with the
    /// reference (every one that arrives during the step is).
    MatchReference,
    /// Destroy the GPU device, as a driver reset would, between frames or during the next
    /// frame; the renderer recreates it and goes on.
    LoseDevice(DeviceLoss),
    /// Ask to close.
    Close,
}

const SCRIPT: &[Step] = &[
    Step::Rendered(320, 240),
    Step::Resize(400, 300),
    Step::Rendered(400, 300),
    // A storm: a new size every update, only the last one needs to show.
    Step::Resize(200, 150),
    Step::Resize(480, 360),
    Step::Resize(256, 192),
    Step::Resize(360, 270),
    Step::Rendered(360, 270),
    Step::Minimize(true),
    Step::StayMinimised,
    // Resize while minimised: the restore must configure the surface for the new size.
    Step::Resize(300, 200),
    Step::StayMinimised,
    Step::Minimize(false),
    Step::Rendered(300, 200),
    Step::Minimize(true),
    Step::StayMinimised,
    Step::Minimize(false),
    Step::Rendered(300, 200),
    Step::Resize(320, 240),
    Step::Rendered(320, 240),
    // 1×1 with bloom (its chain halves the size five times) and motion blur, and back.
    Step::Post(true),
    Step::RenderedFrames(BACK.0, BACK.1, 3),
    Step::CaptureReference,
    Step::Resize(1, 1),
    Step::RenderedFrames(1, 1, ONE_PIXEL_FRAMES),
    Step::Resize(BACK.0, BACK.1),
    Step::MatchReference,
    // A lost device is recreated (surface configured again, the overlay's textures uploaded
    // again), and the frames after it are the same image.
    Step::LoseDevice(DeviceLoss::BetweenFrames),
    Step::RenderedFrames(BACK.0, BACK.1, 3),
    Step::LoseDevice(DeviceLoss::InFrame),
    Step::RenderedFrames(BACK.0, BACK.1, 3),
    Step::MatchReference,
    Step::Post(false),
    Step::Close,
];

/// What the script saw, read by the test after `App::run` returns.
#[derive(Debug, Default)]
struct Log {
    /// Index of the step reached.
    step: usize,
    /// `Some` when a step timed out.
    failure: Option<String>,
    /// Frames really rendered (with passes), by size.
    rendered: Vec<(u32, u32)>,
    /// Updates seen with a 0×0 viewport.
    minimised_updates: u32,
    /// Frames the sink got with a 0×0 viewport (and skipped).
    zero_sized_frames: u32,
    /// `FrameStats::frames_rendered` at the close request.
    frames_rendered: u64,
    /// Rendered frames whose last pass was the egui overlay.
    overlay_frames: u32,
    /// When the close was requested (printed; the test counts updates, not time).
    close_requested: Option<Instant>,
    /// Updates the app ran after the update that requested the close (the app exits after
    /// that update, so none).
    updates_after_close: u32,
    /// Frames whose report counted non-finite pixels.
    nonfinite_frames: u32,
    /// The most views one rendered frame had.
    max_views: usize,
    /// Passes of the last frame rendered at 1×1.
    one_pixel_passes: Vec<String>,
    /// Frames read back at [`BACK`] after the 1×1 ones and compared with the reference.
    compared: u32,
    /// How the first frame that differed from the reference differed.
    mismatch: Option<String>,
    /// `FrameStats::device_recoveries` at the close request.
    device_recoveries: u64,
}

#[derive(Default)]
struct ScriptState {
    step: usize,
    step_started: Option<Instant>,
    minimised_updates: u32,
    last_seen_frame: Option<u64>,
    /// Frames with bloom rendered at the size a `RenderedFrames` step waits for.
    frames_at_size: u32,
    reference: Option<image::RgbaImage>,
    /// Frames compared with the reference in the current `MatchReference` step.
    compared_in_step: u32,
}

/// How `image` differs from `reference`: `None` when equal.
fn difference(image: &image::RgbaImage, reference: &image::RgbaImage) -> Option<String> {
    if image.dimensions() != reference.dimensions() {
        return Some(format!("size {:?}, reference {:?}", image.dimensions(), reference.dimensions()));
    }
    let (mut pixels, mut largest) = (0, 0);
    for (a, b) in image.pixels().zip(reference.pixels()) {
        let d = a.0.iter().zip(b.0).map(|(&x, y)| x.abs_diff(y)).max().unwrap_or(0);
        pixels += u32::from(d > 0);
        largest = largest.max(d);
    }
    (pixels > 0).then(|| format!("{pixels} pixels differ, by up to {largest}/255"))
}

/// Runs the script's current step; returns `Some(on)` when bloom and motion blur go on or off
/// the camera.
// The script reads and drives every part of the app the test touches, one parameter each.
#[allow(clippy::too_many_arguments)]
fn run_script(
    log: &Mutex<Log>,
    state: &mut ScriptState,
    viewport: &ViewportSize,
    stats: &FrameStats,
    requests: &mut WindowRequests,
    capture: &mut HeadlessCapture,
    backend: &mut RenderBackend,
    exit: &mut MessageWriter<AppExit>,
) -> Option<bool> {
    let Ok(mut log) = log.lock() else {
        exit.write(AppExit::error());
        return None;
    };
    // Record each newly finished frame once.
    let minimised = viewport.0.min_element() == 0;
    if let Some(report) = &stats.last
        && state.last_seen_frame != Some(report.frame_index)
    {
        state.last_seen_frame = Some(report.frame_index);
        if report.nonfinite_pixels.is_some_and(|n| n > 0) {
            log.nonfinite_frames += 1;
        }
        log.max_views = log.max_views.max(report.views.len());
        if let Some(Step::RenderedFrames(w, h, _)) = SCRIPT.get(state.step)
            && (report.width, report.height) == (*w, *h)
            && report.pass_names().contains(&"bloom_composite")
        {
            state.frames_at_size += 1;
        }
        if (report.width, report.height) == (1, 1) && !report.passes.is_empty() {
            log.one_pixel_passes = report.passes.iter().map(|p| p.name.clone()).collect();
        }
        if report.width == 0 || report.height == 0 {
            log.zero_sized_frames += 1;
            assert!(report.passes.is_empty(), "a 0×0 frame ran passes");
        } else if !report.passes.is_empty() {
            log.rendered.push((report.width, report.height));
            if report.passes.last().is_some_and(|p| p.name == manylight::app::window::OVERLAY_PASS) {
                log.overlay_frames += 1;
            }
        }
    }
    if minimised {
        log.minimised_updates += 1;
    }
    // Frames read back at the size the 1×1 steps come back to.
    let image = capture.image.take().filter(|i| i.dimensions() == BACK);
    let Some(&step) = SCRIPT.get(state.step) else {
        // Past the last step, `Close`.
        log.updates_after_close += 1;
        return None;
    };
    let mut post = None;
    let started = *state.step_started.get_or_insert_with(Instant::now);
    let done = match step {
        Step::Resize(w, h) => {
            requests.request_resize(UVec2::new(w, h));
            true
        }
        Step::Minimize(m) => {
            requests.request_minimize(m);
            state.minimised_updates = 0;
            true
        }
        Step::Rendered(w, h) => stats.last.as_ref().is_some_and(|r| {
            (r.width, r.height) == (w, h) && !r.passes.is_empty() && viewport.0 == UVec2::new(w, h)
        }),
        Step::StayMinimised => {
            if minimised {
                state.minimised_updates += 1;
            }
            let done = state.minimised_updates >= MINIMISED_UPDATES;
            if done {
                state.minimised_updates = 0;
            }
            done
        }
        Step::Post(on) => {
            post = Some(on);
            capture.enabled = on;
            state.frames_at_size = 0;
            true
        }
        Step::RenderedFrames(_, _, n) => {
            let done = state.frames_at_size >= n;
            if done {
                state.frames_at_size = 0;
            }
            done
        }
        Step::CaptureReference => {
            state.reference = image;
            state.reference.is_some()
        }
        Step::MatchReference => {
            if let (Some(image), Some(reference)) = (image, &state.reference) {
                log.compared += 1;
                state.compared_in_step += 1;
                let compared = log.compared;
                if let Some(d) = difference(&image, reference) {
                    log.mismatch
                        .get_or_insert(format!("compared frame {compared} (step {}): {d}", state.step));
                }
            }
            let done = state.compared_in_step >= COMPARED_FRAMES;
            if done {
                state.compared_in_step = 0;
            }
            done
        }
        Step::LoseDevice(when) => {
            backend.lose_device(when);
            true
        }
        Step::Close => {
            requests.request_close();
            log.frames_rendered = stats.frames_rendered;
            log.device_recoveries = stats.device_recoveries;
            log.close_requested = Some(Instant::now());
            true
        }
    };
    if done {
        state.step += 1;
        state.step_started = None;
        log.step = state.step;
    } else if started.elapsed() > STEP_TIMEOUT {
        log.failure = Some(format!(
            "step {} {step:?} did not finish in {STEP_TIMEOUT:?} (viewport {:?}, last frame {:?})",
            state.step,
            viewport.0,
            stats.last.as_ref().map(|r| (r.width, r.height, r.passes.len()))
        ));
        exit.write(AppExit::error());
    }
    post
}

/// Names of this process's threads (Linux), to check the render thread is gone.
fn thread_names() -> Vec<String> {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| std::fs::read_to_string(e.path().join("comm")).ok())
        .map(|s| s.trim().to_string())
        .collect()
}

#[test]
fn window_resize_minimise_close() {
    let Some(_xvfb) = support::window_display() else {
        return;
    };
    // Stops a hung event loop from hanging the test run (the Xvfb child dies with the guard
    // only on a normal exit, so kill it here too).
    let xvfb_pid = _xvfb.as_ref().map(|x| x.pid());
    std::thread::spawn(move || {
        std::thread::sleep(WATCHDOG);
        eprintln!("window test: still running after {WATCHDOG:?}, aborting");
        if let Some(pid) = xvfb_pid {
            let _ = Command::new("kill").arg(pid.to_string()).status();
        }
        std::process::exit(101);
    });

    // winit allows one event loop per process: the pipelined mode runs here, the synchronous
    // one (surface on the main thread) in a child process running this test alone.
    let child = std::env::var(MODE_VAR).is_ok_and(|m| m == "sync");
    drive_window(!child);
    if !child {
        let exe = match std::env::current_exe() {
            Ok(e) => e,
            Err(e) => panic!("cannot find the test executable: {e}"),
        };
        let status = Command::new(exe)
            .args(["--exact", "window_resize_minimise_close", "--nocapture", "--test-threads=1"])
            .env(MODE_VAR, "sync")
            .status();
        assert!(status.as_ref().is_ok_and(|s| s.success()), "the synchronous run failed: {status:?}");
    }
}

/// Runs the script in a window, rendering on a render thread (`pipelined`) or on the main
/// thread, and checks what it saw.
fn drive_window(pipelined: bool) {
    // Render errors and warnings reach the test's output.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()),
        )
        .try_init();
    let panics = Arc::new(AtomicUsize::new(0));
    let default_hook = std::panic::take_hook();
    let counter = panics.clone();
    std::panic::set_hook(Box::new(move |info| {
        counter.fetch_add(1, Ordering::SeqCst);
        default_hook(info);
    }));

    let log = Arc::new(Mutex::new(Log::default()));
    let script_log = log.clone();
    let config = WindowConfig {
        title: "manylight window test".into(),
        width: 320,
        height: 240,
        vsync: false,
        any_thread: true,
        overlay: true,
    };
    let started = Instant::now();
    let exit = App::new()
        .add_plugins(ManyLightPlugin::window(config).with_pipelined(pipelined))
        .add_systems(Startup, spawn_small_scene)
        .add_systems(
            Update,
            move |mut state: Local<ScriptState>,
                  viewport: Res<ViewportSize>,
                  stats: Res<FrameStats>,
                  mut requests: ResMut<WindowRequests>,
                  mut capture: ResMut<HeadlessCapture>,
                  mut backend: ResMut<RenderBackend>,
                  mut commands: Commands,
                  cameras: Query<Entity, With<Camera3d>>,
                  mut exit: MessageWriter<AppExit>| {
                let post = run_script(
                    &script_log,
                    &mut state,
                    &viewport,
                    &stats,
                    &mut requests,
                    &mut capture,
                    &mut backend,
                    &mut exit,
                );
                for camera in &cameras {
                    match post {
                        Some(true) => {
                            commands.entity(camera).insert((Bloom::default(), MotionBlur::default()))
                        }
                        Some(false) => commands.entity(camera).remove::<(Bloom, MotionBlur)>(),
                        None => continue,
                    };
                }
            },
        )
        .run();
    let returned = Instant::now();
    let elapsed = started.elapsed();

    let log = match log.lock() {
        Ok(l) => l,
        Err(e) => panic!("script log poisoned: {e}"),
    };
    eprintln!(
        "window test ({}): {elapsed:.1?}, exit {exit:?}, {} frames, steps {}/{}, {} updates minimised, \
         close took {:?}, {} zero-sized frames, {} frames compared after 1×1, rendered sizes {:?}",
        if pipelined { "pipelined" } else { "synchronous" },
        log.frames_rendered,
        log.step,
        SCRIPT.len(),
        log.minimised_updates,
        log.close_requested.map(|c| returned - c),
        log.zero_sized_frames,
        log.compared,
        {
            let mut sizes = log.rendered.clone();
            sizes.dedup();
            sizes
        }
    );
    assert_eq!(log.failure, None, "the script failed");
    assert!(exit.is_success(), "the app exited with {exit:?}");
    assert_eq!(log.step, SCRIPT.len(), "the script did not finish");
    assert!(log.frames_rendered > 0, "no frame was rendered");
    assert!(log.overlay_frames > 0, "no frame drew the egui overlay as its last pass");
    for size in [(320, 240), (400, 300), (360, 270), (300, 200), (1, 1)] {
        assert!(log.rendered.contains(&size), "no frame rendered at {size:?}: {:?}", log.rendered);
    }
    assert!(log.minimised_updates >= 3 * MINIMISED_UPDATES, "too few minimised updates");
    assert!(log.zero_sized_frames > 0, "no 0×0 frame reached the renderer while minimised");
    assert_eq!(log.nonfinite_frames, 0, "frames with non-finite pixels");
    assert_eq!(log.max_views, 2, "both cameras rendered, the second into its viewport");
    for pass in ["cluster_build", "clustered_forward", "bloom_composite", "tonemap"] {
        assert!(
            log.one_pixel_passes.iter().any(|p| p == pass),
            "no {pass} at 1×1: {:?}",
            log.one_pixel_passes
        );
    }
    assert!(
        log.compared >= 2 * COMPARED_FRAMES,
        "only {} frames compared after 1×1 and device losses",
        log.compared
    );
    assert_eq!(log.mismatch, None, "a frame after the 1×1 ones or a device loss differs from the one before");
    assert_eq!(log.device_recoveries, 2, "the two device losses were not both recovered");
    assert_eq!(panics.load(Ordering::SeqCst), 0, "a thread panicked");
    let render_threads = thread_names().iter().filter(|n| n.starts_with("manylight-rend")).count();
    assert_eq!(render_threads, 0, "the render thread outlived App::run");
    assert_eq!(log.updates_after_close, 0, "the app updated after the update that requested the close");
}

//! `manylight soak`: thousands of frames in a real window with many animated lights while the
//! settings keep changing, watching resident memory, the transient pool, render errors and
//! non-finite pixels.
//!
//! The run, frame by frame:
//! 1. [`plan::Plan`] says what the frame asks for: the window size (a new one every
//!    `--resize-every` frames), the post stages (none, bloom, motion blur, both: a step every
//!    `--post-every` frames), the debug view (the next view of the cycle, then none, switching
//!    every `--debug-every` frames, half a period after the post steps) and the light count
//!    (every `--lights-every` frames the rig is despawned and spawned again with the next count).
//! 2. The camera sways a little every frame, so motion blur has motion to blur.
//! 3. Every frame report the app sees is checked for non-finite pixels and fed to the pool's
//!    reuse check ([`measure::PoolCheck`]); every `--sample-every` frames resident memory and
//!    the pool's figures are sampled.
//! 4. After the last frame the window closes and [`measure::verdict`] applies the pass
//!    criterion; the command prints one line and exits 0 on a pass, 1 on a failure.
//!
//! The window is pipelined (a render thread), as the plugin's default window is. Without a
//! display the command starts its own Xvfb server and runs itself again under it.

mod display;
mod measure;
mod plan;

use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use bevy_app::{App, AppExit, Startup, Update};
use bevy_ecs::prelude::{
    Commands, Entity, IntoScheduleConfigs, Local, MessageWriter, Query, Res, ResMut, Resource, With,
};
use glam::{Quat, UVec2};
use manylight_app::cli::parse_size;
use manylight_app::scene::{spawn_light_rig, spawn_scene};
use manylight_app::{
    Bloom, Camera3d, DebugView, FrameStats, LightAnimation, ManyLightPlugin, MotionBlur, RenderFailure,
    Transform, WindowConfig, WindowRequests,
};
use manylight_core::Aabb;
use manylight_scene::{LoadOptions, load_scene};
use measure::{Outcome, Sample};
use plan::Plan;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Largest sway of the camera about the vertical axis, in radians.
const SWAY_RADIANS: f32 = 0.1;
/// Radians of the sway's phase per frame (a full sway every ~125 frames).
const SWAY_PHASE_PER_FRAME: f32 = 0.05;

/// Options of `manylight soak`.
#[derive(clap::Args, Clone, Debug)]
pub struct SoakArgs {
    /// Frames to render.
    #[arg(long, default_value_t = 10_000)]
    frames: u64,
    /// Frames of warm-up: growth is measured from the sample at their end.
    #[arg(long, default_value_t = 1_000)]
    warmup: u64,
    /// Frames between samples of memory and the transient pool.
    #[arg(long, default_value_t = 100)]
    sample_every: u64,
    /// Comma-separated light counts of the animated rig, cycled through.
    #[arg(long, value_delimiter = ',', default_value = "4096,2048")]
    lights: Vec<usize>,
    /// Comma-separated window sizes WxH, cycled through (small: a CPU adapter is slow).
    #[arg(long, value_delimiter = ',', default_value = "320x180,256x256,200x120", value_parser = parse_size)]
    sizes: Vec<UVec2>,
    /// Frames between resizes.
    #[arg(long, default_value_t = 50)]
    resize_every: u64,
    /// Frames between steps of the post stages (none, bloom, motion blur, both).
    #[arg(long, default_value_t = 100)]
    post_every: u64,
    /// Frames between switching the debug view on (the next view) and off.
    #[arg(long, default_value_t = 100)]
    debug_every: u64,
    /// Frames between light-count changes.
    #[arg(long, default_value_t = 500)]
    lights_every: u64,
    /// Allowed growth of resident memory after warm-up, in percent.
    #[arg(long, default_value_t = 5.0)]
    max_growth: f64,
    /// `default` (the embedded hall), `sphere-shell` or a .gltf/.glb path.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Seed of the light placement.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also write the samples as CSV here.
    #[arg(long)]
    csv: Option<PathBuf>,
}

/// What the soak systems share with the command after the app has run.
struct Log {
    outcome: Outcome,
    progress: Option<Progress>,
    started: Instant,
    last_sample: (u64, Instant),
    last_report: Option<u64>,
}

/// The soak's parameters and its log, as an app resource.
#[derive(Resource)]
struct Soak {
    plan: Plan,
    frames: u64,
    warmup: u64,
    sample_every: u64,
    bounds: Aabb,
    seed: u64,
    log: Arc<Mutex<Log>>,
}

/// Frames (app updates) done so far.
#[derive(Resource, Default)]
struct FrameCount(u64);

/// Applies the plan's settings for this frame and sways the camera.
#[allow(clippy::too_many_arguments)]
fn drive(
    soak: Res<Soak>,
    frame: Res<FrameCount>,
    mut base_rotation: Local<Option<Quat>>,
    mut commands: Commands,
    mut cameras: Query<(Entity, &mut Transform), With<Camera3d>>,
    lights: Query<Entity, With<LightAnimation>>,
    mut debug: ResMut<DebugView>,
    mut requests: ResMut<WindowRequests>,
    mut exit: MessageWriter<AppExit>,
) {
    let f = frame.0;
    let now = soak.plan.at(f);
    let before = f.checked_sub(1).map(|p| soak.plan.at(p));
    if before.is_some_and(|b| b.size != now.size) {
        requests.request_resize(now.size);
    }
    if debug.mode != now.debug {
        debug.mode = now.debug;
    }
    if before.is_none_or(|b| b.lights != now.lights) {
        for light in &lights {
            commands.entity(light).despawn();
        }
        // `Plan::validate` checked every count; memory taken since then ends the run here.
        if let Err(e) = spawn_light_rig(&mut commands, now.lights, soak.bounds, soak.seed) {
            tracing::error!("--lights: {e}");
            exit.write(AppExit::error());
        }
    }
    for (entity, mut transform) in &mut cameras {
        let base = *base_rotation.get_or_insert(transform.rotation);
        let sway = SWAY_RADIANS * (f as f32 * SWAY_PHASE_PER_FRAME).sin();
        transform.rotation = base * Quat::from_rotation_y(sway);
        let mut camera = commands.entity(entity);
        if before.map(|b| b.bloom) != Some(now.bloom) {
            match now.bloom {
                true => camera.insert(Bloom::default()),
                false => camera.remove::<Bloom>(),
            };
        }
        if before.map(|b| b.motion_blur) != Some(now.motion_blur) {
            match now.motion_blur {
                true => camera.insert(MotionBlur::default()),
                false => camera.remove::<MotionBlur>(),
            };
        }
    }
}

/// Checks each new frame report, samples every `sample_every` frames and closes the window
/// after the last frame.
fn measure(
    soak: Res<Soak>,
    mut frame: ResMut<FrameCount>,
    stats: Res<FrameStats>,
    failure: Res<RenderFailure>,
    mut requests: ResMut<WindowRequests>,
) {
    let f = frame.0;
    frame.0 += 1;
    let Ok(mut log) = soak.log.lock() else {
        requests.request_close();
        return;
    };
    let log = &mut *log;
    if let Some(report) = &stats.last
        && log.last_report != Some(report.frame_index)
    {
        log.last_report = Some(report.frame_index);
        log.outcome.reports += 1;
        if let Some(n) = report.nonfinite_pixels.filter(|&n| n > 0) {
            log.outcome.nonfinite_pixels += u64::from(n);
            log.outcome.nonfinite_frames += 1;
        }
        log.outcome.pool.observe(report, report.frame_index >= soak.warmup);
    }
    if let Some(message) = &failure.0 {
        log.outcome.error.get_or_insert_with(|| message.clone());
    }
    log.outcome.frames_rendered = stats.frames_rendered;
    let done = f + 1;
    if done.is_multiple_of(soak.sample_every) || done == soak.frames {
        let now = Instant::now();
        let asked = soak.plan.at(f);
        let last = stats.last.clone().unwrap_or_default();
        let sample = Sample {
            frame: done,
            seconds: (now - log.started).as_secs_f64(),
            frame_ms: (now - log.last_sample.1).as_secs_f64() * 1e3
                / (done - log.last_sample.0).max(1) as f64,
            rss_kib: measure::resident_kib().unwrap_or(0),
            width: last.width,
            height: last.height,
            lights: last.light_count,
            bloom: asked.bloom,
            motion_blur: asked.motion_blur,
            debug_view: asked.debug.name(),
            transient_textures: last.transient_textures,
            transient_bytes: last.transient_bytes,
            transient_allocations: last.transient_allocations,
            repeat_allocations: log.outcome.pool.repeat_allocations,
            reports: log.outcome.reports,
            nonfinite_pixels: log.outcome.nonfinite_pixels,
        };
        log.last_sample = (done, now);
        if let Some(progress) = log.progress.as_mut() {
            progress.step(|| {
                format!(
                    "frame {done}: {:.1} MiB resident, {} transient textures, {} allocations, {:.0} ms/frame",
                    sample.rss_kib as f64 / 1024.0,
                    sample.transient_textures,
                    sample.transient_allocations,
                    sample.frame_ms
                )
            });
        }
        log.outcome.samples.push(sample);
    }
    if done >= soak.frames {
        requests.request_close();
    }
}

/// Runs the soak and prints its summary; a failed criterion is an error (exit status 1).
pub fn run(args: SoakArgs) -> Result<()> {
    let plan = checked_plan(&args)?;
    measure::resident_kib().map_err(anyhow::Error::msg)?;
    if !display::has_display() {
        let status = display::rerun_under_xvfb()?;
        if !status.success() {
            bail!("the soak under Xvfb failed ({status})");
        }
        return Ok(());
    }
    // A path that cannot be written fails now, not after the run.
    let csv = match &args.csv {
        Some(path) => Some((path, create_csv(path)?)),
        None => None,
    };
    let scene = load_scene(&args.scene, &LoadOptions::default())?;
    let first = plan.at(0).size;
    let log = Arc::new(Mutex::new(new_log(&args)));
    let soak = Soak {
        bounds: scene.bounds(),
        plan,
        frames: args.frames,
        warmup: args.warmup,
        sample_every: args.sample_every,
        seed: args.seed,
        log: log.clone(),
    };
    let config = WindowConfig {
        title: "manylight soak".into(),
        width: first.x,
        height: first.y,
        vsync: false,
        ..WindowConfig::default()
    };
    let aspect = first.x as f32 / first.y as f32;
    let started = Instant::now();
    let exit = App::new()
        .add_plugins(ManyLightPlugin::window(config))
        .insert_resource(soak)
        .init_resource::<FrameCount>()
        .add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, aspect);
        })
        .add_systems(Update, (drive, measure).chain())
        .run();
    let seconds = started.elapsed().as_secs_f64();
    conclude(&log, seconds, &exit, csv)
}

/// Completes the run's outcome with its `seconds` and how the app exited, writes the samples
/// to the `csv` file, prints the summary and applies the pass criterion.
fn conclude(
    log: &Mutex<Log>,
    seconds: f64,
    exit: &AppExit,
    csv: Option<(&PathBuf, std::fs::File)>,
) -> Result<()> {
    let mut log = log.lock().map_err(|_| anyhow::anyhow!("the soak's log was poisoned by a panic"))?;
    let Log { outcome, progress, .. } = &mut *log;
    if let Some(p) = progress.take() {
        p.finish();
    }
    outcome.seconds = seconds;
    if !exit.is_success() && outcome.error.is_none() {
        outcome.error = Some(format!("the app exited with {exit:?} (see the log above)"));
    }
    if let Some((path, mut file)) = csv {
        use std::io::Write as _;
        file.write_all(measure::csv(&outcome.samples)?.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    let verdict = measure::verdict(outcome);
    println!("{}", verdict.summary);
    if !verdict.pass {
        bail!("soak failed: {}", verdict.failures.join("; "));
    }
    Ok(())
}

/// The plan of `args`, refused with the flag's problem when it or the sampling cannot run.
fn checked_plan(args: &SoakArgs) -> Result<Plan> {
    let plan = Plan {
        sizes: args.sizes.clone(),
        light_counts: args.lights.clone(),
        resize_every: args.resize_every,
        post_every: args.post_every,
        debug_every: args.debug_every,
        lights_every: args.lights_every,
    };
    plan.validate().map_err(anyhow::Error::msg)?;
    if args.sample_every == 0 {
        bail!("--sample-every: must be at least 1");
    }
    if args.frames < args.warmup + args.sample_every {
        bail!(
            "--frames {} leaves no sample after the {} warm-up frames (sampled every {})",
            args.frames,
            args.warmup,
            args.sample_every
        );
    }
    Ok(plan)
}

/// Creates `--csv`'s file (and its folder), so that a path that cannot be written fails
/// before the run.
fn create_csv(path: &std::path::Path) -> Result<std::fs::File> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))
}

/// The log of a run of `args`, before its first frame.
fn new_log(args: &SoakArgs) -> Log {
    Log {
        outcome: Outcome {
            frames: args.frames,
            warmup: args.warmup,
            max_growth_percent: args.max_growth,
            ..Outcome::default()
        },
        progress: Some(Progress::new(args.frames.div_ceil(args.sample_every), "samples")),
        started: Instant::now(),
        last_sample: (0, Instant::now()),
        last_report: None,
    }
}

//! Stress: thousands of animated point lights, with the overlay to change settings at run time.
//!
//! ```text
//! cargo run --release --example stress -- [--lights N] [--scene default|sphere-shell|PATH.glb]
//!     [--pipeline NAME] [--size WxH] [--frames F --warmup W] [--headless OUT.png] [--no-overlay]
//!     [--gpu-animation]
//! ```
//!
//! - `--scene default` (the embedded hall) or a glTF path: `--lights N` (default 4096) lights
//!   that orbit, bob and flicker in colour, moved by [`animate_lights`], an ordinary `Update`
//!   system on `Transform` and `PointLight` you can copy into your own app. With
//!   `--gpu-animation` they carry a [`LightAnimation`] instead and the renderer's compute pass
//!   moves them ([`LightAnimationMode::Gpu`]): no light changes on the CPU after it is spawned.
//! - `--scene sphere-shell`: the many-lights layout other engines publish. N lights (default
//!   100 000) of range 0.3 with random hues on a golden-ratio (Fibonacci) lattice just inside a
//!   white inward-facing sphere of radius 50, a 5×5×5 box at (0, 50, 0), and a camera at the
//!   origin (45° fov, near 0.1, far 1000) turning 0.0025 rad per frame about the z and x axes
//!   ([`turn_camera`]; per frame, not per second, so every run shows the same views). Shaded
//!   with Forward+ without per-cluster depth bounds, and refined light lists only from 16 384
//!   lights on (the fastest on this scene: docs/benchmarks.md).
//! - `--frames F --warmup W`: renders W + F frames, prints `median_frame_ms=… mean_frame_ms=…`
//!   over the last F (wall time between updates; in a window with vsync off) and the last
//!   frame's passes, then exits.
//! - `--headless OUT.png`: no window; renders (1, or W + F + 1 with `--frames`) frames and
//!   writes the last one.
//!
//! In the window the overlay (F1 hides it) changes the pipeline, shading, G-buffer, debug
//! view, the light count and a radius multiplier ([`LightControls`], read by
//! [`sync_light_count`] and [`animate_lights`]), bloom and motion blur, and the cluster grid.

use anyhow::{Result, bail};
use clap::Parser;
use manylight::app::cli::{parse_on_off, parse_pipeline, parse_size};
use manylight::math::{Aabb, lumens_from_candela};
use manylight::prelude::*;
use manylight::scene::{AnimatedLight, SHELL_LIGHT_RANGE, SHELL_RADIUS, light_rig, sphere_shell_lights};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Lights of the default and glTF scenes unless `--lights` says otherwise.
pub const DEFAULT_LIGHTS: u32 = 4096;
/// Light count from which the sphere-shell preset shades from refined light lists: below it
/// their pass costs more than it saves, above it the frame is faster with them
/// (docs/benchmarks.md, "Refined light lists").
const SHELL_REFINE_FROM: u32 = 16_384;
/// Lights of the sphere-shell preset unless `--lights` says otherwise.
pub const DEFAULT_SHELL_LIGHTS: u32 = 100_000;
/// Radians the sphere-shell camera turns per frame about the z axis, then the x axis.
pub const SHELL_TURN_PER_FRAME: f32 = 0.0025;

/// Command-line arguments.
#[derive(Parser, Clone, Debug)]
#[command(about = "manylight stress scene: many animated lights, with the egui overlay")]
pub struct Args {
    /// `default` (the embedded hall), `sphere-shell`, or a path to a .gltf/.glb file.
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Lights (default 4096; 100 000 for sphere-shell).
    #[arg(long)]
    pub lights: Option<u32>,
    /// The many-light pipeline (default: clustered-forward; forward-plus for sphere-shell,
    /// whose lights hug its one surface, so depth slices add build cost and cut nothing).
    #[arg(long, value_parser = parse_pipeline)]
    pub pipeline: Option<PipelineKind>,
    /// Refined light lists (4 × 4-pixel blocks): on or off (default: on, but off for
    /// sphere-shell below 16 384 lights).
    #[arg(long, value_parser = parse_on_off)]
    pub refined_lists: Option<bool>,
    /// Window or image size, WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: UVec2,
    /// Measure: render `--warmup` frames, then this many, print the frame times and exit.
    #[arg(long)]
    pub frames: Option<u32>,
    /// Frames rendered before measuring.
    #[arg(long, default_value_t = 5)]
    pub warmup: u32,
    /// Render without a window and write the last frame to this PNG.
    #[arg(long)]
    pub headless: Option<PathBuf>,
    /// No egui overlay in the window.
    #[arg(long)]
    pub no_overlay: bool,
    /// Seed of the light placement and colours.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Animate the rig's lights in the renderer's compute pass (`LightAnimationMode::Gpu`)
    /// instead of an `Update` system on their components.
    #[arg(long)]
    pub gpu_animation: bool,
}

/// Where the example's lights go: the rig's bounds, or the sphere shell.
#[derive(Resource, Clone, Copy, Debug)]
pub struct StressLayout {
    /// Sphere-shell lattice (static lights) instead of the animated rig.
    pub shell: bool,
    /// Volume the animated rig fills.
    pub bounds: Aabb,
    /// Placement and colour seed.
    pub seed: u64,
    /// The rig's lights carry a [`LightAnimation`] and animate on the GPU.
    pub gpu_animation: bool,
}

/// An animated light: orbit, bob and colour flicker parameters (see [`animate_lights`]).
#[derive(Component, Clone, Copy, Debug)]
pub struct StressLight(pub AnimatedLight);

/// A static sphere-shell light with its unscaled radius.
#[derive(Component, Clone, Copy, Debug)]
pub struct ShellLight {
    /// Radius before [`LightControls::radius_scale`].
    pub base_radius: f32,
}

/// Marks the camera [`turn_camera`] turns.
#[derive(Component, Clone, Copy, Debug)]
pub struct Turning;

/// Frame times collected for `--frames`.
#[derive(Resource, Debug, Default)]
pub struct FrameTimes {
    /// Updates to skip before measuring.
    pub warmup: u32,
    /// Frames to measure (0: do not measure).
    pub frames: u32,
    /// Send `AppExit` when done (the window); headless the runner stops by itself.
    pub exit_when_done: bool,
    /// Measured frame times in ms.
    pub samples: Vec<f64>,
    /// Render-side CPU times (`FrameReport::frame_cpu_ms`) of the frames reported while
    /// measuring.
    pub render_cpu: Vec<f64>,
    /// The same frames' CPU time by phase and upload bytes (`FrameReport::cpu`).
    pub phases: Vec<manylight::render::CpuPhases>,
    last_reported: Option<u64>,
    last: Option<Instant>,
    seen: u32,
    done: bool,
}

/// Moves each animated light along its orbit, bobs it, flickers its colour, and applies the
/// radius multiplier: a plain system on `Transform` and `PointLight`. Lights that carry a
/// [`LightAnimation`] (`--gpu-animation`) are the renderer's to move.
pub fn animate_lights(
    time: Res<Time>,
    controls: Res<LightControls>,
    mut lights: Query<(&StressLight, &mut Transform, &mut PointLight), Without<LightAnimation>>,
) {
    let t = time.elapsed_secs();
    for (light, mut transform, mut point) in &mut lights {
        transform.translation = light.0.position_at(t); // orbit in XZ + bob in Y
        point.color = manylight::app::from_linear_rgb(light.0.color_at(t)); // hue drift + flicker
        point.range = light.0.radius * controls.radius_scale;
    }
}

/// Applies the radius multiplier to the lights animated on the GPU when it changes.
pub fn scale_gpu_animated_lights(
    controls: Res<LightControls>,
    mut lights: Query<(&StressLight, &mut PointLight), With<LightAnimation>>,
) {
    if controls.is_changed() {
        for (light, mut point) in &mut lights {
            point.range = light.0.radius * controls.radius_scale;
        }
    }
}

/// Applies the radius multiplier to the static sphere-shell lights when it changes.
pub fn scale_shell_lights(controls: Res<LightControls>, mut lights: Query<(&ShellLight, &mut PointLight)>) {
    if controls.is_changed() {
        for (shell, mut point) in &mut lights {
            point.radius = shell.base_radius * controls.radius_scale;
        }
    }
}

/// The lights this example spawned (animated or sphere-shell).
pub type ExampleLights = Or<(With<StressLight>, With<ShellLight>)>;

/// Keeps [`LightControls::count`] lights alive: on the first frame and whenever the count
/// changes, the example's lights are despawned and the layout spawned again with the new count.
pub fn sync_light_count(
    mut commands: Commands,
    controls: Res<LightControls>,
    layout: Res<StressLayout>,
    lights: Query<Entity, ExampleLights>,
) {
    if !controls.is_changed() || lights.iter().count() == controls.count as usize {
        return;
    }
    for entity in &lights {
        commands.entity(entity).despawn();
    }
    let count = controls.count as usize;
    let scale = controls.radius_scale;
    if layout.shell {
        let lights = match sphere_shell_lights(count, SHELL_RADIUS, SHELL_LIGHT_RANGE, layout.seed) {
            Ok(lights) => lights,
            Err(e) => return eprintln!("error: {e}"),
        };
        commands.spawn_batch(lights.into_iter().map(move |l| {
            (
                Transform::from_translation(l.position),
                PointLight {
                    color: manylight::app::from_linear_rgb(l.color),
                    intensity: lumens_from_candela(l.intensity),
                    range: l.radius * scale,
                    radius: 0.0,
                    ..Default::default()
                },
                ShellLight { base_radius: l.radius },
            )
        }));
    } else {
        let rig = match light_rig(count, layout.bounds, layout.seed) {
            Ok(rig) => rig,
            Err(e) => return eprintln!("error: {e}"),
        };
        let light = move |a: AnimatedLight| {
            (
                Transform::from_translation(a.position_at(0.0)),
                PointLight {
                    color: manylight::app::from_linear_rgb(a.color_at(0.0)),
                    intensity: lumens_from_candela(a.intensity),
                    range: a.radius * scale,
                    radius: 0.0,
                    ..Default::default()
                },
                StressLight(a),
            )
        };
        if layout.gpu_animation {
            commands.spawn_batch(rig.into_iter().map(move |a| (light(a), LightAnimation(a))));
        } else {
            commands.spawn_batch(rig.into_iter().map(light));
        }
    }
}

/// Turns the sphere-shell camera a fixed step per frame about the world z axis, then the x
/// axis (it stays at the origin).
pub fn turn_camera(mut cameras: Query<&mut Transform, (With<Camera3d>, With<Turning>)>) {
    let step = Quat::from_rotation_x(SHELL_TURN_PER_FRAME) * Quat::from_rotation_z(SHELL_TURN_PER_FRAME);
    for mut t in &mut cameras {
        t.rotation = (step * t.rotation).normalize();
    }
}

/// Collects the wall time between updates; after `warmup + frames` prints the median and
/// mean and the last frame's passes.
pub fn time_frames(
    mut times: ResMut<FrameTimes>,
    stats: Res<FrameStats>,
    settings: Res<RenderSettings>,
    mut exit: MessageWriter<AppExit>,
) {
    if times.frames == 0 || times.done {
        return;
    }
    let now = Instant::now();
    if let Some(last) = times.last {
        times.seen += 1;
        if times.seen > times.warmup {
            times.samples.push((now - last).as_secs_f64() * 1e3);
            if let Some(report) = stats.last.as_ref().filter(|r| times.last_reported != Some(r.frame_index)) {
                times.last_reported = Some(report.frame_index);
                times.render_cpu.push(report.frame_cpu_ms);
                times.phases.push(report.cpu);
            }
        }
    }
    times.last = Some(now);
    if times.samples.len() < times.frames as usize {
        return;
    }
    times.done = true;
    let (median, mean) = median_mean(&times.samples);
    let (render_cpu, _) = median_mean(&times.render_cpu);
    let lights = stats.last.as_ref().map_or(0, |r| r.light_count);
    println!(
        "median_frame_ms={median:.2} mean_frame_ms={mean:.2} median_render_cpu_ms={render_cpu:.2} frames={} lights={lights} pipeline={}",
        times.samples.len(),
        settings.pipeline.name()
    );
    let phase = |f: fn(&manylight::render::CpuPhases) -> f64| {
        median_mean(&times.phases.iter().map(f).collect::<Vec<_>>()).0
    };
    println!(
        "median_cpu_ms: extract={:.2} upload={:.2} prepare={:.2} record={:.2} submit={:.2} upload_bytes={:.0}",
        phase(|p| p.extract_ms),
        phase(|p| p.upload_ms),
        phase(|p| p.prepare_ms),
        phase(|p| p.record_ms),
        phase(|p| p.submit_ms),
        phase(|p| p.upload_bytes as f64),
    );
    if let Some(report) = &stats.last {
        let passes: Vec<String> = report
            .passes
            .iter()
            .map(|p| match p.gpu_ms {
                Some(g) if p.gpu_trusted => format!("{}={g:.2}", p.name),
                Some(g) => format!("{}={g:.2}(untrusted)", p.name),
                None => format!("{}=cpu:{:.2}", p.name, p.cpu_ms),
            })
            .collect();
        println!("last_frame_gpu_ms: {} render_cpu_ms={:.2}", passes.join(" "), report.frame_cpu_ms);
        println!(
            "last_reported_frame={} submitted={} frames_in_flight={}/{} blocking_waits={} buffers_created={} bind_groups_created={}",
            report.frame_index,
            stats.submitted,
            report.frames_in_flight,
            report.frames_in_flight_limit,
            report.blocking_waits,
            report.buffers_created,
            report.bind_groups_created
        );
    }
    if times.exit_when_done {
        exit.write(AppExit::Success);
    }
}

/// Median and mean of `samples` (0 for none).
pub fn median_mean(samples: &[f64]) -> (f64, f64) {
    if samples.is_empty() {
        return (0.0, 0.0);
    }
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let median = if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) };
    (median, sorted.iter().sum::<f64>() / n as f64)
}

/// Adds the scene, the lights and the example's systems to `app` (which already has the
/// plugin). `exit_when_done` ends the app after a `--frames` measurement.
pub fn setup(app: &mut App, args: &Args, exit_when_done: bool) -> Result<()> {
    let shell = args.scene == "sphere-shell";
    // The error names the file and the problem.
    let scene = manylight::scene::load_scene(&args.scene, &LoadOptions::default())?;
    let count = args.lights.unwrap_or(if shell { DEFAULT_SHELL_LIGHTS } else { DEFAULT_LIGHTS });
    if count > 1 << 20 {
        bail!("--lights {count}: at most {} lights", 1 << 20);
    }
    let aspect = args.size.x as f32 / args.size.y.max(1) as f32;
    if shell && args.gpu_animation {
        bail!("--gpu-animation: the sphere-shell lights do not move (it animates the rig's lights)");
    }
    let layout =
        StressLayout { shell, bounds: scene.bounds(), seed: args.seed, gpu_animation: args.gpu_animation };
    let mut settings = RenderSettings {
        pipeline: args.pipeline.unwrap_or(if shell {
            PipelineKind::ForwardPlus
        } else {
            RenderSettings::default().pipeline
        }),
        ..RenderSettings::default()
    };
    // The shell's lights hug its only surface: per-cluster depth bounds cut nothing there and
    // cost their pass (docs/benchmarks.md, "Per-cluster depth bounds").
    settings.clusters.depth_bounds = !shell;
    // Below SHELL_REFINE_FROM shell lights the pairs refined lists would save are too few to
    // pay for their pass (docs/benchmarks.md, "Refined light lists").
    settings.clusters.refined_lists = args.refined_lists.unwrap_or(!shell || count >= SHELL_REFINE_FROM);
    let animation = if args.gpu_animation { LightAnimationMode::Gpu } else { LightAnimationMode::Cpu };
    app.insert_resource(settings)
        .insert_resource(animation)
        .insert_resource(layout)
        .insert_resource(LightControls { count, radius_scale: 1.0 })
        .insert_resource(FrameTimes {
            warmup: args.warmup,
            frames: args.frames.unwrap_or(0),
            exit_when_done,
            ..FrameTimes::default()
        })
        .add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, !shell, aspect);
            if shell {
                let p = scene.cameras.first().map(|c| c.projection).unwrap_or_default();
                commands.spawn((Transform::IDENTITY, Camera3d, Projection::from(p), Turning));
            }
        })
        .add_systems(
            Update,
            (
                sync_light_count,
                animate_lights,
                scale_gpu_animated_lights,
                scale_shell_lights,
                turn_camera,
                time_frames,
            )
                .chain(),
        );
    Ok(())
}

fn run(args: Args) -> Result<AppExit> {
    let measuring = args.frames.is_some_and(|f| f > 0);
    let mut app = App::new();
    match &args.headless {
        Some(out) => {
            let frames = match args.frames {
                Some(f) if f > 0 => args.warmup + f + 1,
                _ => 1,
            };
            app.add_plugins(ManyLightPlugin::headless(args.size).with_frames(frames).with_output(out));
        }
        None => {
            app.add_plugins(ManyLightPlugin::window(WindowConfig {
                title: format!("manylight stress: {}", args.scene),
                width: args.size.x,
                height: args.size.y,
                vsync: !measuring,
                overlay: !args.no_overlay,
                ..WindowConfig::default()
            }));
        }
    }
    setup(&mut app, &args, args.headless.is_none())?;
    Ok(app.run())
}

fn main() -> ExitCode {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    tracing_subscriber::fmt().with_env_filter(filter).init();
    let args = Args::parse();
    match run(args) {
        Ok(exit) if exit.is_success() => ExitCode::SUCCESS,
        Ok(_) => {
            eprintln!("error: the stress example failed (see the log above)");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

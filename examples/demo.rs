//! The manylight demo: the embedded hall lit by a rig of animated coloured lights.
//!
//! ```text
//! cargo run --release --example demo -- [--lights N] [--pipeline NAME] [--shadows on|off] [--headless] [--out-dir DIR]
//! ```
//!
//! Every light casts a shadow (`--shadows off` renders them unshadowed); the overlay's
//! "Shadows" section turns them off and on.
//!
//! With a display (`DISPLAY` or `WAYLAND_DISPLAY` set) it opens a window and prints the frame
//! rate once a second; Esc closes it. Without one (or with `--headless`) it renders three
//! 1280x720 frames two seconds of animation apart and writes them as PNGs.

use clap::Parser;
use manylight::app::RenderFailure;
use manylight::app::cli::{parse_on_off, parse_pipeline};
use manylight::app::headless::save_png;
use manylight::app::window::WindowConfig;
use manylight::math::light_count::check_app_lights;
use manylight::prelude::*;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Size of the window and of the headless frames.
const SIZE: UVec2 = UVec2::new(1280, 720);
/// Headless: frames written, and the animation time between them in seconds.
const HEADLESS_FRAMES: u32 = 3;
const HEADLESS_STEP: f32 = 2.0;

#[derive(Parser)]
#[command(about = "The manylight demo: a hall lit by many animated lights")]
struct Args {
    /// Animated lights in the rig.
    #[arg(long, default_value_t = 256)]
    lights: usize,
    /// The many-light pipeline (default: the renderer's default).
    #[arg(long, value_parser = parse_pipeline)]
    pipeline: Option<PipelineKind>,
    /// Every light of the hall and the rig casts a shadow: on (default) or off.
    #[arg(long, default_value = "on", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    shadows: bool,
    /// Render frames to PNG even when a display is available.
    #[arg(long)]
    headless: bool,
    /// Where headless frames go (default: target/demo in the workspace).
    #[arg(long)]
    out_dir: Option<PathBuf>,
}

/// Spawns the hall (with its camera and six warm lights) and the light rig, every light
/// casting a shadow when `shadows` is on.
fn scene_setup(lights: usize, shadows: bool) -> impl FnMut(&mut World) {
    let scene = default_scene();
    move |world: &mut World| {
        let mut commands = world.commands();
        spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
        spawn_light_rig(&mut commands, lights, scene.bounds(), 1).expect("--lights was checked in main");
        world.flush();
        manylight::app::scene::set_shadows(world, shadows);
    }
}

/// Prints frames per second, and the last frame's light count and timings, once a second.
fn print_fps(stats: Res<FrameStats>, mut last: Local<Option<(Instant, u64)>>) {
    let now = Instant::now();
    let (since, frames) = *last.get_or_insert((now, stats.frames_rendered));
    let seconds = (now - since).as_secs_f64();
    if seconds < 1.0 {
        return;
    }
    let fps = (stats.frames_rendered - frames) as f64 / seconds;
    match &stats.last {
        Some(r) => println!(
            "{fps:6.1} fps  {}x{}  {} lights  cpu {:.1} ms  gpu {}",
            r.width,
            r.height,
            r.light_count,
            r.frame_cpu_ms,
            r.frame_gpu_ms.map_or("n/a".to_string(), |g| format!("{g:.1} ms"))
        ),
        None => println!("{fps:6.1} fps"),
    }
    *last = Some((now, stats.frames_rendered));
}

fn run_window(lights: usize, shadows: bool, settings: RenderSettings) -> ExitCode {
    println!("manylight demo: {lights} animated lights in a window (Esc closes it)");
    let config = WindowConfig {
        title: "manylight demo".into(),
        width: SIZE.x,
        height: SIZE.y,
        ..WindowConfig::default()
    };
    let exit = App::new()
        .add_plugins(ManyLightPlugin::window(config))
        .insert_resource(settings)
        .insert_resource(bundled_environments())
        .add_systems(Startup, scene_setup(lights, shadows))
        .add_systems(Update, print_fps)
        .run();
    if exit.is_success() {
        ExitCode::SUCCESS
    } else {
        eprintln!("error: the demo failed (see the log above); `--headless` renders without a window");
        ExitCode::FAILURE
    }
}

/// The bundled panoramas, for the overlay's environment picker (the hall is lit by its lights
/// alone until one is picked). One that cannot be read is left out, with a warning.
fn bundled_environments() -> EnvironmentImages {
    let mut images = EnvironmentImages::default();
    for name in ["venice_sunset", "studio_small_03"] {
        let path =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/environments").join(format!("{name}.hdr"));
        match manylight::scene::load_environment(&path, &Default::default()) {
            Ok(decoded) => {
                images.add_named(name, decoded.image);
            }
            Err(e) => eprintln!("warning: {e}"),
        }
    }
    images
}

fn run_headless(
    lights: usize,
    shadows: bool,
    settings: RenderSettings,
    out_dir: PathBuf,
) -> anyhow::Result<()> {
    println!(
        "manylight demo: no display, rendering {HEADLESS_FRAMES} frames of {}x{} headless",
        SIZE.x, SIZE.y
    );
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE))
        .insert_resource(settings)
        .insert_resource(TimeUpdateStrategy::ManualDuration(std::time::Duration::from_secs_f32(
            HEADLESS_STEP,
        )))
        .add_systems(Startup, scene_setup(lights, shadows));
    for i in 0..HEADLESS_FRAMES {
        let started = Instant::now();
        app.update();
        if let Some(message) = app.world().resource::<RenderFailure>().0.clone() {
            anyhow::bail!("rendering failed: {message}");
        }
        let world = app.world_mut();
        let t = world.resource::<Time>().elapsed_secs();
        let image = world.resource_mut::<HeadlessCapture>().image.take();
        let Some(image) = image else { anyhow::bail!("frame {i} was not captured") };
        let path = out_dir.join(format!("frame_{i}.png"));
        save_png(&image, &path).map_err(anyhow::Error::msg)?;
        let lights = world.resource::<FrameStats>().last.as_ref().map_or(0, |r| r.light_count);
        println!(
            "t = {t:4.1} s: {} ({lights} lights, {:.1} s)",
            path.display(),
            started.elapsed().as_secs_f64()
        );
    }
    println!("frames written to {}", out_dir.display());
    Ok(())
}

fn main() -> ExitCode {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let args = Args::parse();
    if let Err(e) = check_app_lights(args.lights) {
        eprintln!("error: --lights: {e}");
        return ExitCode::FAILURE;
    }
    let mut settings = RenderSettings::default();
    if let Some(pipeline) = args.pipeline {
        settings.pipeline = pipeline;
    }
    let has_display =
        ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()));
    if has_display && !args.headless {
        return run_window(args.lights, args.shadows, settings);
    }
    let out_dir =
        args.out_dir.unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/demo"));
    match run_headless(args.lights, args.shadows, settings, out_dir) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

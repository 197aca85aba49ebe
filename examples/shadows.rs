//! A thousand shadowed lights: the embedded hall lit by a rig of animated lights that all cast
//! shadows, into one atlas of cube-face tiles sized per light each frame (`--shadows maps`, the
//! default) or found with a ray per light and pixel through the scene's BVH (`--shadows rays`:
//! exact, and for any number of lights, e.g. `--lights 100000`).
//!
//! ```text
//! cargo run --release --example shadows -- [--lights N] [--shadows maps|rays] [--headless] [--out-dir DIR]
//! ```
//!
//! With a display it opens a window; the overlay's "Shadows" section turns shadows off and on
//! and shows the atlas counters. Without one (or with `--headless`) it renders the same frame
//! at 640x360 without and with shadows, writes both PNGs and prints what the shadows cost.

use clap::Parser;
use manylight::app::RenderFailure;
use manylight::app::headless::save_png;
use manylight::app::scene::set_shadows;
use manylight::app::window::WindowConfig;
use manylight::math::light_count::check_app_lights;
use manylight::prelude::*;
use manylight::render::ShadowMethod;
use std::path::PathBuf;
use std::process::ExitCode;

/// Size of the window.
const WINDOW: UVec2 = UVec2::new(1280, 720);
/// Size of the headless frames.
const HEADLESS: UVec2 = UVec2::new(640, 360);

#[derive(Parser)]
#[command(about = "A thousand animated lights in the hall, every one casting a shadow")]
struct Args {
    /// Animated lights in the rig (all casting).
    #[arg(long, default_value_t = 1000)]
    lights: usize,
    /// How shadows are found: `maps` (the shadow atlas) or `rays` (one ray per light and pixel
    /// through the scene's BVH).
    #[arg(long, default_value = "maps", value_parser = parse_method)]
    shadows: ShadowMethod,
    /// Render the two frames to PNG even when a display is available.
    #[arg(long)]
    headless: bool,
    /// Where headless frames go (default: target/shadows in the workspace).
    #[arg(long)]
    out_dir: Option<PathBuf>,
}

/// Spawns the hall and the light rig, and makes every light cast.
fn scene_setup(lights: usize, aspect: f32) -> impl FnMut(&mut World) {
    let scene = default_scene();
    move |world: &mut World| {
        let mut commands = world.commands();
        spawn_scene(&mut commands, &scene, true, aspect);
        spawn_light_rig(&mut commands, lights, scene.bounds(), 1).expect("--lights was checked in main");
        world.flush();
        set_shadows(world, true);
    }
}

/// `maps` or `rays` (`--shadows off` has nothing to show here).
fn parse_method(s: &str) -> Result<ShadowMethod, String> {
    match manylight::app::cli::parse_shadows(s)? {
        manylight::app::cli::ShadowChoice::Off => {
            Err("`off`: this example shows shadows; use maps or rays".into())
        }
        choice => Ok(choice.method()),
    }
}

/// The frame settings with shadows found by `method`.
fn settings(method: ShadowMethod) -> RenderSettings {
    let mut settings = RenderSettings::default();
    settings.shadows.method = method;
    settings
}

fn run_window(lights: usize, method: ShadowMethod) -> ExitCode {
    println!("manylight shadows: {lights} shadowed lights in a window (Esc closes it)");
    let config = WindowConfig {
        title: "manylight shadows".into(),
        width: WINDOW.x,
        height: WINDOW.y,
        ..WindowConfig::default()
    };
    let exit = App::new()
        .add_plugins(ManyLightPlugin::window(config))
        .insert_resource(settings(method))
        .add_systems(Startup, scene_setup(lights, WINDOW.x as f32 / WINDOW.y as f32))
        .run();
    if exit.is_success() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}

/// Renders one frame with shadows `on` (found by `method`) and returns its image and report.
fn frame(
    lights: usize,
    method: ShadowMethod,
    on: bool,
) -> anyhow::Result<(image::RgbaImage, manylight::render::FrameReport)> {
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(HEADLESS))
        .insert_resource(settings(method))
        .add_systems(Startup, scene_setup(lights, HEADLESS.x as f32 / HEADLESS.y as f32))
        .add_systems(PostStartup, move |world: &mut World| set_shadows(world, on));
    // Frames in flight: the second update brings the first frame's GPU times.
    for _ in 0..2 {
        app.update();
    }
    let world = app.world_mut();
    if let Some(message) = world.resource::<RenderFailure>().0.clone() {
        anyhow::bail!("rendering failed: {message}");
    }
    let image = world.resource_mut::<HeadlessCapture>().image.take();
    let report = world.resource::<FrameStats>().last.clone();
    match (image, report) {
        (Some(image), Some(report)) => Ok((image, report)),
        _ => anyhow::bail!("the frame was not captured"),
    }
}

fn run_headless(lights: usize, method: ShadowMethod, out_dir: PathBuf) -> anyhow::Result<()> {
    println!(
        "manylight shadows: no display, rendering {}x{} without and with shadows ({})",
        HEADLESS.x,
        HEADLESS.y,
        method.name()
    );
    let mut gpu_ms = [0.0; 2];
    for (i, on) in [false, true].into_iter().enumerate() {
        let (image, report) = frame(lights, method, on)?;
        let name = if on { format!("shadows_{}.png", method.name()) } else { "shadows_off.png".to_string() };
        let path = out_dir.join(name);
        save_png(&image, &path).map_err(anyhow::Error::msg)?;
        gpu_ms[i] = report.frame_gpu_ms.unwrap_or(f64::NAN);
        println!("{} ({} lights, frame {:.1} ms GPU)", path.display(), report.light_count, gpu_ms[i]);
        if let Some(s) = report.shadows {
            println!(
                "  {} casting lights: {} maps drawn, {} cached, {} unseen; atlas {}x{} {:.0} % used; {} \
                 lights got smaller maps than asked, {} none",
                s.casting_lights,
                s.maps_rendered,
                s.maps_cached,
                s.unseen_lights,
                s.atlas_size,
                s.atlas_size,
                s.atlas_occupancy * 100.0,
                s.downgraded_lights,
                s.dropped_lights
            );
        }
    }
    println!("shadows cost {:.2}x the unshadowed frame (one frame each)", gpu_ms[1] / gpu_ms[0]);
    Ok(())
}

fn main() -> ExitCode {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let args = Args::parse();
    if let Err(e) = check_app_lights(args.lights) {
        eprintln!("error: --lights: {e}");
        return ExitCode::FAILURE;
    }
    let has_display =
        ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()));
    if has_display && !args.headless {
        return run_window(args.lights, args.shadows);
    }
    let out_dir =
        args.out_dir.unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/shadows"));
    match run_headless(args.lights, args.shadows, out_dir) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

//! Views a glTF/GLB file: its meshes and lights, seen through its first camera (or one that
//! frames the whole scene), with an optional rig of animated lights. A file without lights is
//! lit by a dome of studio lights around it, as a model viewer does.
//!
//! ```text
//! cargo run --example gltf_viewer -- PATH [--lights N] [--fit] [--headless OUT.png]
//! ```
//!
//! A file that cannot be loaded prints the loader's error (naming the file and the problem)
//! and exits with code 1.

use clap::Parser;
use manylight::app::window::WindowConfig;
use manylight::math::light_count::check_app_lights;
use manylight::prelude::*;
use std::path::PathBuf;
use std::process::ExitCode;

/// Studio lights (`manylight::scene::studio_lights`) around a file that brings no lights when
/// `--lights` is not given.
const STUDIO_LIGHTS: usize = 32;

#[derive(Parser)]
#[command(about = "View a glTF/GLB file with manylight")]
struct Args {
    /// The .gltf or .glb file.
    path: PathBuf,
    /// Animated lights added to the file's own lights (default 0; a file without lights and
    /// without this option gets 32 static studio lights around it instead).
    #[arg(long)]
    lights: Option<usize>,
    /// Frame the whole scene instead of looking through the file's first camera.
    #[arg(long)]
    fit: bool,
    /// Render one 1280x720 frame to this PNG instead of opening a window.
    #[arg(long, value_name = "OUT.png")]
    headless: Option<PathBuf>,
}

fn main() -> ExitCode {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let args = Args::parse();
    let mut scene = match load_gltf(&args.path, &LoadOptions::default()) {
        Ok(scene) => scene,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if args.fit {
        scene.cameras.clear();
    }
    if scene.lights.is_empty() && args.lights.is_none() {
        let studio =
            manylight::scene::studio_lights(STUDIO_LIGHTS, scene.bounds()).expect("the studio's lights fit");
        scene.lights.extend(studio);
    }
    let lights = args.lights.unwrap_or(0);
    if let Err(e) = check_app_lights(lights) {
        eprintln!("error: --lights: {e}");
        return ExitCode::FAILURE;
    }
    println!(
        "{}: {} meshes, {} instances, {} lights{}, {}",
        args.path.display(),
        scene.meshes.len(),
        scene.instances.len(),
        scene.lights.len(),
        if lights > 0 { format!(" + {lights} animated") } else { String::new() },
        if scene.cameras.is_empty() { "fitted camera" } else { "the file's camera" },
    );

    let size = UVec2::new(1280, 720);
    let plugin = match &args.headless {
        Some(out) => ManyLightPlugin::headless(size).with_output(out),
        None => ManyLightPlugin::window(WindowConfig {
            title: format!("manylight: {}", args.path.display()),
            width: size.x,
            height: size.y,
            ..WindowConfig::default()
        }),
    };
    let aspect = size.x as f32 / size.y as f32;
    let exit = App::new()
        .add_plugins(plugin)
        .add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, aspect);
            if lights > 0 {
                spawn_light_rig(&mut commands, lights, manylight::scene::rig_bounds(scene.bounds()), 1)
                    .expect("--lights was checked before the app was built");
            }
        })
        .run();
    match (exit.is_success(), &args.headless) {
        (true, Some(out)) => {
            println!("wrote {}", out.display());
            ExitCode::SUCCESS
        }
        (true, None) => ExitCode::SUCCESS,
        (false, _) => {
            eprintln!("error: rendering failed (see the log above)");
            ExitCode::FAILURE
        }
    }
}

//! Views a glTF/GLB file: its meshes and lights, seen through its first camera (or one that
//! frames the whole scene), with an optional rig of animated lights, lit by an HDR panorama (the
//! bundled Venice Sunset by default; the overlay picks another bundled one or none) shown as
//! its skybox, as a model viewer does. Without an environment, a file without lights is lit by a
//! dome of studio lights around it.
//!
//! ```text
//! cargo run --example gltf_viewer -- PATH [--lights N] [--fit] [--environment PATH.hdr | --no-environment] [--headless OUT.png]
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
/// neither `--lights` nor an environment is given.
const STUDIO_LIGHTS: usize = 32;

/// The bundled panoramas, offered by the overlay's environment picker; the first is the default.
const BUNDLED_ENVIRONMENTS: [&str; 2] = [
    concat!(env!("CARGO_MANIFEST_DIR"), "/assets/environments/venice_sunset.hdr"),
    concat!(env!("CARGO_MANIFEST_DIR"), "/assets/environments/studio_small_03.hdr"),
];

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
    /// An equirectangular HDR panorama (.hdr or .exr) that lights the scene and shows behind
    /// it (default: the bundled Venice Sunset).
    #[arg(long, value_name = "PATH.hdr", conflicts_with = "no_environment")]
    environment: Option<PathBuf>,
    /// No environment: the file's lights only (studio lights for a file without any).
    #[arg(long)]
    no_environment: bool,
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
    let environments = match load_environments(&args) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let lit_by = environments.iter().next().map(|(handle, _)| handle);
    if scene.lights.is_empty() && args.lights.is_none() && lit_by.is_none() {
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
        .insert_resource(environments)
        .add_systems(PostStartup, move |mut commands: Commands, cameras: Query<Entity, With<Camera3d>>| {
            for camera in &cameras {
                if let Some(image) = lit_by {
                    commands.entity(camera).insert((EnvironmentMapLight::new(image), Skybox::new(image)));
                }
            }
        })
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

/// The panoramas the viewer offers: the one `--environment` names (or the bundled default)
/// first, then the other bundled ones; none with `--no-environment`.
fn load_environments(args: &Args) -> Result<EnvironmentImages, manylight::scene::EnvironmentError> {
    let mut images = EnvironmentImages::default();
    if args.no_environment {
        return Ok(images);
    }
    let budget = manylight::scene::EnvironmentBudget::default();
    let chosen = args.environment.clone().unwrap_or_else(|| PathBuf::from(BUNDLED_ENVIRONMENTS[0]));
    let others = BUNDLED_ENVIRONMENTS.iter().map(PathBuf::from).filter(|p| *p != chosen);
    for path in std::iter::once(chosen.clone()).chain(others) {
        let decoded = manylight::scene::load_environment(&path, &budget)?;
        let name =
            path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
        images.add_named(name, decoded.image);
    }
    Ok(images)
}

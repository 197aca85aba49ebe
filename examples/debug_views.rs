//! Debug views toggled at run time by a system: the embedded hall with 256 animated lights.
//!
//! `cargo run --release --example debug_views` opens a window. Keys: Right / Space next view,
//! Left previous view, 0–9 pick one of the first ten views (the others by Right / Left), `b` toggles bloom, `m` toggles motion blur, `c` toggles
//! a per-cluster cap of 8 (so the overflow view has something to show), Esc quits. Each change
//! logs one line saying what the view shows and how to read its colours (the light-count view
//! also draws its scale along the bottom edge).
//!
//! `cargo run --release --example debug_views -- --headless DIR` writes one PNG per view to DIR.

use manylight::app::headless::{finish_frames, finish_plugins, save_png};
use manylight::app::{DebugView, HeadlessCapture, PressedKeys};
use manylight::prelude::*;

fn setup(mut commands: Commands) {
    let scene = default_scene();
    spawn_scene(&mut commands, &scene, true, 16.0 / 9.0);
    spawn_light_rig(&mut commands, 256, scene.bounds(), 1).expect("256 lights fit");
}

/// Reads the keys pressed this frame and changes the `DebugView` resource and the camera's
/// opt-in effects; logs the legend of the new view.
fn toggle(
    keys: Res<PressedKeys>,
    mut debug: ResMut<DebugView>,
    mut settings: ResMut<RenderSettings>,
    cameras: Query<(Entity, Has<Bloom>, Has<MotionBlur>), With<Camera3d>>,
    mut commands: Commands,
) {
    let all = DebugViewMode::ALL;
    let index = all.iter().position(|&m| m == debug.mode).unwrap_or(0);
    for key in &keys.0 {
        match key.as_str() {
            "ArrowRight" | "Space" => debug.mode = all[(index + 1) % all.len()],
            "ArrowLeft" => debug.mode = all[(index + all.len() - 1) % all.len()],
            "b" | "m" => {
                for (camera, bloom, motion_blur) in &cameras {
                    let mut camera = commands.entity(camera);
                    match (key.as_str(), bloom, motion_blur) {
                        ("b", true, _) => camera.remove::<Bloom>(),
                        ("b", false, _) => camera.insert(Bloom::default()),
                        (_, _, true) => camera.remove::<MotionBlur>(),
                        (_, _, false) => camera.insert(MotionBlur::default()),
                    };
                    println!(
                        "{} {}",
                        if key == "b" { "bloom" } else { "motion blur" },
                        match key.as_str() {
                            "b" if bloom => "off",
                            "m" if motion_blur => "off",
                            _ => "on",
                        }
                    );
                }
            }
            "c" => {
                settings.clusters.cap = if settings.clusters.cap.is_some() { None } else { Some(8) };
                println!("per-cluster cap: {:?}", settings.clusters.cap);
            }
            digit => {
                if let Some(mode) = digit.parse::<usize>().ok().and_then(|i| all.get(i)) {
                    debug.mode = *mode;
                }
            }
        }
    }
    if debug.is_changed() {
        println!("debug view {}: {}", debug.mode.name(), debug.legend());
    }
}

/// The command line: a window by default.
#[derive(clap::Parser)]
struct Args {
    /// Write one PNG per view to this directory (`debug_views` without one) instead of opening
    /// a window.
    #[arg(long, num_args = 0..=1)]
    headless: Option<Option<std::path::PathBuf>>,
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error").init();
    let args = <Args as clap::Parser>::parse();
    if let Some(dir) = args.headless {
        return headless(&dir.unwrap_or_else(|| "debug_views".into()));
    }
    println!("keys: Right/Space next view, Left previous, 0-9 pick, b bloom, m motion blur, c cap");
    App::new()
        .add_plugins(ManyLightPlugin::default())
        .add_systems(Startup, setup)
        .add_systems(Update, toggle)
        .run()
}

/// Renders every view once into `dir`.
fn headless(dir: &std::path::Path) -> AppExit {
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("cannot create {}: {e}", dir.display());
        return AppExit::error();
    }
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(960, 540))).add_systems(Startup, setup);
    finish_plugins(&mut app);
    for mode in DebugViewMode::ALL {
        app.world_mut().resource_mut::<DebugView>().mode = mode;
        app.update();
        finish_frames(&mut app);
        let Some(image) = app.world().resource::<HeadlessCapture>().image.clone() else {
            eprintln!("no frame was rendered");
            return AppExit::error();
        };
        let path = dir.join(format!("{}.png", mode.name()));
        if let Err(e) = save_png(&image, &path) {
            eprintln!("{e}");
            return AppExit::error();
        }
        println!("{} — {}", path.display(), DebugView::new(mode).legend());
    }
    AppExit::Success
}

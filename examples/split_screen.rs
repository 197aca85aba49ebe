//! Four cameras in one window, each in its quarter: each renders its own view of the same 512
//! animated lights, with its own clusters and its own post-processing and debug view.
//!
//! - top left: the hall from its entrance;
//! - top right: from above, with `Bloom`;
//! - bottom left: the light-count debug view (`CameraDebugView`) of the top-left camera's view;
//! - bottom right: a camera circling the hall, with `MotionBlur`.
//!
//! The lights are uploaded once per frame and shared by the four views (the overlay, F1, shows
//! each view's time and clusters).
//!
//! `cargo run --release --example split_screen` opens a window (Esc closes it);
//! `cargo run --release --example split_screen -- --headless out.png --frames 30` renders 30
//! frames headless and writes the last one.

mod support;

use manylight::prelude::*;

/// Which quarter a camera takes: (column, row).
#[derive(Component, Clone, Copy)]
struct Quarter(u32, u32);

/// The camera that circles the hall.
#[derive(Component)]
struct Circling;

fn setup(mut commands: Commands) {
    let scene = default_scene();
    spawn_scene(&mut commands, &scene, false, 16.0 / 9.0);
    spawn_light_rig(&mut commands, 512, scene.bounds(), 7).expect("512 lights fit");
    let entrance = Transform::from_xyz(-18.0, 1.7, 0.0).looking_at(Vec3::new(0.0, 1.2, 0.0), Vec3::Y);
    let above = Transform::from_xyz(0.0, 14.0, 0.1).looking_at(Vec3::ZERO, Vec3::Y);
    commands.spawn((entrance, Camera3d, Camera { order: 0, ..default() }, Quarter(0, 0)));
    commands.spawn((above, Camera3d, Camera { order: 1, ..default() }, Bloom::default(), Quarter(1, 0)));
    commands.spawn((
        entrance,
        Camera3d,
        Camera { order: 2, ..default() },
        CameraDebugView(DebugViewMode::LightCount),
        Quarter(0, 1),
    ));
    commands.spawn((
        Transform::default(),
        Camera3d,
        Camera { order: 3, ..default() },
        MotionBlur::default(),
        Circling,
        Quarter(1, 1),
    ));
}

/// Keeps each camera in its quarter of the window, whatever its size.
fn layout(size: Res<manylight::app::ViewportSize>, mut cameras: Query<(&mut Camera, &Quarter)>) {
    let half = size.0 / 2;
    for (mut camera, quarter) in &mut cameras {
        let viewport = Viewport {
            physical_position: UVec2::new(quarter.0 * half.x, quarter.1 * half.y),
            physical_size: half.max(UVec2::ONE),
        };
        if camera.viewport != Some(viewport) {
            camera.viewport = Some(viewport);
        }
    }
}

fn circle(time: Res<Time>, mut cameras: Query<&mut Transform, With<Circling>>) {
    let a = 0.5 * time.elapsed_secs();
    for mut t in &mut cameras {
        *t = Transform::from_xyz(12.0 * a.cos(), 3.0, 5.0 * a.sin())
            .looking_at(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let plugin = support::ExampleArgs::from_env().plugin("split_screen.png");
    App::new().add_plugins(plugin).add_systems(Startup, setup).add_systems(Update, (layout, circle)).run()
}

//! Bevy's transform hierarchy: a carousel (a parent that moves back and forth down the hall)
//! carries a spinning hub (its child), and the hub carries eight coloured lights on arms (its
//! children). Each system moves only its own level's `Transform`; `TransformPlugin` composes
//! the `GlobalTransform`s that the renderer reads.
//!
//! `cargo run --release --example hierarchy` opens a window (Esc closes it);
//! `cargo run --release --example hierarchy -- --headless out.png --frames 30` renders 30
//! frames headless (1/60 s apart) and writes the last one.

mod support;

use manylight::prelude::*;

/// The top of the hierarchy: slides back and forth along the hall.
#[derive(Component)]
struct Carousel;

/// The carousel's child: spins about its vertical axis.
#[derive(Component)]
struct Hub;

fn setup(mut commands: Commands) {
    spawn_scene(&mut commands, &default_scene(), true, 16.0 / 9.0);
    let carousel = commands.spawn((Transform::from_xyz(-8.0, 1.2, 0.0), Carousel)).id();
    let hub = commands.spawn((Transform::IDENTITY, Hub, ChildOf(carousel))).id();
    for i in 0..8 {
        let angle = i as f32 / 8.0 * std::f32::consts::TAU;
        let hue = i as f32 / 8.0;
        let color = Vec3::new(
            (hue * 6.0 - 3.0).abs() - 1.0,
            2.0 - (hue * 6.0 - 2.0).abs(),
            2.0 - (hue * 6.0 - 4.0).abs(),
        )
        .clamp(Vec3::ZERO, Vec3::ONE);
        commands.spawn((
            Transform::from_xyz(2.5 * angle.cos(), 0.3 * (3.0 * angle).sin(), 2.5 * angle.sin()),
            PointLight {
                color: manylight::app::from_linear_rgb(color),
                intensity: 500.0,
                range: 4.0,
                radius: 0.05,
                ..Default::default()
            },
            ChildOf(hub),
        ));
    }
}

fn slide(time: Res<Time>, mut carousels: Query<&mut Transform, With<Carousel>>) {
    for mut t in &mut carousels {
        t.translation.x = -8.0 + 6.0 * (0.4 * time.elapsed_secs()).sin();
    }
}

fn spin(time: Res<Time>, mut hubs: Query<&mut Transform, With<Hub>>) {
    for mut t in &mut hubs {
        t.rotate_y(1.5 * time.delta_secs());
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let plugin = support::ExampleArgs::from_env().plugin("hierarchy.png");
    App::new().add_plugins(plugin).add_systems(Startup, setup).add_systems(Update, (slide, spin)).run()
}

//! The smallest manylight app: the plugin, a scene, point, spot and directional lights and a
//! system that moves one.
//!
//! `cargo run --example add_as_plugin` opens a window (Esc closes it);
//! `cargo run --example add_as_plugin -- --headless out.png` renders 30 frames headless and
//! writes the last one (`--frames N` for another count).

mod support;

use manylight::prelude::*;

/// The light that `orbit` moves.
#[derive(Component)]
struct Orbiting;

fn setup(mut commands: Commands) {
    // The embedded hall: meshes, materials, six warm lights and a camera.
    spawn_scene(&mut commands, &default_scene(), true, 16.0 / 9.0);
    for (x, z, color) in
        [(-13.0, -2.5, Color::linear_rgb(1.0, 0.1, 0.05)), (-9.0, 2.5, Color::linear_rgb(0.1, 0.3, 1.0))]
    {
        commands.spawn((
            Transform::from_xyz(x, 1.0, z),
            PointLight { color, intensity: 750.0, range: 6.0, ..PointLight::default() },
        ));
    }
    let green = PointLight {
        color: Color::linear_rgb(0.2, 1.0, 0.3),
        intensity: 750.0,
        range: 6.0,
        ..PointLight::default()
    };
    commands.spawn((Transform::from_xyz(-6.0, 1.5, 0.0), green, Orbiting));
    // A spot light over the nave, pointing down its -Z (here: straight down).
    commands.spawn((
        Transform::from_xyz(-2.0, 5.0, 0.0).looking_to(Vec3::NEG_Y, Vec3::X),
        SpotLight { intensity: 3800.0, range: 12.0, inner_angle: 0.25, outer_angle: 0.4, ..default() },
    ));
    // Dim moonlight from above and to the side, reaching every surface that faces it.
    commands.spawn((
        Transform::default().looking_to(Vec3::new(0.3, -1.0, 0.4), Vec3::Y),
        DirectionalLight { color: Color::linear_rgb(0.6, 0.7, 1.0), illuminance: 0.15, ..Default::default() },
    ));
}

fn orbit(time: Res<Time>, mut lights: Query<&mut Transform, With<Orbiting>>) {
    let t = time.elapsed_secs() * 0.5;
    for mut transform in &mut lights {
        transform.translation = Vec3::new(-6.0 + 4.0 * t.cos(), 1.5, 3.0 * t.sin());
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let plugin = support::ExampleArgs::from_env().plugin("add_as_plugin.png");
    App::new().add_plugins(plugin).add_systems(Startup, setup).add_systems(Update, orbit).run()
}

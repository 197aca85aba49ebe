//! The `stress` example's logic, headless and small: 65 536 animated lights at 128×72, a light
//! count changed at run time through `LightControls` (as the overlay does), and the
//! sphere-shell preset's turning camera. Runs on a real device (lavapipe in CI).

mod support;

#[allow(dead_code)]
#[path = "../examples/stress.rs"]
mod stress;

use clap::Parser;
use manylight::app::RenderFailure;
use manylight::prelude::*;
use stress::{Args, StressLight, Turning};
use support::gpu;

/// A headless app set up as `stress` sets itself up with `args`.
fn stress_app(args: &[&str]) -> App {
    let args =
        Args::try_parse_from(std::iter::once("stress").chain(args.iter().copied())).expect("valid args");
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(args.size));
    stress::setup(&mut app, &args, false).expect("scene loads");
    app
}

fn update(app: &mut App) -> FrameStats {
    app.update();
    if let Some(message) = &app.world().resource::<RenderFailure>().0 {
        panic!("rendering failed: {message}");
    }
    app.world().resource::<FrameStats>().clone()
}

fn light_positions(app: &mut App) -> Vec<Vec3> {
    let world = app.world_mut();
    let mut q = world.query_filtered::<&Transform, With<StressLight>>();
    q.iter(world).take(64).map(|t| t.translation).collect()
}

#[test]
fn many_animated_lights_render_move_and_follow_the_light_count() {
    let _gpu = gpu();
    let scene_lights = default_scene().lights.len() as u32;
    let mut app = stress_app(&["--lights", "65536", "--size", "128x72"]);
    let first = update(&mut app);
    let report = first.last.expect("a report");
    assert_eq!(report.light_count, 65_536 + scene_lights);
    assert_eq!(
        report.pass_names(),
        ["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    let before = light_positions(&mut app);
    let second = update(&mut app);
    assert_eq!(second.frames_rendered, 2);
    let after = light_positions(&mut app);
    assert_eq!(before.len(), 64);
    let moved = before.iter().zip(&after).filter(|(a, b)| a.distance(**b) > 1e-5).count();
    assert!(moved > 32, "only {moved} of 64 lights moved between frames");

    // What the overlay's light slider does: the example respawns the rig with the new count.
    app.world_mut().resource_mut::<LightControls>().count = 100;
    let third = update(&mut app);
    assert_eq!(third.last.expect("a report").light_count, 100 + scene_lights);
    let image = app.world().resource::<manylight::app::HeadlessCapture>().image.clone().expect("an image");
    let lit = image.pixels().filter(|p| p.0[..3].iter().any(|&c| c > 40)).count();
    assert!(lit > image.pixels().len() / 4, "the frame is mostly black ({lit} lit pixels)");
}

#[test]
fn sphere_shell_preset_has_its_lattice_and_turns_the_camera() {
    let _gpu = gpu();
    let mut app = stress_app(&["--scene", "sphere-shell", "--lights", "2048", "--size", "128x72"]);
    for _ in 0..3 {
        update(&mut app);
    }
    let stats = app.world().resource::<FrameStats>().clone();
    let report = stats.last.expect("a report");
    assert_eq!(report.light_count, 2048);
    assert_eq!(report.instance_count, 2);
    // The shell's pipeline: Forward+ without depth bounds (docs/benchmarks.md).
    assert_eq!(report.pass_names(), ["depth_prepass", "cluster_build", "clustered_forward", "tonemap"]);
    let settings = app.world().resource::<manylight::app::RenderSettings>();
    assert_eq!(settings.pipeline, PipelineKind::ForwardPlus);
    assert!(!settings.clusters.depth_bounds);
    assert!(!settings.clusters.refined_lists, "few lights: no refined lists");
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<(&Transform, &Projection), (With<Camera3d>, With<Turning>)>();
    let (t, cam) = cameras.single(world).expect("one turning camera");
    assert_eq!(t.translation, Vec3::ZERO);
    let Projection::Perspective(cam) = *cam else { panic!("a perspective camera: {cam:?}") };
    assert!((cam.fov - 45f32.to_radians()).abs() < 1e-6 && cam.near == 0.1 && cam.far == 1000.0);
    let step = Quat::from_rotation_x(stress::SHELL_TURN_PER_FRAME)
        * Quat::from_rotation_z(stress::SHELL_TURN_PER_FRAME);
    let expected = step * step * step;
    assert!(t.rotation.angle_between(expected) < 1e-5, "camera rotation {:?}", t.rotation);
    // Many lights: refined light lists after the build.
    let mut app = stress_app(&["--scene", "sphere-shell", "--lights", "20000", "--size", "128x72"]);
    let report = update(&mut app).last.expect("a report");
    assert_eq!(
        report.pass_names(),
        ["depth_prepass", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    let mut lights = world.query::<(&Transform, &PointLight)>();
    for (t, l) in lights.iter(world) {
        let r = t.translation.length();
        assert!(
            r < manylight::scene::SHELL_RADIUS && r > manylight::scene::SHELL_RADIUS - 1.0,
            "light at radius {r}"
        );
        assert_eq!(l.radius, manylight::scene::SHELL_LIGHT_RANGE);
    }
}

//! The plugin as an app uses it: build an `App` with the headless plugin, run frames, read
//! `FrameStats`. Runs on a real device (lavapipe in CI).

mod support;
// The examples' shared command line; this test reads it, the examples use the rest.
#[allow(dead_code)]
#[path = "../examples/support/mod.rs"]
mod example_support;

use manylight::app::headless::{finish_frames, render_headless};
use manylight::app::{FrameStats, HeadlessCapture, RenderFailure, RenderSettings, ViewportSize};
use manylight::prelude::*;
use std::time::Duration;
use support::gpu;

const SIZE: UVec2 = UVec2::new(96, 64);

fn scene_app(plugin: ManyLightPlugin, lights: usize) -> App {
    let mut app = App::new();
    app.add_plugins(plugin).add_systems(Startup, move |mut commands: Commands| {
        let scene = default_scene();
        spawn_scene(&mut commands, &scene, true, 1.5);
        spawn_light_rig(&mut commands, lights, scene.bounds(), 7).expect("the rig's lights fit");
    });
    app
}

fn stats(app: &App) -> FrameStats {
    app.world().resource::<FrameStats>().clone()
}

#[test]
fn frame_stats_list_the_passes_with_timings() {
    let _gpu = gpu();
    let mut app = scene_app(ManyLightPlugin::headless(SIZE), 8);
    for _ in 0..3 {
        app.update();
    }
    let s = stats(&app);
    assert_eq!(s.frames_rendered, 3);
    assert_eq!(
        s.pass_names(),
        ["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    let report = s.last.expect("a report");
    assert_eq!(report.light_count as usize, default_scene().lights.len() + 8);
    assert_eq!(report.instance_count as usize, default_scene().instances.len());
    assert_eq!((report.width, report.height), (SIZE.x, SIZE.y));
    // lavapipe and every real GPU we target support timestamp queries (compute-pass figures
    // are flagged untrusted on CPU adapters, but present).
    let gpu_ms: Vec<f64> = (report.passes.iter())
        .map(|p| p.gpu_ms.unwrap_or_else(|| panic!("{} has no GPU time", p.name)))
        .collect();
    assert!(gpu_ms.iter().chain(report.passes.iter().map(|p| &p.cpu_ms)).all(|ms| ms.is_finite()));
    // The frame's GPU time is its passes' (summed in the same order: the same float).
    assert_eq!(report.frame_gpu_ms, Some(gpu_ms.iter().sum()), "{:?}", report.passes);
    assert!(report.frame_cpu_ms > 0.0);
    // The CPU time by phase: extraction (main world), then the render side's phases, which
    // happen inside the frame's CPU time; the uploads include the lights.
    let cpu = report.cpu;
    assert!(cpu.extract_ms > 0.0 && cpu.upload_ms > 0.0 && cpu.prepare_ms > 0.0, "{cpu:?}");
    assert!(cpu.record_ms > 0.0 && cpu.submit_ms > 0.0, "{cpu:?}");
    // Each pass's CPU time is its recording, which the record phase sums (with any recording
    // made only to count the light lists, which no pass of the report shows).
    let recorded: f64 = report.passes.iter().map(|p| p.cpu_ms).sum();
    assert!(recorded <= cpu.record_ms, "passes recorded in {recorded} ms, the phase took {cpu:?}");
    let render_side = cpu.upload_ms + cpu.prepare_ms + cpu.record_ms + cpu.submit_ms;
    assert!(render_side <= report.frame_cpu_ms + 1e-6, "{cpu:?} against {} ms", report.frame_cpu_ms);
    assert!(report.light_upload_bytes > 0 && cpu.upload_bytes >= report.light_upload_bytes, "{cpu:?}");
}

#[test]
fn transient_textures_are_reused_across_frames() {
    let _gpu = gpu();
    let mut app = scene_app(ManyLightPlugin::headless(SIZE), 4);
    for _ in 0..5 {
        app.update();
    }
    let report = stats(&app).last.expect("a report");
    assert_eq!(report.transient_textures, 3, "hdr + depth + shading distance");
    let pixels = (SIZE.x * SIZE.y) as u64;
    assert_eq!(report.transient_bytes, pixels * (8 + 4 + 4), "rgba16f hdr + depth32f + r32f distance");
    let clusters = report.clusters.as_ref().expect("clusters were built");
    assert!(clusters.buffer_bytes >= clusters.index_capacity * 4, "{clusters:?}");
    assert_eq!(report.transient_allocations, 3, "no texture re-created after the first frame");
}

#[test]
fn resizing_reallocates_and_frees_old_transients() {
    let _gpu = gpu();
    let mut app = scene_app(ManyLightPlugin::headless(SIZE), 4);
    app.update();
    app.world_mut().insert_resource(ViewportSize(UVec2::new(64, 48)));
    for _ in 0..5 {
        app.update();
    }
    let report = stats(&app).last.expect("a report");
    assert_eq!((report.width, report.height), (64, 48));
    assert_eq!(report.transient_allocations, 6);
    assert_eq!(report.transient_textures, 3, "the old size's textures were freed");
    assert_eq!(report.transient_bytes, 64 * 48 * (8 + 4 + 4));
    let image = app.world().resource::<HeadlessCapture>().image.clone().expect("image");
    assert_eq!(image.dimensions(), (64, 48));
}

#[test]
fn zero_sized_viewport_and_missing_camera_render_nothing_and_do_not_fail() {
    let _gpu = gpu();
    let mut app = scene_app(ManyLightPlugin::headless(SIZE), 4);
    app.world_mut().insert_resource(ViewportSize(UVec2::ZERO));
    app.update();
    assert!(stats(&app).pass_names().is_empty());
    assert!(app.world().resource::<RenderFailure>().0.is_none());

    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE));
    app.update();
    assert!(stats(&app).pass_names().is_empty());
    assert!(app.world().resource::<RenderFailure>().0.is_none());
}

#[test]
fn invalid_lights_are_dropped_and_counted_and_the_image_stays_finite() {
    let _gpu = gpu();
    let frame = render_headless(SIZE, 1, |app| {
        app.add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, 1.5);
            commands.spawn((Transform::from_xyz(f32::NAN, 1.0, 0.0), PointLight::default()));
            commands.spawn((
                Transform::from_xyz(0.0, 1.0, 0.0),
                PointLight { range: f32::INFINITY, ..PointLight::default() },
            ));
            commands.spawn((
                Transform::from_xyz(0.0, 1.0, 0.0),
                PointLight { intensity: -1.0, ..PointLight::default() },
            ));
            // Finite colour and intensity whose product overflows to infinity.
            commands.spawn((
                Transform::from_xyz(0.0, 1.0, 0.0),
                PointLight {
                    color: Color::linear_rgb(1e30, 1e30, 1e30),
                    intensity: 1e30,
                    ..PointLight::default()
                },
            ));
            // Valid edge cases: range 0 (lights nothing) and a huge range.
            commands.spawn((
                Transform::from_xyz(0.0, 1.0, 0.0),
                PointLight { range: 0.0, ..PointLight::default() },
            ));
            commands.spawn((
                Transform::from_xyz(0.0, 1.0, 0.0),
                PointLight { range: 1e6, ..PointLight::default() },
            ));
        });
    })
    .expect("renders");
    support::assert_finite(&frame);
    let report = frame.stats.last.expect("a report");
    assert_eq!(report.invalid_lights, 4);
    assert_eq!(report.light_count as usize, default_scene().lights.len() + 2);
    assert!(frame.image.pixels().any(|p| p.0[0] > 10), "the frame is lit");
}

#[test]
fn a_light_at_the_camera_position_is_finite() {
    let _gpu = gpu();
    let scene = default_scene();
    let eye = scene.camera_or_fit(1.5).transform.w_axis.truncate();
    let frame = render_headless(SIZE, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, 1.5);
            commands.spawn((
                Transform::from_translation(eye),
                PointLight { range: 30.0, ..PointLight::default() },
            ));
        });
    })
    .expect("renders");
    assert!(frame.image.pixels().any(|p| p.0[1] > 200), "the light at the eye lights what it sees");
    support::assert_finite(&frame);
}

#[test]
fn pipelined_mode_renders_every_frame_and_shuts_down_cleanly() {
    let _gpu = gpu();
    let mut app = scene_app(ManyLightPlugin::headless(SIZE).with_pipelined(true), 8);
    for _ in 0..4 {
        app.update();
    }
    finish_frames(&mut app);
    let s = stats(&app);
    assert_eq!(s.frames_rendered, 4);
    assert_eq!(
        s.pass_names(),
        ["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    assert!(app.world().resource::<HeadlessCapture>().image.is_some());

    // Dropping an app with a frame in flight joins the render thread without hanging.
    let mut app = scene_app(ManyLightPlugin::headless(SIZE).with_pipelined(true), 8);
    app.update();
    app.update();
    // (App is not Send, so a watchdog thread ends the process if the drop hangs.)
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        if rx.recv_timeout(Duration::from_secs(60)).is_err() {
            eprintln!("dropping the app did not join the render thread within 60 s");
            std::process::exit(1);
        }
    });
    drop(app);
    let _ = tx.send(());
    watchdog.join().expect("watchdog");
}

#[test]
fn app_run_writes_the_png() {
    let _gpu = gpu();
    let out = support::output_dir().join("app_run.png");
    let _ = std::fs::remove_file(&out);
    let exit = scene_app(ManyLightPlugin::headless(SIZE).with_frames(2).with_output(&out), 4).run();
    assert_eq!(exit, AppExit::Success);
    let img = image::open(&out).expect("the PNG was written").to_rgba8();
    assert_eq!(img.dimensions(), (SIZE.x, SIZE.y));
}

#[test]
fn user_systems_before_extract_show_in_the_same_frame() {
    let _gpu = gpu();
    #[derive(Component)]
    struct Added;
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE))
        .add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, 1.5);
        })
        .add_systems(
            Last,
            (|mut commands: Commands, q: Query<&Added>| {
                if q.is_empty() {
                    commands.spawn((Transform::from_xyz(0.0, 2.0, 0.0), PointLight::default(), Added));
                }
            })
            .before(ManyLightSystems::Extract),
        );
    app.update();
    let report = stats(&app).last.expect("a report");
    assert_eq!(report.light_count as usize, default_scene().lights.len() + 1);
}

#[test]
fn a_scene_without_lights_builds_no_clusters() {
    let _gpu = gpu();
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, |mut commands: Commands| {
        let mut scene = default_scene();
        scene.lights.clear();
        spawn_scene(&mut commands, &scene, true, 1.5);
    });
    app.update();
    let s = stats(&app);
    assert_eq!(s.pass_names(), ["forward", "tonemap"]);
    assert!(s.last.expect("a report").clusters.is_none());
}

#[test]
fn each_pipeline_builds_exactly_its_passes() {
    let _gpu = gpu();
    let cases: [(PipelineKind, bool, &[&str]); 7] = [
        (PipelineKind::NaiveForward, true, &["forward", "tonemap"]),
        (
            PipelineKind::ForwardPlus,
            true,
            &[
                "depth_prepass",
                "cluster_depth",
                "cluster_build",
                "light_refine",
                "clustered_forward",
                "tonemap",
            ],
        ),
        (
            PipelineKind::ClusteredForward,
            true,
            &[
                "depth_prepass",
                "cluster_depth",
                "cluster_build",
                "light_refine",
                "clustered_forward",
                "tonemap",
            ],
        ),
        (
            PipelineKind::ClusteredDeferred,
            true,
            &["gbuffer", "cluster_depth", "cluster_build", "light_refine", "deferred_lighting", "tonemap"],
        ),
        (
            PipelineKind::TiledDeferred,
            true,
            &["gbuffer", "cluster_depth", "cluster_build", "tiled_deferred", "tonemap"],
        ),
        // Without lights nothing is assigned: no cluster build, no light lists, plain forward.
        (PipelineKind::ClusteredDeferred, false, &["forward", "tonemap"]),
        (PipelineKind::TiledDeferred, false, &["forward", "tonemap"]),
    ];
    for (pipeline, lights, expected) in cases {
        let mut app = App::new();
        app.add_plugins(ManyLightPlugin::headless(SIZE))
            .insert_resource(RenderSettings { pipeline, ..RenderSettings::default() })
            .add_systems(Startup, move |mut commands: Commands| {
                let mut scene = default_scene();
                if !lights {
                    scene.lights.clear();
                }
                spawn_scene(&mut commands, &scene, true, 1.5);
            });
        app.update();
        assert_eq!(stats(&app).pass_names(), expected, "{pipeline:?}, lights: {lights}");
    }
}

#[test]
fn an_invalid_camera_renders_nothing_and_is_counted() {
    let _gpu = gpu();
    let cameras = [
        Transform::from_xyz(f32::NAN, 1.0, 5.0),
        Transform::from_xyz(0.0, f32::INFINITY, 5.0),
        Transform {
            rotation: Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0),
            ..Transform::from_xyz(0.0, 1.0, 5.0)
        },
    ];
    for camera in cameras {
        let mut app = App::new();
        app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(
            Startup,
            move |mut commands: Commands| {
                let scene = default_scene();
                spawn_scene(&mut commands, &scene, false, 1.5);
                spawn_light_rig(&mut commands, 8, scene.bounds(), 1).expect("the rig's lights fit");
                commands.spawn((camera, Camera3d));
            },
        );
        app.update();
        let s = stats(&app);
        let report = s.last.as_ref().expect("a report");
        assert_eq!(report.invalid_cameras, 1, "{camera:?}");
        assert!(report.passes.is_empty(), "{camera:?}: {:?}", report.pass_names());
        assert!(app.world().resource::<RenderFailure>().0.is_none(), "{camera:?}");
    }
}

#[test]
fn extreme_projections_render_finite_images() {
    let _gpu = gpu();
    let projections = [
        (1e-6, 1e-6, 1000.0),
        (std::f32::consts::PI - 1e-6, 0.1, 1000.0),
        (manylight::math::camera::MAX_FOV_Y, 0.1, 1000.0),
        (0.0, 0.0, 0.0),
        (1.0, 1e-6, f32::INFINITY),
        (1.0, 1e30, f32::NAN),
        (1.0, f32::MAX, f32::MAX),
        (f32::NAN, f32::NAN, f32::NAN),
        (1.0, 10.0, 1.0),
    ];
    for (fov_y, near, far) in projections {
        let frame = render_headless(SIZE, 1, move |app| {
            app.add_systems(Startup, move |mut commands: Commands| {
                let scene = default_scene();
                spawn_scene(&mut commands, &scene, false, 1.5);
                spawn_light_rig(&mut commands, 8, scene.bounds(), 1).expect("the rig's lights fit");
                commands.spawn((
                    Transform::from_xyz(0.0, 2.0, 8.0).looking_at(Vec3::ZERO, Vec3::Y),
                    Camera3d,
                    Projection::Perspective(PerspectiveProjection { fov: fov_y, near, far }),
                ));
            });
        })
        .unwrap_or_else(|e| panic!("fov {fov_y} near {near} far {far}: {e}"));
        support::assert_finite(&frame);
        let report = frame.stats.last.as_ref().expect("a report");
        let valid = (1e-6..=manylight::math::camera::MAX_FOV_Y).contains(&fov_y) && near > 0.0 && far > near; // an infinite far plane is valid and kept
        assert_eq!(report.sanitized_cameras, u32::from(!valid), "fov {fov_y} near {near} far {far}");
    }
}

#[test]
fn a_target_beyond_the_device_limit_is_refused_with_the_limit_named() {
    let _gpu = gpu();
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("adapter");
    let limit = renderer.render_world.gpu().device.limits().max_texture_dimension_2d;
    let scene = default_scene();
    let snapshot = manylight::app::scene::scene_snapshot(
        &scene,
        Vec::new(),
        UVec2::new(limit + 1, 16),
        manylight::render::FrameSettings::default(),
        0,
    );
    let err = renderer.render(snapshot, false).expect_err("refused");
    let message = err.to_string();
    assert!(
        message.contains("max_texture_dimension_2d") && message.contains(&limit.to_string()),
        "{message}"
    );
}

/// The windowed examples' command line: a window by default, `--headless` with or without a
/// path, `--frames`; a misspelt flag is refused, not ignored.
#[test]
fn examples_read_their_command_line_with_clap() {
    use clap::Parser;
    use example_support::ExampleArgs;
    let parse = |s: &str| ExampleArgs::try_parse_from(s.split_whitespace());
    let window = parse("ex").expect("no arguments");
    assert_eq!((window.output("x.png"), window.frames), (None, 30));
    let default = parse("ex --headless --frames 5").expect("headless without a path");
    assert_eq!((default.output("x.png"), default.frames), (Some("x.png".into()), 5));
    let named = parse("ex --frames 2 --headless o.png").expect("headless with a path");
    assert_eq!((named.output("x.png"), named.frames), (Some("o.png".into()), 2));
    assert!(parse("ex --frame 2").is_err() && parse("ex --frames two").is_err());
}

/// Lights that did not change are not uploaded again: a still frame uploads no light byte after
/// the first, moving one light uploads that light's bytes, and each image equals the one a
/// fresh renderer (which uploads everything) makes of the same snapshot. The app's still lights
/// upload nothing after their first frame either.
#[test]
fn only_the_lights_that_changed_are_uploaded() {
    use manylight::app::render_world::HeadlessRenderer;
    use manylight::app::scene::{extracted_light, scene_snapshot};
    let _gpu = gpu();
    let scene = default_scene();
    let rig = manylight::scene::light_rig(64, scene.bounds(), 3).expect("64 lights fit");
    let lights: Vec<_> =
        rig.iter().map(|l| extracted_light(&manylight::scene::animated_light_at(l, 0.0))).collect();
    let snapshot = |lights: &[manylight::render::ExtractedPointLight], frame: u64| {
        scene_snapshot(&scene, lights.to_vec(), SIZE, manylight::render::FrameSettings::default(), frame)
    };
    let fresh = |lights: &[manylight::render::ExtractedPointLight]| {
        let mut renderer = HeadlessRenderer::new().expect("adapter");
        renderer.render(snapshot(lights, 0), true).expect("renders").1.expect("image")
    };
    let mut renderer = HeadlessRenderer::new().expect("adapter");
    let light_bytes =
        |n: usize| (n * std::mem::size_of::<manylight::render::gpu_types::GpuPointLight>()) as u64;
    let (first, _) = renderer.render(snapshot(&lights, 0), false).expect("renders");
    assert_eq!(first.light_upload_bytes, light_bytes(lights.len()));
    let (still, image) = renderer.render(snapshot(&lights, 1), true).expect("renders");
    assert_eq!(still.light_upload_bytes, 0, "a still frame uploaded lights");
    assert_eq!(image.expect("image"), fresh(&lights));
    let mut moved = lights.clone();
    moved[17].position += Vec3::new(0.5, 0.0, 0.25);
    let (one, image) = renderer.render(snapshot(&moved, 2), true).expect("renders");
    assert_eq!(one.light_upload_bytes, light_bytes(1), "one light moved");
    assert_eq!(image.expect("image"), fresh(&moved));
    // A light removed from the middle shifts the ones after it: they are written again.
    moved.remove(5);
    let (shifted, image) = renderer.render(snapshot(&moved, 3), true).expect("renders");
    assert!(shifted.light_upload_bytes > 0 && shifted.light_upload_bytes <= light_bytes(moved.len()));
    assert_eq!(image.expect("image"), fresh(&moved));

    // The app: the scene's own lights never move.
    let mut app = scene_app(ManyLightPlugin::headless(SIZE), 0);
    for _ in 0..3 {
        app.update();
    }
    finish_frames(&mut app);
    let report = stats(&app).last.expect("a report");
    assert_eq!(report.light_upload_bytes, 0, "the app's still lights were uploaded again");
    // Nor are its still objects: the frame's bytes are the view's constants, fewer than the
    // instances' own.
    let instance_bytes = u64::from(report.instance_count)
        * std::mem::size_of::<manylight::render::gpu_types::GpuInstance>() as u64;
    assert!(report.cpu.upload_bytes < instance_bytes, "{} B uploaded", report.cpu.upload_bytes);
}

/// Extraction keeps a slot per light entity and copies only what changed: after the first
/// frame a still world uploads no light; moving one light entity uploads that light's bytes;
/// despawning one moves the last light into its slot (that light's bytes); hiding one takes it
/// out and showing it again puts it back at the end; a light that loses its component leaves.
#[test]
fn extraction_follows_the_light_entities_that_changed() {
    let _gpu = gpu();
    let light_bytes = std::mem::size_of::<manylight::render::gpu_types::GpuPointLight>() as u64;
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, |mut commands: Commands| {
        spawn_scene(&mut commands, &default_scene(), true, 1.5);
        // More than one chunk of lights (LIGHT_CHUNK).
        for i in 0..1500 {
            let (x, z) = ((i % 50) as f32 * 0.2 - 5.0, (i / 50) as f32 * 0.2 - 3.0);
            commands
                .spawn((Transform::from_xyz(x, 1.0, z), PointLight { range: 1.0, ..PointLight::default() }));
        }
    });
    let step = |app: &mut App| {
        app.update();
        finish_frames(app);
        stats(app).last.expect("a report")
    };
    let first = step(&mut app);
    let count = first.light_count;
    assert!(count >= 1500 && first.light_upload_bytes == u64::from(count) * light_bytes, "{first:?}");
    let still = step(&mut app);
    assert_eq!(still.light_upload_bytes, 0, "a still world uploaded lights");
    let lights: Vec<Entity> =
        app.world_mut().query_filtered::<Entity, With<PointLight>>().iter(app.world()).collect();
    app.world_mut().get_mut::<Transform>(lights[3]).expect("a light").translation.y += 0.5;
    let moved = step(&mut app);
    assert_eq!((moved.light_count, moved.light_upload_bytes), (count, light_bytes), "one light moved");
    app.world_mut().despawn(lights[1]);
    let despawned = step(&mut app);
    assert_eq!(
        (despawned.light_count, despawned.light_upload_bytes),
        (count - 1, light_bytes),
        "the last light moves into the freed slot"
    );
    app.world_mut().entity_mut(lights[2]).insert(Visibility::Hidden);
    let hidden = step(&mut app);
    assert_eq!(hidden.light_count, count - 2, "a hidden light leaves");
    app.world_mut().entity_mut(lights[2]).insert(Visibility::Visible);
    let shown = step(&mut app);
    assert_eq!((shown.light_count, shown.light_upload_bytes), (count - 1, light_bytes), "and comes back");
    app.world_mut().entity_mut(lights[4]).remove::<PointLight>();
    let removed = step(&mut app);
    assert_eq!(removed.light_count, count - 2, "a light without its component leaves");
    assert_eq!(removed.nonfinite_pixels, Some(0));
}

/// The compute pass animates the rig's lights as `animate_lights` does on the CPU: after the
/// same frames (the same times, far enough apart that the pass takes its angles again at a new
/// epoch) both images match (FLIP, STRICT). On the GPU path a frame uploads no animated light,
/// only the pass's 16 B of parameters, and the lights' components stay where they were
/// spawned; a light that casts shadows animates on the CPU on both paths. Switching back to
/// the CPU path takes every animated light again.
#[test]
fn gpu_light_animation_matches_the_cpu_one() {
    use manylight::app::LightAnimationMode;
    use manylight::render::gpu_types::{GpuLightAnimationParams, GpuLightMotion, GpuPointLight};
    let _gpu = gpu();
    let size = UVec2::new(128, 96);
    // 37.3 s a frame: frame 3 is more than EPOCH_SPAN_SECS past frame 1's epoch.
    let step = Duration::from_secs_f64(37.3);
    let run = |mode: LightAnimationMode| {
        let mut app = App::new();
        app.add_plugins(ManyLightPlugin::headless(size))
            .insert_resource(mode)
            .insert_resource(TimeUpdateStrategy::ManualDuration(step))
            .add_systems(Startup, |mut commands: Commands| {
                let scene = default_scene();
                spawn_scene(&mut commands, &scene, true, 1.5);
                spawn_light_rig(&mut commands, 200, scene.bounds(), 11).expect("the rig's lights fit");
                let rig = manylight::scene::light_rig(1, scene.bounds(), 5).expect("one light");
                commands.spawn((
                    Transform::from_translation(rig[0].position_at(0.0)),
                    PointLight { intensity: 4000.0, range: 4.0, shadows_enabled: true, ..default() },
                    LightAnimation(rig[0]),
                ));
            });
        for _ in 0..4 {
            app.update();
        }
        finish_frames(&mut app);
        assert!(app.world().resource::<RenderFailure>().0.is_none(), "{mode:?}");
        app
    };
    let (mut cpu, mut gpu_app) = (run(LightAnimationMode::Cpu), run(LightAnimationMode::Gpu));
    let image = |app: &App| app.world().resource::<HeadlessCapture>().image.clone().expect("an image");
    support::assert_similar("gpu_light_animation", &image(&cpu), &image(&gpu_app), support::STRICT);

    let bytes = |n: usize| n as u64;
    let report = stats(&gpu_app).last.expect("a report");
    let (light, motion, params) = (
        bytes(std::mem::size_of::<GpuPointLight>()),
        bytes(std::mem::size_of::<GpuLightMotion>()),
        bytes(std::mem::size_of::<GpuLightAnimationParams>()),
    );
    // The shadowed light (its record and its zeroed motion) and the time.
    assert_eq!(report.light_upload_bytes, light + motion + params, "{report:?}");
    let cpu_report = stats(&cpu).last.expect("a report");
    assert_eq!(cpu_report.light_upload_bytes, 201 * light, "every light moved on the CPU path");

    let spawned = |app: &mut App| -> Vec<(Vec3, Vec3, bool)> {
        let mut query = app.world_mut().query::<(&Transform, &LightAnimation, &PointLight)>();
        query
            .iter(app.world())
            .map(|(t, a, p)| (t.translation, a.0.position_at(0.0), p.shadows_enabled))
            .collect()
    };
    for (at, start, shadowed) in spawned(&mut gpu_app) {
        assert_eq!(at == start, !shadowed, "GPU path: only the shadowed light moves on the CPU");
    }
    assert!(spawned(&mut cpu).iter().all(|(at, start, _)| at != start), "CPU path: every light moves");

    // Back to the CPU: every animated light is extracted again and shows where the CPU puts it.
    gpu_app.insert_resource(LightAnimationMode::Cpu);
    for app in [&mut cpu, &mut gpu_app] {
        app.update();
        finish_frames(app);
    }
    support::assert_similar("gpu_light_animation_back", &image(&cpu), &image(&gpu_app), support::STRICT);
    let back = stats(&gpu_app).last.expect("a report");
    assert_eq!(back.light_upload_bytes, 201 * light, "{back:?}");
}

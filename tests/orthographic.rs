//! Orthographic cameras: every pipeline matches naive forward through an orthographic view,
//! the GPU light lists of its box-shaped, linearly sliced clusters equal the CPU reference, and
//! the app's `Projection::Orthographic` component renders the same image.

mod support;

use manylight::app::RenderSettings;
use manylight::app::render_world::HeadlessRenderer;
use manylight::app::scene::extracted_light;
use manylight::math::Projection as Params;
use manylight::math::cluster::{CullTest, GridConfig, ZSlicing, assign_lights};
use manylight::prelude::*;
use manylight::render::{ClusterSettings, FrameSettings};
use manylight::scene::SceneCamera;
use support::{STRICT, assert_similar, gpu, render_scene as render};

const SIZE: UVec2 = UVec2::new(192, 128);

/// Above the hall, looking down at it diagonally.
fn eye() -> Transform {
    Transform::from_xyz(-14.0, 11.0, 9.0).looking_at(Vec3::new(-2.0, 0.0, 0.0), Vec3::Y)
}

fn orthographic() -> Params {
    Params::orthographic(14.0, 0.5, 60.0)
}

/// The default scene seen through `projection` from [`eye`].
fn scene(projection: Params) -> Scene {
    let mut scene = default_scene();
    scene.cameras = vec![SceneCamera { transform: eye().to_matrix(), projection }];
    scene
}

/// Every pipeline, layout and codec (one per layout) against naive forward, all through the
/// same orthographic camera; the image is not the perspective one.
#[test]
fn an_orthographic_view_matches_naive_forward_in_every_pipeline() {
    let _gpu = gpu();
    let with = |pipeline| RenderSettings { pipeline, ..RenderSettings::default() };
    let naive = render(scene(orthographic()), SIZE, 128, with(PipelineKind::NaiveForward));
    let perspective =
        render(scene(Params::perspective(1.0, 0.5, 60.0)), SIZE, 128, with(PipelineKind::NaiveForward));
    let differs = support::flip(&naive.image, &perspective.image);
    assert!(
        differs.mean > 0.05,
        "the orthographic image is not the perspective one: FLIP mean {}",
        differs.mean
    );
    let configs = [
        (PipelineKind::ForwardPlus, GBufferLayout::Full, NormalCodec::Octa16),
        (PipelineKind::ClusteredForward, GBufferLayout::Full, NormalCodec::Octa16),
        (PipelineKind::ClusteredDeferred, GBufferLayout::Full, NormalCodec::Octa16),
        (PipelineKind::ClusteredDeferred, GBufferLayout::Packed, NormalCodec::Octa16),
        (PipelineKind::ClusteredDeferred, GBufferLayout::Compact, NormalCodec::Octa16),
        (PipelineKind::TiledDeferred, GBufferLayout::Full, NormalCodec::Octa16),
        (PipelineKind::TiledDeferred, GBufferLayout::Compact, NormalCodec::Octa16),
        (PipelineKind::LightVolumes, GBufferLayout::Full, NormalCodec::Octa16),
    ];
    for (pipeline, gbuffer, normal_codec) in configs {
        let name = format!("orthographic_{}_{}", pipeline.name(), gbuffer.name());
        let settings = RenderSettings { gbuffer, normal_codec, ..with(pipeline) };
        let frame = render(scene(orthographic()), SIZE, 128, settings);
        // Compact stores albedo in 8-bit sRGB (docs/accuracy.md).
        let tol = if gbuffer == GBufferLayout::Compact { support::COMPACT } else { STRICT };
        let s = assert_similar(&name, &naive.image, &frame.image, tol);
        eprintln!("{name} vs naive: FLIP mean {:.5}, p99 {:.5}", s.mean, s.p99);
        if pipeline.uses_clusters() {
            let c = frame.stats.last.as_ref().and_then(|r| r.clusters.clone()).expect("clusters");
            assert!(c.total_entries > 0, "{name}: lights were assigned");
        }
    }
}

/// The GPU lists of an orthographic view equal the CPU reference for every culling test, with
/// lights on tile borders, across the near plane and around the view.
#[test]
fn orthographic_gpu_lists_equal_the_cpu_reference() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = scene(orthographic());
    let mut lights: Vec<_> = manylight::scene::light_rig(300, scene.bounds(), 5)
        .expect("300 lights")
        .iter()
        .map(|a| extracted_light(&manylight::scene::animated_light_at(a, 0.0)))
        .collect();
    let view = eye();
    // A light at the camera, one just behind its plane, one on the view's edge.
    for (local, radius) in
        [(Vec3::ZERO, 3.0), (Vec3::new(0.0, 0.0, 0.4), 1.0), (Vec3::new(7.0 * 1.5, 0.0, -10.0), 2.0)]
    {
        let position = view.transform_point(local);
        lights.push(manylight::render::ExtractedPointLight::point(position, Vec3::ONE, 1.0, radius));
    }
    for cull in [CullTest::Aabb, CullTest::Planes, CullTest::Both] {
        for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ForwardPlus] {
            let settings = FrameSettings {
                render: RenderSettings {
                    pipeline,
                    clusters: ClusterSettings {
                        // Exponential is asked for; an orthographic grid slices linearly anyway.
                        grid: GridConfig { slicing: ZSlicing::Exponential, ..GridConfig::default() },
                        cull,
                        // The CPU reference has whole slices (depth bounds: tests/clusters.rs).
                        depth_bounds: false,
                        ..ClusterSettings::default()
                    },
                    ..Default::default()
                },
                ..FrameSettings::default()
            };
            let snap = manylight::app::scene::scene_snapshot(&scene, lights.clone(), SIZE, settings, 0);
            r.render(snap, false).expect("renders");
            let renderer = r.render_world.renderer();
            let clusters = renderer.view_clusters(0).expect("clusters");
            assert!(clusters.grid.ortho_half.is_some() && clusters.grid.slicing == ZSlicing::Linear);
            let gpu = clusters.read_assignment(&renderer.gpu).expect("readback");
            let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
            let cpu = assign_lights(&clusters.grid, &spheres, cull, None);
            let what = format!("{cull:?}/{}", pipeline.name());
            assert!(cpu.ranges.iter().any(|r| r[1] > 0), "{what}: lights were assigned");
            for c in 0..cpu.ranges.len() as u32 {
                let (mut g, mut e) = (gpu.lights_of(c).to_vec(), cpu.lights_of(c).to_vec());
                g.sort_unstable();
                e.sort_unstable();
                assert_eq!(g, e, "{what}: cluster {c}");
            }
        }
    }
}

/// `Projection::Orthographic` on a `Camera3d` renders what the orthographic scene camera does.
#[test]
fn the_projection_component_selects_an_orthographic_view() {
    let _gpu = gpu();
    let expected = render(scene(orthographic()), SIZE, 0, RenderSettings::default());
    let frame = manylight::app::headless::render_headless(SIZE, 1, |app| {
        app.add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), false, 1.0);
            commands.spawn((
                eye(),
                Camera3d,
                Projection::Orthographic(OrthographicProjection {
                    near: 0.5,
                    far: 60.0,
                    viewport_height: 14.0,
                }),
            ));
        });
    })
    .expect("renders");
    support::assert_finite(&frame);
    assert_similar("orthographic_component", &expected.image, &frame.image, STRICT);
}

//! Every debug view renders its data on the default scene and replaces tone mapping; the views
//! of geometry and material (albedo, normal, metallic, roughness, emissive, occlusion, depth,
//! cluster x/y/z) match stored references (FLIP); the views
//! of cluster contents (light count, overflow) show, pixel by pixel, what the CPU reference
//! assignment says of the pixel's cluster; and the view follows the `DebugView` resource when a
//! system changes it.
//!
//! Light counts are not compared with stored images: which cluster a light at a cluster border
//! lands in depends on the last bit of its position, and that differs between CPUs (libm and
//! the rasteriser's floating point), so a stored count image holds only on the machine that
//! stored it. The count views are checked against the CPU reference computed from the same
//! frame instead.

mod support;

use glam::Vec2;
use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::app::render_world::HeadlessRenderer;
use manylight::app::scene::{extracted_light, scene_snapshot};
use manylight::app::{DebugView, FrameStats};
use manylight::math::TextureData;
use manylight::math::camera::linearize_depth_reverse_z;
use manylight::math::cluster::assign_lights;
use manylight::prelude::*;
use manylight::render::{ClusterSettings, FrameSettings};
use support::{STRICT, assert_matches_reference, gpu};

const SIZE: UVec2 = UVec2::new(128, 72);

/// The default scene with an emissive material and an occlusion texture, so that every
/// surface view has something to show.
fn scene() -> Scene {
    let mut scene = default_scene();
    let checker: Vec<u8> = (0..16 * 16)
        .flat_map(|i: u32| {
            let v = if (i % 16 / 4 + i / 64).is_multiple_of(2) { 255 } else { 64 };
            [v, v, v, 255]
        })
        .collect();
    let occlusion = std::sync::Arc::new(TextureData {
        label: "checker occlusion".into(),
        width: 16,
        height: 16,
        rgba8: checker,
        srgb: false,
    });
    for (i, material) in scene.materials.iter_mut().enumerate() {
        let m = std::sync::Arc::make_mut(material);
        if i == 0 {
            m.emissive = LinearRgba::rgb(1.0, 0.5, 0.2);
        } else {
            m.occlusion_texture = Some(occlusion.clone().into());
        }
    }
    scene
}

fn render(debug: DebugView, settings: RenderSettings) -> HeadlessFrame {
    let scene = scene();
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let bounds = scene.bounds();
    render_headless(SIZE, 1, move |app| {
        app.insert_resource(settings).insert_resource(debug).add_systems(
            Startup,
            move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, aspect);
                spawn_light_rig(&mut commands, 64, bounds, 1).expect("the rig's lights fit");
            },
        );
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"))
}

#[test]
fn every_debug_view_renders_its_data() {
    let _gpu = gpu();
    // The shadow views need casting lights: tests/shadows.rs.
    for mode in DebugViewMode::ALL.into_iter().filter(|&m| m != DebugViewMode::None && !m.uses_shadows()) {
        let mut settings =
            RenderSettings { pipeline: PipelineKind::ClusteredForward, ..RenderSettings::default() };
        if mode == DebugViewMode::Overflow {
            // A small cap, so some clusters overflow (red) and others do not (green).
            settings.clusters.cap = Some(8);
        }
        let frame = render(DebugView::new(mode), settings);
        let names = frame.stats.pass_names();
        assert_eq!(names.last().map(String::as_str), Some("debug_view"), "{mode:?}: {names:?}");
        assert!(!names.iter().any(|n| n == "tonemap" || n == "clustered_forward"), "{mode:?}: {names:?}");
        let mut colors: Vec<[u8; 4]> = frame.image.pixels().map(|p| p.0).collect();
        colors.sort_unstable();
        colors.dedup();
        // At least the background and two different surfaces / clusters.
        if colors.len() < 3 {
            let _ = frame.image.save(support::output_dir().join(format!("debug_{}.actual.png", mode.name())));
        }
        assert!(colors.len() >= 3, "{mode:?} shows {} colours", colors.len());
        if mode == DebugViewMode::Overflow {
            let red = frame.image.pixels().filter(|p| p[0] > 200 && p[1] < 100).count();
            let green = frame.image.pixels().filter(|p| p[1] > p[0] && p[1] > 30).count();
            assert!(red > 0 && green > 0, "overflow: {red} red and {green} green pixels");
            let c = frame.stats.last.as_ref().and_then(|r| r.clusters.clone()).expect("cluster report");
            assert!(c.clusters_overflowed > 0, "{c:?}");
        }
        if !matches!(mode, DebugViewMode::LightCount | DebugViewMode::Overflow) {
            // Views of geometry only; the count views are checked by
            // `count_views_show_the_cpu_reference_of_each_pixels_cluster`.
            assert_matches_reference(
                &format!("debug_{}", mode.name().replace('-', "_")),
                &frame.image,
                STRICT,
            );
        }
    }
}

#[test]
fn a_system_toggles_the_debug_view_at_run_time() {
    let _gpu = gpu();
    let modes = [DebugViewMode::Depth, DebugViewMode::None, DebugViewMode::Albedo, DebugViewMode::LightCount];
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(64, 48)))
        .add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, 64.0 / 48.0);
        })
        .add_systems(Update, move |mut frame: Local<usize>, mut debug: ResMut<DebugView>| {
            debug.mode = modes[*frame % modes.len()];
            *frame += 1;
        });
    for mode in modes {
        app.update();
        let names = app.world().resource::<FrameStats>().pass_names();
        let last = if mode == DebugViewMode::None { "tonemap" } else { "debug_view" };
        assert_eq!(names.last().map(String::as_str), Some(last), "{mode:?}: {names:?}");
    }
}

/// Linear [0, 1] to an 8-bit sRGB value, as the `Rgba8UnormSrgb` output stores it.
fn srgb8(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    s * 255.0
}

/// `heat` of `shaders/debug_view.wgsl`: blue → cyan → green → yellow → red over [0, 1].
fn heat(t: f32) -> [f32; 3] {
    let x = t.clamp(0.0, 1.0) * 4.0;
    let g = if x > 3.0 { (4.0 - x).clamp(0.0, 1.0) } else { x.clamp(0.0, 1.0) };
    [(x - 2.0).clamp(0.0, 1.0), g, (2.0 - x).clamp(0.0, 1.0)]
}

/// The light-count and overflow views, rendered directly, compared pixel by pixel with the
/// colour that the CPU reference assignment gives the pixel's cluster (the cluster found from
/// the read-back depth). A pixel on a depth-slice border can land in the neighbouring cluster
/// by a rounding step, so a few pixels may differ; nearly all must match.
#[test]
fn count_views_show_the_cpu_reference_of_each_pixels_cluster() {
    let _gpu = gpu();
    let scene = default_scene();
    let rig = manylight::scene::light_rig(64, scene.bounds(), 1).expect("64 lights");
    let lights: Vec<_> = scene
        .lights
        .iter()
        .map(extracted_light)
        .chain(rig.iter().map(|a| extracted_light(&manylight::scene::animated_light_at(a, 0.0))))
        .collect();
    let mut renderer = HeadlessRenderer::new().expect("adapter");
    for (mode, cap) in [
        (DebugViewMode::LightCount, None),
        (DebugViewMode::Overflow, Some(8)),
        (DebugViewMode::Overflow, None),
    ] {
        let settings = FrameSettings {
            render: RenderSettings {
                pipeline: PipelineKind::ClusteredForward,
                clusters: ClusterSettings { cap, ..ClusterSettings::default() },
                ..Default::default()
            },
            debug_view: mode,
            ..FrameSettings::default()
        };
        let heatmap_max = settings.debug_heatmap_max.max(1);
        let snapshot = scene_snapshot(&scene, lights.clone(), SIZE, settings, 0);
        let projection = snapshot.camera().expect("camera").projection;
        let (_, image) = renderer.render(snapshot, true).expect("renders");
        let image = image.expect("image");
        let r = renderer.render_world.renderer();
        let clusters = r.view_clusters(0).expect("the frame built clusters");
        // Uncapped counts: the overflow view shows a capped cluster red when its list hit the cap.
        let spheres = clusters.read_view_spheres(&r.gpu).expect("spheres");
        let reference = assign_lights(&clusters.grid, &spheres, settings.clusters.cull, None);
        let (w, h, depth) = r.read_depth().expect("depth readback").expect("a depth buffer");
        let p = projection.sanitized();
        let legend_top = h as f32 * 0.96;
        let (mut covered, mut wrong, mut red, mut not_red) = (0usize, Vec::new(), 0usize, 0usize);
        for y in 0..h {
            for x in 0..w {
                let z = depth[(y * w + x) as usize];
                let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                if z <= 0.0 || (mode == DebugViewMode::LightCount && centre.y >= legend_top) {
                    continue; // background or the heatmap legend
                }
                covered += 1;
                let d = linearize_depth_reverse_z(z, p.near, p.far);
                let n = reference.lights_of(clusters.grid.cluster_of(centre, d)).len() as u32;
                let expected = match (mode, cap) {
                    (DebugViewMode::LightCount, _) if n == 0 => [0.0; 3],
                    (DebugViewMode::LightCount, _) => heat(n as f32 / heatmap_max as f32),
                    (_, Some(cap)) if n >= cap => [1.0, 0.05, 0.05],
                    (_, cap) => {
                        let full = cap.unwrap_or(heatmap_max).max(1);
                        [0.0, 0.1 + 0.7 * (n as f32 / full as f32).clamp(0.0, 1.0), 0.05]
                    }
                };
                if expected[0] == 1.0 {
                    red += 1;
                } else {
                    not_red += 1;
                }
                let actual = image.get_pixel(x, y).0;
                if (0..3).any(|c| (srgb8(expected[c]) - f32::from(actual[c])).abs() > 2.0) {
                    wrong.push((x, y, n, actual));
                }
            }
        }
        let what = format!("{mode:?} cap {cap:?}");
        assert!(covered > (w * h / 2) as usize, "{what}: {covered} covered pixels");
        if cap.is_some() {
            assert!(
                red > 0 && not_red > 0,
                "{what}: the cap of 8 should leave some clusters full, others not"
            );
        }
        if wrong.len() * 100 > covered {
            let _ = image.save(support::output_dir().join(format!("count_view_{}.actual.png", mode.name())));
            panic!(
                "{what}: {} of {covered} pixels do not show their cluster's reference count, e.g. {:?}",
                wrong.len(),
                &wrong[..wrong.len().min(8)]
            );
        }
    }
}

/// The depth view, rendered directly, shows `1 − ln(d / near) / ln(far / near)` of each pixel's
/// view distance `d` from the read-back depth: `far` is the far plane, and without one the far
/// a cluster grid would slice to (the farthest light's reach, rounded up to a power of two), so
/// a projection without a far plane still gets a finite, meaningful scale.
#[test]
fn the_depth_view_scales_to_the_far_plane_or_to_the_lights_reach() {
    let _gpu = gpu();
    let mut scene = default_scene();
    let rig = manylight::scene::light_rig(64, scene.bounds(), 1).expect("64 lights");
    let lights: Vec<_> =
        rig.iter().map(|a| extracted_light(&manylight::scene::animated_light_at(a, 0.0))).collect();
    let camera = scene.camera_or_fit(SIZE.x as f32 / SIZE.y as f32);
    let mut renderer = HeadlessRenderer::new().expect("adapter");
    for far in [60.0, f32::INFINITY] {
        let projection = manylight::math::Projection { far, ..camera.projection };
        scene.cameras = vec![manylight::scene::SceneCamera { projection, ..camera }];
        let settings = FrameSettings {
            render: RenderSettings { pipeline: PipelineKind::ClusteredForward, ..Default::default() },
            debug_view: DebugViewMode::Depth,
            ..FrameSettings::default()
        };
        let snapshot = scene_snapshot(&scene, lights.clone(), SIZE, settings, 0);
        let (_, image) = renderer.render(snapshot, true).expect("renders");
        let image = image.expect("image");
        let r = renderer.render_world.renderer();
        let spheres = manylight::math::cluster::to_view_space(
            camera.transform.inverse(),
            lights.iter().map(|l| (l.position, l.radius)),
        );
        let reach = manylight::math::cluster::farthest_reach(spheres);
        let scale_far = projection.finite_for(reach).far;
        assert!(scale_far.is_finite() && scale_far > projection.near, "far {far}: scale to {scale_far}");
        let (w, h, depth) = r.read_depth().expect("depth readback").expect("a depth buffer");
        let (mut covered, mut wrong) = (0usize, Vec::new());
        for y in 0..h {
            for x in 0..w {
                let z = depth[(y * w + x) as usize];
                if z <= 0.0 {
                    continue;
                }
                covered += 1;
                let d = linearize_depth_reverse_z(z, projection.near, far);
                let t = ((d / projection.near).ln() / (scale_far / projection.near).ln()).clamp(0.0, 1.0);
                let expected = srgb8(1.0 - t);
                let actual = image.get_pixel(x, y).0;
                if (0..3).any(|c| (expected - f32::from(actual[c])).abs() > 2.0) {
                    wrong.push((x, y, expected, actual));
                }
            }
        }
        assert!(covered > (w * h / 2) as usize, "far {far}: {covered} covered pixels");
        if !wrong.is_empty() {
            let _ = image.save(support::output_dir().join(format!("depth_view_far_{far}.actual.png")));
            panic!(
                "far {far}: {} of {covered} pixels off, e.g. {:?}",
                wrong.len(),
                &wrong[..wrong.len().min(8)]
            );
        }
    }
}

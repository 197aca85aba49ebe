//! GPU light assignment against the CPU reference, light for light, on ordinary and hard
//! scenes; the per-cluster cap; growth of the light-index list. Real device (lavapipe in CI).

mod support;

use glam::{UVec2, Vec3};
use manylight::app::render_world::HeadlessRenderer;
use manylight::app::scene::extracted_light;
use manylight::math::LightShape;
use manylight::math::Projection;
use manylight::math::cluster::{ClusterAssignment, CullTest, GridConfig, ZSlicing, assign_lights};
use manylight::prelude::*;
use manylight::render::{ClusterSettings, ExtractedPointLight, FrameReport, FrameSettings, FrameSnapshot};
use support::gpu;

fn scene_snapshot(
    scene: &Scene,
    size: UVec2,
    lights: Vec<ExtractedPointLight>,
    settings: FrameSettings,
) -> FrameSnapshot {
    manylight::app::scene::scene_snapshot(scene, lights, size, settings, 0)
}

fn rig(scene: &Scene, count: usize, seed: u64) -> Vec<ExtractedPointLight> {
    manylight::scene::light_rig(count, scene.bounds(), seed)
        .expect("the rig's lights fit")
        .iter()
        .map(|a| extracted_light(&manylight::scene::animated_light_at(a, 0.0)))
        .collect()
}

/// The sphere-shell scene's 100 000 lights (each a few pixels wide, all at one depth).
fn shell_lights() -> Vec<ExtractedPointLight> {
    manylight::scene::sphere_shell_lights(
        100_000,
        manylight::scene::SHELL_RADIUS,
        manylight::scene::SHELL_LIGHT_RANGE,
        7,
    )
    .expect("100 000 lights")
    .iter()
    .map(extracted_light)
    .collect()
}

fn light(position: Vec3, radius: f32) -> ExtractedPointLight {
    ExtractedPointLight::point(position, Vec3::ONE, 1.0, radius)
}

/// Clustered forward with whole slices: the lists the CPU reference (`assign_lights`) builds.
/// With depth bounds the lists are a subset (`depth_bounded_lists_keep_every_contributing_light`).
fn clustered(cull: CullTest, slicing: ZSlicing, cap: Option<u32>) -> FrameSettings {
    FrameSettings {
        render: RenderSettings {
            pipeline: PipelineKind::ClusteredForward,
            clusters: ClusterSettings {
                grid: GridConfig { slicing, ..GridConfig::default() },
                cull,
                cap,
                depth_bounds: false,
                ..ClusterSettings::default()
            },
            ..Default::default()
        },
        ..FrameSettings::default()
    }
}

/// Renders the snapshot and returns the report, the GPU assignment and the CPU reference.
fn gpu_and_cpu(
    r: &mut HeadlessRenderer,
    snapshot: FrameSnapshot,
) -> (FrameReport, ClusterAssignment, ClusterAssignment) {
    let settings = snapshot.settings;
    let (report, _) = r.render(snapshot, false).expect("renders");
    let renderer = r.render_world.renderer();
    let clusters = renderer.view_clusters(0).expect("the frame built clusters");
    let gpu = clusters.read_assignment(&renderer.gpu).expect("readback");
    let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
    let cpu = assign_lights(&clusters.grid, &spheres, settings.clusters.cull, settings.clusters.cap);
    (report, gpu, cpu)
}

fn assert_same_lists(what: &str, gpu: &ClusterAssignment, cpu: &ClusterAssignment) {
    assert_eq!(assert_same_lists_where_kept(what, gpu, cpu), 0, "{what}: clusters shading from every light");
}

/// [`assert_same_lists`] for the clusters that kept a list; returns how many shade from every
/// light instead (their list did not fit the frame's lists: `LIST_EVERY_LIGHT`).
fn assert_same_lists_where_kept(what: &str, gpu: &ClusterAssignment, cpu: &ClusterAssignment) -> u32 {
    use manylight::render::gpu_types::LIST_EVERY_LIGHT;
    assert_eq!(gpu.ranges.len(), cpu.ranges.len(), "{what}: cluster count");
    let mut every_light = 0;
    for c in 0..cpu.ranges.len() as u32 {
        if gpu.ranges[c as usize] == [0, LIST_EVERY_LIGHT] {
            every_light += 1;
            continue;
        }
        let mut g = gpu.lights_of(c).to_vec();
        let mut e = cpu.lights_of(c).to_vec();
        g.sort_unstable();
        e.sort_unstable();
        assert_eq!(g, e, "{what}: cluster {c} differs");
    }
    if every_light == 0 {
        assert_eq!(gpu.dropped_pairs, cpu.dropped_pairs, "{what}: dropped pairs");
        assert_eq!(gpu.clusters_overflowed, cpu.clusters_overflowed, "{what}: overflowed clusters");
    }
    every_light
}

#[test]
fn gpu_lists_equal_the_cpu_reference_on_ordinary_scenes() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(200, 120);
    for (cull, slicing) in [
        (CullTest::Both, ZSlicing::Exponential),
        (CullTest::Planes, ZSlicing::Exponential),
        (CullTest::Aabb, ZSlicing::Exponential),
        (CullTest::Planes, ZSlicing::Linear),
        (CullTest::Aabb, ZSlicing::Linear),
    ] {
        let snap = scene_snapshot(&scene, size, rig(&scene, 300, 3), clustered(cull, slicing, None));
        let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
        let what = format!("{cull:?}/{slicing:?}");
        assert!(
            report.clusters.as_ref().is_some_and(|c| c.total_entries > 0),
            "{what}: lights were assigned"
        );
        assert_same_lists(&what, &gpu, &cpu);
        assert_eq!(cpu.dropped_pairs, 0, "{what}: exact mode drops nothing");
    }
    // Forward+: one slice.
    let mut settings = clustered(CullTest::Planes, ZSlicing::Exponential, None);
    settings.pipeline = PipelineKind::ForwardPlus;
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, scene_snapshot(&scene, size, rig(&scene, 300, 4), settings));
    assert_eq!(report.clusters.as_ref().map(|c| c.dims[2]), Some(1));
    assert_same_lists("forward+", &gpu, &cpu);
}

/// Lights that stress the assignment for the scene's camera at `size`: around and behind the
/// camera, across the near and far planes, radius 0 (index 4), covering the view (index 5), on
/// tile planes, tiny.
fn hard_lights(scene: &Scene, size: UVec2) -> Vec<ExtractedPointLight> {
    let cam = scene.camera_or_fit(size.x as f32 / size.y as f32);
    let eye = cam.transform.w_axis.truncate();
    let forward = -cam.transform.z_axis.truncate().normalize();
    let right = cam.transform.x_axis.truncate().normalize();
    let up = cam.transform.y_axis.truncate().normalize();
    let at = |d: f32, x: f32, y: f32| eye + forward * d + right * x + up * y;
    vec![
        light(eye, 2.0),                 // contains the camera
        light(eye - forward * 1.0, 1.5), // behind the camera, reaching forward
        light(eye - forward * 5.0, 1.0), // behind the camera, touching nothing
        light(at(0.1, 0.0, 0.0), 0.5),   // straddles the near plane
        light(at(5.0, 0.0, 0.0), 0.0),   // radius 0
        light(at(5.0, 0.0, 0.0), 1.0e4), // covers the whole view
        light(at(8.0, 0.0, 0.0), 0.25),  // on the central tile planes
        light(at(199.0, 0.0, 0.0), 3.0), // straddles the far plane
        light(at(3.0, 1.0, 0.5), 1e-3),  // tiny
    ]
}

#[test]
fn gpu_lists_equal_the_cpu_reference_on_hard_cases() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(160, 96);
    let cam = scene.camera_or_fit(size.x as f32 / size.y as f32);
    let forward = -cam.transform.z_axis.truncate().normalize();
    let at = |d: f32| cam.transform.w_axis.truncate() + forward * d;
    let hard = hard_lights(&scene, size);
    // Each test with coarse tiles of 2 × 2 tiles (3 × 2 of them, the last column and row
    // clipped), one coarse tile over the whole grid (8) and no coarse level (0).
    for (cull, coarse_tiles) in CullTest::ALL.into_iter().flat_map(|c| [(c, 2), (c, 8), (c, 0)]) {
        let mut settings = clustered(cull, ZSlicing::Exponential, None);
        settings.clusters.coarse_tiles = coarse_tiles;
        let snap = scene_snapshot(&scene, size, hard.clone(), settings);
        let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
        let c = report.clusters.as_ref().expect("cluster report");
        let coarse = coarse_tiles > 0 && cull != CullTest::Planes;
        assert_eq!(c.coarse_entries > 0, coarse, "{cull:?}, coarse {coarse_tiles}: {c:?}");
        assert_same_lists(&format!("hard cases {cull:?}, coarse tiles {coarse_tiles}"), &gpu, &cpu);
        // The covering light is in every cluster; the radius-0 light in none.
        for c in 0..cpu.ranges.len() as u32 {
            assert!(cpu.lights_of(c).contains(&5), "cluster {c} misses the covering light");
            assert!(!cpu.lights_of(c).contains(&4), "cluster {c} has the radius-0 light");
        }
    }

    // Extreme near/far with exponential slicing, lights on the slice boundaries.
    let mut scene = default_scene();
    scene.cameras = vec![manylight::scene::SceneCamera {
        transform: cam.transform,
        projection: Projection::perspective(1.0, 1e-4, 1e6),
    }];
    let mut lights = Vec::new();
    for k in 0..24 {
        let d = 1e-4 * (1e10f32).powf(k as f32 / 24.0);
        lights.push(light(at(d.min(5e5)), d.min(5e5) * 0.01));
    }
    let snap = scene_snapshot(&scene, size, lights, clustered(CullTest::Planes, ZSlicing::Exponential, None));
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
    assert_same_lists("near 1e-4, far 1e6", &gpu, &cpu);
    assert!(report.clusters.is_some());
}

/// The sphere-shell stress scene with 100 000 lights of its lattice (each a few pixels wide, all
/// at one depth), 256 × 144: the lists equal the CPU reference with the coarse level (coarse
/// tiles of 2 × 2 tiles: 4 × 3 of them, the last row clipped) and without it, and the coarse
/// lists are much shorter than the lights.
#[test]
fn gpu_lists_equal_the_cpu_reference_on_the_sphere_shell() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = manylight::scene::sphere_shell_scene();
    let lights = shell_lights();
    // Coarse tiles of 2 and 8 tiles: levels 0 and 1 from the lights' side; none: every light
    // per tile; 520 × 130 tiles make more coarse tiles than the lights' side takes
    // (COARSE_SCATTER_TILES), so each coarse tile loops over every light.
    for (coarse_tiles, dims, from_lights) in
        [(2, None, true), (8, None, true), (0, None, false), (2, Some(glam::UVec3::new(520, 130, 1)), false)]
    {
        let mut settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
        settings.clusters.coarse_tiles = coarse_tiles;
        settings.clusters.grid.dims = dims;
        let snap = scene_snapshot(&scene, UVec2::new(256, 144), lights.clone(), settings);
        let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
        let c = report.clusters.as_ref().expect("cluster report");
        assert!(c.total_entries > 0, "{c:?}");
        assert_eq!(c.from_lights, from_lights, "{c:?}");
        assert_same_lists(&format!("sphere shell, coarse tiles {coarse_tiles}, grid {dims:?}"), &gpu, &cpu);
        if coarse_tiles > 0 {
            let span = coarse_tiles;
            let coarse = u64::from(c.dims[0].div_ceil(span) * c.dims[1].div_ceil(span));
            assert!(c.coarse_entries < coarse * 20_000, "coarse lists barely cut: {c:?}");
            // Levels 0 and 1 run over every light's chunks (no CPU pass over the lights says
            // which ones some tile can list).
            let all_chunks = 100_000u32.div_ceil(4096);
            assert_eq!(c.chunks, [all_chunks, all_chunks], "{c:?}");
        } else {
            assert_eq!(c.chunks[0], c.chunks[1], "{c:?}");
        }
    }
}

/// Without a far plane the grid slices up to the farthest light's reach (a power of two), so
/// lights a million units away still land in clusters: the GPU lists equal the CPU reference,
/// and a light beyond any finite stand-in far plane (near × 10⁴ here is 1 000) is listed.
#[test]
fn an_infinite_projection_slices_to_the_farthest_light() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let mut scene = default_scene();
    let size = UVec2::new(160, 96);
    let cam = scene.camera_or_fit(size.x as f32 / size.y as f32);
    scene.cameras = vec![manylight::scene::SceneCamera {
        transform: cam.transform,
        projection: Projection::infinite(1.0, 0.1),
    }];
    let eye = cam.transform.w_axis.truncate();
    let forward = -cam.transform.z_axis.truncate().normalize();
    let right = cam.transform.x_axis.truncate().normalize();
    let mut lights: Vec<_> = [0.5f32, 3.0, 40.0, 900.0, 5e3, 1e5, 1e6]
        .iter()
        .map(|&d| light(eye + forward * d + right * (0.05 * d), 0.2 * d))
        .collect();
    lights.extend(rig(&scene, 64, 3));
    for slicing in [ZSlicing::Exponential, ZSlicing::Linear] {
        let snap = scene_snapshot(&scene, size, lights.clone(), clustered(CullTest::Both, slicing, None));
        let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
        assert_same_lists(&format!("infinite projection, {slicing:?}"), &gpu, &cpu);
        assert_eq!(report.sanitized_cameras, 0, "an infinite projection is valid as it is");
        let grid = r.render_world.renderer().view_clusters(0).expect("clusters").grid;
        let reach = 1e6 * 1.2;
        assert!(grid.far >= reach && grid.far < 2.0 * reach, "grid far {} for reach {reach}", grid.far);
        assert!(grid.far.log2().fract() == 0.0, "grid far {} is not a power of two", grid.far);
        // The light at 10⁵ (index 5) lies past any finite stand-in and is still listed.
        assert!((0..cpu.ranges.len() as u32).any(|c| cpu.lights_of(c).contains(&5)), "{slicing:?}");
    }
}

#[test]
fn a_cap_drops_deterministically_and_is_counted() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(160, 96);
    let snap = scene_snapshot(
        &scene,
        size,
        rig(&scene, 400, 5),
        clustered(CullTest::Planes, ZSlicing::Exponential, Some(2)),
    );
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
    assert_same_lists("cap 2", &gpu, &cpu);
    let c = report.clusters.expect("cluster report");
    assert!(c.dropped_pairs > 0 && c.clusters_overflowed > 0, "{c:?}");
    assert_eq!(c.dropped_pairs, cpu.dropped_pairs);
}

/// Lights that grow and move from frame to frame (tens of thousands of pairs, past the initial
/// capacities), so a frame's lists, sized from the counters of the frames before, fall short.
/// That frame is not rendered again: the clusters whose list does not fit shade from every
/// light (`LIST_EVERY_LIGHT`, counted in `fallback_clusters`), every other cluster's list
/// equals the CPU reference, the image is the one a renderer whose lists were counted for the
/// frame draws, and the lists grow for the frames after it.
#[test]
fn short_lists_shade_from_every_light_then_grow() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(256, 144);
    let base = rig(&scene, 600, 6);
    let (mut short_frames, mut grew, mut last_capacity) = (0, 0, 0);
    for frame in 0..6u32 {
        let radius = 0.5 * 2f32.powi(frame as i32).min(24.0);
        let shift = Vec3::new(frame as f32 * 1.5, 0.0, 0.0);
        let lights: Vec<_> = base
            .iter()
            .map(|l| ExtractedPointLight { radius, position: l.position + shift, ..l.clone() })
            .collect();
        let snap =
            scene_snapshot(&scene, size, lights, clustered(CullTest::Aabb, ZSlicing::Exponential, None));
        let (report, image) = r.render(snap.clone(), true).expect("renders");
        let renderer = r.render_world.renderer();
        let clusters = renderer.view_clusters(0).expect("clusters");
        let gpu = clusters.read_assignment(&renderer.gpu).expect("lists");
        let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
        let cpu = assign_lights(&clusters.grid, &spheres, CullTest::Aabb, None);
        let c = report.clusters.expect("cluster report");
        let what = format!("frame {frame}, radius {radius}");
        assert_eq!(c.counted_first, frame == 0, "{what}: only the first frame counts first: {c:?}");
        let every_light = assert_same_lists_where_kept(&what, &gpu, &cpu);
        assert_eq!(every_light, c.fallback_clusters, "{what}: {c:?}");
        if every_light > 0 {
            short_frames += 1;
            // A renderer that counts this frame's lists first draws it from lists alone.
            let mut counted = HeadlessRenderer::new().expect("adapter");
            let (exact, expected) = counted.render(snap, true).expect("renders");
            let exact = exact.clusters.expect("cluster report");
            assert!(exact.counted_first && exact.fallback_clusters == 0, "{what}: {exact:?}");
            let (image, expected) = (image.expect("image"), expected.expect("image"));
            support::assert_similar(&format!("short_lists_{frame}"), &expected, &image, support::STRICT);
        }
        grew += u32::from(c.index_capacity > last_capacity && frame > 0);
        last_capacity = c.index_capacity;
        if frame == 5 {
            assert!(c.total_entries > 1 << 16, "the last frame outgrows the initial list: {c:?}");
        }
    }
    assert!(short_frames > 0, "a frame outgrew the lists sized before it");
    assert!(grew > 0, "the lists grew between frames");
}

#[test]
fn culling_efficiency_finds_no_missing_light_and_clusters_beat_tiles() {
    use manylight::math::efficiency::culling_efficiency;
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(160, 96);
    let mut ratios = Vec::new();
    for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ForwardPlus] {
        let mut settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
        settings.pipeline = pipeline;
        let snap = scene_snapshot(&scene, size, rig(&scene, 256, 9), settings);
        let projection = snap.camera().expect("camera").projection;
        r.render(snap, false).expect("renders");
        let renderer = r.render_world.renderer();
        let clusters = renderer.view_clusters(0).expect("clusters");
        let assignment = clusters.read_assignment(&renderer.gpu).expect("lists");
        let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
        let (w, h, depth) = renderer.read_depth().expect("readback").expect("depth");
        assert_eq!((w, h), (size.x, size.y));
        // Check every pixel against every light: nothing that lights a pixel may be missing.
        let e = culling_efficiency(&clusters.grid, &projection, &assignment, &spheres, &depth, 1);
        assert!(e.pixels > 0 && e.contributing_pairs > 0, "{e:?}");
        assert_eq!(e.missed_pairs, 0, "{pipeline:?}: a contributing light is missing from a list: {e:?}");
        assert!(e.ratio() >= 1.0);
        ratios.push(e.ratio());
    }
    assert!(ratios[0] < ratios[1], "depth slices must cut evaluated pairs: {ratios:?}");
}

/// Tens of thousands of lights: level 1 of the build splits the lights into chunks, so no
/// invocation loops long enough to hit lavapipe's limit (65 535 loop iterations per
/// invocation, which silently dropped every light past about the 16 000th). The lists equal the
/// CPU reference, and lights past index 65 535 are in them.
#[test]
fn gpu_lists_keep_every_light_of_a_large_rig() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
    let snap = scene_snapshot(&scene, UVec2::new(128, 72), rig(&scene, 70_000, 5), settings);
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
    let c = report.clusters.as_ref().expect("cluster report");
    // Levels 0 and 1 from the lights' side, over every light's chunks.
    assert!(c.from_lights && c.chunks == [70_000u32.div_ceil(4096); 2], "{c:?}");
    assert_eq!(c.fallback_clusters, 0, "{c:?}");
    assert_same_lists("70 000 lights", &gpu, &cpu);
    let last = (0..gpu.ranges.len() as u32).flat_map(|c| gpu.lights_of(c).to_vec()).max().unwrap_or(0);
    assert!(last >= 65_536, "lights past index 65 535 must be assigned (largest: {last})");
}

/// More workgroups than a dispatch may have in one dimension (65 535): with a workgroup size
/// of 1, 65 536 tiles and 131 072 clusters are split into rows, and every tile and cluster is
/// still built exactly once.
#[test]
fn gpu_lists_are_exact_past_the_workgroups_per_dimension_limit() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let mut settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
    settings.clusters.workgroup_size = 1;
    settings.clusters.grid.dims = Some(glam::UVec3::new(256, 256, 2));
    let snapshot = scene_snapshot(&scene, UVec2::new(512, 512), rig(&scene, 256, 3), settings);
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, snapshot);
    let c = report.clusters.as_ref().expect("cluster report");
    assert_eq!(gpu.ranges.len(), 256 * 256 * 2);
    assert!(c.total_entries > 0, "{c:?}");
    assert_same_lists("256×256×2 grid, workgroup size 1", &gpu, &cpu);
}

/// 2 097 152 lights that each cover every one of 64 × 32 tiles make 2³² light–tile pairs, one
/// more than the build's u32 sums hold. A wrapped sum would be 0 and pass every capacity check
/// with empty lists; the saturating sums refuse the frame instead, naming the limit. The same
/// holds for the coarse level: 64 × 32 coarse tiles of 2 × 2 tiles.
#[test]
fn more_pairs_than_32_bits_hold_are_refused_not_wrapped() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    // 2^21 lights (48 bytes each: 96 MiB, under the 128 MiB a storage binding may hold)
    // times 2^11 tiles (no coarse level) or coarse tiles.
    let count = 1usize << 21;
    let center = scene.bounds().center();
    let lights = vec![light(center, 1e6); count];
    for (grid, coarse_tiles, level) in [
        (glam::UVec3::new(64, 32, 1), 0, "light–tile"),
        (glam::UVec3::new(128, 64, 1), 2, "light–coarse-tile"),
    ] {
        let mut settings = clustered(CullTest::Aabb, ZSlicing::Exponential, None);
        settings.clusters.grid.dims = Some(grid);
        settings.clusters.coarse_tiles = coarse_tiles;
        let snapshot = scene_snapshot(&scene, UVec2::new(128, 64), lights.clone(), settings);
        let start = std::time::Instant::now();
        let err = r.render(snapshot, false).expect_err("2^32 pairs are refused");
        eprintln!("refused in {:.1} s: {err}", start.elapsed().as_secs_f64());
        assert!(matches!(err, manylight::render::RenderError::TooManyPairs { .. }), "{err}");
        assert!(err.to_string().contains("PAIR_COUNT_SATURATED"), "{err}");
        assert!(err.to_string().contains(level), "{level}: {err}");
    }
}

/// 70 000 lights that all touch one tile make a tile list longer than lavapipe's 65 535 loop
/// iterations per invocation: the cluster build's per-cluster loop over that list would stop
/// early and lights would be missing from the lists without an error. On lavapipe the build
/// does not loop over it: the tile's clusters shade from every light (counted), the others'
/// lists equal the CPU reference; on a device without the limit every list does.
#[test]
fn a_list_longer_than_lavapipes_loop_limit_shades_from_every_light_there() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
    let center = scene.bounds().center();
    let lights: Vec<_> = (0..70_000).map(|i| light(center + Vec3::splat(i as f32 * 1e-6), 0.5)).collect();
    let snap = scene_snapshot(&scene, UVec2::new(128, 72), lights, settings);
    let limited = manylight::render::gpu_types::has_loop_limit(&r.render_world.gpu().info);
    let (report, gpu, cpu) = gpu_and_cpu(&mut r, snap);
    let c = report.clusters.expect("cluster report");
    let every_light = assert_same_lists_where_kept("70 000 lights in one tile", &gpu, &cpu);
    assert_eq!(every_light, c.fallback_clusters, "{c:?}");
    assert_eq!(every_light > 0, limited, "{c:?}");
    assert_eq!(report.nonfinite_pixels, Some(0));
}

/// Spot lights (narrow, wide, a hemisphere, inner = outer) are culled with the sphere around
/// their cone: the GPU lists equal the CPU reference, and they hold fewer light–cluster pairs
/// than the same lights shining in every direction.
#[test]
fn spot_light_lists_equal_the_cpu_reference_and_are_tighter_than_point_lights() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(200, 120);
    let points = rig(&scene, 300, 5);
    let spots = spot_rig(&points);
    let settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
    let (spot_report, gpu, cpu) = gpu_and_cpu(&mut r, scene_snapshot(&scene, size, spots, settings));
    assert_same_lists("spot lights", &gpu, &cpu);
    let (point_report, ..) = gpu_and_cpu(&mut r, scene_snapshot(&scene, size, points, settings));
    let entries = |r: &FrameReport| r.clusters.as_ref().map_or(0, |c| c.total_entries);
    assert!(entries(&spot_report) > 0, "spot lights were assigned");
    assert!(
        // Measured: 1 174 against 1 870 (a fifth of the cones are hemispheres, no tighter).
        (entries(&spot_report) as f32) < 0.75 * entries(&point_report) as f32,
        "cone spheres: {} entries, point spheres: {}",
        entries(&spot_report),
        entries(&point_report)
    );
}

/// The rig's lights as spot lights pointing every which way, with cones from a hair's width to
/// a hemisphere.
fn spot_rig(points: &[ExtractedPointLight]) -> Vec<ExtractedPointLight> {
    use manylight::math::SpotCone;
    points
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let a = i as f32 * 2.399;
            let direction = Vec3::new(a.cos(), (i % 7) as f32 / 3.0 - 1.0, a.sin());
            let outer = [0.02, 0.3, 0.6, 1.0, std::f32::consts::FRAC_PI_2][i % 5];
            let inner = if i % 3 == 0 { outer } else { outer * 0.5 };
            ExtractedPointLight {
                shape: LightShape::Spot(SpotCone { direction, inner_angle: inner, outer_angle: outer }),
                ..l.clone()
            }
        })
        .collect()
}

/// The oracle: exact per-pixel lists built on the CPU from a clustered frame's depth and lists.
/// Shaded from them (no cluster build), the frame equals naive forward's (the same sum: only
/// lights whose sphere does not hold the pixel are left out), and clustered deferred from them
/// equals clustered deferred; the lists hold exactly the contributing pairs (culling ratio 1,
/// nothing missing against every light) and never more than the clustered lists. On the rig,
/// and on the hard cases among 512 rig lights.
#[test]
fn exact_pixel_lists_shade_the_naive_image() {
    use manylight::math::efficiency::{culling_efficiency, exact_pixel_lists, pixel_grid};
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    let size = UVec2::new(160, 96);
    let mut hard = rig(&scene, 512, 4);
    hard.extend(hard_lights(&scene, size));
    let lit = |lights: &[ExtractedPointLight]| {
        let mut lights = lights.to_vec();
        for l in &mut lights {
            l.intensity *= 0.2;
        }
        lights
    };
    for (what, lights) in [("rig", rig(&scene, 256, 9)), ("hard cases", lit(&hard))] {
        let settings = clustered(CullTest::Both, ZSlicing::Exponential, None);
        let snap = scene_snapshot(&scene, size, lights.clone(), settings);
        let projection = snap.camera().expect("camera").projection;
        r.render(snap.clone(), false).expect("renders");
        let renderer = r.render_world.renderer();
        let clusters = renderer.view_clusters(0).expect("clusters");
        let assignment = clusters.read_assignment(&renderer.gpu).expect("lists");
        let (_, _, depth) = renderer.read_depth().expect("readback").expect("depth");
        let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
        let lists = exact_pixel_lists(&clusters.grid, &projection, &assignment, &spheres, &depth);
        assert!(lists.indices.len() < assignment.indices.len() * 64, "{what}: lists are per pixel");
        let grid = pixel_grid(size, &projection);
        let e = culling_efficiency(&grid, &projection, &lists, &spheres, &depth, 1);
        assert_eq!(e.missed_pairs, 0, "{what}: the exact lists miss a contributing light: {e:?}");
        assert_eq!(
            e.evaluated_pairs, e.contributing_pairs,
            "{what}: the exact lists hold a light that does not contribute"
        );
        let clustered = culling_efficiency(&clusters.grid, &projection, &assignment, &spheres, &depth, 0);
        assert!(e.evaluated_pairs <= clustered.evaluated_pairs);

        let oracle_lists = Some(std::sync::Arc::new(lists));
        let oracle = FrameSnapshot { pixel_light_lists: oracle_lists.clone(), ..snap.clone() };
        let (report, image) = r.render(oracle, true).expect("renders from the lists");
        let names: Vec<&str> = report.passes.iter().map(|p| p.name.as_str()).collect();
        assert!(!names.contains(&"cluster_build") && names.contains(&"pixel_light_lists"), "{names:?}");
        assert_eq!(report.nonfinite_pixels, Some(0));
        let mut naive = snap.clone();
        naive.settings.render.pipeline = PipelineKind::NaiveForward;
        let (_, expected) = r.render(naive, true).expect("naive renders");
        let (image, expected) = (image.expect("image"), expected.expect("image"));
        support::assert_similar(&format!("oracle, {what}"), &expected, &image, support::STRICT);

        // The deferred oracle: clustered deferred's lighting pass reads the same lists and
        // draws clustered deferred's image.
        let mut deferred = snap;
        deferred.settings.render.pipeline = PipelineKind::ClusteredDeferred;
        let (_, expected) = r.render(deferred.clone(), true).expect("deferred renders");
        let lists = FrameSnapshot { pixel_light_lists: oracle_lists.clone(), ..deferred };
        let (report, image) = r.render(lists, true).expect("deferred renders from the lists");
        assert!(report.passes.iter().any(|p| p.name == "deferred_lighting"));
        assert!(!report.passes.iter().any(|p| p.name == "cluster_build"));
        let (image, expected) = (image.expect("image"), expected.expect("image"));
        support::assert_similar(&format!("deferred oracle, {what}"), &expected, &image, support::STRICT);
    }

    // Lists that do not fit the view are refused, not read out of bounds.
    let snap = scene_snapshot(
        &scene,
        size,
        rig(&scene, 16, 1),
        clustered(CullTest::Both, ZSlicing::Exponential, None),
    );
    let wrong = ClusterAssignment {
        ranges: vec![[0, 1]; 10],
        indices: vec![0],
        dropped_pairs: 0,
        clusters_overflowed: 0,
    };
    let err = r.render(FrameSnapshot { pixel_light_lists: Some(std::sync::Arc::new(wrong)), ..snap }, false);
    assert!(err.is_err(), "lists of 10 pixels for a 160×96 view must be refused");
}

/// Tiled deferred cuts each tile's list to its pixels' depths in workgroup memory, where no
/// test can read it back; a contributing light it dropped would darken its pixels. With the
/// same G-buffer and shading code its image equals clustered deferred's to one 8-bit step (the
/// lists differ only by lights that add exactly zero, summed in another order) on the hard
/// cases, a 70 000-light rig, the sphere shell with 100 000 lights, tiles wider than its
/// workgroup (each invocation then visits several pixels) and an orthographic view.
#[test]
fn tiled_deferred_shades_what_clustered_deferred_shades() {
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let settings = |pipeline, tile_px| FrameSettings {
        render: RenderSettings {
            pipeline,
            clusters: ClusterSettings {
                grid: GridConfig { tile_px, ..GridConfig::default() },
                ..ClusterSettings::default()
            },
            ..Default::default()
        },
        ..FrameSettings::default()
    };
    let mut check = |what: &str, scene: &Scene, size: UVec2, lights: Vec<ExtractedPointLight>, tile_px| {
        let clustered =
            scene_snapshot(scene, size, lights.clone(), settings(PipelineKind::ClusteredDeferred, 16));
        let (_, expected) = r.render(clustered, true).expect("clustered deferred renders");
        let tiled = scene_snapshot(scene, size, lights, settings(PipelineKind::TiledDeferred, tile_px));
        let (report, image) = r.render(tiled, true).expect("tiled deferred renders");
        assert!(report.pass_names().contains(&"tiled_deferred"), "{what}: {:?}", report.pass_names());
        assert_eq!(report.nonfinite_pixels, Some(0), "{what}");
        let (image, expected) = (image.expect("image"), expected.expect("image"));
        let steps =
            image.as_raw().iter().zip(expected.as_raw()).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
        if steps > 1 {
            support::assert_similar(&format!("tiled_deferred_{what}"), &expected, &image, support::STRICT);
        }
        assert!(steps <= 1, "{what}: tiled deferred differs from clustered deferred by {steps} steps");
    };
    let scene = default_scene();
    let size = UVec2::new(160, 96);
    check("hard cases", &scene, size, hard_lights(&scene, size), 16);
    check("hard cases, 40-px tiles", &scene, size, hard_lights(&scene, size), 40);
    check("70 000 lights", &scene, size, rig(&scene, 70_000, 5), 16);
    let shell = manylight::scene::sphere_shell_scene();
    let lights = shell_lights();
    check("sphere shell", &shell, UVec2::new(256, 144), lights, 16);
    let ortho = orthographic(size);
    check("orthographic", &ortho, size, rig(&ortho, 512, 9), 16);
}

/// Per-cluster depth bounds (`ClusterSettings::depth_bounds`) cut each cluster
/// to the depth range of its pixels: every list is a subset of the CPU reference's whole-slice
/// list, and no light that contributes at a pixel (rebuilt from the read-back depth) is missing
/// from that pixel's list — on an ordinary rig, the hard cases, near 1e-4 / far 1e6, an
/// orthographic view and the sphere shell with 100 000 lights, for every culling test where the
/// scene is small, and for the forward pipelines (after the depth pre-pass) and the deferred
/// ones (after the G-buffer).
#[test]
fn depth_bounded_lists_keep_every_contributing_light() {
    use manylight::math::efficiency::culling_efficiency;
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let size = UVec2::new(160, 96);
    let settings = |pipeline, cull| FrameSettings {
        render: RenderSettings {
            pipeline,
            clusters: ClusterSettings { cull, depth_bounds: true, ..ClusterSettings::default() },
            ..Default::default()
        },
        ..FrameSettings::default()
    };
    // Returns (entries with bounds, entries of the whole-slice reference).
    let mut check = |what: &str, snapshot: FrameSnapshot, stride: usize| -> (usize, usize) {
        let projection = snapshot.camera().map(|c| c.projection).unwrap_or_default();
        let cull = snapshot.settings.render.clusters.cull;
        let (report, _) = r.render(snapshot, false).expect("renders");
        assert!(report.pass_names().contains(&"cluster_depth"), "{what}: {:?}", report.pass_names());
        let renderer = r.render_world.renderer();
        let clusters = renderer.view_clusters(0).expect("the frame built clusters");
        let gpu = clusters.read_assignment(&renderer.gpu).expect("readback");
        let spheres = clusters.read_view_spheres(&renderer.gpu).expect("spheres");
        let cpu = assign_lights(&clusters.grid, &spheres, cull, None);
        for c in 0..cpu.ranges.len() as u32 {
            let whole = cpu.lights_of(c);
            let kept = gpu.lights_of(c);
            assert!(
                kept.iter().all(|l| whole.contains(l)),
                "{what}: cluster {c} keeps a light outside its slice"
            );
        }
        let (_, _, depth) = renderer.read_depth().expect("depth readback").expect("a depth buffer");
        let e = culling_efficiency(&clusters.grid, &projection, &gpu, &spheres, &depth, stride);
        assert!(e.sampled_pixels > 0, "{what}: {e:?}");
        assert_eq!(e.missed_pairs, 0, "{what}: contributing lights missing: {e:?}");
        (gpu.indices.len(), cpu.indices.len())
    };
    let scene = default_scene();
    let pipelines = [
        PipelineKind::ClusteredForward,
        PipelineKind::ForwardPlus,
        PipelineKind::ClusteredDeferred,
        PipelineKind::TiledDeferred,
    ];
    for pipeline in pipelines {
        for cull in CullTest::ALL {
            let what = format!("{} {cull:?}", pipeline.name());
            let snap = scene_snapshot(&scene, size, rig(&scene, 1024, 3), settings(pipeline, cull));
            let (bounded, whole) = check(&format!("{what}, 1 024 lights"), snap, 1);
            assert!(bounded < whole, "{what}: depth bounds cut nothing ({bounded} of {whole} entries)");
            let snap = scene_snapshot(&scene, size, hard_lights(&scene, size), settings(pipeline, cull));
            check(&format!("{what}, hard cases"), snap, 1);
        }
    }

    let (extreme, lights) = near_far_extremes(size);
    for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ClusteredDeferred] {
        let snap = scene_snapshot(&extreme, size, lights.clone(), settings(pipeline, CullTest::Both));
        check(&format!("{}, near 1e-4, far 1e6", pipeline.name()), snap, 1);
    }

    let ortho = orthographic(size);
    for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ClusteredDeferred] {
        let snap = scene_snapshot(&ortho, size, rig(&ortho, 1024, 9), settings(pipeline, CullTest::Both));
        let (bounded, whole) = check(&format!("{}, orthographic", pipeline.name()), snap, 1);
        assert!(bounded < whole, "orthographic: depth bounds cut nothing ({bounded} of {whole} entries)");
    }

    let shell = manylight::scene::sphere_shell_scene();
    let lights = shell_lights();
    let snap = scene_snapshot(
        &shell,
        UVec2::new(256, 144),
        lights,
        settings(PipelineKind::ClusteredForward, CullTest::Both),
    );
    check("sphere shell, 100 000 lights", snap, 61);
}

/// Refined light lists (`light_refine` pass) are exact and tight: at every pixel every light
/// that contributes there is in the list the pixel shades from (its block's, or, where the
/// block fell back, its cluster's), and each block's list holds only lights of its pixels'
/// cluster lists that reach the box around its pixels (the CPU model
/// `efficiency::refined_lists`, with a wider slack: the CPU rebuilds positions from the depth
/// buffer, the GPU from the shading distance), each once and at most `REFINED_LIST_SLOTS`.
/// On the rig and hard cases for the forward pipelines (after the depth pre-pass) and clustered
/// deferred in every G-buffer layout, every culling test, with and without depth bounds; a
/// 70 000-light rig; near 1e-4 / far 1e6; orthographic; and the sphere shell with 100 000
/// lights, whose lists the refinement must cut to a small part.
#[test]
fn refined_lists_keep_every_contributing_light() {
    use manylight::app::prelude::GBufferLayout;
    use manylight::math::efficiency::{Refinement, culling_efficiency, pixel_grid, refined_lists};
    use manylight::render::gpu_types::{REFINE_EDGE, REFINED_FALLBACK, REFINED_LIST_SLOTS};
    let _gpu = gpu();
    let mut r = HeadlessRenderer::new().expect("adapter");
    let size = UVec2::new(160, 96);
    // The CPU rebuilds positions from the depth buffer: a wider slack than the GPU's.
    let refinement = Refinement { edge: REFINE_EDGE, slack: 1e-3, offset: 0.0 };
    let settings = |pipeline, cull, depth_bounds, gbuffer| FrameSettings {
        render: RenderSettings {
            pipeline,
            gbuffer,
            clusters: ClusterSettings {
                cull,
                depth_bounds,
                refined_lists: true,
                ..ClusterSettings::default()
            },
            ..Default::default()
        },
        ..FrameSettings::default()
    };
    // Returns (pairs evaluated with the refined lists, with the cluster lists).
    let mut check = |what: &str, snapshot: FrameSnapshot, stride: usize| -> (u64, u64) {
        let projection = snapshot.camera().map(|c| c.projection).unwrap_or_default();
        let (report, _) = r.render(snapshot, false).expect("renders");
        assert!(report.pass_names().contains(&"light_refine"), "{what}: {:?}", report.pass_names());
        let renderer = r.render_world.renderer();
        let clusters = renderer.view_clusters(0).expect("the frame built clusters");
        let lists = clusters.read_assignment(&renderer.gpu).expect("readback");
        let refined = clusters.read_refined(&renderer.gpu).expect("readback").expect("refined lists");
        let (_, _, depth) = renderer.read_depth().expect("depth readback").expect("a depth buffer");
        let spheres = &clusters.read_view_spheres(&renderer.gpu).expect("spheres");
        let blocks = &refined.lists;
        let model = refined_lists(&clusters.grid, &projection, &lists, spheres, &depth, refinement);
        assert_eq!(model.ranges.len(), blocks.ranges.len(), "{what}: block count");
        for (b, r) in blocks.ranges.iter().enumerate() {
            if r[1] == REFINED_FALLBACK {
                continue;
            }
            let kept = blocks.lights_of(b as u32);
            assert!(kept.len() <= REFINED_LIST_SLOTS as usize, "{what}: block {b} holds {}", kept.len());
            let allowed = model.lights_of(b as u32);
            for (i, l) in kept.iter().enumerate() {
                assert!(allowed.contains(l), "{what}: block {b} keeps light {l}, not in {allowed:?}");
                assert!(!kept[..i].contains(l), "{what}: block {b} holds light {l} twice");
            }
        }
        let per_pixel = refined.per_pixel(&clusters.grid, &projection, &lists, &depth);
        let pixels = pixel_grid(clusters.grid.viewport, &projection);
        let e = culling_efficiency(&pixels, &projection, &per_pixel, spheres, &depth, stride);
        assert!(e.sampled_pixels > 0, "{what}: {e:?}");
        assert_eq!(e.missed_pairs, 0, "{what}: contributing lights missing: {e:?}");
        let whole = culling_efficiency(&clusters.grid, &projection, &lists, spheres, &depth, 0);
        assert_eq!(e.contributing_pairs, whole.contributing_pairs, "{what}");
        (e.evaluated_pairs, whole.evaluated_pairs)
    };
    let scene = default_scene();
    let full = GBufferLayout::Full;
    let pipelines = [
        (PipelineKind::ClusteredForward, full),
        (PipelineKind::ForwardPlus, full),
        (PipelineKind::ClusteredDeferred, full),
        (PipelineKind::ClusteredDeferred, GBufferLayout::Packed),
        (PipelineKind::ClusteredDeferred, GBufferLayout::Compact),
    ];
    for (pipeline, gbuffer) in pipelines {
        for cull in CullTest::ALL {
            for bounds in [true, false] {
                let what = format!("{} {} {cull:?}, depth bounds {bounds}", pipeline.name(), gbuffer.name());
                let s = settings(pipeline, cull, bounds, gbuffer);
                let snap = scene_snapshot(&scene, size, rig(&scene, 1024, 3), s);
                let (refined, whole) = check(&format!("{what}, 1 024 lights"), snap, 1);
                assert!(refined < whole, "{what}: refinement cut nothing ({refined} of {whole} pairs)");
                let snap = scene_snapshot(&scene, size, hard_lights(&scene, size), s);
                check(&format!("{what}, hard cases"), snap, 1);
            }
        }
    }
    let s = settings(PipelineKind::ForwardPlus, CullTest::Both, true, full);
    check("forward+, 70 000 lights", scene_snapshot(&scene, size, rig(&scene, 70_000, 5), s), 7);
    // A size that is not a multiple of the block or the tile: partial blocks at the edges.
    let odd = UVec2::new(130, 77);
    for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ClusteredDeferred] {
        let s = settings(pipeline, CullTest::Both, true, full);
        let snap = scene_snapshot(&scene, odd, rig(&scene, 1024, 11), s);
        check(&format!("{}, 130 × 77", pipeline.name()), snap, 1);
    }

    let (extreme, lights) = near_far_extremes(size);
    let ortho = orthographic(size);
    for pipeline in [PipelineKind::ClusteredForward, PipelineKind::ClusteredDeferred] {
        let s = settings(pipeline, CullTest::Both, true, full);
        let snap = scene_snapshot(&extreme, size, lights.clone(), s);
        check(&format!("{}, near 1e-4, far 1e6", pipeline.name()), snap, 1);
        let snap = scene_snapshot(&ortho, size, rig(&ortho, 1024, 9), s);
        let (refined, whole) = check(&format!("{}, orthographic", pipeline.name()), snap, 1);
        assert!(refined < whole, "orthographic: refinement cut nothing ({refined} of {whole} pairs)");
    }

    let shell = manylight::scene::sphere_shell_scene();
    for pipeline in [PipelineKind::ForwardPlus, PipelineKind::ClusteredDeferred] {
        let s = settings(pipeline, CullTest::Both, false, full);
        let snap = scene_snapshot(&shell, UVec2::new(256, 144), shell_lights(), s);
        let (refined, whole) = check(&format!("{}, sphere shell, 100 000 lights", pipeline.name()), snap, 61);
        assert!(3 * refined < whole, "sphere shell: {refined} of {whole} pairs left");
    }
}

/// The default scene seen through near 1e-4 / far 1e6, with 24 lights spread over that range
/// (radius 1 % of their distance) and a 256-light rig.
fn near_far_extremes(size: UVec2) -> (Scene, Vec<ExtractedPointLight>) {
    let mut extreme = default_scene();
    let cam = extreme.camera_or_fit(size.x as f32 / size.y as f32);
    let forward = -cam.transform.z_axis.truncate().normalize();
    let at = |d: f32| cam.transform.w_axis.truncate() + forward * d;
    extreme.cameras = vec![manylight::scene::SceneCamera {
        transform: cam.transform,
        projection: Projection::perspective(1.0, 1e-4, 1e6),
    }];
    let lights = (0..24)
        .map(|k| {
            let d = 1e-4 * (1e10f32).powf(k as f32 / 24.0);
            light(at(d.min(5e5)), d.min(5e5) * 0.01)
        })
        .chain(rig(&extreme, 256, 4))
        .collect();
    (extreme, lights)
}

/// The default scene through an orthographic camera (12 units high, near 0.1, far 200) where
/// its fitted camera stands.
fn orthographic(size: UVec2) -> Scene {
    let mut ortho = default_scene();
    let cam = ortho.camera_or_fit(size.x as f32 / size.y as f32);
    ortho.cameras = vec![manylight::scene::SceneCamera {
        transform: cam.transform,
        projection: Projection::orthographic(12.0, 0.1, 200.0),
    }];
    ortho
}

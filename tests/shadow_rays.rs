//! Shadow rays through the scene's two-level BVH on the GPU (`shaders/common/ray_bvh.wgsl`)
//! against their CPU twin (`manylight_core::ray_bvh::trace`) and the exact visibility oracle,
//! on the default hall: the same answers, within rounding at edges; the instance level follows
//! moved instances; and more segments than one invocation's loop limit.

mod support;

use glam::{Mat4, Vec3};
use manylight::math::AlphaMode;
use manylight::math::ray_bvh::{MeshSlot, RAY_MAX_STEPS, RayOutcome, trace};
use manylight::math::shadow_oracle::{LightSource, OccluderSet, ShadowQuery};
use manylight::prelude::default_scene;
use manylight::render::GpuContext;
use manylight::render::ray_geometry::{RayGeometry, RaySegment, trace_segments};
use manylight::scene::Scene;

/// The geometry of `scene`'s meshes, each added once, and their slots.
fn geometry(scene: &Scene) -> (RayGeometry, Vec<MeshSlot>) {
    let mut geometry = RayGeometry::new();
    let slots = scene.meshes.iter().map(|m| geometry.add_mesh(m)).collect();
    (geometry, slots)
}

/// Places `scene`'s opaque instances (what casts shadows) at `transforms`.
fn place(geometry: &mut RayGeometry, slots: &[MeshSlot], scene: &Scene, transforms: &[Mat4]) {
    geometry.place(casting(scene).map(|(i, instance)| (slots[instance.mesh], transforms[i])));
}

fn casting(scene: &Scene) -> impl Iterator<Item = (usize, &manylight::scene::SceneInstance)> {
    scene
        .instances
        .iter()
        .enumerate()
        .filter(|(_, i)| scene.materials.get(i.material).is_none_or(|m| m.alpha_mode != AlphaMode::Blend))
}

fn oracle(scene: &Scene, transforms: &[Mat4]) -> OccluderSet {
    OccluderSet::from_instances(
        casting(scene).map(|(i, instance)| (scene.meshes[instance.mesh].as_ref(), transforms[i])),
    )
}

/// Light–point pairs spread through the hall's box: points on a jittered grid, lights from the
/// scene's own lights.
fn queries(scene: &Scene, count: usize) -> Vec<ShadowQuery> {
    let mut bounds = manylight::math::Aabb::EMPTY;
    for instance in &scene.instances {
        let b = scene.meshes[instance.mesh].bounds();
        for corner in [b.min, b.max] {
            bounds.extend(instance.transform.transform_point3(corner));
        }
    }
    let size = bounds.size();
    let lights: Vec<Vec3> = scene.lights.iter().map(|l| l.position).collect();
    assert!(!lights.is_empty(), "the default scene has lights");
    (0..count)
        .map(|i| {
            let f = i as f32;
            let frac = |a: f32| (f * a).fract();
            let point = bounds.min + size * Vec3::new(frac(0.618_034), frac(0.754_878), frac(0.569_840));
            ShadowQuery { point, normal: Vec3::ZERO, light: LightSource::At(lights[i % lights.len()]) }
        })
        .collect()
}

fn segments(queries: &[ShadowQuery]) -> Vec<RaySegment> {
    queries
        .iter()
        .map(|q| match q.segment() {
            Some((origin, direction, t_max)) => RaySegment { origin, direction, t_max },
            // No segment (the point on its light): a zero-length one, visible.
            None => RaySegment { origin: q.point, direction: Vec3::X, t_max: 0.0 },
        })
        .collect()
}

#[test]
fn gpu_rays_agree_with_their_cpu_twin_and_the_oracle() {
    let _gpu = support::gpu();
    let gpu = GpuContext::headless().expect("adapter");
    let scene = default_scene();
    let transforms: Vec<Mat4> = scene.instances.iter().map(|i| i.transform).collect();
    let (mut geometry, slots) = geometry(&scene);
    place(&mut geometry, &slots, &scene, &transforms);
    geometry.upload(&gpu);
    let report = geometry.report();
    assert!(report.triangles > 0 && report.instances > 0, "{report:?}");
    // More segments than lavapipe's 65 535 loop iterations: one invocation a segment.
    let queries = queries(&scene, 70_000);
    let traced = trace_segments(&gpu, &geometry, &segments(&queries)).expect("trace").traced;
    let oracle = oracle(&scene, &transforms);
    let mut nodes = Vec::new();
    let cpu = geometry.cpu_scene(&mut nodes);
    let (mut vs_twin, mut vs_oracle, mut blocked, mut steps_differ) = (0, 0, 0, 0);
    for (q, gpu_traced) in queries.iter().zip(&traced) {
        assert!(
            matches!(gpu_traced.outcome, RayOutcome::Visible | RayOutcome::Blocked),
            "{gpu_traced:?} at {q:?}"
        );
        assert!(gpu_traced.steps <= RAY_MAX_STEPS + 8);
        let twin = match q.segment() {
            Some((o, d, t)) => trace(&cpu, o, d, t),
            None => continue,
        };
        vs_twin += usize::from(twin.outcome != gpu_traced.outcome);
        steps_differ += usize::from(twin.steps != gpu_traced.steps);
        vs_oracle += usize::from(gpu_traced.outcome.lit() != oracle.visible(q));
        blocked += usize::from(gpu_traced.outcome == RayOutcome::Blocked);
    }
    let n = queries.len();
    assert!(blocked > n / 20 && blocked < n - n / 20, "{blocked} of {n} blocked: the pairs test little");
    assert!(vs_twin * 1000 <= n, "{vs_twin} of {n} differ from the CPU twin");
    assert!(steps_differ * 100 <= n, "{steps_differ} of {n} took other steps than the CPU twin");
    assert!(vs_oracle * 1000 <= n, "{vs_oracle} of {n} differ from the oracle");
}

#[test]
fn the_instance_level_follows_moved_instances() {
    let _gpu = support::gpu();
    let gpu = GpuContext::headless().expect("adapter");
    let scene = default_scene();
    let mut transforms: Vec<Mat4> = scene.instances.iter().map(|i| i.transform).collect();
    let (mut geometry, slots) = geometry(&scene);
    place(&mut geometry, &slots, &scene, &transforms);
    geometry.upload(&gpu);
    let mesh_bytes = geometry.report().mesh_level_bytes;
    let queries = queries(&scene, 4_000);
    let before = trace_segments(&gpu, &geometry, &segments(&queries)).expect("trace").traced;
    assert!(before.iter().any(|t| t.outcome == RayOutcome::Blocked));
    // Every other casting instance 100 m up: the mesh level stays, the instance level moves.
    for t in transforms.iter_mut().step_by(2) {
        *t = Mat4::from_translation(Vec3::Y * 100.0) * *t;
    }
    place(&mut geometry, &slots, &scene, &transforms);
    geometry.upload(&gpu);
    assert_eq!(geometry.report().mesh_level_bytes, mesh_bytes);
    let after = trace_segments(&gpu, &geometry, &segments(&queries)).expect("trace").traced;
    let oracle = oracle(&scene, &transforms);
    let differ = queries.iter().zip(&after).filter(|(q, t)| t.outcome.lit() != oracle.visible(q)).count();
    assert!(
        differ * 1000 <= queries.len(),
        "{differ} of {} differ from the oracle after the move",
        queries.len()
    );
    let changed = before.iter().zip(&after).filter(|(b, a)| b.outcome != a.outcome).count();
    assert!(changed > 0, "moving instances changed no pair");
}

#[test]
fn empty_geometry_traces_every_segment_visible_with_no_buffer() {
    let _gpu = support::gpu();
    let gpu = GpuContext::headless().expect("adapter");
    let geometry = RayGeometry::new();
    assert!(geometry.buffers().is_none());
    let segment = RaySegment { origin: Vec3::ZERO, direction: Vec3::X, t_max: 10.0 };
    let traced = trace_segments(&gpu, &geometry, &[segment; 3]).expect("trace").traced;
    assert!(traced.iter().all(|t| t.outcome == RayOutcome::Visible));
}

/// A floor 8 wide (top at y = 0) with `extra` meshes placed on it, lit from above, seen from
/// above.
fn floor_scene(extra: Vec<(manylight::math::MeshData, Mat4)>) -> Scene {
    use manylight::math::MaterialData;
    use manylight::scene::shapes::cuboid;
    use manylight::scene::{SceneCamera, SceneInstance, camera_looking_at};
    use std::sync::Arc;
    let mut scene = Scene {
        name: "floor".into(),
        meshes: vec![Arc::new(cuboid("floor", Vec3::new(8.0, 0.2, 8.0), 1.0))],
        materials: vec![Arc::new(MaterialData::default())],
        instances: vec![SceneInstance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_translation(-0.1 * Vec3::Y),
        }],
        cameras: vec![SceneCamera {
            transform: camera_looking_at(Vec3::new(0.0, 5.0, 5.0), Vec3::ZERO),
            projection: Default::default(),
        }],
        ..Scene::default()
    };
    for (mesh, transform) in extra {
        scene.meshes.push(Arc::new(mesh));
        scene.instances.push(SceneInstance { mesh: scene.meshes.len() - 1, material: 0, transform });
    }
    scene
}

fn point_light(at: Vec3, casts: bool) -> manylight::render::ExtractedPointLight {
    manylight::render::ExtractedPointLight {
        position: at,
        color: Vec3::ONE,
        intensity: 100.0,
        radius: 8.0,
        shape: manylight::math::LightShape::Point,
        shadow: casts.then_some(manylight::render::ShadowBias::POINT),
        animation: None,
    }
}

fn settings(method: manylight::render::ShadowMethod) -> manylight::render::FrameSettings {
    let mut s = manylight::render::FrameSettings::default();
    s.render.shadows.method = method;
    s
}

const SIZE: glam::UVec2 = glam::UVec2::new(128, 96);

/// The frame's own shadow test (`Renderer::probe_shadows`: the shading passes' ray test) at
/// `points` towards light 0, against the oracle through `scene`'s triangles: the pairs that
/// disagree.
fn wrong_pairs(
    renderer: &manylight::app::render_world::HeadlessRenderer,
    scene: &Scene,
    light: Vec3,
    points: &[(Vec3, Vec3)],
) -> usize {
    use manylight::render::shadow_probe::ShadowProbe;
    let probes: Vec<ShadowProbe> =
        points.iter().map(|&(position, normal)| ShadowProbe { position, normal, light: 0 }).collect();
    let tested = renderer.render_world.renderer().probe_shadows(&probes).expect("probe");
    let transforms: Vec<Mat4> = scene.instances.iter().map(|i| i.transform).collect();
    let oracle = oracle(scene, &transforms);
    points
        .iter()
        .zip(&tested)
        .filter(|((point, normal), v)| {
            let exact = oracle.visible(&ShadowQuery {
                point: *point,
                normal: *normal,
                light: LightSource::At(light),
            });
            (**v > 0.5) != exact
        })
        .count()
}

/// Floor points on a grid (the floor's normal).
fn floor_points() -> Vec<(Vec3, Vec3)> {
    (0..40 * 40)
        .map(|i| (Vec3::new((i % 40) as f32 * 0.1 - 1.95, 0.0, (i / 40) as f32 * 0.1 - 1.95), Vec3::Y))
        .collect()
}

#[test]
fn rays_follow_a_moving_instance_within_the_frame() {
    let _gpu = support::gpu();
    use manylight::scene::shapes::cuboid;
    let light = Vec3::new(0.0, 2.0, 0.0);
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let points = floor_points();
    for (frame, x) in [-1.0f32, 0.0, 1.5].into_iter().enumerate() {
        let plate =
            (cuboid("plate", Vec3::new(1.0, 0.05, 1.0), 1.0), Mat4::from_translation(Vec3::new(x, 1.0, 0.0)));
        let scene = floor_scene(vec![plate]);
        let snapshot = manylight::app::scene::scene_snapshot(
            &scene,
            vec![point_light(light, true)],
            SIZE,
            settings(manylight::render::ShadowMethod::Rays),
            frame as u64,
        );
        renderer.render(snapshot, false).expect("the frame renders");
        let wrong = wrong_pairs(&renderer, &scene, light, &points);
        assert_eq!(
            wrong, 0,
            "frame {frame}: plate at x = {x}: {wrong} floor points disagree with the oracle"
        );
    }
}

#[test]
fn a_curved_mesh_does_not_shadow_its_lit_side() {
    let _gpu = support::gpu();
    use manylight::scene::shapes::uv_sphere;
    let centre = Vec3::new(0.0, 1.0, 0.0);
    let sphere = uv_sphere("ball", 0.7, 24, 48, false);
    // Points on the faceted sphere: each triangle's centroid and face normal.
    let points: Vec<(Vec3, Vec3)> = sphere
        .indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] =
                [t[0], t[1], t[2]].map(|i| Vec3::from(sphere.vertices[i as usize].position) + centre);
            ((a + b + c) / 3.0, (b - a).cross(c - a).normalize_or_zero())
        })
        .filter(|(_, n)| *n != Vec3::ZERO)
        .collect();
    let scene = floor_scene(vec![(sphere, Mat4::from_translation(centre))]);
    let light = Vec3::new(1.5, 3.0, 0.5);
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let snapshot = manylight::app::scene::scene_snapshot(
        &scene,
        vec![point_light(light, true)],
        SIZE,
        settings(manylight::render::ShadowMethod::Rays),
        0,
    );
    renderer.render(snapshot, false).expect("the frame renders");
    let probes: Vec<manylight::render::shadow_probe::ShadowProbe> = points
        .iter()
        .map(|&(position, normal)| manylight::render::shadow_probe::ShadowProbe {
            position,
            normal,
            light: 0,
        })
        .collect();
    let tested = renderer.render_world.renderer().probe_shadows(&probes).expect("probe");
    let (mut lit_side, mut acne) = (0, 0);
    for ((p, n), v) in points.iter().zip(&tested) {
        // Facing the light by more than the facets' tilt: nothing of the sphere is in between.
        if n.dot((light - *p).normalize()) > 0.2 {
            lit_side += 1;
            acne += usize::from(*v < 0.5);
        }
    }
    assert!(lit_side > 200, "{lit_side} facets face the light");
    assert_eq!(acne, 0, "{acne} of {lit_side} facets facing the light shadow themselves");
    assert_eq!(
        wrong_pairs(&renderer, &scene, light, &points),
        0,
        "the sphere's facets disagree with the oracle"
    );
}

#[test]
fn without_a_casting_light_rays_build_nothing_and_no_frame_adds_a_pass() {
    let _gpu = support::gpu();
    use manylight::render::ShadowMethod;
    use manylight::scene::shapes::cuboid;
    let scene =
        floor_scene(vec![(cuboid("plate", Vec3::new(1.0, 0.05, 1.0), 1.0), Mat4::from_translation(Vec3::Y))]);
    let light = Vec3::new(0.0, 2.0, 0.0);
    let passes = |casts: bool, method: ShadowMethod| {
        let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
        let snapshot = manylight::app::scene::scene_snapshot(
            &scene,
            vec![point_light(light, casts)],
            SIZE,
            settings(method),
            0,
        );
        let (report, _) = renderer.render(snapshot, false).expect("the frame renders");
        let built = renderer.render_world.renderer().rays.geometry().is_some();
        let names: Vec<String> = report.passes.iter().map(|p| p.name.to_string()).collect();
        (names, built, report.shadows.is_some())
    };
    let (unshadowed, built, report) = passes(false, ShadowMethod::Rays);
    assert!(!built && !report, "no casting light: no BVH, no shadow report");
    let (maps, built_for_maps, _) = passes(true, ShadowMethod::Maps);
    assert!(!built_for_maps && maps.iter().any(|p| p == "shadow_maps"), "{maps:?}");
    let (rays, built, report) = passes(true, ShadowMethod::Rays);
    assert!(built && !report, "rays: a BVH and no atlas");
    assert_eq!(rays, unshadowed, "rays add no pass to the unshadowed frame");
}

//! A floor whose corners lie at ±10⁷ under point lights, drawn as one quad (two triangles
//! whose vertices lie up to 10⁷ units from pixels two units from the camera), in every
//! pipeline, G-buffer layout and normal codec, against the same plane tessellated into rings
//! that grow geometrically with the distance from the camera's foot point (the reference: no
//! triangle's vertices lie much farther from the camera than the pixels it covers), which is
//! itself checked against the floor shaded analytically on the CPU. The figures before and after
//! shading `surface_point` are in docs/reliability.md (very large surfaces).

mod support;

use glam::Mat4;
use manylight::app::RenderSettings;
use manylight::math::{Projection, Vertex};
use manylight::prelude::*;
use manylight::scene::{SceneCamera, SceneInstance, SceneLight, camera_looking_at};
use std::sync::Arc;
use support::{STRICT, Tolerance, assert_similar, gpu, render_scene as render};

const SIZE: UVec2 = UVec2::new(256, 144);
const EYE: Vec3 = Vec3::new(0.0, 2.0, 6.0);
const TARGET: Vec3 = Vec3::new(0.0, 0.0, 0.0);
const NEAR: f32 = 0.1;

fn camera(far: f32) -> SceneCamera {
    SceneCamera {
        transform: camera_looking_at(EYE, TARGET),
        projection: Projection::perspective(60f32.to_radians(), NEAR, far),
    }
}

fn floor_vertex(x: f64, z: f64) -> Vertex {
    Vertex { position: [x as f32, 0.0, z as f32], normal: [0.0, 1.0, 0.0], ..Vertex::default() }
}

/// The floor as one quad with corners at ±`extent`.
fn quad_floor(extent: f64) -> MeshData {
    let vertices = vec![
        floor_vertex(-extent, -extent),
        floor_vertex(extent, -extent),
        floor_vertex(extent, extent),
        floor_vertex(-extent, extent),
    ];
    MeshData { label: "floor_quad".into(), vertices, indices: vec![0, 2, 1, 0, 3, 2] }
}

/// The floor `y = 0` out to ±`extent`, tessellated into square rings around the camera's foot
/// point whose size grows by `GROWTH` per ring; every ring has `SEGMENTS` segments per side on
/// both boundaries, so neighbouring rings share their boundary vertices exactly (watertight,
/// no T-junctions). Triangles behind the camera are cut in f64 at the plane half-way between
/// the eye and the near plane, so the rasteriser never clips a large triangle at the near
/// plane.
fn ring_floor(extent: f64) -> MeshData {
    ring_floor_seen_from(extent, EYE, (TARGET - EYE).normalize())
}

/// [`ring_floor`] for a camera at `eye` looking along `forward`, both in the floor's own
/// coordinates (the floor is `y = 0` there).
fn ring_floor_seen_from(extent: f64, eye: Vec3, forward: Vec3) -> MeshData {
    const SEGMENTS: usize = 16;
    const GROWTH: f64 = 1.25;
    const INNER: f64 = 0.5;
    let foot = (f64::from(eye.x), f64::from(eye.z));
    // Points of the square of half-size r, SEGMENTS + 1 per side, counter-clockwise, as offsets
    // from the foot point; the last ring is clamped to the floor's extent.
    let boundary = |r: f64| -> Vec<(f64, f64)> {
        let s = |i: usize| -1.0 + 2.0 * i as f64 / SEGMENTS as f64;
        let mut pts = Vec::with_capacity(4 * SEGMENTS);
        for i in 0..SEGMENTS {
            pts.push((r * s(i), -r));
        }
        for i in 0..SEGMENTS {
            pts.push((r, r * s(i)));
        }
        for i in 0..SEGMENTS {
            pts.push((-r * s(i), r));
        }
        for i in 0..SEGMENTS {
            pts.push((-r, -r * s(i)));
        }
        pts
    };
    let mut tris: Vec<[(f64, f64); 3]> = Vec::new();
    // The inner square as a grid.
    for j in 0..SEGMENTS {
        for i in 0..SEGMENTS {
            let c = |i: usize, j: usize| {
                (
                    INNER * (-1.0 + 2.0 * i as f64 / SEGMENTS as f64),
                    INNER * (-1.0 + 2.0 * j as f64 / SEGMENTS as f64),
                )
            };
            let (a, b, cc, d) = (c(i, j), c(i + 1, j), c(i + 1, j + 1), c(i, j + 1));
            tris.push([a, b, cc]);
            tris.push([a, cc, d]);
        }
    }
    let mut r = INNER;
    // Rings, until the floor's edge (extent measured from the world origin; the foot point is
    // near it, so the last ring is cut to the extent below).
    while r < extent + foot.0.abs().max(foot.1.abs()) {
        let next = r * GROWTH;
        let (inner, outer) = (boundary(r), boundary(next));
        let n = inner.len();
        for k in 0..n {
            let (a, b) = (inner[k], inner[(k + 1) % n]);
            let (c, d) = (outer[(k + 1) % n], outer[k]);
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
        r = next;
    }
    // To world, cut to the floor's edges and behind the camera.
    let eye = (f64::from(eye.x), f64::from(eye.y), f64::from(eye.z));
    let f = (f64::from(forward.x), f64::from(forward.y), f64::from(forward.z));
    let planes: [&dyn Fn((f64, f64)) -> f64; 5] = [
        &|p| extent - p.0,
        &|p| extent + p.0,
        &|p| extent - p.1,
        &|p| extent + p.1,
        // In front of the plane at half the near distance.
        &|p| (p.0 - eye.0) * f.0 + (0.0 - eye.1) * f.1 + (p.1 - eye.2) * f.2 - 0.5 * f64::from(NEAR),
    ];
    let mut vertices = Vec::new();
    for t in tris {
        let mut poly: Vec<(f64, f64)> = t.iter().map(|p| (p.0 + foot.0, p.1 + foot.1)).collect();
        for plane in planes {
            poly = clip_polygon(&poly, plane);
        }
        for i in 1..poly.len().saturating_sub(1) {
            for p in [poly[0], poly[i], poly[i + 1]] {
                vertices.push(floor_vertex(p.0, p.1));
            }
        }
    }
    let indices = (0..vertices.len() as u32).collect();
    MeshData { label: "floor_rings".into(), vertices, indices }
}

/// The part of a convex polygon where `inside(p) >= 0` (Sutherland–Hodgman, f64).
fn clip_polygon(poly: &[(f64, f64)], inside: &dyn Fn((f64, f64)) -> f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (dp, dq) = (inside(p), inside(q));
        if dp >= 0.0 {
            out.push(p);
        }
        if (dp >= 0.0) != (dq >= 0.0) {
            let s = dp / (dp - dq);
            out.push((p.0 + s * (q.0 - p.0), p.1 + s * (q.1 - p.1)));
        }
    }
    out
}

fn lights() -> Vec<SceneLight> {
    let light = |x: f32, y: f32, z: f32, color: Vec3| SceneLight {
        position: Vec3::new(x, y, z),
        color,
        intensity: 0.3,
        radius: 5.0,
        spot: None,
    };
    vec![
        light(-1.5, 0.5, 1.0, Vec3::new(1.0, 0.8, 0.6)),
        light(1.5, 0.5, 1.0, Vec3::new(0.6, 0.8, 1.0)),
        light(-1.0, 0.8, -2.0, Vec3::new(1.0, 0.5, 0.5)),
        light(1.0, 0.3, -1.0, Vec3::new(0.5, 1.0, 0.6)),
    ]
}

fn floor_material() -> MaterialData {
    MaterialData {
        label: "floor".into(),
        base_color: Color::linear_rgb(0.8, 0.8, 0.8),
        shininess: 32.0,
        specular: 0.5,
        ..MaterialData::default()
    }
}

fn floor_scene(mesh: MeshData, far: f32) -> Scene {
    floor_scene_at(mesh, far, Mat4::IDENTITY)
}

fn floor_scene_at(mesh: MeshData, far: f32, transform: Mat4) -> Scene {
    let material = floor_material();
    Scene {
        name: mesh.label.clone(),
        meshes: vec![Arc::new(mesh)],
        materials: vec![Arc::new(material)],
        instances: vec![SceneInstance { mesh: 0, material: 0, transform }],
        lights: lights(),
        cameras: vec![camera(far)],
        ..Scene::default()
    }
}

/// The floor of [`floor_scene`] shaded on the CPU in f64: the ray through each pixel centre
/// intersected with `y = 0`, Blinn-Phong under [`lights`] with the default ambient and
/// exposure, the ACES fit and the sRGB encoding of the output (`shaders/common/brdf.wgsl`,
/// `shaders/tonemap.wgsl`).
/// `pipeline` with Blinn-Phong shading, the model `analytic_floor` evaluates (in f64, so the
/// reference keeps its precision at 10⁷ units; the PBR model is checked against its twin in
/// `tests/pbr.rs`).
fn settings_for(pipeline: PipelineKind) -> RenderSettings {
    RenderSettings { pipeline, shading: ShadingModel::BlinnPhong, ..RenderSettings::default() }
}

fn analytic_floor(extent: f64, far: f64, settings: &RenderSettings) -> image::RgbaImage {
    type V = [f64; 3];
    let sub = |a: V, b: V| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: V, b: V| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let len = |a: V| dot(a, a).sqrt();
    let scale = |a: V, k: f64| [a[0] * k, a[1] * k, a[2] * k];
    let v = |a: Vec3| [f64::from(a.x), f64::from(a.y), f64::from(a.z)];
    let cam = camera(far as f32);
    let (right, up, back) = (
        v(cam.transform.x_axis.truncate()),
        v(cam.transform.y_axis.truncate()),
        v(cam.transform.z_axis.truncate()),
    );
    let eye = v(EYE);
    let tan = (0.5 * f64::from(cam.projection.fov_y)).tan();
    let aspect = f64::from(SIZE.x) / f64::from(SIZE.y);
    let material = floor_material();
    let albedo = v(material.base_color_linear().truncate());
    let (shininess, specular) = (f64::from(material.shininess), f64::from(material.specular));
    let aces = |x: f64| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let srgb = |c: f64| if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    let clear = settings.clear_color.map(f64::from);
    image::RgbaImage::from_fn(SIZE.x, SIZE.y, |px, py| {
        let ndc_x = (f64::from(px) + 0.5) / f64::from(SIZE.x) * 2.0 - 1.0;
        let ndc_y = 1.0 - (f64::from(py) + 0.5) / f64::from(SIZE.y) * 2.0;
        let dir_view = [ndc_x * tan * aspect, ndc_y * tan, -1.0];
        let dir = [0, 1, 2].map(|i| right[i] * dir_view[0] + up[i] * dir_view[1] + back[i] * dir_view[2]);
        let t = -eye[1] / dir[1];
        // t is the view depth too: the view-space z of `dir` is -1.
        let hit = [eye[0] + t * dir[0], 0.0, eye[2] + t * dir[2]];
        let color = if dir[1] < 0.0 && t <= far && hit[0].abs() <= extent && hit[2].abs() <= extent {
            let n = [0.0, 1.0, 0.0];
            let to_eye = sub(eye, hit);
            let view_dir = scale(to_eye, 1.0 / len(to_eye));
            let mut c = scale(albedo, f64::from(settings.ambient));
            for light in lights() {
                let to_light = sub(v(light.position), hit);
                let d = len(to_light);
                let r = f64::from(light.radius);
                if d >= r {
                    continue;
                }
                let ratio2 = (d / r) * (d / r);
                let window = (1.0 - ratio2 * ratio2).clamp(0.0, 1.0);
                let min_d = f64::from(manylight::math::LIGHT_MIN_DISTANCE);
                let att = window * window / (d * d).max(min_d * min_d);
                let l = scale(to_light, 1.0 / d);
                let n_dot_l = dot(n, l).max(0.0);
                let mut spec = 0.0;
                if n_dot_l > 0.0 {
                    let h = [l[0] + view_dir[0], l[1] + view_dir[1], l[2] + view_dir[2]];
                    let h = scale(h, 1.0 / len(h));
                    spec = specular * dot(n, h).max(0.0).powf(shininess) * n_dot_l;
                }
                let radiance = v(light.color * light.intensity);
                for i in 0..3 {
                    c[i] += (albedo[i] * n_dot_l + spec) * radiance[i] * att;
                }
            }
            c.map(|x| aces(x * f64::from(settings.exposure)))
        } else {
            // The clear colour is written into the HDR target and tone mapped like the rest.
            clear.map(|x| aces(x * f64::from(settings.exposure)))
        };
        let [r, g, b] = color.map(|x| (srgb(x) * 255.0).round() as u8);
        image::Rgba([r, g, b, 255])
    })
}

/// Every (pipeline, layout, codec) the settings allow, with a name.
fn configurations() -> Vec<(String, RenderSettings)> {
    let mut out = Vec::new();
    for pipeline in PipelineKind::ALL {
        let base = settings_for(pipeline);
        // Per-cluster depth bounds (on by default) take the distance the shading computes, not
        // the depth buffer's, which drifts on these triangles (the bounds would drop lights);
        // clustered forward also runs with whole slices.
        if pipeline == PipelineKind::ClusteredForward {
            let mut whole = base;
            whole.clusters.depth_bounds = false;
            out.push((format!("{}_whole_slices", pipeline.name()), whole));
        }
        // Refined light lists (on by default) take the same distances, in boxes much tighter
        // than a cluster; these shade from the cluster lists alone.
        if matches!(pipeline, PipelineKind::ClusteredForward | PipelineKind::ForwardPlus) {
            let mut unrefined = base;
            unrefined.clusters.refined_lists = false;
            out.push((format!("{}_unrefined", pipeline.name()), unrefined));
        }
        if pipeline == PipelineKind::ClusteredDeferred {
            let mut unrefined = base;
            unrefined.clusters.refined_lists = false;
            out.push((format!("{}_full_unrefined", pipeline.name()), unrefined));
        }
        if !matches!(pipeline, PipelineKind::ClusteredDeferred | PipelineKind::LightVolumes) {
            out.push((pipeline.name().to_string(), base));
            continue;
        }
        for gbuffer in GBufferLayout::ALL {
            for normal_codec in NormalCodec::ALL {
                if !gbuffer.supports(normal_codec)
                    || (!gbuffer.uses_codec() && normal_codec != NormalCodec::Octa16)
                {
                    continue;
                }
                let name = if gbuffer.uses_codec() {
                    format!("{}_{}_{}", pipeline.name(), gbuffer.name(), normal_codec.name())
                } else {
                    format!("{}_{}", pipeline.name(), gbuffer.name())
                };
                out.push((name, RenderSettings { gbuffer, normal_codec, ..base }));
            }
        }
    }
    out
}

/// The tolerance of a configuration against naive forward on ordinary scenes
/// (`tests/deferred.rs`, `tests/image.rs`).
fn tolerance(settings: &RenderSettings) -> Tolerance {
    let deferred = settings.pipeline.is_deferred();
    match (deferred, settings.gbuffer, settings.normal_codec) {
        (true, GBufferLayout::Compact, _) => support::COMPACT,
        (true, GBufferLayout::Packed, NormalCodec::Xyz) => Tolerance { mean: 0.005, p99: 0.08 },
        _ => STRICT,
    }
}

/// Half-size of the floor: its corners lie 10⁷ units from pixels two units from the camera.
const HUGE: f64 = 1e7;
/// Far plane beyond the whole floor (no far-plane clipping).
const FAR: f32 = 1e8;

/// The reference is right: the ring floor drawn by naive forward equals the analytic floor to
/// one 8-bit step (the rounding of the f16 HDR target and of the output).
#[test]
fn ring_floor_matches_the_analytic_floor() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward);
    let rings = render(floor_scene(ring_floor(HUGE), FAR), SIZE, 0, naive);
    let analytic = analytic_floor(HUGE, f64::from(FAR), &naive);
    let worst = worst_channel(&analytic, &rings.image);
    let s = support::flip(&analytic, &rings.image);
    eprintln!("rings vs analytic: FLIP mean {:.5}, p99 {:.5}, worst channel {worst}", s.mean, s.p99);
    assert!(worst <= 2, "ring floor vs analytic floor: worst channel {worst}/255");
}

/// Every pipeline, layout and codec draws the one-quad floor like the ring floor, within the
/// tolerance it is held to on ordinary scenes, with no NaN or infinite pixel (`render`).
/// Before each pass shaded `surface_point`, naive forward measured FLIP mean 0.134 here and
/// the Compact layout 0.218.
#[test]
fn huge_floor_matches_the_tessellated_reference_in_every_pipeline() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward);
    let reference = render(floor_scene(ring_floor(HUGE), FAR), SIZE, 0, naive);
    for (name, settings) in configurations() {
        let frame = render(floor_scene(quad_floor(HUGE), FAR), SIZE, 0, settings);
        let passes = frame.stats.last.as_ref().expect("report").pass_names();
        if settings.pipeline == PipelineKind::LightVolumes {
            assert!(passes.contains(&"light_volumes"), "{name}: {passes:?}");
        } else if settings.pipeline == PipelineKind::ClusteredDeferred {
            assert!(passes.contains(&"deferred_lighting"), "{name}: {passes:?}");
        } else if settings.pipeline == PipelineKind::TiledDeferred {
            assert!(passes.contains(&"tiled_deferred"), "{name}: {passes:?}");
        }
        let s = assert_similar(
            &format!("huge_floor_{name}"),
            &reference.image,
            &frame.image,
            tolerance(&settings),
        );
        let worst = worst_channel(&reference.image, &frame.image);
        eprintln!("huge floor {name}: FLIP mean {:.5}, p99 {:.5}, worst channel {worst}", s.mean, s.p99);
    }
}

/// Without a far plane nothing is clipped however far the floor reaches (it runs to the
/// horizon at 10⁷, where a finite stand-in of near × 10⁴ would have cut it at 1 000): the ring
/// floor matches the analytic floor with `t ≤ ∞`, and every pipeline, layout and codec draws
/// the one-quad floor like it. The lights reach 16 units, so the cluster grid ends there and
/// the floor beyond lies in its last slice.
#[test]
fn an_infinite_projection_clips_nothing_in_every_pipeline() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward);
    let reference = render(floor_scene(ring_floor(HUGE), f32::INFINITY), SIZE, 0, naive);
    let analytic = analytic_floor(HUGE, f64::INFINITY, &naive);
    // The frame shows floor beyond 1 000 units: a far plane there would change pixels.
    let clipped = analytic_floor(HUGE, f64::from(NEAR) * 1e4, &naive);
    assert!(worst_channel(&analytic, &clipped) > 2, "the view shows no floor beyond 1 000 units");
    let worst = worst_channel(&analytic, &reference.image);
    assert!(worst <= 2, "infinite ring floor vs analytic floor: worst channel {worst}/255");
    for (name, settings) in configurations() {
        let frame = render(floor_scene(quad_floor(HUGE), f32::INFINITY), SIZE, 0, settings);
        let report = frame.stats.last.as_ref().expect("report");
        assert_eq!(report.sanitized_cameras, 0, "{name}: an infinite projection is kept as it is");
        let s = assert_similar(
            &format!("infinite_floor_{name}"),
            &reference.image,
            &frame.image,
            tolerance(&settings),
        );
        eprintln!("infinite floor {name}: FLIP mean {:.5}, p99 {:.5}", s.mean, s.p99);
    }
}

/// Largest difference of one 8-bit colour channel between two images.
fn worst_channel(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p.0[c].abs_diff(q.0[c])))
        .max()
        .unwrap_or(0)
}

/// Prints FLIP mean, p99 and the worst channel of every configuration on the quad floor
/// against the ring floor drawn by naive forward, at several extents and far planes.
/// `MANYLIGHT_LARGE_EXTENTS` (comma-separated) and `MANYLIGHT_LARGE_FAR` choose them.
#[test]
#[ignore = "measurement: prints a table"]
fn measure_large_floor() {
    let _gpu = gpu();
    let extents: Vec<f64> = std::env::var("MANYLIGHT_LARGE_EXTENTS")
        .unwrap_or_else(|_| "10,1e4,1e7".into())
        .split(',')
        .map(|s| s.trim().parse().expect("extent"))
        .collect();
    let far: f32 = std::env::var("MANYLIGHT_LARGE_FAR").map(|s| s.parse().expect("far")).unwrap_or(1e8);
    let only = std::env::var("MANYLIGHT_LARGE_ONLY").ok();
    let naive = settings_for(PipelineKind::NaiveForward);
    let out = support::output_dir();
    for extent in extents {
        let reference = render(floor_scene(ring_floor(extent), far), SIZE, 0, naive);
        let _ = reference.image.save(out.join(format!("large_{extent:e}_reference.png")));
        let analytic = analytic_floor(extent, f64::from(far), &naive);
        let _ = analytic.save(out.join(format!("large_{extent:e}_analytic.png")));
        let s = support::flip(&analytic, &reference.image);
        eprintln!(
            "extent {extent:e} rings vs analytic: FLIP mean {:.5} p99 {:.5} worst channel {}",
            s.mean,
            s.p99,
            worst_channel(&analytic, &reference.image)
        );
        for (name, settings) in configurations() {
            if only.as_deref().is_some_and(|o| !name.contains(o)) {
                continue;
            }
            let frame = render(floor_scene(quad_floor(extent), far), SIZE, 0, settings);
            let _ = frame.image.save(out.join(format!("large_{extent:e}_{name}.png")));
            let s = support::flip(&reference.image, &frame.image);
            let worst = worst_channel(&reference.image, &frame.image);
            eprintln!(
                "extent {extent:e} far {far:e} {name:40} FLIP mean {:.5} p99 {:.5} worst channel {worst}",
                s.mean, s.p99
            );
            if settings.pipeline == PipelineKind::NaiveForward {
                let rings = render(floor_scene(ring_floor(extent), far), SIZE, 0, settings);
                let s = support::flip(&reference.image, &rings.image);
                eprintln!("extent {extent:e} rings vs rings {:.5}", s.mean);
            }
        }
    }
}

#[test]
#[ignore = "measurement: prints a table"]
fn measure_tilted_floor() {
    let _gpu = gpu();
    let tilt = Mat4::from_rotation_x(0.3) * Mat4::from_rotation_z(0.2);
    let inv = tilt.inverse();
    let eye = inv.transform_point3(EYE);
    let forward = inv.transform_vector3((TARGET - EYE).normalize());
    let naive = settings_for(PipelineKind::NaiveForward);
    for extent in [10.0, 1e4, 1e7] {
        let reference =
            render(floor_scene_at(ring_floor_seen_from(extent, eye, forward), 1e8, tilt), SIZE, 0, naive);
        for (name, settings) in configurations() {
            let frame = render(floor_scene_at(quad_floor(extent), 1e8, tilt), SIZE, 0, settings);
            let s = support::flip(&reference.image, &frame.image);
            let worst = worst_channel(&reference.image, &frame.image);
            eprintln!(
                "tilted extent {extent:e} {name:40} FLIP mean {:.5} p99 {:.5} worst channel {worst}",
                s.mean, s.p99
            );
        }
    }
}

//! The very large floor and its references, shared by `manylight report --large-floor` and
//! `tests/large_surfaces.rs` (which includes this file): a floor quad with corners at ±extent
//! under four point lights, seen from 2 units up; the same floor tessellated into rings that
//! grow with the distance from the camera's foot point (no triangle's vertices lie much farther
//! from the camera than the pixels it covers); and the floor shaded analytically on the CPU.
//!
//! Plain functions of the scene crates only (no `crate::` paths), so both crates compile it.

use glam::{Mat4, UVec2, Vec3};
use manylight_core::codec::NormalCodec;
use manylight_core::{Color, MaterialData, MeshData, Projection, ShadingModel, Vertex};
use manylight_render::{GBufferLayout, PipelineKind, RenderSettings};
use manylight_scene::{Scene, SceneCamera, SceneInstance, SceneLight, camera_looking_at};
use std::sync::Arc;

/// Where the camera stands: 2 units above the floor, 6 from the origin.
pub const EYE: Vec3 = Vec3::new(0.0, 2.0, 6.0);
/// What the camera looks at: the origin, on the floor.
pub const TARGET: Vec3 = Vec3::new(0.0, 0.0, 0.0);
/// The camera's near plane.
pub const NEAR: f32 = 0.1;
/// The tilt of [`tilted_scene`]: 0.3 rad about x, then 0.2 about z.
pub const TILT: [f32; 2] = [0.3, 0.2];

/// The camera at [`EYE`] looking at [`TARGET`] (60° vertical field of view) with far plane
/// `far` (infinite allowed).
pub fn camera(far: f32) -> SceneCamera {
    SceneCamera {
        transform: camera_looking_at(EYE, TARGET),
        projection: Projection::perspective(60f32.to_radians(), NEAR, far),
    }
}

fn floor_vertex(x: f64, z: f64) -> Vertex {
    Vertex { position: [x as f32, 0.0, z as f32], normal: [0.0, 1.0, 0.0], ..Vertex::default() }
}

/// The floor as one quad with corners at ±`extent`.
pub fn quad_floor(extent: f64) -> MeshData {
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
pub fn ring_floor(extent: f64) -> MeshData {
    ring_floor_seen_from(extent, EYE, (TARGET - EYE).normalize())
}

/// [`ring_floor`] for a camera at `eye` looking along `forward`, both in the floor's own
/// coordinates (the floor is `y = 0` there).
pub fn ring_floor_seen_from(extent: f64, eye: Vec3, forward: Vec3) -> MeshData {
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

/// Four coloured point lights of radius 5 near the origin, just above the floor.
pub fn lights() -> Vec<SceneLight> {
    let light = |x: f32, y: f32, z: f32, color: Vec3| SceneLight {
        position: Vec3::new(x, y, z),
        color,
        intensity: 0.3,
        radius: 5.0,
        shape: manylight_core::LightShape::Point,
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

/// `mesh` as the floor (placed by `transform`) under [`lights`], seen by [`camera`]`(far)`.
pub fn floor_scene_at(mesh: MeshData, far: f32, transform: Mat4) -> Scene {
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

/// [`floor_scene_at`] with the floor in place (`y = 0`).
pub fn floor_scene(mesh: MeshData, far: f32) -> Scene {
    floor_scene_at(mesh, far, Mat4::IDENTITY)
}

/// The floor of [`tilted_scene`] placed in the world: turned by [`TILT`].
pub fn tilt() -> Mat4 {
    Mat4::from_rotation_x(TILT[0]) * Mat4::from_rotation_z(TILT[1])
}

/// The floor turned by [`tilt`] as one quad (`rings: false`) or as rings seen from the
/// camera (`rings: true`), out to ±`extent`, with far plane `far`.
pub fn tilted_scene(extent: f64, far: f32, rings: bool) -> Scene {
    let inv = tilt().inverse();
    let mesh = if rings {
        let eye = inv.transform_point3(EYE);
        let forward = inv.transform_vector3((TARGET - EYE).normalize());
        ring_floor_seen_from(extent, eye, forward)
    } else {
        quad_floor(extent)
    };
    floor_scene_at(mesh, far, tilt())
}

/// `pipeline` with Blinn-Phong shading, the model [`analytic_floor`] evaluates (in f64, so the
/// reference keeps its precision at 10⁷ units), on `base`'s other settings.
pub fn settings_for(pipeline: PipelineKind, base: RenderSettings) -> RenderSettings {
    RenderSettings { pipeline, shading: ShadingModel::BlinnPhong, ..base }
}

/// The floor of [`floor_scene`] out to ±`extent` at `size` shaded on the CPU in f64: the ray
/// through each pixel centre intersected with `y = 0`, Blinn-Phong under [`lights`] with
/// `settings`' ambient, exposure and clear colour, the ACES fit and the sRGB encoding of the
/// output (`shaders/common/brdf.wgsl`, `shaders/tonemap.wgsl`).
pub fn analytic_floor(extent: f64, far: f64, size: UVec2, settings: &RenderSettings) -> image::RgbaImage {
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
    let aspect = f64::from(size.x) / f64::from(size.y);
    let material = floor_material();
    let albedo = v(material.base_color_linear().truncate());
    let (shininess, specular) = (f64::from(material.shininess), f64::from(material.specular));
    let aces = |x: f64| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let srgb = |c: f64| if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    let clear = settings.clear_color.map(f64::from);
    image::RgbaImage::from_fn(size.x, size.y, |px, py| {
        let ndc_x = (f64::from(px) + 0.5) / f64::from(size.x) * 2.0 - 1.0;
        let ndc_y = 1.0 - (f64::from(py) + 0.5) / f64::from(size.y) * 2.0;
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
                let min_d = f64::from(manylight_core::LIGHT_MIN_DISTANCE);
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

/// Every (pipeline, layout, codec) the settings allow, with a name, Blinn-Phong on `base`'s
/// other settings.
pub fn configurations(base: RenderSettings) -> Vec<(String, RenderSettings)> {
    let mut out = Vec::new();
    for pipeline in PipelineKind::ALL {
        let base = settings_for(pipeline, base);
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

/// Largest difference of one 8-bit colour channel between two images.
pub fn worst_channel(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p.0[c].abs_diff(q.0[c])))
        .max()
        .unwrap_or(0)
}

//! Inputs at and past the device's limits, and transforms that must not poison a frame: each
//! renders, or is refused with an error naming the limit, or is skipped and counted in the
//! frame's report. Real device (lavapipe in CI); a missing adapter fails.

mod support;

use manylight::app::headless::render_headless;
use manylight::math::{MaterialData, MeshData, TextureData, Vertex};
use manylight::prelude::*;
use manylight::render::GpuContext;
use std::sync::Arc;
use support::{STRICT, assert_finite, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(96, 64);

/// A quad facing the default scene's camera, 2 units in front of it, as the last four of
/// `vertex_count` vertices (the others are never referenced).
fn quad_in_front(vertex_count: usize) -> MeshData {
    let camera = default_scene().camera_or_fit(SIZE.x as f32 / SIZE.y as f32).transform;
    let corner = |x: f32, y: f32| camera.transform_point3(Vec3::new(x, y, -2.0));
    let normal = camera.transform_vector3(Vec3::Z).normalize();
    let mut vertices =
        vec![Vertex { position: [0.0; 3], normal: [0.0, 1.0, 0.0], ..Vertex::default() }; vertex_count - 4];
    for (x, y) in [(-0.4, -0.3), (0.4, -0.3), (0.4, 0.3), (-0.4, 0.3)] {
        vertices.push(Vertex {
            position: corner(x, y).to_array(),
            normal: normal.to_array(),
            ..Vertex::default()
        });
    }
    let first = (vertex_count - 4) as u32;
    let indices = [0, 1, 2, 0, 2, 3].map(|i| first + i).to_vec();
    MeshData { label: format!("quad_{vertex_count}"), vertices, indices }
}

fn render_with(mesh: MeshData) -> Result<manylight::app::headless::HeadlessFrame, String> {
    let mesh = Arc::new(mesh);
    render_headless(SIZE, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
            commands.spawn((
                Transform::IDENTITY,
                Mesh3d(mesh.clone()),
                Material(Arc::new(MaterialData {
                    base_color: Color::linear_rgb(0.9, 0.2, 0.1),
                    ..Default::default()
                })),
            ));
        });
    })
}

#[test]
fn a_mesh_of_more_than_2_pow_24_vertices_renders_or_is_refused_naming_the_limit() {
    let _gpu = gpu();
    let count = (1usize << 24) + 4;
    let bytes = (count * std::mem::size_of::<Vertex>()) as u64;
    let limit = GpuContext::headless().expect("adapter").device.limits().max_buffer_size;
    let small = render_with(quad_in_front(4)).expect("the small quad renders");
    match render_with(quad_in_front(count)) {
        Ok(big) => {
            eprintln!("{count} vertices ({bytes} bytes, max_buffer_size {limit}): rendered");
            assert!(bytes <= limit, "{bytes} bytes rendered past max_buffer_size {limit}");
            assert_finite(&big);
            // Indices past 2^24 reach the same vertices as the small mesh's 0..4.
            assert_similar("limits_2_pow_24_vertices", &small.image, &big.image, STRICT);
            assert!(
                flip_differs(&small.image, &render_without_quad()),
                "the quad must show in the image for the comparison to mean anything"
            );
        }
        Err(message) => {
            eprintln!("{count} vertices: refused: {message}");
            assert!(bytes > limit, "refused below the limit: {message}");
            assert!(message.contains("max_buffer_size") && message.contains(&limit.to_string()), "{message}");
        }
    }
}

fn render_without_quad() -> image::RgbaImage {
    render_headless(SIZE, 1, |app| {
        app.add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
        });
    })
    .expect("renders")
    .image
}

fn flip_differs(a: &image::RgbaImage, b: &image::RgbaImage) -> bool {
    support::flip(a, b).mean > 0.01
}

#[test]
fn a_texture_larger_than_the_device_allows_is_refused_naming_the_limit() {
    let _gpu = gpu();
    let limit = GpuContext::headless().expect("adapter").max_texture_size();
    // One row, one pixel wider than the device allows: small in memory, past the limit.
    let texture = Arc::new(TextureData {
        label: "wide.png".into(),
        width: limit + 1,
        height: 1,
        rgba8: vec![255; (limit as usize + 1) * 4],
        srgb: true,
    });
    let result = render_headless(SIZE, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
            commands.spawn((
                Transform::IDENTITY,
                Mesh3d(Arc::new(quad_in_front(4))),
                Material(Arc::new(MaterialData {
                    base_color_texture: Some(texture.clone().into()),
                    ..Default::default()
                })),
            ));
        });
    });
    let message = result.expect_err("refused");
    assert!(message.contains("wide.png") && message.contains(&limit.to_string()), "{message}");
}

#[test]
fn nan_zero_scale_and_flattening_transforms_are_skipped_or_drawn_and_counted() {
    let _gpu = gpu();
    let frame = render_headless(SIZE, 1, |app| {
        app.add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
            let mesh = Arc::new(quad_in_front(4));
            let material = Arc::new(MaterialData::default());
            let mut spawn = |transform: Transform| {
                commands.spawn((transform, Mesh3d(mesh.clone()), Material(material.clone())));
            };
            spawn(Transform::from_xyz(f32::NAN, 0.0, 0.0));
            spawn(Transform { scale: Vec3::new(1.0, f32::INFINITY, 1.0), ..Transform::IDENTITY });
            spawn(Transform { scale: Vec3::ZERO, ..Transform::IDENTITY });
            spawn(Transform { scale: Vec3::new(0.0, 0.0, 1.0), ..Transform::IDENTITY });
            // Flattened to a plane (one zero axis): still drawn, with finite normals.
            spawn(Transform { scale: Vec3::new(1.0, 0.0, 1.0), ..Transform::IDENTITY });
        });
    })
    .expect("renders");
    assert_finite(&frame);
    let report = frame.stats.last.expect("a report");
    assert_eq!(report.invalid_instances, 2, "NaN and infinite transforms");
    assert_eq!(report.collapsed_instances, 2, "zero scale on three and on two axes");
    assert_eq!(
        report.instance_count as usize,
        default_scene().instances.len() + 1,
        "the flattened one is drawn"
    );
}

/// A glTF node tree whose parent has scale 0 (its child's mesh collapses to a point) and a
/// sibling flattened to a plane: loaded, rendered, counted, and free of NaN pixels.
#[test]
fn a_gltf_parent_with_scale_zero_collapses_its_children_and_is_counted() {
    let _gpu = gpu();
    let dir = support::output_dir().join("limits_parent_scale");
    std::fs::create_dir_all(&dir).expect("output dir");
    let path = dir.join("parent_scale_zero.gltf");
    std::fs::write(&path, PARENT_SCALE_ZERO_GLTF).expect("write the fixture");
    let scene = manylight::scene::load_gltf(&path, &Default::default()).expect("a valid file loads");
    assert_eq!(scene.instances.len(), 2);
    let frame = support::render_scene(scene, SIZE, 4, Default::default());
    let report = frame.stats.last.expect("a report");
    assert_eq!(report.invalid_instances + report.collapsed_instances, 1, "{report:?}");
    assert_eq!(report.instance_count, 1, "the flattened sibling is drawn");
}

/// One triangle (positions only) drawn by the child of a scale-0 node and by a node scaled to
/// a plane.
const PARENT_SCALE_ZERO_GLTF: &str = r#"{
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 2]}],
  "nodes": [
    {"scale": [0, 0, 0], "children": [1]},
    {"mesh": 0, "translation": [0, 0, -3]},
    {"mesh": 0, "scale": [1, 1, 0], "translation": [0, 0, -3]}
  ],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [-1, -1, 0], "max": [1, 1, 0]}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "buffers": [{"byteLength": 36,
               "uri": "data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAAAAAAAAgD8AAAAA"}]
}"#;

//! Small valid fixtures (`tests/data`) exercising loader features one by one.

use glam::{Mat4, Vec3};
use manylight_scene::{LoadOptions, load_gltf};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

#[test]
fn a_utf8_bom_before_the_json_is_accepted() {
    let s = load_gltf(&fixture("bom_ok.gltf"), &LoadOptions::default()).expect("BOM is accepted");
    assert_eq!(s.instances.len(), 1);
    assert_eq!(s.meshes[0].triangle_count(), 1);
    // Normals were missing and are generated: the triangle is CCW in XY, so +Z.
    for v in &s.meshes[0].vertices {
        assert!((Vec3::from(v.normal) - Vec3::Z).length() < 1e-6);
    }
    s.validate().expect("valid");
}

#[test]
fn a_16_bit_png_texture_is_converted_to_8_bit_srgb() {
    let s = load_gltf(&fixture("png16.gltf"), &LoadOptions::default()).expect("loads");
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    assert_eq!(m.label, "png16");
    assert_eq!(m.base_color_linear(), glam::Vec4::new(1.0, 0.5, 1.0, 1.0));
    assert_eq!(m.shading, None);
    // roughness 0.5: 2 / 0.0625 - 2 = 30; metallic 0: specular 0.04.
    assert!((m.shininess - 30.0).abs() < 1e-3, "{}", m.shininess);
    assert!((m.specular - 0.04).abs() < 1e-6);
    let t = m.base_color_texture.as_ref().map(|t| &t.image).expect("texture");
    assert!(t.srgb);
    assert_eq!((t.width, t.height), (4, 4));
    assert_eq!(t.rgba8.len(), 4 * 4 * 4);
    assert_eq!(&t.rgba8[..4], &[255, 128, 0, 255]);
    assert_eq!(s.meshes[0].vertices[1].uv, [1.0, 0.0]);
}

#[test]
fn a_glb_with_an_embedded_png_loads() {
    let s = load_gltf(&fixture("triangle.glb"), &LoadOptions::default()).expect("loads");
    let t = s.materials[0].base_color_texture.as_ref().map(|t| &t.image).expect("texture");
    assert_eq!((t.width, t.height), (2, 2));
    assert_eq!(&t.rgba8[..4], &[0, 255, 0, 255]);
    s.validate().expect("valid");
}

#[test]
fn hierarchy_lights_and_cameras_without_a_scene_list() {
    let s = load_gltf(&fixture("features.gltf"), &LoadOptions::default()).expect("loads");
    s.validate().expect("valid");
    // Root nodes 0 and 3; node 3's only primitive is POINTS (skipped), node 1 has a triangle.
    assert_eq!(s.instances.len(), 1);
    let parent = Mat4::from_scale_rotation_translation(
        Vec3::splat(2.0),
        glam::Quat::IDENTITY,
        Vec3::new(10.0, 0.0, 0.0),
    );
    let expected = parent * Mat4::from_translation(Vec3::Y);
    assert!(s.instances[0].transform.abs_diff_eq(expected, 1e-6));
    // The node tree is kept: composing the local transforms from the root gives the
    // instance's world transform.
    let node = s.nodes.iter().position(|n| n.instances == [0]).expect("the instance's node");
    let (mut world, mut at) = (Mat4::IDENTITY, Some(node));
    while let Some(i) = at {
        world = s.nodes[i].local * world;
        at = s.nodes[i].parent;
    }
    assert!(s.nodes[node].parent.is_some(), "{:?}", s.nodes);
    assert!(world.abs_diff_eq(expected, 1e-6), "{world:?}");
    // The non-indexed triangle got sequential indices.
    assert_eq!(s.meshes[s.instances[0].mesh].indices, vec![0, 1, 2]);
    // The point light sits at node 2's world position; the spot light at node 3's (the
    // origin), pointing down its -Z with the specification's default cone (0 to pi/4).
    assert_eq!(s.lights.len(), 2);
    let spot = s.lights[1];
    assert_eq!(spot.position, Vec3::ZERO);
    assert_eq!(spot.intensity, 10.0);
    let manylight_core::LightShape::Spot(cone) = spot.shape else { panic!("a spot light: {spot:?}") };
    assert_eq!(cone.direction, Vec3::NEG_Z);
    assert_eq!((cone.inner_angle, cone.outer_angle), (0.0, std::f32::consts::FRAC_PI_4));
    // The directional light hangs from node 0 (no rotation): it shines down -Z.
    assert_eq!(s.directional_lights.len(), 1);
    let sun = s.directional_lights[0];
    assert_eq!(sun.direction, Vec3::NEG_Z);
    assert_eq!((sun.color, sun.illuminance), (Vec3::new(1.0, 0.9, 0.8), 3.0));
    let l = s.lights[0];
    assert!((l.position - Vec3::new(10.0, 0.0, 10.0)).length() < 1e-5, "{:?}", l.position);
    assert_eq!(l.intensity, 4.0);
    assert_eq!(l.color, Vec3::new(1.0, 0.5, 0.25));
    let cutoff = manylight_core::attenuation::RANGELESS_LIGHT_CUTOFF;
    assert_eq!(l.radius, manylight_core::radius_for_intensity(4.0, cutoff));
    // The camera: znear 0.05, no zfar (infinite), scale removed from the transform.
    assert_eq!(s.cameras.len(), 1);
    let c = s.cameras[0];
    assert_eq!(c.projection.near, 0.05);
    assert!(c.projection.is_infinite(), "{:?}", c.projection);
    assert!((c.projection.fov_y - 0.8).abs() < 1e-6);
    let (scale, _, translation) = c.transform.to_scale_rotation_translation();
    assert!((scale - Vec3::ONE).length() < 1e-5);
    assert!((translation - Vec3::new(10.0, 0.0, 10.0)).length() < 1e-5);
    // Rotated 90 degrees about Y: the camera looks down world -X.
    let forward = c.transform.transform_vector3(Vec3::NEG_Z);
    assert!((forward - Vec3::NEG_X).length() < 1e-5, "{forward:?}");
}

#[test]
fn extras_of_any_json_type_are_accepted() {
    // glTF allows any JSON value as `extras` (objects are only recommended).
    let s = load_gltf(&fixture("extras_any_type.gltf"), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.instances.len(), 1);
    s.validate().expect("valid");
}

#[test]
fn an_infinite_camera_with_a_huge_znear_loads_with_a_finite_matrix() {
    // znear 3.4e38 without zfar: once refused, because the old finite stand-in for the missing
    // far plane (znear × 10⁴) overflowed; the infinite projection needs no far plane at all.
    let s = load_gltf(&fixture("huge_znear.gltf"), &LoadOptions::default()).expect("loads");
    let c = s.cameras[0];
    assert_eq!(c.projection.near, 3.4e38);
    assert!(c.projection.is_infinite(), "{:?}", c.projection);
    assert!(c.projection.matrix(1.0).is_finite(), "{:?}", c.projection.matrix(1.0));
}

#[test]
fn an_orthographic_camera_loads_as_one() {
    // ymag is half the height; znear 0 (allowed) moves to zfar × 10⁻⁶, as the renderer needs a
    // positive near plane.
    let s = load_gltf(&fixture("orthographic_camera.gltf"), &LoadOptions::default()).expect("loads");
    let c = s.cameras[0];
    assert_eq!(c.projection.kind, manylight_core::ProjectionKind::Orthographic { height: 4.0 });
    assert_eq!((c.projection.near, c.projection.far), (50.0 * 1e-6, 50.0));
    assert_eq!(c.transform.w_axis.truncate(), Vec3::new(0.0, 0.0, 5.0));
    assert!(c.projection.matrix(1.5).is_finite());
}

/// `ymag` 3e38 makes a view height of 6e38, infinite in `f32`: refused by name instead of
/// silently rendered with a height of 1.
#[test]
fn an_orthographic_camera_too_tall_for_f32_is_refused() {
    let text = std::fs::read_to_string(fixture("orthographic_camera.gltf")).expect("fixture");
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    json["cameras"][0]["orthographic"]["ymag"] = serde_json::json!(3e38);
    let dir = std::env::temp_dir().join(format!("manylight_ortho_ymag_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("huge_ymag.gltf");
    std::fs::write(&path, json.to_string()).expect("write");
    let error = load_gltf(&path, &LoadOptions::default()).expect_err("refused");
    let _ = std::fs::remove_dir_all(&dir);
    let message = error.to_string();
    assert!(message.contains("huge_ymag.gltf") && message.contains("MAX_ORTHOGRAPHIC_HEIGHT"), "{message}");
}

// Files the glTF 2.0 specification (and the Khronos validator) allow, one family per test.

/// Loads fixture `name`, panicking with the error's message.
fn load_ok(name: &str) -> manylight_scene::Scene {
    let s = load_gltf(&fixture(name), &LoadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
    s.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    s
}

/// The world-space positions of instance `i`'s vertices.
fn world_positions(s: &manylight_scene::Scene, i: usize) -> Vec<Vec3> {
    let instance = &s.instances[i];
    let mesh = &s.meshes[instance.mesh];
    mesh.vertices.iter().map(|v| instance.transform.transform_point3(Vec3::from(v.position))).collect()
}

fn assert_near<const N: usize>(found: &[[f32; N]], expected: &[[f32; N]], what: &str) {
    assert_eq!(found.len(), expected.len(), "{what}");
    for (f, e) in found.iter().zip(expected) {
        assert!(f.iter().zip(e).all(|(a, b)| (a - b).abs() < 1e-5), "{what}: {found:?} != {expected:?}");
    }
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn integers_written_with_a_zero_fraction_are_integers() {
    let s = load_ok("integers_as_floats.gltf");
    assert_eq!(s.instances.len(), 1);
    assert_eq!(s.meshes[0].indices, vec![0, 1, 2]);
    let found: Vec<[f32; 3]> = world_positions(&s, 0).iter().map(|p| p.to_array()).collect();
    assert_near(&found, &TRIANGLE.map(|p| [p[0], p[1], p[2] + 2.0]), "positions");
}

#[test]
fn extras_of_any_type_are_accepted_on_every_object() {
    let s = load_ok("extras_everywhere.gltf");
    assert_eq!((s.instances.len(), s.lights.len(), s.cameras.len()), (1, 1, 1));
    assert_eq!(s.lights[0].intensity, 2.0);
    assert_eq!(s.cameras[0].projection.far, 50.0);
    let t = s.materials[0].base_color_texture.as_ref().map(|t| &t.image).expect("texture");
    assert_eq!(&t.rgba8[..4], &[0, 0, 255, 255]);
}

#[test]
fn a_scene_without_nodes_is_empty() {
    let s = load_ok("scene_without_nodes.gltf");
    assert!(s.instances.is_empty() && s.meshes.is_empty() && s.lights.is_empty());
}

#[test]
fn animation_channels_without_a_target_node_are_ignored() {
    let s = load_ok("animation_channel_without_node.gltf");
    assert_eq!(s.instances.len(), 1);
    assert_eq!(s.instances[0].transform, Mat4::IDENTITY);
}

#[test]
fn data_uris_without_base64_are_percent_decoded() {
    let s = load_ok("data_uri_percent.gltf");
    assert_eq!(s.meshes[0].indices, vec![0, 1, 2]);
    let found: Vec<[f32; 3]> = s.meshes[0].vertices.iter().map(|v| v.position).collect();
    assert_near(&found, &TRIANGLE, "positions");
    let t = s.materials[0].base_color_texture.as_ref().map(|t| &t.image).expect("texture");
    assert_eq!((t.width, t.height, &t.rgba8[..]), (1, 1, &[255, 0, 0, 255][..]));
}

#[test]
fn a_buffer_without_uri_that_nothing_reads_is_accepted() {
    let s = load_ok("unused_buffer_without_uri.gltf");
    assert_eq!(s.instances.len(), 1);
    // In a GLB too, besides buffer 0 (the binary chunk).
    let s = load_ok("unused_buffer_without_uri.glb");
    assert_eq!((s.instances.len(), s.meshes[0].indices.len()), (1, 3));
}

#[test]
fn a_glb_may_have_buffers_besides_its_binary_chunk() {
    let s = load_ok("several_buffers.glb");
    let mesh = &s.meshes[0];
    assert_eq!(mesh.indices, vec![0, 1, 2]); // buffer 1: an external file
    let found: Vec<[f32; 3]> = mesh.vertices.iter().map(|v| v.position).collect();
    assert_near(&found, &TRIANGLE, "positions (buffer 0, the binary chunk)");
    let uvs: Vec<[f32; 2]> = mesh.vertices.iter().map(|v| v.uv).collect();
    assert_near(&uvs, &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], "uvs (buffer 2, a data URI)");
}

#[test]
fn quantized_attributes_are_dequantised() {
    let s = load_ok("quantized.gltf");
    assert_eq!(s.instances.len(), 4);
    let positions: [[[f32; 3]; 3]; 4] = [
        // SHORT, node scale 0.001.
        [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        // Normalized UNSIGNED_BYTE (255 is 1), node scale 2 and translation (5, 0, 0).
        [[5.0, 0.0, 0.0], [7.0, 0.0, 0.0], [5.0, 2.0, 0.0]],
        // BYTE, node translation (0, 5, 0).
        [[-2.0, 5.0, 0.0], [2.0, 5.0, 0.0], [0.0, 8.0, 0.0]],
        // Normalized SHORT (-32768 clamps to -1), node translation (0, 0, 5).
        [[-1.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]],
    ];
    let normals: [[[f32; 3]; 3]; 4] = [
        [[0.0, 0.0, 1.0]; 3],                                 // normalized BYTE
        [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]], // normalized SHORT, -32768 is -1
        [[0.0, 0.0, 1.0]; 3],                                 // none: generated
        [[0.0, 0.0, 1.0]; 3],
    ];
    let uvs: [[[f32; 2]; 3]; 4] = [
        [[0.0, 0.0], [1.0, 0.0], [0.0, 32768.0 / 65535.0]], // normalized UNSIGNED_SHORT
        [[0.0, 0.0], [1.0, 0.0], [0.0, -1.0]],              // normalized BYTE, -128 is -1
        [[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]],               // UNSIGNED_BYTE
        [[0.0, 0.0], [1.0, 0.0], [-1.0, 1.0]],              // SHORT
    ];
    for i in 0..4 {
        let found: Vec<[f32; 3]> = world_positions(&s, i).iter().map(|p| p.to_array()).collect();
        assert_near(&found, &positions[i], &format!("triangle {i} positions"));
        let mesh = &s.meshes[s.instances[i].mesh];
        let found: Vec<[f32; 3]> = mesh.vertices.iter().map(|v| v.normal).collect();
        assert_near(&found, &normals[i], &format!("triangle {i} normals"));
        let found: Vec<[f32; 2]> = mesh.vertices.iter().map(|v| v.uv).collect();
        assert_near(&found, &uvs[i], &format!("triangle {i} uvs"));
    }
}

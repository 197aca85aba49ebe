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
    assert_eq!(m.base_color, glam::Vec4::new(1.0, 0.5, 1.0, 1.0));
    assert_eq!(m.shading, None);
    // roughness 0.5: 2 / 0.0625 - 2 = 30; metallic 0: specular 0.04.
    assert!((m.shininess - 30.0).abs() < 1e-3, "{}", m.shininess);
    assert!((m.specular - 0.04).abs() < 1e-6);
    let t = m.base_color_texture.as_ref().expect("texture");
    assert!(t.srgb);
    assert_eq!((t.width, t.height), (4, 4));
    assert_eq!(t.rgba8.len(), 4 * 4 * 4);
    assert_eq!(&t.rgba8[..4], &[255, 128, 0, 255]);
    assert_eq!(s.meshes[0].vertices[1].uv, [1.0, 0.0]);
}

#[test]
fn a_glb_with_an_embedded_png_loads() {
    let s = load_gltf(&fixture("triangle.glb"), &LoadOptions::default()).expect("loads");
    let t = s.materials[0].base_color_texture.as_ref().expect("texture");
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
    // The non-indexed triangle got sequential indices.
    assert_eq!(s.meshes[s.instances[0].mesh].indices, vec![0, 1, 2]);
    // The point light sits at node 2's world position; the spot light is skipped.
    assert_eq!(s.lights.len(), 1);
    let l = s.lights[0];
    assert!((l.position - Vec3::new(10.0, 0.0, 10.0)).length() < 1e-5, "{:?}", l.position);
    assert_eq!(l.intensity, 4.0);
    assert_eq!(l.color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(l.radius, manylight_core::radius_for_intensity(4.0, 0.01));
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

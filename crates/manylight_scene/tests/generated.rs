//! The generated scenes and lights: default hall, light rig, sphere shell, and `load_scene`.

use glam::Vec3;
use manylight_core::Aabb;
use manylight_scene::{
    LoadOptions, SceneError, default_scene, light_rig, load_scene, sphere_shell_lights, sphere_shell_scene,
};
use proptest::prelude::*;

#[test]
fn default_scene_is_a_lit_hall_with_a_camera() {
    let s = default_scene();
    s.validate().expect("valid");
    assert!(s.instances.len() > 20, "{}", s.instances.len());
    let b = s.bounds();
    assert!(b.min.is_finite() && b.max.is_finite());
    assert!(b.size().x > 35.0 && b.size().z > 14.0, "{b:?}");
    assert!((4..=8).contains(&s.lights.len()));
    let cam = s.camera_or_fit(16.0 / 9.0);
    assert_eq!(cam, s.cameras[0]);
    assert!((cam.projection.fov_y - 60f32.to_radians()).abs() < 1e-6);
    let eye = cam.transform.transform_point3(Vec3::ZERO);
    assert!((eye.y - 1.7).abs() < 0.5 && eye.x < b.min.x + 5.0);
    // Looking down the hall (+X).
    assert!(cam.transform.transform_vector3(Vec3::NEG_Z).dot(Vec3::X) > 0.99);
    // Deterministic.
    let again = default_scene();
    assert_eq!(s.instances, again.instances);
    assert_eq!(s.materials, again.materials);
    assert!(s.meshes.iter().zip(&again.meshes).all(|(a, b)| a == b));
}

fn hall() -> Aabb {
    Aabb { min: Vec3::new(-20.0, 0.0, -8.0), max: Vec3::new(20.0, 12.0, 8.0) }
}

fn inside(p: Vec3, b: &Aabb) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

#[test]
fn light_rig_is_deterministic_and_stays_inside() {
    for count in [1, 16, 256, 4096] {
        let a = light_rig(count, hall(), 42).unwrap();
        assert_eq!(a.len(), count);
        assert_eq!(a, light_rig(count, hall(), 42).unwrap());
        assert_ne!(a, light_rig(count, hall(), 43).unwrap());
        for l in &a {
            assert!((0.5..=8.0).contains(&l.radius) && l.intensity > 0.0);
            for step in 0..=200 {
                let t = step as f32 * 5.0;
                assert!(inside(l.position_at(t), &hall()), "{l:?} at {t}");
                let c = l.color_at(t);
                assert!(c.is_finite() && c.min_element() >= 0.0);
            }
        }
    }
    // Radii shrink as the count grows (fewer overlaps per light).
    assert!(light_rig(4096, hall(), 1).unwrap()[0].radius < light_rig(16, hall(), 1).unwrap()[0].radius);
}

#[test]
fn light_rig_handles_degenerate_bounds() {
    for b in [Aabb::EMPTY, Aabb { min: Vec3::NAN, max: Vec3::ONE }, Aabb { min: Vec3::ONE, max: Vec3::ONE }] {
        for l in light_rig(10, b, 7).unwrap() {
            assert!(l.position_at(3.0).is_finite() && l.color_at(3.0).is_finite());
            assert!(l.radius.is_finite() && l.intensity.is_finite());
        }
    }
}

#[test]
fn sphere_shell_lights_lie_just_inside_the_shell() {
    let lights = sphere_shell_lights(4096, 50.0, 0.3, 9).unwrap();
    assert_eq!(lights.len(), 4096);
    for l in &lights {
        let d = l.position.length();
        assert!((49.0..=50.0).contains(&d), "{d}");
        assert!(d + l.radius > 50.0 - 0.25, "a range-0.3 light must reach the shell");
        assert_eq!(l.radius, 0.3);
        assert!(l.color.is_finite() && l.color.min_element() >= 0.0 && l.intensity > 0.0);
    }
    assert_eq!(lights, sphere_shell_lights(4096, 50.0, 0.3, 9).unwrap());
    // Well spread: the mean of a Fibonacci lattice is close to the centre.
    let mean = lights.iter().map(|l| l.position).sum::<Vec3>() / lights.len() as f32;
    assert!(mean.length() < 0.5, "{mean:?}");
}

#[test]
fn sphere_shell_scene_matches_its_description() {
    let s = sphere_shell_scene();
    s.validate().expect("valid");
    assert!(s.lights.is_empty());
    assert_eq!(s.cameras.len(), 1);
    assert!((s.cameras[0].projection.fov_y - 45f32.to_radians()).abs() < 1e-6);
    assert_eq!(s.cameras[0].transform.transform_point3(Vec3::ZERO), Vec3::ZERO);
    let b = s.bounds();
    assert!((b.max.y - 52.5).abs() < 1e-3 && (b.min.y + 50.0).abs() < 1e-3, "{b:?}");
}

#[test]
fn load_scene_dispatches_on_the_spec() {
    let o = LoadOptions::default();
    assert_eq!(load_scene("default", &o).expect("default").name, "default");
    assert_eq!(load_scene("sphere-shell", &o).expect("shell").name, "sphere-shell");
    let e = load_scene("defualt", &o).expect_err("typo");
    assert!(matches!(e, SceneError::UnknownSpec { .. }), "{e}");
    let e = load_scene("/nonexistent/dir/scene.gltf", &o).expect_err("missing");
    assert!(matches!(e, SceneError::Io { .. }), "{e}");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/png16.gltf");
    assert_eq!(load_scene(fixture, &o).expect("fixture").instances.len(), 1);
}

#[test]
fn camera_or_fit_frames_a_scene_without_cameras() {
    let mut s = default_scene();
    s.cameras.clear();
    let b = s.bounds();
    let cam = s.camera_or_fit(1.5);
    let eye = cam.transform.transform_point3(Vec3::ZERO);
    let forward = cam.transform.transform_vector3(Vec3::NEG_Z);
    // From the front (+Z), as glTF viewers frame a model.
    assert!(eye.is_finite() && eye.z > b.max.z, "{eye:?}");
    assert!(forward.dot((b.center() - eye).normalize()) > 0.999);
    let radius = b.size().length() * 0.5;
    assert!(cam.projection.far >= (eye - b.center()).length() + radius);
    // No geometry at all: still a usable camera.
    let empty = manylight_scene::Scene::default().camera_or_fit(0.0);
    assert!(empty.transform.is_finite());
}

proptest! {
    #[test]
    fn light_rig_is_always_finite(seed in any::<u64>(), count in 0usize..64, t in prop::num::f32::ANY) {
        for l in light_rig(count, hall(), seed).unwrap() {
            let p = l.position_at(t);
            let c = l.color_at(t);
            prop_assert!(p.is_finite());
            prop_assert!(c.is_finite() && c.min_element() >= 0.0);
            if t.is_finite() && t.abs() < 1e6 {
                prop_assert!(inside(p, &hall()));
            }
        }
    }
}

//! glTF materials as their authors made them: normal maps (tangents from the file, generated
//! with MikkTSpace, and mirrored), occlusion, emission, alpha masks and single-sided culling.
//! Khronos sample assets rendered by naive forward match stored references; every other
//! pipeline and G-buffer layout matches naive forward on them; and culling follows each
//! instance's handedness.

mod support;

use glam::{Mat4, Vec4};
use manylight::app::RenderSettings;
use manylight::core::{MaterialData, Projection};
use manylight::prelude::*;
use manylight::scene::shapes::cuboid;
use manylight::scene::{SceneCamera, SceneInstance, SceneLight, camera_looking_at};
use std::sync::Arc;
use support::{STRICT, assert_matches_reference, assert_similar, asset, flip, gpu, render_scene};

const SIZE: UVec2 = UVec2::new(160, 160);
/// Rig lights added to the assets (which bring none).
const LIGHTS: usize = 48;

/// (reference name, asset): each exercises a material feature.
const ASSETS: [(&str, &str); 4] = [
    // Normal, occlusion and emissive maps, tangents generated with MikkTSpace.
    ("damaged_helmet", "DamagedHelmet/DamagedHelmet.glb"),
    // Tangents from the file, with mirrored uvs.
    ("normal_tangent_mirror", "NormalTangentMirrorTest/NormalTangentMirrorTest.gltf"),
    // Tangents generated, normal maps against the geometry they were baked from.
    ("normal_tangent", "NormalTangentTest/NormalTangentTest.gltf"),
    // Alpha masks with several cutoffs (its blended materials are drawn opaque for now).
    ("alpha_blend_mode", "AlphaBlendModeTest/AlphaBlendModeTest.gltf"),
];

fn settings(pipeline: PipelineKind) -> RenderSettings {
    RenderSettings { pipeline, ambient: 0.2, ..RenderSettings::default() }
}

fn load(rel: &str) -> Scene {
    load_gltf(&asset(rel), &LoadOptions::default()).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Naive forward's image of each asset matches its stored reference.
#[test]
fn khronos_material_assets_match_their_references() {
    let _gpu = gpu();
    for (name, rel) in ASSETS {
        let frame = render_scene(load(rel), SIZE, LIGHTS, settings(PipelineKind::NaiveForward));
        assert_matches_reference(&format!("{name}_naive"), &frame.image, STRICT);
    }
}

/// Every pipeline and G-buffer layout draws normal maps, occlusion, emission and alpha masks
/// as naive forward does.
#[test]
fn every_pipeline_matches_naive_forward_on_gltf_materials() {
    let _gpu = gpu();
    for (name, rel) in [ASSETS[0], ASSETS[3]] {
        let scene = load(rel);
        let naive = render_scene(scene.clone(), SIZE, LIGHTS, settings(PipelineKind::NaiveForward));
        let variants = support::pipelines_besides_naive(name, settings);
        for (variant, s) in variants {
            let frame = render_scene(scene.clone(), SIZE, LIGHTS, s);
            let stats = assert_similar(&variant, &naive.image, &frame.image, STRICT);
            eprintln!("{variant}: {stats:?}");
        }
    }
}

/// A single-sided box seen from the front, lit by one light on the axis, with a transform of
/// x scale `sx`.
fn box_scene(sx: f32, double_sided: bool) -> Scene {
    let material = MaterialData {
        label: "box".into(),
        base_color: Vec4::new(0.8, 0.6, 0.4, 1.0),
        double_sided,
        ..MaterialData::default()
    };
    Scene {
        name: format!("box x{sx}"),
        meshes: vec![Arc::new(cuboid("box", Vec3::ONE, 1.0))],
        materials: vec![Arc::new(material)],
        instances: vec![SceneInstance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(sx, 1.0, 1.0)) * Mat4::from_rotation_y(0.5),
        }],
        lights: vec![SceneLight {
            position: Vec3::new(0.0, 0.0, 3.0),
            color: Vec3::ONE,
            intensity: 8.0,
            radius: 20.0,
            spot: None,
        }],
        cameras: vec![SceneCamera {
            transform: camera_looking_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO),
            projection: Projection::perspective(0.6, 0.1, 50.0),
        }],
        ..Scene::default()
    }
}

/// A mirrored instance (negative determinant) of a single-sided box shows its outside, as the
/// unmirrored box does: its triangles wind the other way on screen, and culling follows. The
/// mirror of a box turned by +0.5 about y is the box turned by -0.5, whose image is the
/// first's mirror image.
#[test]
fn a_mirrored_single_sided_box_shows_its_outside() {
    let _gpu = gpu();
    let size = UVec2::new(96, 96);
    for pipeline in [PipelineKind::NaiveForward, PipelineKind::ClusteredDeferred] {
        let plain = render_scene(box_scene(1.0, false), size, 0, settings(pipeline));
        let mirrored = render_scene(box_scene(-1.0, false), size, 0, settings(pipeline));
        let flipped = image::imageops::flip_horizontal(&plain.image);
        let name = format!("mirrored_box_{}", pipeline.name());
        assert_similar(&name, &flipped, &mirrored.image, STRICT);
        // Drawn from both sides, the nearest faces still win: the same image.
        let double = render_scene(box_scene(-1.0, true), size, 0, settings(pipeline));
        assert_similar(&format!("{name}_double_sided"), &mirrored.image, &double.image, STRICT);
    }
}

/// Seen from inside, a single-sided box shows nothing (its faces all turn their backs), and a
/// double-sided one shows its inner walls.
#[test]
fn single_sided_faces_seen_from_behind_are_not_drawn() {
    let _gpu = gpu();
    let size = UVec2::new(64, 64);
    let inside = |double_sided: bool| {
        let mut scene = box_scene(1.0, double_sided);
        scene.instances[0].transform = Mat4::from_scale(Vec3::splat(20.0));
        scene.cameras[0].transform = camera_looking_at(Vec3::ZERO, Vec3::new(0.3, 0.1, -1.0));
        scene.lights[0].position = Vec3::new(0.0, 0.0, -5.0);
        render_scene(scene, size, 0, settings(PipelineKind::NaiveForward)).image
    };
    let single = inside(false);
    let background = *single.get_pixel(0, 0);
    assert!(single.pixels().all(|p| *p == background), "a single-sided box seen from inside draws something");
    let double = inside(true);
    let drawn = double.pixels().filter(|p| **p != background).count();
    assert!(drawn == double.pixels().len(), "{drawn} of {} pixels drawn from inside", double.pixels().len());
    assert!(flip(&single, &double).mean > 0.05);
}

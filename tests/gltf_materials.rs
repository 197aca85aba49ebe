//! glTF materials as their authors made them: normal maps (tangents from the file, generated
//! with MikkTSpace, and mirrored), occlusion, emission, alpha masks, single-sided culling,
//! per-texture samplers, texture transforms and the second uv set.
//! Khronos sample assets rendered by naive forward match stored references; every other
//! pipeline and G-buffer layout matches naive forward on them; and culling follows each
//! instance's handedness.

mod support;

use glam::Mat4;
use manylight::app::RenderSettings;
use manylight::math::LightShape;
use manylight::math::{MaterialData, Projection};
use manylight::prelude::*;
use manylight::scene::shapes::cuboid;
use manylight::scene::{SceneCamera, SceneInstance, SceneLight, camera_looking_at, studio_lights};
use std::sync::Arc;
use support::{STRICT, assert_matches_reference, assert_similar, asset, flip, gpu, render_scene};

const SIZE: UVec2 = UVec2::new(160, 160);
/// Lights added to the assets (which bring none, except the lamp): a dome of studio lights for
/// the references (as a model viewer lights them), animated rig lights among the geometry for
/// the pipeline comparisons (harder for the light lists).
const LIGHTS: usize = 48;

/// (reference name, asset): each exercises a material feature.
const ASSETS: [(&str, &str); 9] = [
    // Normal, occlusion and emissive maps, tangents generated with MikkTSpace.
    ("damaged_helmet", "DamagedHelmet/DamagedHelmet.glb"),
    // Tangents from the file, with mirrored uvs.
    ("normal_tangent_mirror", "NormalTangentMirrorTest/NormalTangentMirrorTest.gltf"),
    // Tangents generated, normal maps against the geometry they were baked from.
    ("normal_tangent", "NormalTangentTest/NormalTangentTest.gltf"),
    // Alpha masks with several cutoffs, and a blended material.
    ("alpha_blend_mode", "AlphaBlendModeTest/AlphaBlendModeTest.gltf"),
    // Per-texture samplers: repeat, mirrored repeat and clamp on each axis.
    ("texture_settings", "TextureSettingsTest/TextureSettingsTest.gltf"),
    // Where uv (0, 0) lies on the image and which way v runs.
    ("texture_coordinate", "TextureCoordinateTest/TextureCoordinateTest.gltf"),
    // sRGB decoding of PNGs with and without gamma and ICC chunks: all alike.
    ("texture_encoding", "TextureEncodingTest/TextureEncodingTest.gltf"),
    // Metallic and roughness factors from mirror to rough, metal to plastic.
    ("metal_rough_spheres", "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf"),
    // Range-less point lights of the file (cut off by the loader), emissive and normal maps.
    ("lights_punctual_lamp", "LightsPunctualLamp/LightsPunctualLamp.gltf"),
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
        let mut scene = load(rel);
        scene.lights.extend(studio_lights(LIGHTS, scene.bounds()).expect("studio lights"));
        let frame = render_scene(scene, SIZE, 0, settings(PipelineKind::NaiveForward));
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
        base_color: Color::linear_rgb(0.8, 0.6, 0.4),
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
            shape: LightShape::Point,
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

/// A 2 × 2 quad in the xy plane facing +z, every vertex's two uv sets from `uv0` and `uv1`
/// of its corner (u along +x, v along -y in `[0, 1]`).
fn uv_quad(uv0: impl Fn(Vec2) -> Vec2, uv1: impl Fn(Vec2) -> Vec2) -> manylight::math::MeshData {
    let corners = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let positions: Vec<Vec3> =
        corners.iter().map(|c| Vec3::new(c.x * 2.0 - 1.0, 1.0 - c.y * 2.0, 0.0)).collect();
    let normals = [Vec3::Z; 4];
    let uvs: Vec<Vec2> = corners.iter().map(|&c| uv0(c)).collect();
    let mut mesh = manylight::math::MeshData::from_attributes(
        "uv quad",
        &positions,
        Some(&normals),
        Some(&uvs),
        Some(vec![0, 1, 2, 0, 2, 3]),
    )
    .expect("valid quad");
    mesh.set_uv1(&corners.map(uv1));
    mesh
}

/// A 16 × 16 texture with no symmetry: red along x, green along y, a blue diagonal stripe.
fn asymmetric_texture() -> Arc<manylight::math::TextureData> {
    let mut rgba8 = Vec::new();
    for y in 0..16u8 {
        for x in 0..16u8 {
            let stripe = if (x + 2 * y) % 7 == 0 { 255 } else { 0 };
            rgba8.extend_from_slice(&[x * 16, y * 16, stripe, 255]);
        }
    }
    Arc::new(manylight::math::TextureData {
        label: "asymmetric".into(),
        width: 16,
        height: 16,
        rgba8,
        srgb: true,
    })
}

/// `KHR_texture_transform` and `TEXCOORD_1`: a quad whose base colour and emissive textures
/// transform their uvs (each its own way) looks like the same quad with those transforms
/// applied to its vertices' uvs beforehand, whichever uv set the textures read; and unlike the
/// quad sampled without them.
#[test]
fn texture_transforms_and_the_second_uv_set_match_pre_transformed_uvs() {
    use manylight::math::{MaterialTexture, UvChannel};
    let _gpu = gpu();
    let base = MaterialTexture::gltf_uv_transform(Vec2::new(0.25, 0.5), 0.7, Vec2::new(1.5, -0.8));
    let emissive = MaterialTexture::gltf_uv_transform(Vec2::new(0.1, 0.3), -1.2, Vec2::new(0.6, 2.0));
    let image = asymmetric_texture();
    let texture = |channel, transform| MaterialTexture {
        uv_channel: channel,
        uv_transform: transform,
        ..MaterialTexture::new(image.clone())
    };
    let scene = |mesh: manylight::math::MeshData, base_texture, emissive_texture| {
        let material = MaterialData {
            label: "transformed".into(),
            base_color_texture: Some(base_texture),
            emissive: LinearRgba::rgb(0.5, 0.5, 0.5),
            emissive_texture: Some(emissive_texture),
            ..MaterialData::default()
        };
        Scene {
            name: "uv quad".into(),
            meshes: vec![Arc::new(mesh)],
            materials: vec![Arc::new(material)],
            instances: vec![SceneInstance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
            cameras: vec![SceneCamera {
                transform: camera_looking_at(Vec3::new(0.3, -0.2, 2.5), Vec3::ZERO),
                projection: Projection::perspective(0.9, 0.1, 20.0),
            }],
            ..Scene::default()
        }
    };
    let id = glam::Affine2::IDENTITY;
    let (apply_base, apply_emissive) = (|uv| base.transform_point2(uv), |uv| emissive.transform_point2(uv));
    let size = UVec2::new(96, 96);
    for pipeline in [PipelineKind::NaiveForward, PipelineKind::ClusteredDeferred] {
        let render =
            |s: Scene| render_scene(s, size, 0, RenderSettings { ambient: 0.5, ..settings(pipeline) }).image;
        // The transforms baked into the vertices: base colour from uv0, emissive from uv1.
        let baked = render(scene(
            uv_quad(apply_base, apply_emissive),
            texture(UvChannel::Uv0, id),
            texture(UvChannel::Uv1, id),
        ));
        let on_uv0 = render(scene(
            uv_quad(|c| c, |_| Vec2::ZERO),
            texture(UvChannel::Uv0, base),
            texture(UvChannel::Uv0, emissive),
        ));
        let on_uv1 = render(scene(
            uv_quad(|_| Vec2::ZERO, |c| c),
            texture(UvChannel::Uv1, base),
            texture(UvChannel::Uv1, emissive),
        ));
        let plain =
            render(scene(uv_quad(|c| c, |c| c), texture(UvChannel::Uv0, id), texture(UvChannel::Uv0, id)));
        let name = format!("texture_transform_{}", pipeline.name());
        assert_similar(&format!("{name}_uv0"), &baked, &on_uv0, STRICT);
        assert_similar(&format!("{name}_uv1"), &baked, &on_uv1, STRICT);
        let untransformed = flip(&baked, &plain).mean;
        assert!(untransformed > 0.05, "{name}: the transforms change little ({untransformed})");
    }
}

/// An unlit quad at depth `z` (facing +z, 2 × 2, centred on the axis) emitting `emissive`,
/// blended with alpha `alpha` when below 1.
fn emitting_quad(z: f32, emissive: Vec3, alpha: f32) -> (MaterialData, Mat4) {
    let material = MaterialData {
        label: format!("quad at {z}"),
        base_color: Color::linear_rgba(0.0, 0.0, 0.0, alpha),
        emissive: LinearRgba::from_vec3(emissive),
        alpha_mode: if alpha < 1.0 {
            manylight::math::AlphaMode::Blend
        } else {
            manylight::math::AlphaMode::Opaque
        },
        ..MaterialData::default()
    };
    (material, Mat4::from_translation(Vec3::new(0.0, 0.0, z)))
}

/// Blended surfaces are drawn farthest first whatever their order in the scene, over the
/// opaque ones and behind nearer opaque ones: half-transparent red in front of half-transparent
/// blue in front of grey shows 0.5 red + 0.25 blue + 0.25 grey in the middle (the reverse
/// order would show more blue than red), in every pipeline.
#[test]
fn blended_surfaces_are_drawn_back_to_front_over_the_opaque_ones() {
    let _gpu = gpu();
    let quads = [
        emitting_quad(0.5, Vec3::new(1.0, 0.0, 0.0), 0.5),
        emitting_quad(0.0, Vec3::new(0.0, 0.0, 1.0), 0.5),
        emitting_quad(-0.5, Vec3::splat(0.2), 1.0),
    ];
    let scene = |order: [usize; 3]| Scene {
        name: "blended quads".into(),
        meshes: vec![Arc::new(uv_quad(|c| c, |c| c))],
        materials: order.iter().map(|&i| Arc::new(quads[i].0.clone())).collect(),
        instances: (0..3)
            .map(|k| SceneInstance { mesh: 0, material: k, transform: quads[order[k]].1 })
            .collect(),
        cameras: vec![SceneCamera {
            transform: camera_looking_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO),
            projection: Projection::perspective(0.5, 0.1, 20.0),
        }],
        ..Scene::default()
    };
    let size = UVec2::new(48, 48);
    let centre = |image: &image::RgbaImage| *image.get_pixel(size.x / 2, size.y / 2);
    let render = |order, pipeline| {
        render_scene(scene(order), size, 1, RenderSettings { ambient: 0.0, ..settings(pipeline) }).image
    };
    let reference = render([0, 1, 2], PipelineKind::NaiveForward);
    let [r, _, b, _] = centre(&reference).0;
    assert!(r > b + 20, "red over blue: {:?}", centre(&reference));
    for pipeline in PipelineKind::ALL {
        for order in [[0, 1, 2], [2, 1, 0], [1, 2, 0]] {
            let image = render(order, pipeline);
            assert_similar(
                &format!("blended_quads_{}_{order:?}", pipeline.name()),
                &reference,
                &image,
                STRICT,
            );
        }
    }
    // The opaque quad in front hides the blended ones.
    let mut hidden = scene([0, 1, 2]);
    hidden.instances[2].transform = Mat4::from_translation(Vec3::new(0.0, 0.0, 1.0));
    let image = render_scene(
        hidden,
        size,
        0,
        RenderSettings { ambient: 0.0, ..settings(PipelineKind::NaiveForward) },
    )
    .image;
    let [r, g, b, _] = centre(&image).0;
    assert!(r == g && g == b, "grey in front: {:?}", centre(&image));
}

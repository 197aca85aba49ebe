//! Every glTF scene in the repository's `assets/` folder loads, with the expected counts.

use manylight_scene::{LoadOptions, Scene, load_gltf};
use std::path::{Path, PathBuf};

/// The repository's `assets/` folder.
fn assets() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets")).to_path_buf()
}

fn load(rel: &str) -> Scene {
    let path = assets().join(rel);
    load_gltf(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_asset_loads() {
    let dir = assets();
    let mut files = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("read assets") {
        let sub = entry.expect("entry").path();
        if !sub.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&sub).expect("read asset folder") {
            let f = f.expect("entry").path();
            if matches!(f.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")) {
                files.push(f);
            }
        }
    }
    files.sort();
    assert!(files.len() >= 16, "found only {} glTF files in {}", files.len(), dir.display());
    for f in &files {
        let scene = load_gltf(f, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        scene.validate().unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.instances.is_empty(), "{}: no instances", f.display());
        let b = scene.bounds();
        assert!(b.min.is_finite() && b.max.is_finite(), "{}: bounds {b:?}", f.display());
    }
}

/// A large scene that may not be redistributed (3DRT's VirtualCity, licensed for testing
/// only) is never part of the repository; point `MANYLIGHT_VIRTUAL_CITY` at its `VC.gltf` and
/// run `cargo test -p manylight_scene --release --test assets -- --ignored`.
#[test]
#[ignore = "needs MANYLIGHT_VIRTUAL_CITY=path/to/VC.gltf (not redistributable)"]
fn virtual_city_has_many_instances_and_shares_textures() {
    let path = std::env::var_os("MANYLIGHT_VIRTUAL_CITY")
        .expect("set MANYLIGHT_VIRTUAL_CITY to the path of VC.gltf to run this test");
    // The load time is printed for whoever runs it, not asserted: it depends on the machine.
    let start = std::time::Instant::now();
    let s = load_gltf(Path::new(&path), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("VC.gltf loaded in {:?}", start.elapsed());
    assert!(s.instances.len() > 100, "{} instances", s.instances.len());
    assert_eq!(s.cameras.len(), 14);
    // 20 images: each decoded once and shared by pointer.
    let mut textures: Vec<*const manylight_core::TextureData> = s
        .materials
        .iter()
        .filter_map(|m| m.base_color_texture.as_ref().map(|t| &t.image).map(std::sync::Arc::as_ptr))
        .collect();
    textures.sort();
    textures.dedup();
    assert!(!textures.is_empty() && textures.len() <= 20, "{} textures", textures.len());
}

#[test]
fn lights_punctual_lamp_has_five_point_lights() {
    let s = load("LightsPunctualLamp/LightsPunctualLamp.gltf");
    assert_eq!(s.lights.len(), 5);
    for l in &s.lights {
        assert!(l.intensity > 0.0 && l.radius > 0.0 && l.position.is_finite());
    }
}

#[test]
fn cornell_box_many_lights_has_64_small_lights() {
    let s = load("CornellBox/CornellBoxManyLights.gltf");
    assert_eq!(s.lights.len(), 64);
    for l in &s.lights {
        assert!((l.radius - 0.15).abs() < 1e-6, "{}", l.radius);
        assert!((l.intensity - 0.0001).abs() < 1e-9);
    }
    assert_eq!(s.cameras.len(), 1);
    let single = load("CornellBox/CornellBox.gltf");
    assert_eq!(single.lights.len(), 1);
}

#[test]
fn shared_primitives_become_one_mesh() {
    // 98 sphere primitives share one accessor set: one mesh, many instances.
    let s = load("MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf");
    assert!(s.instances.len() >= 98);
    assert!(s.meshes.len() < 30, "{} meshes", s.meshes.len());
}

/// Checks that every tangent of `mesh` is finite and either zero (no frame) or a unit vector
/// with handedness ±1 perpendicular to the normal; returns how many vertices have a frame.
fn check_tangents(mesh: &manylight_core::MeshData) -> usize {
    let mut framed = 0;
    for (i, v) in mesh.vertices.iter().enumerate() {
        let t = glam::Vec4::from(v.tangent);
        assert!(t.is_finite(), "{}: vertex {i} tangent {t:?}", mesh.label);
        if t == glam::Vec4::ZERO {
            continue;
        }
        framed += 1;
        assert!((t.truncate().length() - 1.0).abs() < 1e-4, "{}: vertex {i} tangent {t:?}", mesh.label);
        assert_eq!(t.w.abs(), 1.0, "{}: vertex {i} tangent {t:?}", mesh.label);
        let dot = t.truncate().dot(glam::Vec3::from(v.normal));
        assert!(dot.abs() < 1e-2, "{}: vertex {i} tangent {t:?} not ⟂ normal ({dot})", mesh.label);
    }
    framed
}

#[test]
fn damaged_helmet_has_normal_occlusion_and_emissive_maps_and_generated_tangents() {
    let s = load("DamagedHelmet/DamagedHelmet.glb");
    s.validate().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    assert_eq!(m.label, "Material_MR");
    let normal = m.normal_texture.as_ref().map(|t| &t.image).expect("normal texture");
    let occlusion = m.occlusion_texture.as_ref().map(|t| &t.image).expect("occlusion texture");
    let emissive = m.emissive_texture.as_ref().map(|t| &t.image).expect("emissive texture");
    assert!(!normal.srgb && !occlusion.srgb && emissive.srgb);
    assert!(m.base_color_texture.as_ref().map(|t| &t.image).is_some_and(|t| t.srgb));
    assert!(m.metallic_roughness_texture.as_ref().map(|t| &t.image).is_some_and(|t| !t.srgb));
    assert_eq!(m.textures().count(), 5);
    assert_eq!(m.emissive_rgb(), glam::Vec3::ONE);
    assert_eq!((m.normal_scale, m.occlusion_strength), (1.0, 1.0));
    assert!(!m.double_sided, "the file does not say doubleSided");
    assert_eq!(m.alpha_mode, manylight_core::AlphaMode::Opaque);
    // The file has no TANGENT: MikkTSpace gives (almost) every vertex a frame.
    assert_eq!(s.meshes.len(), 1);
    let mesh = &s.meshes[0];
    assert!(mesh.has_tangents());
    let framed = check_tangents(mesh);
    assert!(framed * 100 >= mesh.vertices.len() * 99, "{framed} of {} vertices", mesh.vertices.len());
}

#[test]
fn normal_tangent_tests_have_normal_maps_and_tangents() {
    // NormalTangentMirrorTest has TANGENT (with both handednesses: mirrored uvs);
    // NormalTangentTest has none, so they are generated.
    for (file, mirrored) in [
        ("NormalTangentMirrorTest/NormalTangentMirrorTest.gltf", true),
        ("NormalTangentTest/NormalTangentTest.gltf", false),
    ] {
        let s = load(file);
        s.validate().unwrap_or_else(|e| panic!("{file}: {e}"));
        let m = &s.materials[0];
        assert!(m.normal_texture.as_ref().map(|t| &t.image).is_some_and(|t| !t.srgb), "{file}");
        // Occlusion and metallic-roughness share one image: one linear copy.
        let occlusion = m.occlusion_texture.as_ref().map(|t| &t.image).expect("occlusion texture");
        let mr = m.metallic_roughness_texture.as_ref().map(|t| &t.image).expect("metallic-roughness texture");
        assert!(std::sync::Arc::ptr_eq(occlusion, mr), "{file}");
        assert!(m.double_sided, "{file}");
        for mesh in &s.meshes {
            assert!(mesh.has_tangents(), "{file}: {}", mesh.label);
            let framed = check_tangents(mesh);
            if mirrored {
                assert_eq!(framed, mesh.vertices.len(), "{file}: every TANGENT is usable");
                assert!(mesh.vertices.iter().any(|v| v.tangent[3] == -1.0), "{file}: no mirrored frame");
                assert!(mesh.vertices.iter().any(|v| v.tangent[3] == 1.0), "{file}");
            }
        }
    }
}

#[test]
fn alpha_blend_mode_test_has_the_authored_alpha_modes() {
    use manylight_core::AlphaMode;
    let s = load("AlphaBlendModeTest/AlphaBlendModeTest.gltf");
    let expected = [
        ("MatBed", AlphaMode::Opaque, false),
        ("MatBlend", AlphaMode::Blend, true),
        ("MatCutoff25", AlphaMode::Mask(0.25), true),
        ("MatCutoff75", AlphaMode::Mask(0.75), true),
        ("MatCutoffDefault", AlphaMode::Mask(0.5), true),
        ("MatOpaque", AlphaMode::Opaque, true),
    ];
    assert_eq!(s.materials.len(), expected.len());
    for (label, alpha_mode, double_sided) in expected {
        let m = s.materials.iter().find(|m| m.label == label).unwrap_or_else(|| panic!("no {label}"));
        assert_eq!((m.alpha_mode, m.double_sided), (alpha_mode, double_sided), "{label}");
    }
    // Every primitive has TANGENT.
    for mesh in &s.meshes {
        assert_eq!(check_tangents(mesh), mesh.vertices.len(), "{}", mesh.label);
    }
}

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
    let start = std::time::Instant::now();
    let s = load_gltf(Path::new(&path), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let elapsed = start.elapsed();
    eprintln!("VC.gltf loaded in {elapsed:?}");
    // Well under a second in release; a loose bound so a busy machine does not flake.
    if !cfg!(debug_assertions) {
        assert!(elapsed.as_secs_f64() < 3.0, "VC took {elapsed:?}");
    }
    assert!(s.instances.len() > 100, "{} instances", s.instances.len());
    assert_eq!(s.cameras.len(), 14);
    // 20 images: each decoded once and shared by pointer.
    let mut textures: Vec<*const manylight_core::TextureData> = s
        .materials
        .iter()
        .filter_map(|m| m.base_color_texture.as_ref().map(std::sync::Arc::as_ptr))
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
        assert!((l.intensity - 0.02).abs() < 1e-6);
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

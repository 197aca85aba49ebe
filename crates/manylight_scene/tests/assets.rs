//! Every real test asset of `/work/shared/assets` loads, with the expected counts.
//!
//! The assets live outside the repository. Without them these tests pass vacuously, except
//! under `CI=true`, where a missing assets folder is a failure.

use manylight_scene::{LoadOptions, Scene, load_gltf};
use std::path::{Path, PathBuf};

/// The shared assets folder, or `None` when it is absent outside CI (panics under CI).
fn assets() -> Option<PathBuf> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/assets")).to_path_buf();
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("CI=true but the shared assets folder {} is missing", dir.display());
    }
    eprintln!("skipping: {} is absent", dir.display());
    None
}

fn load(rel: &str) -> Option<Scene> {
    let path = assets()?.join(rel);
    Some(load_gltf(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}")))
}

#[test]
fn every_shared_asset_loads() {
    let Some(dir) = assets() else { return };
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
    assert!(files.len() >= 19, "found only {} glTF files", files.len());
    for f in &files {
        let scene = load_gltf(f, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        scene.validate().unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.instances.is_empty(), "{}: no instances", f.display());
        let b = scene.bounds();
        assert!(b.min.is_finite() && b.max.is_finite(), "{}: bounds {b:?}", f.display());
    }
}

#[test]
fn virtual_city_has_many_instances_and_shares_textures() {
    let start = std::time::Instant::now();
    let Some(s) = load("VC/VC.gltf") else { return };
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
    let Some(s) = load("LightsPunctualLamp/LightsPunctualLamp.gltf") else { return };
    assert_eq!(s.lights.len(), 5);
    for l in &s.lights {
        assert!(l.intensity > 0.0 && l.radius > 0.0 && l.position.is_finite());
    }
}

#[test]
fn cornell_box_many_lights_has_64_small_lights() {
    let Some(s) = load("CornellBox/CornellBoxManyLights.gltf") else { return };
    assert_eq!(s.lights.len(), 64);
    for l in &s.lights {
        assert!((l.radius - 0.15).abs() < 1e-6, "{}", l.radius);
        assert!((l.intensity - 0.02).abs() < 1e-6);
    }
    assert_eq!(s.cameras.len(), 1);
    let single = load("CornellBox/CornellBox.gltf").expect("assets present");
    assert_eq!(single.lights.len(), 1);
}

#[test]
fn shared_primitives_become_one_mesh() {
    // 98 sphere primitives share one accessor set: one mesh, many instances.
    let Some(s) = load("MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf") else { return };
    assert!(s.instances.len() >= 98);
    assert!(s.meshes.len() < 30, "{} meshes", s.meshes.len());
}

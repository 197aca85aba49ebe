//! What `check` does: loads a glTF/GLB file and renders one small frame of it, so a bad file
//! fails with its error (exit 1) and a good one prints what it holds.

use super::headless::{Extras, render_scene};
use anyhow::{Context, Result};
use glam::UVec2;
use manylight_app::RenderSettings;
use manylight_scene::LoadOptions;
use std::path::PathBuf;

/// `check`: loads the glTF/GLB file at `path` and renders one small frame of it; the error
/// names the file when either fails.
pub(crate) fn run(path: PathBuf) -> Result<()> {
    let spec = path.to_string_lossy().to_string();
    let scene = manylight_scene::load_gltf(&path, &LoadOptions::default())?;
    let summary = format!(
        "{}: {} meshes, {} materials, {} instances, {} lights, {} cameras",
        path.display(),
        scene.meshes.len(),
        scene.materials.len(),
        scene.instances.len(),
        scene.lights.len(),
        scene.cameras.len()
    );
    render_scene(scene, UVec2::new(64, 64), 1, 0, 1, RenderSettings::default(), Extras::default())
        .with_context(|| format!("`{spec}` loaded but did not render"))?;
    println!("ok: {summary}");
    Ok(())
}

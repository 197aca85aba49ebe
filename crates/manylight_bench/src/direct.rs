//! Rendering without the app: snapshots built straight from a scene and a light rig, rendered
//! by the app's headless renderer (same render world and graph systems), for benchmarks and
//! measurements that need the renderer's internals (depth buffer, cluster lists).

use anyhow::{Context, Result};
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::efficiency::{CullingEfficiency, culling_efficiency};
use manylight_render::{
    ExtractedCamera, ExtractedInstance, ExtractedPointLight, FrameReport, FrameSettings, FrameSnapshot,
};
use manylight_scene::{AnimatedLight, Scene};

/// The snapshot of `scene` plus `rig` at animation time `t` (the camera is the scene's first,
/// or one framing it).
pub fn snapshot(
    scene: &Scene,
    rig: &[AnimatedLight],
    t: f32,
    size: UVec2,
    settings: FrameSettings,
    frame_index: u64,
) -> FrameSnapshot {
    let cam = scene.camera_or_fit(size.x as f32 / size.y.max(1) as f32);
    let scene_lights = scene.lights.iter().map(|l| ExtractedPointLight {
        position: l.position,
        color: l.color,
        intensity: l.intensity,
        radius: l.radius,
    });
    let rig_lights = rig.iter().map(|a| {
        let l = a.at(t);
        ExtractedPointLight { position: l.position, color: l.color, intensity: l.intensity, radius: l.radius }
    });
    FrameSnapshot {
        frame_index,
        viewport: size,
        camera: Some(ExtractedCamera {
            world_from_view: cam.transform,
            projection: cam.projection,
            prev_clip_from_world: None,
        }),
        instances: scene
            .instances
            .iter()
            .filter_map(|i| {
                Some(ExtractedInstance {
                    mesh: scene.meshes.get(i.mesh)?.clone(),
                    material: scene.materials.get(i.material)?.clone(),
                    world_from_local: i.transform,
                })
            })
            .collect(),
        lights: scene_lights.chain(rig_lights).collect(),
        settings,
    }
}

/// Renders `snapshot` and measures the culling efficiency of its cluster lists against its
/// depth buffer (every 64th covered pixel is also checked against all lights).
pub fn measure_culling(
    renderer: &mut HeadlessRenderer,
    snapshot: FrameSnapshot,
) -> Result<(FrameReport, CullingEfficiency)> {
    let projection = snapshot.camera.map(|c| c.projection).unwrap_or_default();
    let (report, _) = renderer.render(snapshot, false)?;
    let r = renderer.render_world.renderer();
    let clusters =
        r.clusters.as_ref().context("the frame built no clusters (naive pipeline, or no lights)")?;
    let assignment = clusters.read_assignment(&r.gpu)?;
    let (_, _, depth) = r.read_depth()?.context("the frame has no depth buffer")?;
    let eff =
        culling_efficiency(&clusters.grid, &projection, &assignment, &clusters.view_spheres, &depth, 64);
    Ok((report, eff))
}

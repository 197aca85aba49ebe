//! Turning a [`Scene`] (loaded glTF or the embedded default) into entities.

use crate::components::{
    Camera3d, LightAnimation, Material, Mesh3d, PointLight, Transform, Visibility, transform_from_matrix,
};
use bevy_ecs::prelude::*;
use manylight_core::Aabb;
use manylight_render::{
    ExtractedCamera, ExtractedInstance, ExtractedPointLight, FrameSettings, FrameSnapshot,
};
use manylight_scene::light_rig;
use manylight_scene::{Scene, SceneLight};

/// Spawns the scene under one root entity (returned; `Transform::IDENTITY`, named by the
/// scene): its instances and lights are the root's children (`ChildOf`), so moving, hiding
/// or despawning the root moves, hides or despawns the whole scene. With `spawn_camera`, the
/// scene's camera is spawned as a child of the root too, or, when the scene has none, a camera
/// framing it at the top level. `aspect` is the viewport's width / height.
pub fn spawn_scene(commands: &mut Commands, scene: &Scene, spawn_camera: bool, aspect: f32) -> Entity {
    let root =
        commands.spawn((Transform::IDENTITY, Visibility::default(), SceneRoot(scene.name.clone()))).id();
    for inst in &scene.instances {
        let (Some(mesh), Some(material)) = (scene.meshes.get(inst.mesh), scene.materials.get(inst.material))
        else {
            tracing::warn!("scene `{}`: instance refers to a missing mesh or material", scene.name);
            continue;
        };
        commands.spawn((
            transform_from_matrix(inst.transform),
            Mesh3d(mesh.clone()),
            Material(material.clone()),
            ChildOf(root),
        ));
    }
    for light in &scene.lights {
        commands.spawn((
            Transform::from_translation(light.position),
            PointLight { color: light.color, intensity: light.intensity, range: light.radius, radius: 0.0 },
            ChildOf(root),
        ));
    }
    if spawn_camera {
        let cam = scene.camera_or_fit(aspect);
        let p = cam.projection;
        let camera = commands
            .spawn((
                transform_from_matrix(cam.transform),
                Camera3d { fov_y: p.fov_y, near: p.near, far: p.far },
            ))
            .id();
        if !scene.cameras.is_empty() {
            commands.entity(camera).insert(ChildOf(root));
        }
    }
    root
}

/// Marks the root entity of a spawned [`Scene`]; holds the scene's name.
#[derive(Component, Clone, Debug, PartialEq, Eq)]
pub struct SceneRoot(pub String);

/// Spawns `count` animated lights inside `bounds` (deterministic for a `seed`).
pub fn spawn_light_rig(commands: &mut Commands, count: usize, bounds: Aabb, seed: u64) {
    for anim in light_rig(count, bounds, seed) {
        commands.spawn((
            Transform::from_translation(anim.position_at(0.0)),
            PointLight {
                color: anim.color_at(0.0),
                intensity: anim.intensity,
                range: anim.radius,
                radius: 0.0,
            },
            LightAnimation(anim),
        ));
    }
}

/// A scene light as the render side sees it.
pub fn extracted_light(l: &SceneLight) -> ExtractedPointLight {
    ExtractedPointLight { position: l.position, color: l.color, intensity: l.intensity, radius: l.radius }
}

/// The snapshot of `scene` seen through its camera (or one framing it) at `size`, lit by
/// `lights`, without an app: for benchmarks and tests that drive the renderer directly.
pub fn scene_snapshot(
    scene: &Scene,
    lights: Vec<ExtractedPointLight>,
    size: glam::UVec2,
    settings: FrameSettings,
    frame_index: u64,
) -> FrameSnapshot {
    let cam = scene.camera_or_fit(size.x as f32 / size.y.max(1) as f32);
    FrameSnapshot {
        frame_index,
        viewport: size,
        camera: Some(ExtractedCamera {
            world_from_view: cam.transform,
            projection: cam.projection,
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
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
        lights,
        settings,
    }
}

//! Turning a [`Scene`] (loaded glTF or the embedded default) into entities.

use crate::components::{
    Camera3d, DirectionalLight, LightAnimation, Material, Mesh3d, PointLight, Projection, SpotLight,
    Transform, Visibility, from_linear_rgb, transform_from_matrix,
};
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use manylight_core::{Aabb, LightCountError, LightShape, lumens_from_candela};
use manylight_render::{
    ExtractedCamera, ExtractedDirectionalLight, ExtractedInstance, ExtractedPointLight, ExtractedView,
    FrameSettings, FrameSnapshot, ShadowBias,
};
use manylight_scene::light_rig;
use manylight_scene::{Scene, SceneLight};

/// Spawns the scene under one root entity (returned; `Transform::IDENTITY`, a [`SceneRoot`]
/// named by the scene), so moving, hiding or despawning the root moves, hides or despawns the
/// whole scene:
/// - a scene with a node tree (glTF) spawns one entity per node (`Name` from the file, its
///   local `Transform`, `ChildOf` its parent or the root), and each node's meshes, lights and
///   camera as children of its entity at the node's origin, so moving a node moves what hangs
///   from it;
/// - instances and lights outside any node (generated scenes) are children of the root at
///   their world transforms.
///
/// With `spawn_camera`, the scene's first camera is spawned where it hangs, or, when the scene
/// has none, a camera framing it at the top level. `aspect` is the viewport's width / height.
pub fn spawn_scene(commands: &mut Commands, scene: &Scene, spawn_camera: bool, aspect: f32) -> Entity {
    let root =
        commands.spawn((Transform::IDENTITY, Visibility::default(), SceneRoot(scene.name.clone()))).id();
    let mut placed_instances = vec![false; scene.instances.len()];
    let mut placed_lights = vec![false; scene.lights.len()];
    let mut camera_placed = false;
    let mut node_entities: Vec<Entity> = Vec::with_capacity(scene.nodes.len());
    for node in &scene.nodes {
        let parent = node.parent.and_then(|p| node_entities.get(p).copied()).unwrap_or(root);
        let mut entity = commands.spawn((
            transform_from_matrix(node.local),
            Visibility::default(),
            SceneNodeIndex(node_entities.len()),
            ChildOf(parent),
        ));
        if let Some(name) = &node.name {
            entity.insert(Name::new(name.clone()));
        }
        let entity = entity.id();
        node_entities.push(entity);
        for &i in &node.instances {
            if spawn_instance(commands, scene, i, Transform::IDENTITY, entity) {
                placed_instances[i] = true;
            }
        }
        for &l in &node.lights {
            if let Some(light) = scene.lights.get(l) {
                spawn_light(commands, light, Transform::IDENTITY, true, entity);
                placed_lights[l] = true;
            }
        }
        if spawn_camera && node.cameras.contains(&0) {
            commands.spawn((
                Transform::IDENTITY,
                Camera3d,
                Projection::from(scene.cameras[0].projection),
                ChildOf(entity),
            ));
            camera_placed = true;
        }
    }
    for (i, inst) in scene.instances.iter().enumerate() {
        if !placed_instances[i] {
            spawn_instance(commands, scene, i, transform_from_matrix(inst.transform), root);
        }
    }
    for (light, _) in scene.lights.iter().zip(&placed_lights).filter(|(_, placed)| !**placed) {
        spawn_light(commands, light, Transform::from_translation(light.position), false, root);
    }
    for l in &scene.directional_lights {
        let rotation =
            Quat::from_rotation_arc(Vec3::NEG_Z, l.direction.try_normalize().unwrap_or(Vec3::NEG_Z));
        let light = DirectionalLight {
            color: from_linear_rgb(l.color),
            illuminance: l.illuminance,
            ..Default::default()
        };
        commands.spawn((Transform::from_rotation(rotation), light, ChildOf(root)));
    }
    if spawn_camera && !camera_placed {
        let cam = scene.camera_or_fit(aspect);
        let camera = commands
            .spawn((transform_from_matrix(cam.transform), Camera3d, Projection::from(cam.projection)))
            .id();
        if !scene.cameras.is_empty() {
            commands.entity(camera).insert(ChildOf(root));
        }
    }
    root
}

/// Spawns instance `index` of `scene` at `transform` under `parent`; false (with a warning)
/// when it refers to a missing mesh or material.
fn spawn_instance(
    commands: &mut Commands,
    scene: &Scene,
    index: usize,
    transform: Transform,
    parent: Entity,
) -> bool {
    let Some(inst) = scene.instances.get(index) else { return false };
    let (Some(mesh), Some(material)) = (scene.meshes.get(inst.mesh), scene.materials.get(inst.material))
    else {
        tracing::warn!("scene `{}`: instance {index} refers to a missing mesh or material", scene.name);
        return false;
    };
    commands.spawn((transform, Mesh3d(mesh.clone()), Material(material.clone()), ChildOf(parent)));
    true
}

/// Spawns scene light `light` under `parent`: a [`PointLight`], or a [`SpotLight`] turned so
/// that its -Z is the cone's direction. `local` places it relative to the parent; a light that
/// hangs from a glTF node (`on_node`) already points down that node's -Z.
fn spawn_light(commands: &mut Commands, light: &SceneLight, local: Transform, on_node: bool, parent: Entity) {
    // Scene lights are in candela (glTF); the components in lumens (Bevy).
    let (color, intensity, range) =
        (from_linear_rgb(light.color), lumens_from_candela(light.intensity), light.radius);
    match &light.shape {
        LightShape::Point => {
            let point = PointLight { color, intensity, range, radius: 0.0, ..Default::default() };
            commands.spawn((local, point, ChildOf(parent)));
        }
        LightShape::Spot(cone) => {
            let mut transform = local;
            if !on_node {
                transform.rotation = Quat::from_rotation_arc(Vec3::NEG_Z, cone.sanitized().direction);
            }
            let spot = SpotLight {
                color,
                intensity,
                range,
                radius: 0.0,
                inner_angle: cone.inner_angle,
                outer_angle: cone.outer_angle,
                ..Default::default()
            };
            commands.spawn((transform, spot, ChildOf(parent)));
        }
    }
}

/// Marks the entity of node `.0` of `Scene::nodes` (spawned by [`spawn_scene`]).
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneNodeIndex(pub usize);

/// Marks the root entity of a spawned [`Scene`]; holds the scene's name.
#[derive(Component, Clone, Debug, PartialEq, Eq)]
pub struct SceneRoot(pub String);

/// Spawns `count` animated lights inside `bounds` (deterministic for a `seed`).
///
/// A `count` past [`manylight_core::MAX_LIGHTS`], or whose entities would not fit the memory
/// available ([`manylight_core::light_count::APP_BYTES_PER_LIGHT`] each), is refused before
/// anything is spawned or allocated. A device holds fewer lights than `MAX_LIGHTS`
/// (`GpuContext::light_limit`): past that, frames fail with `RenderError::BufferTooLarge`.
pub fn spawn_light_rig(
    commands: &mut Commands,
    count: usize,
    bounds: Aabb,
    seed: u64,
) -> Result<(), LightCountError> {
    manylight_core::light_count::check_app_lights(count)?;
    for anim in light_rig(count, bounds, seed)? {
        commands.spawn((
            Transform::from_translation(anim.position_at(0.0)),
            PointLight {
                color: from_linear_rgb(anim.color_at(0.0)),
                intensity: lumens_from_candela(anim.intensity),
                range: anim.radius,
                radius: 0.0,
                ..Default::default()
            },
            LightAnimation(anim),
        ));
    }
    Ok(())
}

/// A scene light as the render side sees it.
pub fn extracted_light(l: &SceneLight) -> ExtractedPointLight {
    ExtractedPointLight {
        position: l.position,
        color: l.color,
        intensity: l.intensity,
        radius: l.radius,
        shape: l.shape,
        shadow: None,
        animation: None,
    }
}

/// Turns shadows on or off for every point, spot and directional light of `world` (glTF has
/// no shadow flag: the CLI's `--shadows on|off` and the examples decide for a whole scene).
/// Biases are left as they are.
pub fn set_shadows(world: &mut World, enabled: bool) {
    let mut points = world.query::<&mut PointLight>();
    for mut l in points.iter_mut(world) {
        l.shadows_enabled = enabled;
    }
    let mut spots = world.query::<&mut SpotLight>();
    for mut l in spots.iter_mut(world) {
        l.shadows_enabled = enabled;
    }
    let mut suns = world.query::<&mut DirectionalLight>();
    for mut l in suns.iter_mut(world) {
        l.shadows_enabled = enabled;
    }
}

/// `light` casting a shadow with the biases Bevy gives its kind (`shadows`), or not.
pub fn with_shadow(mut light: ExtractedPointLight, shadows: bool) -> ExtractedPointLight {
    light.shadow = shadows.then_some(ShadowBias::for_shape(light.shape));
    light
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
    let directional_lights = scene
        .directional_lights
        .iter()
        .map(|l| ExtractedDirectionalLight {
            direction: l.direction,
            color: l.color,
            illuminance: l.illuminance,
            shadow: None,
        })
        .collect();
    FrameSnapshot {
        directional_lights,
        extract_cpu_ms: 0.0,
        elapsed_secs: 0.0,
        frame_index,
        viewport: size,
        views: vec![ExtractedView::main(ExtractedCamera {
            world_from_view: cam.transform,
            projection: cam.projection,
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
            exposure: None,
            environment: None,
            skybox: None,
        })],
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
        lights: lights.into(),
        settings,
        pixel_light_lists: None,
        environments: Default::default(),
    }
}

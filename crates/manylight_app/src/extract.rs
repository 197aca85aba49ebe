//! Extract: copy what rendering needs out of the ECS world into a [`FrameSnapshot`] and hand
//! it to the render side. Mesh and material data travel as `Arc`s (no copy of the data).

use crate::backend::{RenderBackend, record_results};
use crate::components::{
    Bloom, Camera, Camera3d, CameraDebugView, CameraShadows, CascadeShadowConfig, DirectionalLight,
    EnvironmentMapLight, Exposure, GlobalTransform, InheritedVisibility, LightAnimation, Material, Mesh3d,
    MotionBlur, PointLight, Projection, RenderTarget, Skybox, SpotLight, Transform, from_linear_rgb,
    linear_rgb,
};
use crate::resources::{
    DebugView, EnvironmentImages, HeadlessCapture, LightAnimationMode, RenderFailure, RenderSettings,
    ViewportSize,
};
use crate::stages::{ExtractedCameraComponents, RenderStages};
use bevy_app::AppExit;
use bevy_ecs::hierarchy::ChildOf;
use bevy_ecs::prelude::*;
use bevy_ecs::query::QueryData;
use bevy_ecs::system::SystemParam;
use bevy_time::Time;
use glam::Mat4;
use manylight_core::{LightShape, MaterialData, SpotCone, candela_from_lumens};
use manylight_render::{
    ExtractedCamera, ExtractedDirectionalLight, ExtractedInstance, ExtractedPointLight, ExtractedView,
    FrameSnapshot, PointLights, ViewComponents, ViewRect, ViewTarget,
};
use std::collections::HashMap;
use std::sync::Arc;

/// State the extract system keeps between frames.
#[derive(Default)]
pub struct ExtractState {
    /// Each camera's last frame: motion blur projects with its placement and projection.
    prev_cameras: HashMap<Entity, ExtractedCamera>,
    frame_index: u64,
    default_material: Option<Arc<MaterialData>>,
    /// The point and spot lights, kept from frame to frame.
    lights: LightSlots,
}

/// The shown point and spot lights as extraction keeps them between frames: one slot per light
/// entity in a [`PointLights`] list, updated from change detection, so a frame visits and
/// copies only the lights that changed (and the renderer uploads only those). A light that is
/// despawned, hidden or loses its light component leaves its slot to the last light, which
/// moves there.
#[derive(Default)]
struct LightSlots {
    lights: PointLights,
    slot_of: bevy_ecs::entity::EntityHashMap<usize>,
    entity_at: Vec<Entity>,
}

impl LightSlots {
    /// Puts `entity`'s light in its slot (a new one at the end), or frees the slot (`None`).
    fn set(&mut self, entity: Entity, light: Option<ExtractedPointLight>) {
        match (self.slot_of.get(&entity).copied(), light) {
            (Some(slot), Some(light)) => {
                self.lights.set(slot, light);
            }
            (None, Some(light)) => {
                self.slot_of.insert(entity, self.lights.len());
                self.entity_at.push(entity);
                self.lights.push(light);
            }
            (Some(slot), None) => {
                self.slot_of.remove(&entity);
                let (Some(last), Some(last_entity)) = (self.lights.pop(), self.entity_at.pop()) else {
                    return;
                };
                if slot < self.lights.len() {
                    self.lights.set(slot, last);
                    self.entity_at[slot] = last_entity;
                    self.slot_of.insert(last_entity, slot);
                }
            }
            (None, None) => {}
        }
    }
}

/// What extract reads of a camera: which one, placement, projection, target and order, and
/// its opt-in effects.
#[derive(QueryData)]
pub struct CameraItem {
    /// The camera's entity (its last frame's matrix is kept by it).
    pub entity: Entity,
    /// Where it looks from.
    pub transform: &'static GlobalTransform,
    /// Its projection.
    pub projection: &'static Projection,
    /// Target, viewport, order and whether it is active (the default without one).
    pub camera: Option<&'static Camera>,
    /// Bloom on its image.
    pub bloom: Option<&'static Bloom>,
    /// Motion blur on its image.
    pub motion_blur: Option<&'static MotionBlur>,
    /// Its own debug view.
    pub debug_view: Option<&'static CameraDebugView>,
    /// Its exposure.
    pub exposure: Option<&'static Exposure>,
    /// The environment that lights what it sees.
    pub environment: Option<&'static EnvironmentMapLight>,
    /// The panorama behind its geometry.
    pub skybox: Option<&'static Skybox>,
    /// Its shadows checkbox (shadows shown without one).
    pub shadows: Option<&'static CameraShadows>,
}

/// What extract reads of a mesh entity (hidden ones are skipped).
pub type MeshItem = (
    &'static GlobalTransform,
    &'static Mesh3d,
    Option<&'static Material>,
    Option<&'static InheritedVisibility>,
);

/// What extract reads of a point or spot light entity (hidden ones are skipped): its
/// animation, and whether it has a parent, say whether it animates on the GPU.
pub type LightItem = (
    Entity,
    &'static GlobalTransform,
    AnyOf<(&'static PointLight, &'static SpotLight)>,
    Option<&'static InheritedVisibility>,
    Option<&'static LightAnimation>,
    Has<ChildOf>,
);

/// What extract reads of a directional light entity (hidden ones are skipped; an entity with a
/// point or spot light too is that light).
pub type DirectionalItem = (
    &'static GlobalTransform,
    &'static DirectionalLight,
    Option<&'static InheritedVisibility>,
    Option<&'static CascadeShadowConfig>,
);

/// The change that makes extraction look at a point or spot light again.
pub type LightChanged =
    Or<(Changed<GlobalTransform>, Changed<PointLight>, Changed<SpotLight>, Changed<InheritedVisibility>)>;

/// The changes that also make extraction look at a light again while lights animate on the GPU
/// ([`LightAnimationMode::Gpu`]: whether a light does depends on them). Not read otherwise, so
/// that a frame's scan for changes reads no more tick columns than it needs.
pub type AnimationChanged = Or<(Changed<LightAnimation>, Changed<ChildOf>)>;

/// Whether an entity's computed visibility lets it render (none computed yet: visible).
fn shown(visibility: Option<&InheritedVisibility>) -> bool {
    visibility.is_none_or(|v| v.0)
}

/// What extraction reads of the main world.
#[derive(SystemParam)]
pub struct ExtractInputs<'w, 's> {
    viewport: Res<'w, ViewportSize>,
    settings: Res<'w, RenderSettings>,
    time: Res<'w, Time>,
    animation_mode: Res<'w, LightAnimationMode>,
    debug: Res<'w, DebugView>,
    cameras: Query<'w, 's, CameraItem, With<Camera3d>>,
    meshes: Query<'w, 's, MeshItem>,
    /// Point and spot lights that changed since the last extraction (added included).
    changed_lights: Query<'w, 's, LightItem, LightChanged>,
    /// Lights whose animation or parent changed (read with [`LightAnimationMode::Gpu`]).
    changed_animations: Query<'w, 's, LightItem, AnimationChanged>,
    /// Every point and spot light (looked up when one lost a light component).
    lights: Query<'w, 's, LightItem>,
    removed_points: RemovedComponents<'w, 's, PointLight>,
    removed_spots: RemovedComponents<'w, 's, SpotLight>,
    directional_lights: Query<'w, 's, DirectionalItem, (Without<PointLight>, Without<SpotLight>)>,
    environments: Option<Res<'w, EnvironmentImages>>,
}

/// Builds the frame's snapshot from the world; the components an app extracts per camera are
/// in `camera_components`.
pub fn build_snapshot(
    state: &mut ExtractState,
    world: &mut ExtractInputs,
    camera_components: &mut HashMap<Entity, ViewComponents>,
) -> FrameSnapshot {
    let viewport = world.viewport.0;
    let views = extract_views(state, viewport, &world.cameras, camera_components);
    let instances = extract_instances(state, &world.meshes);
    update_lights(&mut state.lights, world);
    let snapshot = FrameSnapshot {
        frame_index: state.frame_index,
        viewport,
        environments: used_environments(&views, world.environments.as_deref()),
        views,
        instances,
        // Shares every chunk no light of which changed with the frames before.
        lights: state.lights.lights.clone(),
        directional_lights: extract_directional_lights(&world.directional_lights),
        settings: crate::resources::frame_settings(&world.settings, &world.debug),
        pixel_light_lists: None,
        extract_cpu_ms: 0.0,
        elapsed_secs: world.time.elapsed_secs(),
    };
    state.frame_index += 1;
    snapshot
}

/// The panoramas the views' environments and skyboxes name (none, and no allocation, when no
/// camera has either).
fn used_environments(views: &[ExtractedView], images: Option<&EnvironmentImages>) -> EnvironmentImages {
    let mut used = EnvironmentImages::default();
    let Some(images) = images else { return used };
    for (handle, image) in images.iter() {
        let named = views.iter().any(|v| {
            v.camera.environment.is_some_and(|e| e.image == handle)
                || v.camera.skybox.is_some_and(|s| s.image == handle)
        });
        if named {
            used.insert(handle, image.clone());
        }
    }
    used
}

/// One view per active camera, lowest order first, each with its last frame's matrix (kept in
/// `state` for the next frame) and the components extracted for it; the components of
/// cameras that rendered nothing this frame are dropped.
fn extract_views(
    state: &mut ExtractState,
    viewport: glam::UVec2,
    cameras: &Query<CameraItem, With<Camera3d>>,
    camera_components: &mut HashMap<Entity, ViewComponents>,
) -> Vec<ExtractedView> {
    let mut views: Vec<ExtractedView> = Vec::with_capacity(cameras.iter().len());
    // Last frame's cameras; the map is rebuilt from this frame's, so removed ones go.
    let prev_cameras = std::mem::take(&mut state.prev_cameras);
    for item in cameras.iter() {
        let (entity, t) = (item.entity, item.transform);
        let camera = item.camera.copied().unwrap_or_default();
        if !camera.is_active {
            continue;
        }
        let (target, target_size) = match camera.target {
            RenderTarget::Window => (ViewTarget::Main, viewport),
            RenderTarget::Image(image) => {
                (ViewTarget::Texture { id: image.id, size: image.size }, image.size)
            }
        };
        let rect = camera.viewport.map(|v| ViewRect { origin: v.physical_position, size: v.physical_size });
        let mut view = ExtractedView {
            camera: ExtractedCamera {
                // Placement only: a camera's scale (its own or a parent's) does not zoom the view.
                world_from_view: {
                    let (_, rotation, translation) = t.to_scale_rotation_translation();
                    Mat4::from_rotation_translation(rotation, translation)
                },
                projection: item.projection.params(),
                prev_clip_from_world: None,
                bloom: item.bloom.copied(),
                motion_blur: item.motion_blur.copied(),
                exposure: item.exposure.copied(),
                environment: item.environment.copied(),
                skybox: item.skybox.copied(),
            },
            target,
            rect,
            debug_view: item.debug_view.map(|d| d.0),
            order: camera.order,
            shadows: item.shadows.is_none_or(|s| s.enabled),
            components: camera_components.remove(&entity).unwrap_or_default(),
        };
        // Last frame's camera at this frame's size: a resize alone moves no pixel, so motion
        // blur does not smear the first frame after one.
        let size = view.rect_in(target_size).size;
        view.camera.prev_clip_from_world = prev_cameras.get(&entity).map(|p| p.clip_from_world(size));
        state.prev_cameras.insert(entity, view.camera);
        views.push(view);
    }
    // Components of cameras that rendered nothing this frame are not kept for the next.
    camera_components.clear();
    // Lower order first; equal orders keep query order.
    views.sort_by_key(|v| v.order);
    views
}

/// Every shown mesh entity as an instance (without a material: the default one, made once
/// and kept in `state`).
fn extract_instances(state: &mut ExtractState, meshes: &Query<MeshItem>) -> Vec<ExtractedInstance> {
    let default_material =
        state.default_material.get_or_insert_with(|| Arc::new(MaterialData::default())).clone();
    meshes
        .iter()
        .filter(|(.., visibility)| shown(*visibility))
        .map(|(t, mesh, material, _)| ExtractedInstance {
            mesh: mesh.0.clone(),
            material: material.map_or_else(|| default_material.clone(), |m| m.0.clone()),
            world_from_local: t.to_matrix(),
        })
        .collect()
}

/// Whether a light animates on the GPU in `mode` ([`LightAnimationMode::Gpu`]): an animated
/// point light that casts no shadow and has no parent.
pub fn animates_on_gpu(
    mode: LightAnimationMode,
    animation: Option<&LightAnimation>,
    point: Option<&PointLight>,
    has_parent: bool,
) -> bool {
    mode == LightAnimationMode::Gpu
        && animation.is_some()
        && point.is_some_and(|p| !p.shadows_enabled)
        && !has_parent
}

/// A shown point or spot light entity as the renderer takes it (`None` when hidden). Point and
/// spot lights come in lumens (Bevy's unit) and render in candela; a point light wins over a
/// spot light on the same entity. A light that animates on the GPU in `mode` carries its
/// animation (its position and colour are the animation's centre and base colour).
fn point_light(
    (_, t, (point, spot), visibility, animation, has_parent): <LightItem as QueryData>::Item<'_, '_>,
    mode: LightAnimationMode,
) -> Option<ExtractedPointLight> {
    if !shown(visibility) {
        return None;
    }
    let (color, lumens, range, shape, shadow) = match (point, spot) {
        (Some(l), _) => (linear_rgb(l.color), l.intensity, l.range, LightShape::Point, l.shadow()),
        (None, Some(l)) => {
            let direction = t.forward().into();
            let cone = SpotCone { direction, inner_angle: l.inner_angle, outer_angle: l.outer_angle };
            (linear_rgb(l.color), l.intensity, l.range, LightShape::Spot(cone), l.shadow())
        }
        (None, None) => return None,
    };
    let animation = animation.filter(|_| animates_on_gpu(mode, animation, point, has_parent)).map(|a| a.0);
    Some(ExtractedPointLight {
        position: animation.map_or_else(|| t.translation(), |a| a.center),
        color: animation.map_or(color, |a| a.color),
        intensity: candela_from_lumens(lumens),
        radius: range,
        shape,
        shadow,
        animation: animation.map(Arc::new),
    })
}

/// Brings the kept lights up to date: the lights that changed since the last extraction (the
/// first time, all of them) and the entities that lost their light component or were
/// despawned. Visits no light that did not change.
/// A change of [`LightAnimationMode`] takes every animated light again.
fn update_lights(slots: &mut LightSlots, world: &mut ExtractInputs) {
    let mode = *world.animation_mode;
    if world.animation_mode.is_changed() && !world.animation_mode.is_added() {
        for item in world.lights.iter().filter(|item| item.4.is_some()) {
            let entity = item.0;
            slots.set(entity, point_light(item, mode));
        }
    }
    for item in &world.changed_lights {
        let entity = item.0;
        slots.set(entity, point_light(item, mode));
    }
    if mode == LightAnimationMode::Gpu {
        for item in &world.changed_animations {
            let entity = item.0;
            slots.set(entity, point_light(item, mode));
        }
    }
    let removed: Vec<Entity> = world.removed_points.read().chain(world.removed_spots.read()).collect();
    for entity in removed {
        // Still a light when it lost only one of the two components.
        let light = world.lights.get(entity).ok().and_then(|item| point_light(item, mode));
        slots.set(entity, light);
    }
}

/// Every shown directional light, in query order.
fn extract_directional_lights(
    lights: &Query<DirectionalItem, (Without<PointLight>, Without<SpotLight>)>,
) -> Vec<ExtractedDirectionalLight> {
    lights
        .iter()
        .filter(|(_, _, visibility, _)| shown(*visibility))
        .map(|(t, l, _, cascades)| ExtractedDirectionalLight {
            direction: t.forward().into(),
            color: linear_rgb(l.color),
            illuminance: l.illuminance,
            shadow: l.shadow(cascades.copied().unwrap_or_default()),
        })
        .collect()
}

/// The extract system (runs in `Last`, in [`crate::ManyLightSystems::Extract`]): takes the
/// snapshot and hands it to the renderer; [`collect_results`] runs right after it.
pub fn extract_and_render(
    mut state: Local<ExtractState>,
    mut inputs: ExtractInputs,
    mut backend: ResMut<RenderBackend>,
    capture: Res<HeadlessCapture>,
    failure: Res<RenderFailure>,
    (stages, mut components): (Res<RenderStages>, ResMut<ExtractedCameraComponents>),
) {
    if failure.0.is_some() {
        return;
    }
    let start = web_time::Instant::now();
    let mut snapshot = build_snapshot(&mut state, &mut inputs, &mut components.0);
    snapshot.extract_cpu_ms = start.elapsed().as_secs_f64() * 1e3;
    // The stages travel with each frame (an `Arc`, shared until the app changes them).
    backend.submit(snapshot, capture.enabled, stages.0.clone());
}

/// Stores the frames that finished since the last update ([`crate::backend::record_results`])
/// and ends the app with `AppExit::error()` when one failed (runs after [`extract_and_render`]).
pub fn collect_results(world: &mut World) {
    if world.resource::<RenderFailure>().0.is_some() {
        return;
    }
    let results = world.resource_mut::<RenderBackend>().drain();
    if record_results(world, results) {
        world.write_message(AppExit::error());
    }
}

/// Moves and tints lights that carry a [`LightAnimation`], at [`Time`]'s elapsed seconds (a
/// fixed step headless, wall time in a window), except those a compute pass animates
/// ([`LightAnimationMode::Gpu`], [`animates_on_gpu`]).
pub fn animate_lights(
    time: Res<Time>,
    mode: Res<LightAnimationMode>,
    mut lights: Query<(&LightAnimation, &mut Transform, &mut PointLight, Has<ChildOf>)>,
) {
    let t = time.elapsed_secs();
    for (anim, mut transform, mut light, has_parent) in &mut lights {
        if animates_on_gpu(*mode, Some(anim), Some(&light), has_parent) {
            continue;
        }
        transform.translation = anim.0.position_at(t);
        light.color = from_linear_rgb(anim.0.color_at(t));
    }
}

//! Scenes for manylight: glTF loading, the embedded procedural default scene, light rigs.
//!
//! A [`Scene`] is plain data (meshes, materials, instances, lights, cameras) that the app turns
//! into ECS entities; mesh and texture data are `Arc`s so they travel to the render thread once.
#![warn(missing_docs)]

mod default_scene;
pub mod environment;
mod error;
mod gltf_loader;
mod light_rig;
mod scene_ops;
pub mod shapes;
mod textures;

pub use default_scene::default_scene;
#[cfg(not(target_arch = "wasm32"))]
pub use environment::load_environment;
pub use environment::{DecodedEnvironment, EnvironmentBudget, EnvironmentError, decode_environment};
pub use error::SceneError;
pub use gltf_loader::{
    FetchedFiles, LoadOptions, MAX_DOWNSCALED_SOURCE, OversizedTextures, ReferencedFile,
    blinn_phong_from_pbr, load_gltf, load_gltf_fetched, referenced_files,
};
pub use light_rig::{
    AnimatedLight, RIG_RADIUS_K, SHELL_LIGHT_RANGE, SHELL_RADIUS, SplitMix64, animated_light_at,
    intensity_for_radius, light_rig, rig_bounds, sphere_shell_lights, sphere_shell_scene, studio_lights,
};
pub use scene_ops::{camera_looking_at, load_scene};

use glam::{Mat4, Vec3};
use manylight_core::{MaterialData, MeshData, Projection};
use std::sync::Arc;

/// A loaded or generated scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Name for logs (file name or generator name).
    pub name: String,
    /// Mesh data, referenced by index from `instances`.
    pub meshes: Vec<Arc<MeshData>>,
    /// Materials, referenced by index from `instances`.
    pub materials: Vec<Arc<MaterialData>>,
    /// Drawn objects.
    pub instances: Vec<SceneInstance>,
    /// Point and spot lights that come with the scene.
    pub lights: Vec<SceneLight>,
    /// Directional lights that come with the scene (glTF `directional`).
    pub directional_lights: Vec<SceneDirectionalLight>,
    /// Cameras that come with the scene (glTF cameras); may be empty.
    pub cameras: Vec<SceneCamera>,
    /// The node tree the instances, lights and cameras hang from (glTF nodes), parents before
    /// children; empty for generated scenes. The world transforms above stay authoritative:
    /// composing the nodes' `local` transforms from the root gives them.
    pub nodes: Vec<SceneNode>,
}

/// A node of a scene's tree: a local transform under its parent, and what hangs from it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneNode {
    /// The node's name in the file, if it has one.
    pub name: Option<String>,
    /// Index of the parent in `Scene::nodes` (always lower than the node's own), or `None` for
    /// a root of the scene.
    pub parent: Option<usize>,
    /// Parent-from-node transform (TRS or the node's matrix).
    pub local: Mat4,
    /// Indices into `Scene::instances` drawn at this node (one per triangle primitive).
    pub instances: Vec<usize>,
    /// Indices into `Scene::lights` placed at this node.
    pub lights: Vec<usize>,
    /// Indices into `Scene::cameras` placed at this node.
    pub cameras: Vec<usize>,
}

/// One drawn object: a mesh with a material at a world transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneInstance {
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// World-from-object transform.
    pub transform: Mat4,
}

/// A point light in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLight {
    /// World position.
    pub position: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Luminous intensity in candela (glTF `KHR_lights_punctual`'s unit), multiplying `color`.
    pub intensity: f32,
    /// Distance at which the light's contribution reaches exactly zero.
    pub radius: f32,
    /// Every direction (a point light) or a cone (a spot light).
    pub shape: manylight_core::LightShape,
}

/// A light travelling along one direction everywhere (the sun): not clustered, it reaches
/// every pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneDirectionalLight {
    /// Unit direction the light travels, in world space (a glTF directional light shines down
    /// its node's local -Z).
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Illuminance (lux in glTF), multiplying `color`.
    pub illuminance: f32,
}

/// A camera placement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneCamera {
    /// World-from-camera transform; the camera looks down its local -Z with +Y up.
    pub transform: Mat4,
    /// Perspective or orthographic parameters.
    pub projection: Projection,
}

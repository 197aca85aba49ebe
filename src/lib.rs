//! manylight: many-light rendering (naive forward today; Forward+, clustered and deferred
//! pipelines next) as a `bevy_app` plugin on wgpu.
//!
//! Add [`prelude::ManyLightPlugin`] to an `App`, spawn entities with `Transform`, `Camera3d`,
//! `PointLight`, `Mesh3d` and `Material`, and run: you get a window, or a headless image.
//! See `examples/add_as_plugin.rs`.

pub use manylight_app as app;
pub use manylight_core as core;
pub use manylight_render as render;
pub use manylight_scene as scene;

/// Everything an app needs in scope.
pub mod prelude {
    pub use manylight_app::prelude::*;
    pub use manylight_scene::{LoadOptions, Scene, default_scene, load_gltf, load_scene};
}

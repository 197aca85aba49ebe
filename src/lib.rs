//! manylight: rendering scenes lit by thousands of moving point lights, as a `bevy_app` plugin
//! on wgpu. Six pipelines produce the same image: naive forward (the reference), tiled
//! Forward+, clustered forward (the default), clustered deferred, tiled deferred (in compute)
//! and deferred light volumes.
//!
//! Add [`prelude::ManyLightPlugin`] to an `App`, spawn entities with `Transform`, `Camera3d`,
//! `PointLight`, `Mesh3d` and `Material`, and run: you get a window, or a headless image.
//! See `examples/add_as_plugin.rs`, `docs/guide.md` (how to use it) and `docs/architecture.md`
//! (how it is built).
#![warn(missing_docs)]

pub use manylight_app as app;
/// Pure math and plain data (`manylight_core`): clusters, lights, materials, meshes, codecs and
/// the oracles; named `math` so that it does not shadow Rust's `core` in paths.
pub use manylight_core as math;
pub use manylight_render as render;
pub use manylight_scene as scene;

/// Everything an app needs in scope.
pub mod prelude {
    pub use manylight_app::prelude::*;
    pub use manylight_scene::{LoadOptions, Scene, default_scene, load_gltf, load_scene};
}

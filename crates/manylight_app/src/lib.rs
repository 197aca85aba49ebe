//! The bevy_app side of manylight: components, resources, the extract step, the render thread,
//! the window and the headless runner.
//!
//! ```no_run
//! use manylight_app::prelude::*;
//! App::new()
//!     .add_plugins(ManyLightPlugin::headless(UVec2::new(256, 256)))
//!     .add_systems(Startup, |mut commands: Commands| {
//!         commands.spawn((Transform::from_xyz(0.0, 1.0, 5.0), Camera3d));
//!         commands.spawn((Transform::from_xyz(0.0, 2.0, 0.0), PointLight::default()));
//!     })
//!     .run();
//! ```
#![warn(missing_docs)]

pub mod backend;
pub mod cli;
pub mod components;
pub mod extract;
pub mod headless;
pub mod plugin;
pub mod render_world;
pub mod resources;
pub mod scene;
pub mod stages;
pub mod visibility;
pub mod window;

pub use backend::RenderFailed;
pub use components::{
    Bloom, Camera, Camera3d, CameraDebugView, CameraShadows, CascadeShadowConfig, CascadeShadowConfigBuilder,
    Color, DirectionalLight, EnvironmentMapLight, Exposure, GlobalTransform, InheritedVisibility,
    LightAnimation, Material, Mesh3d, MotionBlur, OrthographicProjection, PerspectiveProjection, PointLight,
    Projection, RenderImage, RenderTarget, Skybox, SpotLight, Transform, Viewport, Visibility,
    from_linear_rgb, linear_rgb,
};
pub use plugin::{HEADLESS_TIME_STEP, HeadlessConfig, ManyLightPlugin, ManyLightSystems, OutputMode};
pub use resources::{
    DebugView, EnvironmentImages, FrameStats, FrameTotals, FramesInFlight, HeadlessCapture,
    LightAnimationMode, LightControls, RenderFailure, RenderSettings, RenderedImages, ViewportSize,
};
pub use window::{Overlay, PressedKeys, WindowConfig, WindowRequests};

/// What an app needs in scope to use manylight.
pub mod prelude {
    /// `T::default()`, as Bevy's prelude has it: `Camera { order: 1, ..default() }`.
    pub fn default<T: Default>() -> T {
        T::default()
    }

    pub use crate::components::{
        Bloom, Camera, Camera3d, CameraDebugView, CameraShadows, CascadeShadowConfig,
        CascadeShadowConfigBuilder, Color, DirectionalLight, EnvironmentMapLight, Exposure, GlobalTransform,
        InheritedVisibility, LightAnimation, Material, Mesh3d, MotionBlur, OrthographicProjection,
        PerspectiveProjection, PointLight, Projection, RenderImage, RenderTarget, Skybox, SpotLight,
        Transform, Viewport, Visibility,
    };
    pub use crate::plugin::{ManyLightPlugin, ManyLightSystems};
    pub use crate::resources::{
        DebugView, EnvironmentImages, FrameStats, HeadlessCapture, LightAnimationMode, LightControls,
        RenderSettings, RenderedImages,
    };
    pub use crate::scene::{spawn_light_rig, spawn_scene};
    pub use crate::stages::{ExtractCameraComponentPlugin, ManyLightAppExt, RenderStages};
    pub use crate::window::{Overlay, PressedKeys, WindowConfig, WindowRequests};
    pub use bevy_app::prelude::*;
    pub use bevy_ecs::prelude::*;
    pub use bevy_time::{Time, TimeUpdateStrategy};
    pub use glam::{Quat, UVec2, Vec2, Vec3};
    pub use manylight_core::cluster::{CullTest, GridConfig, ZSlicing};
    pub use manylight_core::codec::NormalCodec;
    pub use manylight_core::{
        ColorToComponents, LightCountError, LinearRgba, MaterialData, MeshData, ShadingModel,
    };
    pub use manylight_render::{
        BloomChain, ClusterSettings, DebugViewMode, GBufferLayout, Pass, PassContext, PipelineKind,
        PlanInputs, RenderError, ResourceName, Stage, StageError, TextureSpec,
    };
}

//! How frames are rendered: the plain settings an app chooses, shared by the snapshot, the
//! passes that read them and, through the `bevy` feature, the app's resources and components.
//! One file per question:
//!
//! - `render.rs`: what a frame is rendered with ([`RenderSettings`], [`FrameSettings`]);
//! - `pipeline.rs`: which many-light pipeline, G-buffer layout and cluster setup
//!   ([`PipelineKind`], [`GBufferLayout`], [`ClusterSettings`]);
//! - `debug_view.rs`: what the debug view shows ([`DebugViewMode`]);
//! - `camera.rs`: what a camera carries (bloom, exposure, motion blur, its shadows checkbox);
//! - `environment.rs`: image-based lighting and the skybox ([`EnvironmentMapLight`],
//!   [`Skybox`], [`EnvironmentImages`], [`EnvironmentFilter`]);
//! - `shadows.rs`: how shadows are sized and filtered, a directional light's cascades, and
//!   what the frame's shadows took ([`ShadowSettings`], [`CascadeShadowConfig`],
//!   [`ShadowReport`]).

mod camera;
mod debug_view;
mod environment;
mod pipeline;
mod render;
mod shadows;

pub use camera::{BloomChain, BloomSettings, CameraShadows, Exposure, MAX_BLOOM_LEVELS, MotionBlurSettings};
pub use debug_view::DebugViewMode;
pub use environment::{
    ENVIRONMENT_SPECULAR_MIPS, EnvironmentFilter, EnvironmentHandle, EnvironmentImages, EnvironmentMapLight,
    Skybox,
};
pub use pipeline::{ClusterSettings, DEFAULT_COARSE_TILES, GBufferLayout, PipelineKind};
pub use render::{FrameSettings, RenderSettings};
pub use shadows::{
    CascadeConfigError, CascadeShadowConfig, CascadeShadowConfigBuilder, MAX_CASCADES, SHADOW_FACES,
    SHADOW_TILE_COLUMNS, ShadowFilteringMethod, ShadowMethod, ShadowReport, ShadowSettings,
};

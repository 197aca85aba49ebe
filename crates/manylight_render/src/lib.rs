//! The wgpu side of manylight: GPU context, render graph, passes, timing and readback.
//!
//! It consumes a plain [`FrameSnapshot`] and knows nothing of bevy: tests and benchmarks can
//! drive it directly. The app crate decides which passes a frame needs.
//!
//! The documented API is what this page lists: the types re-exported here (settings, the
//! snapshot, the frame report, the context) and [`ext`], everything an app needs to add a
//! pass of its own. The modules behind them are the renderer's internals: public for manylight's
//! own crates and its benchmark CLI, hidden from these docs, and free to change between
//! releases.
#![warn(missing_docs)]

/// The wgpu this crate renders with, for passes an app writes (the same version, no second
/// dependency to keep in step).
pub use wgpu;

#[doc(hidden)]
pub mod animation;
#[doc(hidden)]
pub mod assets;
#[doc(hidden)]
pub mod atlas;
#[doc(hidden)]
pub mod bindings;
#[doc(hidden)]
pub mod clusters;
#[doc(hidden)]
pub mod context;
#[doc(hidden)]
pub mod environment;
pub mod ext;
#[doc(hidden)]
pub mod gpu_types;
#[doc(hidden)]
pub mod graph;
#[doc(hidden)]
pub mod inflight;
#[doc(hidden)]
pub mod layouts;
#[doc(hidden)]
pub mod lights;
#[doc(hidden)]
pub mod passes;
#[doc(hidden)]
pub mod pipelines;
#[doc(hidden)]
pub mod plan;
#[doc(hidden)]
pub mod planner;
#[doc(hidden)]
pub mod pool;
#[doc(hidden)]
pub mod ray_geometry;
#[doc(hidden)]
pub mod readback;
#[doc(hidden)]
pub mod renderer;
#[doc(hidden)]
pub mod resources;
#[doc(hidden)]
pub mod settings;
#[doc(hidden)]
pub mod shaders;
#[doc(hidden)]
pub mod shadow_probe;
#[doc(hidden)]
pub mod shadows;
#[doc(hidden)]
pub mod snapshot;
#[doc(hidden)]
pub mod stats;
#[doc(hidden)]
pub mod texture_lists;

pub use context::{GpuContext, GpuCounts, NO_ADAPTER_HELP, RenderError};
pub use graph::{
    NamedPass, OUTPUT, Pass, PassContext, PostProcessWrite, RenderGraph, ResourceName, TextureSpec,
};
pub use inflight::{DEFAULT_FRAMES_IN_FLIGHT, MAX_FRAMES_IN_FLIGHT};
pub use plan::PlanInputs;
pub use planner::{FramePlanner, Stage, StageError, StageId, builtin_stages};
pub use readback::{HEADLESS_FORMAT, HeadlessTarget};
pub use renderer::Renderer;
pub use settings::{
    CameraShadows, CascadeShadowConfig, CascadeShadowConfigBuilder, ShadowFilteringMethod, ShadowMethod,
};
pub use shadows::{ShadowReport, ShadowSettings};
pub use snapshot::{
    BloomChain, BloomSettings, ClusterSettings, DEFAULT_COARSE_TILES, DebugViewMode, DirectionalShadow,
    EnvironmentFilter, EnvironmentHandle, EnvironmentImages, EnvironmentMapLight, Exposure, ExtractedCamera,
    ExtractedDirectionalLight, ExtractedInstance, ExtractedPointLight, ExtractedView, FrameSettings,
    FrameSnapshot, GBufferLayout, LIGHT_CHUNK, LightChunk, MotionBlurSettings, PipelineKind, PointLights,
    RenderSettings, RenderTextureId, RenderView, ShadowBias, Skybox, ViewComponents, ViewRect, ViewTarget,
};
pub use stats::{CpuPhases, FrameReport, PassTiming, ViewReport};

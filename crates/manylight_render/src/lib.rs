//! The wgpu side of manylight: GPU context, render graph, passes, timing and readback.
//!
//! It consumes a plain [`FrameSnapshot`] and knows nothing of bevy: tests and benchmarks can
//! drive it directly. The app crate decides which passes a frame needs.
#![warn(missing_docs)]

/// The wgpu this crate renders with, for passes an app writes (the same version, no second
/// dependency to keep in step).
pub use wgpu;

pub mod animation;
pub mod assets;
pub mod atlas;
pub mod bindings;
pub mod clusters;
pub mod context;
pub mod ext;
pub mod gpu_types;
pub mod graph;
pub mod inflight;
pub mod layouts;
pub mod lights;
pub mod passes;
pub mod pipelines;
pub mod plan;
pub mod planner;
pub mod pool;
pub mod readback;
pub mod renderer;
pub mod resources;
pub mod settings;
pub mod shaders;
pub mod shadow_probe;
pub mod shadows;
pub mod snapshot;
pub mod stats;
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
pub use settings::{CameraShadows, CascadeShadowConfig, CascadeShadowConfigBuilder, ShadowFilteringMethod};
pub use shadows::{ShadowReport, ShadowSettings};
pub use snapshot::{
    BloomChain, BloomSettings, ClusterSettings, DEFAULT_COARSE_TILES, DebugViewMode, DirectionalShadow,
    Exposure, ExtractedCamera, ExtractedDirectionalLight, ExtractedInstance, ExtractedPointLight,
    ExtractedView, FrameSettings, FrameSnapshot, GBufferLayout, LIGHT_CHUNK, LightChunk, MotionBlurSettings,
    PipelineKind, PointLights, RenderSettings, RenderTextureId, RenderView, ShadowBias, ViewComponents,
    ViewRect, ViewTarget,
};
pub use stats::{CpuPhases, FrameReport, PassTiming, ViewReport};

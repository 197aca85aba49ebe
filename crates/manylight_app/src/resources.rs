//! Resources a user reads or changes: settings, statistics, the clock, headless capture.

use bevy_ecs::prelude::*;
use glam::UVec2;
use manylight_core::ShadingModel;
use manylight_render::{ClusterSettings, DebugView, FrameReport, FrameSettings, GBufferLayout, PipelineKind};

/// How frames are rendered; changes apply from the next frame.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// The many-light pipeline.
    pub pipeline: PipelineKind,
    /// Shading model for materials that do not choose one.
    pub shading: ShadingModel,
    /// Multiplier before tone mapping.
    pub exposure: f32,
    /// Constant ambient term (fraction of albedo).
    pub ambient: f32,
    /// Linear colour behind everything.
    pub clear_color: [f32; 3],
    /// Cluster grid, culling test, optional cap and depth pre-pass of the tiled and clustered
    /// pipelines.
    pub clusters: ClusterSettings,
    /// Debug view shown instead of the image (`DebugView::None` for the image).
    pub debug_view: DebugView,
    /// Light count shown as the hottest colour of the light-count heatmap.
    pub debug_heatmap_max: u32,
    /// G-buffer layout of the deferred pipeline.
    pub gbuffer: GBufferLayout,
}

impl Default for RenderSettings {
    fn default() -> Self {
        let f = FrameSettings::default();
        Self {
            pipeline: f.pipeline,
            shading: f.shading,
            exposure: f.exposure,
            ambient: f.ambient,
            clear_color: f.clear_color,
            clusters: f.clusters,
            debug_view: f.debug_view,
            debug_heatmap_max: f.debug_heatmap_max,
            gbuffer: f.gbuffer,
        }
    }
}

impl RenderSettings {
    /// The render side's copy.
    pub fn frame_settings(&self) -> FrameSettings {
        FrameSettings {
            pipeline: self.pipeline,
            shading: self.shading,
            exposure: self.exposure,
            ambient: self.ambient,
            clear_color: self.clear_color,
            clusters: self.clusters,
            debug_view: self.debug_view,
            debug_heatmap_max: self.debug_heatmap_max,
            gbuffer: self.gbuffer,
        }
    }
}

/// The statistics of the most recently finished frame: passes in order with GPU/CPU ms, light
/// count and more (see [`FrameReport`]). In pipelined mode it lags the simulation by a frame.
#[derive(Resource, Clone, Debug, Default)]
pub struct FrameStats {
    /// The last report (None before the first frame finished).
    pub last: Option<FrameReport>,
    /// Frames rendered so far.
    pub frames_rendered: u64,
    /// CPU time of the main-world update that produced the last snapshot.
    pub simulation_cpu_ms: f64,
}

impl FrameStats {
    /// Pass names of the last frame in the order they ran.
    pub fn pass_names(&self) -> Vec<String> {
        self.last.as_ref().map(|r| r.passes.iter().map(|p| p.name.clone()).collect()).unwrap_or_default()
    }
}

/// The frame clock: elapsed time advanced once per update, either by wall time or by a fixed
/// step (headless renders use a fixed step so they are reproducible).
#[derive(Resource, Clone, Copy, Debug)]
pub struct FrameClock {
    /// Seconds since start.
    pub elapsed: f32,
    /// Seconds of the last step.
    pub delta: f32,
    /// Updates so far.
    pub frame: u64,
    /// `Some(step)` advances by a fixed step instead of wall time.
    pub fixed_step: Option<f32>,
    last_instant: Option<std::time::Instant>,
}

impl FrameClock {
    /// A clock driven by wall time.
    pub fn real_time() -> Self {
        FrameClock { elapsed: 0.0, delta: 0.0, frame: 0, fixed_step: None, last_instant: None }
    }

    /// A clock that advances `step` seconds per update.
    pub fn fixed(step: f32) -> Self {
        FrameClock { fixed_step: Some(step), ..Self::real_time() }
    }

    pub(crate) fn tick(&mut self) {
        let now = std::time::Instant::now();
        self.delta = match (self.fixed_step, self.last_instant) {
            (Some(step), _) => step,
            (None, Some(last)) => (now - last).as_secs_f32().min(0.25),
            (None, None) => 0.0,
        };
        self.last_instant = Some(now);
        if self.frame > 0 {
            self.elapsed += self.delta;
        }
        self.frame += 1;
    }
}

/// Size of the render target in pixels (the window's inner size, or the headless size).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewportSize(pub UVec2);

/// Headless output: when `enabled`, each rendered frame is read back into `image`.
#[derive(Resource, Clone, Debug, Default)]
pub struct HeadlessCapture {
    /// Read frames back (costs a copy and a GPU wait per frame).
    pub enabled: bool,
    /// The last frame read back.
    pub image: Option<image::RgbaImage>,
}

/// The error that stopped rendering, if any (the app also receives `AppExit::error()`).
#[derive(Resource, Clone, Debug, Default)]
pub struct RenderFailure(pub Option<String>);

//! The render side of the app: a small render `World` and `Schedule` that, for each
//! [`FrameSnapshot`], run `Prepare` (upload), `Graph` (one system per stage adds its pass only
//! if the snapshot calls for it) and `Execute`. It runs on the render thread (pipelined mode)
//! or on the caller's thread (synchronous mode).

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use manylight_render::passes::{
    ClusterBuildPass, ClusteredForwardPass, DebugViewPass, DeferredLightingPass, DepthPrepass, ForwardPass,
    GBufferPass, LightVolumesPass, MotionBlurPass, TonemapPass,
};
use manylight_render::{
    DebugViewMode, FrameReport, FrameSnapshot, GBufferLayout, GpuContext, HeadlessTarget, PipelineKind,
    RenderError, RenderGraph, Renderer,
};

/// The ordered steps of one rendered frame.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RenderSet {
    /// Upload changed meshes/textures, write light and instance buffers.
    Prepare,
    /// Add the passes the frame needs to the graph.
    Graph,
    /// Record and submit the graph.
    Execute,
}

/// Label of the render schedule.
#[derive(ScheduleLabel, Clone, Debug, PartialEq, Eq, Hash)]
pub struct RenderSchedule;

/// The snapshot being rendered.
#[derive(Resource, Default)]
pub struct CurrentSnapshot(pub FrameSnapshot);

/// The graph being built for this frame.
#[derive(Resource, Default)]
pub struct FrameGraph(pub RenderGraph);

/// The renderer (GPU context and everything that lives across frames).
#[derive(Resource)]
pub struct RendererResource(pub Renderer);

/// Where this frame's `OUTPUT` goes.
#[derive(Resource)]
pub struct OutputTarget {
    /// View of the swapchain image or headless texture.
    pub view: wgpu::TextureView,
    /// Its format.
    pub format: wgpu::TextureFormat,
}

/// Result of the frame's steps.
#[derive(Resource, Default)]
pub struct FrameOutcome {
    /// The report, once executed.
    pub report: Option<FrameReport>,
    /// The first error of the frame.
    pub error: Option<RenderError>,
}

/// A lost device is recreated at most this many times within [`DEVICE_LOSS_WINDOW`] frames;
/// one more loss ends rendering with [`RenderError::DeviceLost`] instead of a device that keeps
/// dying being recreated forever.
pub const MAX_DEVICE_LOSSES: usize = 3;

/// Frames over which [`MAX_DEVICE_LOSSES`] is counted.
pub const DEVICE_LOSS_WINDOW: u64 = 600;

/// Frames in which the device was lost lately.
#[derive(Default)]
struct LossHistory {
    frames: std::collections::VecDeque<u64>,
}

impl LossHistory {
    /// Counts a loss in `frame`; `Err` when it is one too many.
    fn admit(&mut self, frame: u64, reason: &str) -> Result<(), RenderError> {
        while self.frames.front().is_some_and(|&f| frame.saturating_sub(f) >= DEVICE_LOSS_WINDOW) {
            self.frames.pop_front();
        }
        if self.frames.len() >= MAX_DEVICE_LOSSES {
            return Err(RenderError::DeviceLost {
                reason: reason.to_string(),
                why: format!(
                    "it was lost {} times within {DEVICE_LOSS_WINDOW} frames (MAX_DEVICE_LOSSES is {MAX_DEVICE_LOSSES})",
                    self.frames.len() + 1
                ),
            });
        }
        self.frames.push_back(frame);
        Ok(())
    }
}

/// When an injected device loss happens (fault injection for tests and the soak run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceLoss {
    /// The device is destroyed at once, between frames: the next frame finds it lost before
    /// it starts, recreates it and renders on the new device.
    BetweenFrames,
    /// The device is destroyed during the next frame, after its work was submitted: that
    /// frame's read-back and presentation meet a lost device, the frame is reported with no
    /// passes, and the frame after it renders on a new device.
    InFrame,
}

/// A render world with its schedule.
pub struct RenderWorld {
    /// The world holding the render resources.
    pub world: World,
    schedule: Schedule,
    losses: LossHistory,
    lose_in_frame: bool,
}

impl RenderWorld {
    /// Builds the render world around a GPU context.
    pub fn new(gpu: GpuContext) -> RenderWorld {
        let mut world = World::new();
        world.insert_resource(RendererResource(Renderer::new(gpu)));
        world.init_resource::<CurrentSnapshot>();
        world.init_resource::<FrameGraph>();
        world.init_resource::<FrameOutcome>();
        let mut schedule = Schedule::new(RenderSchedule);
        schedule.configure_sets((RenderSet::Prepare, RenderSet::Graph, RenderSet::Execute).chain());
        schedule.add_systems(prepare.in_set(RenderSet::Prepare));
        add_graph_systems(&mut schedule);
        schedule.add_systems(execute.in_set(RenderSet::Execute));
        RenderWorld { world, schedule, losses: LossHistory::default(), lose_in_frame: false }
    }

    /// Destroys the device as a driver reset would, now or during the next frame.
    pub fn lose_device(&mut self, when: DeviceLoss) {
        match when {
            DeviceLoss::BetweenFrames => self.gpu().device.destroy(),
            DeviceLoss::InFrame => self.lose_in_frame = true,
        }
    }

    /// Recreates the device after it was lost (`reason`, found in `frame`): a new device on the
    /// same instance (able to present to `surface`, if given) and a new renderer on it, whose
    /// scene resources, pipelines and cluster buffers are built again from the next snapshot.
    /// Fails with [`RenderError::DeviceLost`] when no device can be created or when the device
    /// was lost more than [`MAX_DEVICE_LOSSES`] times within [`DEVICE_LOSS_WINDOW`] frames.
    pub fn recover_device(
        &mut self,
        reason: String,
        frame: u64,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<(), RenderError> {
        self.losses.admit(frame, &reason)?;
        let gpu = self
            .gpu()
            .recreate(surface)
            .map_err(|e| RenderError::DeviceLost { reason: reason.clone(), why: e.to_string() })?;
        tracing::warn!("the GPU device was {reason} in frame {frame}; recreated it on `{}`", gpu.info.name);
        let losses = std::mem::take(&mut self.losses);
        *self = RenderWorld::new(gpu);
        self.losses = losses;
        Ok(())
    }

    /// The GPU context.
    pub fn gpu(&self) -> &GpuContext {
        &self.world.resource::<RendererResource>().0.gpu
    }

    /// The renderer.
    pub fn renderer(&self) -> &Renderer {
        &self.world.resource::<RendererResource>().0
    }

    /// Renders `snapshot` into `output`.
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let mut snapshot = snapshot;
        let invalid_cameras = snapshot.reject_invalid_camera();
        let sanitized_cameras = snapshot.sanitized_cameras();
        self.world.insert_resource(CurrentSnapshot(snapshot));
        self.world.insert_resource(OutputTarget { view: output.clone(), format });
        self.world.resource_mut::<FrameGraph>().0.clear();
        *self.world.resource_mut::<FrameOutcome>() = FrameOutcome::default();
        self.schedule.run(&mut self.world);
        if std::mem::take(&mut self.lose_in_frame) {
            self.gpu().device.destroy();
        }
        let outcome = std::mem::take(&mut *self.world.resource_mut::<FrameOutcome>());
        match (outcome.error, outcome.report) {
            (Some(e), _) => Err(e),
            (None, Some(r)) => Ok(FrameReport { invalid_cameras, sanitized_cameras, ..r }),
            (None, None) => Err(RenderError::Graph("the frame produced no report".into())),
        }
    }

    /// Names of the passes the last frame's graph ran, in order.
    pub fn last_pass_names(&self) -> Vec<&'static str> {
        self.world.resource::<FrameGraph>().0.pass_names().unwrap_or_default()
    }
}

/// Adds the `Graph` systems, in order: each adds its pass only if the snapshot calls for it.
fn add_graph_systems(schedule: &mut Schedule) {
    schedule.add_systems(
        (
            add_depth_prepass,
            add_cluster_build,
            add_forward_pass,
            add_clustered_forward_pass,
            add_gbuffer_pass,
            add_deferred_lighting_pass,
            add_light_volumes_pass,
            add_motion_blur_pass,
            add_bloom_passes,
            add_output_pass,
        )
            .chain()
            .in_set(RenderSet::Graph),
    );
}

/// The passes the `Graph` systems would run for `snapshot`, in order, without a GPU (tests and
/// tools use it to see what a scene calls for).
pub fn plan_passes(snapshot: FrameSnapshot) -> Result<Vec<&'static str>, RenderError> {
    let mut world = World::new();
    world.insert_resource(CurrentSnapshot(snapshot));
    world.init_resource::<FrameGraph>();
    let mut schedule = Schedule::new(RenderSchedule);
    add_graph_systems(&mut schedule);
    schedule.run(&mut world);
    world.resource::<FrameGraph>().0.pass_names()
}

fn prepare(
    mut renderer: ResMut<RendererResource>,
    snapshot: Res<CurrentSnapshot>,
    mut outcome: ResMut<FrameOutcome>,
) {
    if let Err(e) = renderer.0.prepare(&snapshot.0) {
        outcome.error.get_or_insert(e);
    }
}

/// True when the frame shades with cluster lists (a tiled/clustered pipeline with lights).
fn shades_with_clusters(snapshot: &FrameSnapshot) -> bool {
    snapshot.settings.pipeline.uses_clusters() && snapshot.has_lights() && !replaces_shading(snapshot)
}

/// True when the frame is shaded deferred: a G-buffer, then a full-screen lighting pass
/// (clustered deferred) or light volumes. Without lights the forward pass draws the ambient.
fn shades_deferred(snapshot: &FrameSnapshot) -> bool {
    snapshot.settings.pipeline.is_deferred() && snapshot.has_lights() && !replaces_shading(snapshot)
}

/// True when the frame runs a depth pre-pass (forward pipelines only).
fn runs_depth_prepass(snapshot: &FrameSnapshot) -> bool {
    let s = &snapshot.settings;
    shades_with_clusters(snapshot)
        && !shades_deferred(snapshot)
        && (s.pipeline == PipelineKind::ForwardPlus || s.clusters.depth_prepass)
}

/// True when a debug view shows surface attributes (albedo, normal): the frame then draws the
/// Full G-buffer instead of shading (the debug view replaces the image), in every pipeline.
fn shows_surfaces(snapshot: &FrameSnapshot) -> bool {
    snapshot.settings.debug_view.uses_surfaces()
}

/// True when a debug view that needs neither lighting nor clusters replaces the image: albedo
/// and normal draw the Full G-buffer, depth only the depth pre-pass, in every pipeline.
fn replaces_shading(snapshot: &FrameSnapshot) -> bool {
    shows_surfaces(snapshot) || snapshot.settings.debug_view == DebugViewMode::Depth
}

fn add_depth_prepass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if runs_depth_prepass(&snapshot.0) || snapshot.0.settings.debug_view == DebugViewMode::Depth {
        graph.0.add(DepthPrepass);
    }
}

fn add_cluster_build(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if snapshot.0.needs_clusters() {
        graph.0.add(ClusterBuildPass { workgroup_size: snapshot.0.settings.clusters.workgroup_size });
    }
}

fn add_forward_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    // Naive forward, and the other pipelines when there are no lights to assign.
    if !shades_with_clusters(&snapshot.0) && !shades_deferred(&snapshot.0) && !replaces_shading(&snapshot.0) {
        graph.0.add(ForwardPass { clear_color: snapshot.0.settings.clear_color });
    }
}

fn add_gbuffer_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0.settings;
    if shows_surfaces(&snapshot.0) {
        graph.0.add(GBufferPass { layout: GBufferLayout::Full, codec: s.normal_codec });
    } else if shades_deferred(&snapshot.0) {
        graph.0.add(GBufferPass { layout: s.gbuffer, codec: s.normal_codec });
    }
}

fn add_deferred_lighting_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0.settings;
    if shades_deferred(&snapshot.0) && s.pipeline == PipelineKind::ClusteredDeferred {
        let (layout, codec, clear_color) = (s.gbuffer, s.normal_codec, s.clear_color);
        graph.0.add(DeferredLightingPass { layout, codec, clear_color });
    }
}

fn add_light_volumes_pass(
    snapshot: Res<CurrentSnapshot>,
    renderer: Option<Res<RendererResource>>,
    mut graph: ResMut<FrameGraph>,
) {
    let s = &snapshot.0.settings;
    if shades_deferred(&snapshot.0) && s.pipeline == PipelineKind::LightVolumes {
        let (layout, codec, clear_color) = (s.gbuffer, s.normal_codec, s.clear_color);
        // Planning without a GPU (`plan_passes`) lists the same passes with either format.
        let accumulation = renderer.map_or(manylight_render::resources::HDR_FORMAT, |r| {
            LightVolumesPass::accumulation_format(&r.0.gpu.device)
        });
        graph.0.add(LightVolumesPass { layout, codec, clear_color, accumulation });
    }
}

fn add_clustered_forward_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if shades_with_clusters(&snapshot.0) && !shades_deferred(&snapshot.0) {
        graph.0.add(ClusteredForwardPass {
            clear_color: snapshot.0.settings.clear_color,
            after_prepass: runs_depth_prepass(&snapshot.0),
        });
    }
}

/// Camera-motion blur, when the camera has it (and no debug view replaces the image).
fn add_motion_blur_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0;
    if let Some(pass) = s.camera.and_then(|c| MotionBlurPass::for_camera(&c, s.viewport))
        && s.settings.debug_view == DebugViewMode::None
    {
        graph.0.add(pass);
    }
}

/// Bloom's bright pass, blur chain and composite, when the camera has bloom (and no debug view
/// replaces the image).
fn add_bloom_passes(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0;
    if let Some(bloom) = s.camera.and_then(|c| c.bloom)
        && s.settings.debug_view == DebugViewMode::None
    {
        for pass in bloom.passes() {
            graph.0.add_boxed(pass);
        }
    }
}

/// Tone mapping, or the debug view that replaces it.
fn add_output_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0.settings;
    if s.debug_view == DebugViewMode::None {
        graph.0.add(TonemapPass);
    } else {
        graph.0.add(DebugViewPass { view: s.debug_view, heatmap_max: s.debug_heatmap_max });
    }
}

fn execute(
    mut renderer: ResMut<RendererResource>,
    graph: Res<FrameGraph>,
    snapshot: Res<CurrentSnapshot>,
    target: Res<OutputTarget>,
    mut outcome: ResMut<FrameOutcome>,
) {
    if outcome.error.is_some() {
        return;
    }
    match renderer.0.execute(&graph.0, &snapshot.0, &target.view, target.format) {
        Ok(report) => outcome.report = Some(report),
        Err(e) => outcome.error = Some(e),
    }
}

/// A renderer on a device that can be lost: it renders a frame on its device and recreates the
/// device after a loss; [`DeviceSink::render_recovering`] puts the two together.
pub(crate) trait DeviceSink {
    /// The current device.
    fn gpu(&self) -> &GpuContext;
    /// Recreates the device after it was lost (`reason`, found in `frame`).
    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError>;
    /// Renders one frame on the current device.
    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError>;

    /// Renders one frame, recreating the device first if it was lost since the last frame, or
    /// after the frame if it was lost during it. That frame's work went to the lost device: it
    /// is reported with no passes, and rendering goes on from the next frame.
    fn render_recovering(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let frame = snapshot.frame_index;
        let mut recoveries = 0;
        if let Some(reason) = self.gpu().lost() {
            self.recover(reason, frame)?;
            recoveries += 1;
        }
        let (viewport, pipeline) = (snapshot.viewport, snapshot.settings.pipeline);
        let result = self.render_on_device(snapshot, readback);
        match self.gpu().lost() {
            Some(reason) => {
                if let Err(e) = &result {
                    tracing::warn!("frame {frame} failed on the lost device: {e}");
                }
                self.recover(reason, frame)?;
                let lost_frame = report_without_passes(frame, viewport, pipeline);
                Ok((FrameReport { device_recoveries: recoveries + 1, ..lost_frame }, None))
            }
            None => {
                result.map(|(report, image)| (FrameReport { device_recoveries: recoveries, ..report }, image))
            }
        }
    }
}

/// Synchronous headless rendering: a render world plus an offscreen target that follows the
/// snapshot's viewport size.
pub struct HeadlessRenderer {
    /// The render world.
    pub render_world: RenderWorld,
    target: Option<HeadlessTarget>,
}

impl HeadlessRenderer {
    /// Creates a headless GPU context and render world.
    pub fn new() -> Result<HeadlessRenderer, RenderError> {
        Ok(HeadlessRenderer { render_world: RenderWorld::new(GpuContext::headless()?), target: None })
    }

    /// Renders a snapshot; when `readback` is set, returns the image too. A device found lost
    /// is recreated (see [`RenderWorld::recover_device`]); the frame in which the loss is found
    /// renders nothing and says so in [`FrameReport::device_recoveries`].
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        self.render_recovering(snapshot, readback)
    }
}

impl DeviceSink for HeadlessRenderer {
    fn gpu(&self) -> &GpuContext {
        self.render_world.gpu()
    }

    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError> {
        self.render_world.recover_device(reason, frame, None)?;
        self.target = None;
        Ok(())
    }

    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let mut snapshot = snapshot;
        let invalid_cameras = snapshot.reject_invalid_camera();
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 || snapshot.camera.is_none() {
            // Nothing to look through or at.
            return Ok((FrameReport { invalid_cameras, ..empty_report(&snapshot) }, None));
        }
        let gpu = self.render_world.gpu().clone();
        let limit = gpu.device.limits().max_texture_dimension_2d;
        if size.x > limit || size.y > limit {
            return Err(RenderError::TargetTooLarge { width: size.x, height: size.y, limit });
        }
        if self.target.as_ref().map(|t| t.size()) != Some((size.x, size.y)) {
            self.target = Some(HeadlessTarget::new(&gpu, size.x, size.y));
        }
        let Some(target) = self.target.as_ref() else {
            return Err(RenderError::Graph("no headless target".into()));
        };
        let view = target.view().clone();
        let report = self.render_world.render(snapshot, &view, manylight_render::HEADLESS_FORMAT)?;
        let image = if readback { Some(target.read(&gpu)?) } else { None };
        Ok((report, image))
    }
}

/// The report of a frame that rendered nothing (zero-sized viewport).
pub fn empty_report(snapshot: &FrameSnapshot) -> FrameReport {
    report_without_passes(snapshot.frame_index, snapshot.viewport, snapshot.settings.pipeline)
}

/// The report of frame `frame_index` of `viewport` that ran no pass.
fn report_without_passes(frame_index: u64, viewport: glam::UVec2, pipeline: PipelineKind) -> FrameReport {
    FrameReport {
        frame_index,
        width: viewport.x,
        height: viewport.y,
        pipeline: pipeline.name().to_string(),
        ..Default::default()
    }
}

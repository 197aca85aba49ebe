//! The render side of the app: a small render `World` and `Schedule` that, for each
//! [`FrameSnapshot`], run `Prepare` (upload), `Graph` (one system per stage adds its pass only
//! if the snapshot calls for it) and `Execute`. It runs on the render thread (pipelined mode)
//! or on the caller's thread (synchronous mode).

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use manylight_render::passes::{
    ClusterBuildPass, ClusteredForwardPass, DebugViewPass, DeferredLightingPass, DepthPrepass, ForwardPass,
    GBufferPass, TonemapPass,
};
use manylight_render::{
    DebugView, FrameReport, FrameSnapshot, GpuContext, HeadlessTarget, PipelineKind, RenderError,
    RenderGraph, Renderer,
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

/// A render world with its schedule.
pub struct RenderWorld {
    /// The world holding the render resources.
    pub world: World,
    schedule: Schedule,
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
        schedule.add_systems(
            (
                add_depth_prepass,
                add_cluster_build,
                add_forward_pass,
                add_clustered_forward_pass,
                add_gbuffer_pass,
                add_deferred_lighting_pass,
                add_output_pass,
            )
                .chain()
                .in_set(RenderSet::Graph),
        );
        schedule.add_systems(execute.in_set(RenderSet::Execute));
        RenderWorld { world, schedule }
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
        self.world.insert_resource(CurrentSnapshot(snapshot));
        self.world.insert_resource(OutputTarget { view: output.clone(), format });
        self.world.resource_mut::<FrameGraph>().0.clear();
        *self.world.resource_mut::<FrameOutcome>() = FrameOutcome::default();
        self.schedule.run(&mut self.world);
        let outcome = std::mem::take(&mut *self.world.resource_mut::<FrameOutcome>());
        match (outcome.error, outcome.report) {
            (Some(e), _) => Err(e),
            (None, Some(r)) => Ok(r),
            (None, None) => Err(RenderError::Graph("the frame produced no report".into())),
        }
    }

    /// Names of the passes the last frame's graph ran, in order.
    pub fn last_pass_names(&self) -> Vec<&'static str> {
        self.world.resource::<FrameGraph>().0.pass_names().unwrap_or_default()
    }
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
    snapshot.settings.pipeline.uses_clusters() && snapshot.has_lights()
}

/// True when the frame is shaded deferred (G-buffer, then a full-screen lighting pass).
fn shades_deferred(snapshot: &FrameSnapshot) -> bool {
    shades_with_clusters(snapshot) && snapshot.settings.pipeline == PipelineKind::ClusteredDeferred
}

/// True when the frame runs a depth pre-pass (forward pipelines only).
fn runs_depth_prepass(snapshot: &FrameSnapshot) -> bool {
    let s = &snapshot.settings;
    shades_with_clusters(snapshot)
        && !shades_deferred(snapshot)
        && (s.pipeline == PipelineKind::ForwardPlus || s.clusters.depth_prepass)
}

fn add_depth_prepass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if runs_depth_prepass(&snapshot.0) {
        graph.0.add(DepthPrepass);
    }
}

fn add_cluster_build(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if snapshot.0.needs_clusters() {
        graph.0.add(ClusterBuildPass { workgroup_size: snapshot.0.settings.clusters.workgroup_size });
    }
}

fn add_forward_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    // Naive forward, and the tiled/clustered pipelines when there are no lights to assign.
    if !shades_with_clusters(&snapshot.0) {
        graph.0.add(ForwardPass { clear_color: snapshot.0.settings.clear_color });
    }
}

fn add_gbuffer_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if shades_deferred(&snapshot.0) {
        graph.0.add(GBufferPass { layout: snapshot.0.settings.gbuffer });
    }
}

fn add_deferred_lighting_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    if shades_deferred(&snapshot.0) {
        let s = &snapshot.0.settings;
        graph.0.add(DeferredLightingPass { layout: s.gbuffer, clear_color: s.clear_color });
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

/// Tone mapping, or the debug view that replaces it.
fn add_output_pass(snapshot: Res<CurrentSnapshot>, mut graph: ResMut<FrameGraph>) {
    let s = &snapshot.0.settings;
    if s.debug_view == DebugView::None {
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

    /// Renders a snapshot; when `readback` is set, returns the image too.
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 || snapshot.camera.is_none() {
            return Ok((empty_report(&snapshot), None)); // nothing to look through or at
        }
        let gpu = self.render_world.gpu().clone();
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
    FrameReport {
        frame_index: snapshot.frame_index,
        width: snapshot.viewport.x,
        height: snapshot.viewport.y,
        pipeline: snapshot.settings.pipeline.name().to_string(),
        ..Default::default()
    }
}

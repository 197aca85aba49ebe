//! The render side of the app: a small render `World` and `Schedule`. For each
//! [`FrameSnapshot`] the data its views share (lights, instances, meshes) is uploaded once;
//! then, for each view in order, the schedule runs `Prepare` (the view's constants and
//! clusters), `Graph` (one system per stage adds its pass only if the view calls for it) and
//! `Execute`. A view with a viewport rectangle renders into a texture of its size that is
//! copied into its rectangle; render-to-texture views are read back for the app after the
//! frame. It runs on the render thread (pipelined mode) or on the caller's thread (synchronous
//! mode).

mod headless;
mod recovery;
mod targets;

pub use headless::HeadlessRenderer;
pub(crate) use recovery::DeviceSink;
pub(crate) use recovery::panic_message;
pub use recovery::{DEVICE_LOSS_WINDOW, DeviceLoss, MAX_DEVICE_LOSSES, SinkFrame, empty_report};

use bevy_derive::{Deref, DerefMut};
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use manylight_render::passes::LightVolumesPass;
use manylight_render::{
    FramePlanner, FrameReport, FrameSnapshot, GpuContext, PlanInputs, RenderError, RenderGraph,
    RenderTextureId, RenderView, Renderer, ViewComponents, ViewReport, ViewTarget,
};
use recovery::DeviceRecovery;
use std::sync::Arc;
use targets::{ViewPlan, ViewTargets, clear_target, copy_into, target_name};

/// The ordered steps of one rendered frame.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RenderSet {
    /// Write the view's constants and cluster inputs (the frame's shared data is uploaded
    /// once, before the first view).
    Prepare,
    /// Add the passes the view needs to the graph.
    Graph,
    /// Record and submit the graph.
    Execute,
}

/// Label of the render schedule.
#[derive(ScheduleLabel, Clone, Debug, PartialEq, Eq, Hash)]
pub struct RenderSchedule;

/// The snapshot being rendered.
#[derive(Resource, Default, Deref, DerefMut)]
pub struct CurrentSnapshot(pub FrameSnapshot);

/// The view being rendered and what the frame holds that its plan depends on.
#[derive(Resource, Clone, Debug)]
pub struct CurrentView {
    /// Its camera, image size and settings (its shadows checkbox applied).
    pub view: RenderView,
    /// The frame has a valid light to shade with.
    pub has_lights: bool,
    /// The frame draws blended materials.
    pub has_blended: bool,
    /// The frame brings its own per-pixel light lists (`FrameSnapshot::pixel_light_lists`).
    pub has_pixel_lists: bool,
    /// The frame draws shadow maps (`FrameSnapshot::draws_shadow_maps`) and this view shows them.
    pub casts_shadows: bool,
    /// Components an app extracted from the view's camera for its own passes.
    pub components: ViewComponents,
}

impl CurrentView {
    /// View `index` of `snapshot`.
    pub fn of(snapshot: &FrameSnapshot, index: usize) -> CurrentView {
        let view = snapshot.render_view(index);
        CurrentView {
            casts_shadows: snapshot.draws_shadow_maps() && view.settings.render.shadows.enabled,
            view,
            has_lights: snapshot.has_lights(),
            has_blended: snapshot.has_blended(),
            has_pixel_lists: snapshot.pixel_light_lists.is_some(),
            components: snapshot.views.get(index).map(|v| v.components.clone()).unwrap_or_default(),
        }
    }

    /// The plan's inputs for this view.
    fn plan_inputs(&self, accumulation: wgpu::TextureFormat) -> PlanInputs<'_> {
        PlanInputs {
            view: &self.view,
            components: &self.components,
            has_lights: self.has_lights,
            has_blended: self.has_blended,
            has_pixel_lists: self.has_pixel_lists,
            casts_shadows: self.casts_shadows,
            accumulation,
        }
    }
}

/// The graph being built for this frame.
#[derive(Resource, Default, Deref, DerefMut)]
pub struct FrameGraph(pub RenderGraph);

/// The renderer (GPU context and everything that lives across frames).
#[derive(Resource, Deref, DerefMut)]
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

/// A render world with its schedule: the frame's steps here, device losses in
/// `render_world/recovery.rs` ([`DeviceLoss`], [`RenderWorld::recover_device`]), where views
/// draw in `render_world/targets.rs`, headless rendering in [`HeadlessRenderer`].
pub struct RenderWorld {
    /// The world holding the render resources.
    pub world: World,
    schedule: Schedule,
    recovery: DeviceRecovery,
    targets: ViewTargets,
    last_passes: Vec<&'static str>,
}

impl RenderWorld {
    /// Builds the render world around a GPU context, with
    /// [`manylight_render::DEFAULT_FRAMES_IN_FLIGHT`] frames in flight.
    pub fn new(gpu: GpuContext) -> RenderWorld {
        Self::with_frames_in_flight(gpu, manylight_render::DEFAULT_FRAMES_IN_FLIGHT)
    }

    /// Builds the render world around a GPU context; at most `frames_in_flight` frames are
    /// submitted and not yet read back.
    pub fn with_frames_in_flight(gpu: GpuContext, frames_in_flight: u32) -> RenderWorld {
        let mut world = World::new();
        world.insert_resource(RendererResource(Renderer::with_frames_in_flight(gpu, frames_in_flight)));
        world.init_resource::<CurrentSnapshot>();
        world.init_resource::<FrameGraph>();
        world.init_resource::<FrameOutcome>();
        world.init_resource::<Stages>();
        let mut schedule = Schedule::new(RenderSchedule);
        schedule.configure_sets((RenderSet::Prepare, RenderSet::Graph, RenderSet::Execute).chain());
        schedule.add_systems(prepare.in_set(RenderSet::Prepare));
        add_graph_systems(&mut schedule);
        schedule.add_systems(execute.in_set(RenderSet::Execute));
        RenderWorld {
            world,
            schedule,
            recovery: DeviceRecovery::default(),
            targets: ViewTargets::default(),
            last_passes: Vec::new(),
        }
    }

    /// The GPU context.
    pub fn gpu(&self) -> &GpuContext {
        &self.world.resource::<RendererResource>().0.gpu
    }

    /// The renderer.
    pub fn renderer(&self) -> &Renderer {
        &self.world.resource::<RendererResource>().0
    }

    /// Ends the frame [`RenderWorld::render`] recorded: its report (with any passes recorded
    /// after it, such as the window overlay) goes in flight, and comes back complete from
    /// [`RenderWorld::take_reports`].
    pub fn finish_frame(&mut self, report: FrameReport) {
        let report = self.report_empty(report);
        self.world.resource_mut::<RendererResource>().finish_frame(report);
    }

    /// The reports of finished frames whose GPU figures have arrived, oldest first; with
    /// `wait`, waits for every frame in flight first.
    pub fn take_reports(&mut self, wait: bool) -> Result<Vec<FrameReport>, RenderError> {
        self.world.resource_mut::<RendererResource>().take_reports(wait)
    }

    /// Plans the next frames with `stages` (the built-in ones and an app's,
    /// [`crate::stages::RenderStages`]); unchanged when it is the same `Arc`. A recreated device
    /// keeps them.
    pub fn set_stages(&mut self, stages: &Arc<FramePlanner>) {
        if !Arc::ptr_eq(&self.world.resource::<Stages>().0, stages) {
            self.world.insert_resource(Stages(stages.clone()));
        }
    }

    /// The renderer, to record a pass outside the graph (the window overlay).
    pub fn renderer_mut(&mut self) -> &mut Renderer {
        &mut self.world.resource_mut::<RendererResource>().into_inner().0
    }

    /// Renders `snapshot` into `output`: each view in order, into its rectangle of `output`
    /// or into its render-to-texture target (read back afterwards: [`RenderWorld::take_textures`]).
    /// A frame without views draws the clear colour. Returns the frame's report as recorded:
    /// pass [`RenderWorld::finish_frame`] it once everything of the frame is recorded.
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let start = web_time::Instant::now();
        let mut snapshot = snapshot;
        let invalid_cameras = snapshot.reject_invalid_camera();
        let sanitized_cameras = snapshot.sanitized_cameras();
        self.last_passes.clear();
        self.targets.images.clear();
        if self.recovery.lose_in_frame == Some(DeviceLoss::BeforeUploads) {
            self.recovery.lose_in_frame = None;
            self.gpu().device.destroy();
        }
        self.world.resource_mut::<RendererResource>().prepare(&snapshot)?;
        let light_upload_bytes = self.world.resource::<RendererResource>().0.scene.lights.upload_bytes;
        self.world.insert_resource(CurrentSnapshot(snapshot));
        let result = self.render_views(output, format);
        if self.recovery.lose_in_frame.take() == Some(DeviceLoss::InFrame) {
            self.gpu().device.destroy();
        }
        let views = result?;
        let mut report = merge_view_reports(views, &self.world.resource::<CurrentSnapshot>().0);
        report.invalid_cameras = invalid_cameras;
        report.sanitized_cameras = sanitized_cameras;
        report.light_uploads = 1;
        report.light_upload_bytes = light_upload_bytes;
        report.frame_cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        let gpu = self.gpu().clone();
        self.targets.read(&gpu)?;
        Ok(report)
    }

    /// Renders every view of the current snapshot; returns each view's report.
    fn render_views(
        &mut self,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<Vec<(ViewReport, FrameReport)>, RenderError> {
        let gpu = self.gpu().clone();
        let snapshot = &self.world.resource::<CurrentSnapshot>().0;
        let (main_size, clear_color) = (snapshot.viewport, snapshot.settings.clear_color);
        // What each view draws into (a few words per view; the snapshot stays in the world).
        let plans: Vec<ViewPlan> = (0..snapshot.views.len().max(1))
            .map(|index| {
                let extracted = snapshot.views.get(index);
                let target = extracted.map_or(ViewTarget::Main, |v| v.target);
                let target_size = extracted.map_or(main_size, |v| v.target_size(main_size));
                let rect = extracted.map(|v| v.rect_in(target_size));
                ViewPlan {
                    view: CurrentView::of(snapshot, index),
                    target,
                    rect,
                    whole: rect.is_none_or(|r| r.origin == glam::UVec2::ZERO && r.size == target_size),
                    order: extracted.map_or(0, |v| v.order),
                }
            })
            .collect();
        self.targets.keep_for(&gpu, &plans, format)?;
        let mut cleared: Vec<ViewTarget> = Vec::with_capacity(plans.len());
        let mut reports = Vec::with_capacity(plans.len());
        for plan in plans {
            let (target_view, target_format) = self.targets.target_view(plan.target, output, format);
            if !cleared.contains(&plan.target) {
                // What no view covers shows the clear colour.
                if !plan.whole {
                    clear_target(&gpu, &target_view, clear_color);
                }
                cleared.push(plan.target);
            }
            let size = plan.view.view.size;
            if size.x == 0 || size.y == 0 {
                continue;
            }
            let image = (!plan.whole).then(|| self.targets.view_image(&gpu, size, target_format));
            let draw_into =
                image.as_ref().map_or_else(|| target_view.clone(), |t| t.create_view(&Default::default()));
            let report = self.render_view(plan.view.clone(), &draw_into, target_format)?;
            if let (Some(image), Some(rect)) = (&image, plan.rect) {
                copy_into(&gpu, image, target_view.texture(), rect)?;
            }
            let view_report = ViewReport {
                index: plan.view.view.index,
                order: plan.order,
                target: target_name(plan.target),
                width: size.x,
                height: size.y,
                passes: report.passes.iter().map(|p| p.name.clone()).collect(),
                clusters: report.clusters.clone(),
                cpu_ms: report.frame_cpu_ms,
                gpu_ms: report.frame_gpu_ms,
            };
            reports.push((view_report, report));
        }
        Ok(reports)
    }

    /// Renders one view into `output` through the schedule.
    fn render_view(
        &mut self,
        view: CurrentView,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        self.world.insert_resource(view);
        self.world.insert_resource(OutputTarget { view: output.clone(), format });
        self.world.resource_mut::<FrameGraph>().clear();
        *self.world.resource_mut::<FrameOutcome>() = FrameOutcome::default();
        self.schedule.run(&mut self.world);
        self.last_passes.extend(self.world.resource::<FrameGraph>().pass_names().unwrap_or_default());
        let outcome = std::mem::take(&mut *self.world.resource_mut::<FrameOutcome>());
        match (outcome.error, outcome.report) {
            (Some(e), _) => Err(e),
            (None, Some(r)) => Ok(r),
            (None, None) => Err(RenderError::Graph("the view produced no report".into())),
        }
    }

    /// The render-to-texture images of the last frame, by id (empty once taken).
    pub fn take_textures(&mut self) -> Vec<(RenderTextureId, image::RgbaImage)> {
        std::mem::take(&mut self.targets.images)
    }

    /// View-rectangle images alive (one per size and format the last frame's viewports used).
    pub fn view_image_count(&self) -> usize {
        self.targets.view_image_count()
    }

    /// Names of the passes the last frame ran, in order (view after view).
    pub fn last_pass_names(&self) -> Vec<&'static str> {
        self.last_passes.clone()
    }
}

/// One frame's report from its views' reports: their passes one view after the other, the
/// first view's cluster statistics, the sums of their GPU times and non-finite pixels.
fn merge_view_reports(views: Vec<(ViewReport, FrameReport)>, snapshot: &FrameSnapshot) -> FrameReport {
    // The frame-wide figures (lights, instances) are the same in every view's report.
    let mut merged = match views.first() {
        Some((_, first)) => FrameReport {
            width: snapshot.viewport.x,
            height: snapshot.viewport.y,
            passes: Vec::new(),
            views: Vec::new(),
            nonfinite_pixels: None,
            clusters: None,
            ..first.clone()
        },
        None => empty_report(snapshot),
    };
    let mut gpu_ms: Option<f64> = None;
    for (view, report) in views {
        merged.passes.extend(report.passes);
        merged.clusters = merged.clusters.or(report.clusters);
        if let Some(n) = report.nonfinite_pixels {
            merged.nonfinite_pixels = Some(merged.nonfinite_pixels.unwrap_or(0) + n);
        }
        if let Some(ms) = report.frame_gpu_ms {
            gpu_ms = Some(gpu_ms.unwrap_or(0.0) + ms);
        }
        merged.transient_textures = report.transient_textures;
        merged.transient_bytes = report.transient_bytes;
        merged.transient_allocations = report.transient_allocations;
        merged.views.push(view);
    }
    merged.frame_gpu_ms = gpu_ms;
    merged
}

/// Adds the `Graph` system: the view's plan ([`Stages`]) fills the graph.
fn add_graph_systems(schedule: &mut Schedule) {
    schedule.add_systems(plan_graph.in_set(RenderSet::Graph));
}

/// The stages views are planned with ([`RenderWorld::set_stages`]).
#[derive(Resource, Default, Clone, Debug, Deref)]
pub struct Stages(pub Arc<FramePlanner>);

/// The passes the plan runs for `snapshot`, in order, without a GPU (tests and tools use it
/// to see what a scene calls for).
pub fn plan_passes(snapshot: FrameSnapshot) -> Result<Vec<&'static str>, RenderError> {
    plan_view_passes(&snapshot, 0)
}

/// The passes the plan runs for view `index` of `snapshot`, in order.
pub fn plan_view_passes(snapshot: &FrameSnapshot, index: usize) -> Result<Vec<&'static str>, RenderError> {
    let view = CurrentView::of(snapshot, index);
    let inputs = view.plan_inputs(manylight_render::resources::HDR_FORMAT);
    let mut graph = RenderGraph::new();
    FramePlanner::default().plan_into(&inputs, &mut graph);
    graph.pass_names()
}

fn prepare(
    mut renderer: ResMut<RendererResource>,
    view: Res<CurrentView>,
    mut outcome: ResMut<FrameOutcome>,
) {
    let options = view.plan_inputs(manylight_render::resources::HDR_FORMAT).list_options();
    if let Err(e) = renderer.prepare_view(&view.view, view.has_lights, options) {
        outcome.error.get_or_insert(e);
    }
}

/// Plans the view's passes into the graph.
fn plan_graph(
    view: Res<CurrentView>,
    renderer: Res<RendererResource>,
    stages: Res<Stages>,
    mut graph: ResMut<FrameGraph>,
) {
    let accumulation = LightVolumesPass::accumulation_format(&renderer.gpu.device);
    let inputs = view.plan_inputs(accumulation);
    stages.plan_into(&inputs, &mut graph);
}

fn execute(
    mut renderer: ResMut<RendererResource>,
    graph: Res<FrameGraph>,
    snapshot: Res<CurrentSnapshot>,
    view: Res<CurrentView>,
    target: Res<OutputTarget>,
    mut outcome: ResMut<FrameOutcome>,
) {
    if outcome.error.is_some() {
        return;
    }
    match renderer.execute(&graph, &snapshot, &view.view, &target.view, target.format) {
        Ok(report) => outcome.report = Some(report),
        Err(e) => outcome.error = Some(e),
    }
}

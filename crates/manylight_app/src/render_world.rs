//! The render side of the app: a small render `World` and `Schedule`. For each
//! [`FrameSnapshot`] the data its views share (lights, instances, meshes) is uploaded once;
//! then, for each view in order, the schedule runs `Prepare` (the view's constants and
//! clusters), `Graph` (one system per stage adds its pass only if the view calls for it) and
//! `Execute`. A view with a viewport rectangle renders into a texture of its size that is
//! copied into its rectangle; render-to-texture views are read back for the app after the
//! frame. It runs on the render thread (pipelined mode) or on the caller's thread (synchronous
//! mode).

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use manylight_render::passes::LightVolumesPass;
use manylight_render::{
    FramePlanner, FrameReport, FrameSnapshot, GpuContext, HeadlessTarget, PipelineKind, PlanInputs,
    RenderError, RenderGraph, RenderTextureId, RenderView, Renderer, ViewComponents, ViewReport, ViewTarget,
};
use std::collections::HashMap;
use std::sync::Arc;

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
#[derive(Resource, Default)]
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
    /// The frame draws shadow maps (`FrameSnapshot::casts_shadows`) and this view shows them.
    pub casts_shadows: bool,
    /// Components an app extracted from the view's camera for its own passes.
    pub components: ViewComponents,
}

impl CurrentView {
    /// View `index` of `snapshot`.
    pub fn of(snapshot: &FrameSnapshot, index: usize) -> CurrentView {
        let view = snapshot.render_view(index);
        CurrentView {
            casts_shadows: snapshot.casts_shadows() && view.settings.render.shadows.enabled,
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
    /// The device is destroyed at the start of the next frame, after the check for a lost
    /// device and before the frame uploads its meshes, textures and lights: every buffer and
    /// texture of that frame is created on a lost device. The frame is reported with no
    /// passes, and the frame after it renders on a new device.
    BeforeUploads,
}

/// A render world with its schedule.
pub struct RenderWorld {
    /// The world holding the render resources.
    pub world: World,
    schedule: Schedule,
    losses: LossHistory,
    /// An injected loss waiting for the next frame ([`DeviceLoss::InFrame`] or
    /// [`DeviceLoss::BeforeUploads`]).
    lose_in_frame: Option<DeviceLoss>,
    /// Render-to-texture targets, by id (dropped when no view draws into them).
    textures: HashMap<RenderTextureId, HeadlessTarget>,
    /// Images of the view rectangles, copied into their targets, by size and format (only the
    /// sizes the last frame used are kept).
    view_images: HashMap<(u32, u32, wgpu::TextureFormat), wgpu::Texture>,
    /// The render-to-texture images of the last frame, until taken.
    texture_images: Vec<(RenderTextureId, image::RgbaImage)>,
    last_passes: Vec<&'static str>,
    /// Device recoveries not yet counted in a finished frame's report.
    recoveries: u32,
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
            losses: LossHistory::default(),
            lose_in_frame: None,
            textures: HashMap::new(),
            view_images: HashMap::new(),
            texture_images: Vec::new(),
            last_passes: Vec::new(),
            recoveries: 0,
        }
    }

    /// Destroys the device as a driver reset would, now or during the next frame.
    pub fn lose_device(&mut self, when: DeviceLoss) {
        match when {
            DeviceLoss::BetweenFrames => self.gpu().device.destroy(),
            DeviceLoss::InFrame | DeviceLoss::BeforeUploads => self.lose_in_frame = Some(when),
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
        let frames_in_flight = self.renderer().frames_in_flight();
        let recoveries = self.recoveries;
        let stages = self.world.resource::<Stages>().0.clone();
        *self = RenderWorld::with_frames_in_flight(gpu, frames_in_flight);
        self.world.insert_resource(Stages(stages));
        self.losses = losses;
        self.recoveries = recoveries + 1;
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

    /// Ends the frame [`RenderWorld::render`] recorded: its report (with any passes recorded
    /// after it, such as the window overlay) goes in flight, and comes back complete from
    /// [`RenderWorld::take_reports`].
    pub fn finish_frame(&mut self, report: FrameReport) {
        let report = self.report_empty(report);
        self.world.resource_mut::<RendererResource>().0.finish_frame(report);
    }

    /// The reports of finished frames whose GPU figures have arrived, oldest first; with
    /// `wait`, waits for every frame in flight first.
    pub fn take_reports(&mut self, wait: bool) -> Result<Vec<FrameReport>, RenderError> {
        self.world.resource_mut::<RendererResource>().0.take_reports(wait)
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

    /// `report` with the device recoveries not yet counted in a frame's report. A frame that
    /// rendered nothing is reported this way, at once (nothing of it is on the GPU);
    /// [`RenderWorld::finish_frame`] counts them into the frame it sends in flight.
    pub fn report_empty(&mut self, mut report: FrameReport) -> FrameReport {
        report.device_recoveries += std::mem::take(&mut self.recoveries);
        report
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
        let start = std::time::Instant::now();
        let mut snapshot = snapshot;
        let invalid_cameras = snapshot.reject_invalid_camera();
        let sanitized_cameras = snapshot.sanitized_cameras();
        self.last_passes.clear();
        self.texture_images.clear();
        if self.lose_in_frame == Some(DeviceLoss::BeforeUploads) {
            self.lose_in_frame = None;
            self.gpu().device.destroy();
        }
        self.world.resource_mut::<RendererResource>().0.prepare(&snapshot)?;
        let light_upload_bytes = self.world.resource::<RendererResource>().0.scene.light_upload_bytes;
        self.world.insert_resource(CurrentSnapshot(snapshot));
        let result = self.render_views(output, format);
        if self.lose_in_frame.take() == Some(DeviceLoss::InFrame) {
            self.gpu().device.destroy();
        }
        let views = result?;
        let mut report = merge_view_reports(views, &self.world.resource::<CurrentSnapshot>().0);
        report.invalid_cameras = invalid_cameras;
        report.sanitized_cameras = sanitized_cameras;
        report.light_uploads = 1;
        report.light_upload_bytes = light_upload_bytes;
        report.frame_cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        self.read_textures()?;
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
        // Render-to-texture targets of this frame (others are dropped).
        self.textures.retain(|id, _| plans.iter().any(|p| p.texture_id() == Some(*id)));
        let limit = gpu.device.limits().max_texture_dimension_2d;
        for plan in &plans {
            if let ViewTarget::Texture { id, size } = plan.target {
                if size.x > limit || size.y > limit {
                    return Err(RenderError::TargetTooLarge { width: size.x, height: size.y, limit });
                }
                if size.x == 0 || size.y == 0 {
                    return Err(RenderError::UnsupportedSettings(format!(
                        "a render image of {}×{} pixels (each side must be at least 1)",
                        size.x, size.y
                    )));
                }
                if self.textures.get(&id).map(|t| t.size()) != Some((size.x, size.y)) {
                    self.textures.insert(id, HeadlessTarget::new(&gpu, size.x, size.y));
                }
            }
        }
        // View-rectangle images of sizes no view has this frame are freed (a window being
        // resized would otherwise leave one behind per size).
        let format_of = |t: ViewTarget| match t {
            ViewTarget::Main => format,
            ViewTarget::Texture { .. } => manylight_render::HEADLESS_FORMAT,
        };
        self.view_images.retain(|&(w, h, f), _| {
            plans.iter().any(|p| {
                !p.whole && (p.view.view.size.x, p.view.view.size.y, format_of(p.target)) == (w, h, f)
            })
        });
        let mut cleared: Vec<ViewTarget> = Vec::with_capacity(plans.len());
        let mut reports = Vec::with_capacity(plans.len());
        for plan in plans {
            let (target_view, target_format) = match plan.target {
                ViewTarget::Main => (output.clone(), format),
                ViewTarget::Texture { id, .. } => {
                    (self.textures[&id].view().clone(), manylight_render::HEADLESS_FORMAT)
                }
            };
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
            let image = (!plan.whole).then(|| self.view_image(&gpu, size, target_format));
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
        self.world.resource_mut::<FrameGraph>().0.clear();
        *self.world.resource_mut::<FrameOutcome>() = FrameOutcome::default();
        self.schedule.run(&mut self.world);
        self.last_passes.extend(self.world.resource::<FrameGraph>().0.pass_names().unwrap_or_default());
        let outcome = std::mem::take(&mut *self.world.resource_mut::<FrameOutcome>());
        match (outcome.error, outcome.report) {
            (Some(e), _) => Err(e),
            (None, Some(r)) => Ok(r),
            (None, None) => Err(RenderError::Graph("the view produced no report".into())),
        }
    }

    /// The image a view rectangle of `size` renders into before it is copied.
    fn view_image(
        &mut self,
        gpu: &GpuContext,
        size: glam::UVec2,
        format: wgpu::TextureFormat,
    ) -> wgpu::Texture {
        self.view_images
            .entry((size.x, size.y, format))
            .or_insert_with(|| {
                gpu.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("view_rect"),
                    size: wgpu::Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
            })
            .clone()
    }

    /// Reads the render-to-texture targets back (the app asked for their pixels).
    fn read_textures(&mut self) -> Result<(), RenderError> {
        let gpu = self.gpu().clone();
        let mut ids: Vec<_> = self.textures.keys().copied().collect();
        ids.sort();
        for id in ids {
            let image = self.textures[&id].read(&gpu)?;
            self.texture_images.push((id, image));
        }
        Ok(())
    }

    /// The render-to-texture images of the last frame, by id (empty once taken).
    pub fn take_textures(&mut self) -> Vec<(RenderTextureId, image::RgbaImage)> {
        std::mem::take(&mut self.texture_images)
    }

    /// View-rectangle images alive (one per size and format the last frame's viewports used).
    pub fn view_image_count(&self) -> usize {
        self.view_images.len()
    }

    /// Names of the passes the last frame ran, in order (view after view).
    pub fn last_pass_names(&self) -> Vec<&'static str> {
        self.last_passes.clone()
    }
}

/// What one view draws into.
struct ViewPlan {
    view: CurrentView,
    target: ViewTarget,
    /// Its rectangle of the target (`None`: a frame without views, drawing the whole target).
    rect: Option<manylight_render::ViewRect>,
    /// True when it covers the whole target (it draws straight into it).
    whole: bool,
    order: isize,
}

impl ViewPlan {
    fn texture_id(&self) -> Option<RenderTextureId> {
        match self.target {
            ViewTarget::Texture { id, .. } => Some(id),
            ViewTarget::Main => None,
        }
    }
}

/// `main`, or `texture N`.
fn target_name(target: ViewTarget) -> String {
    match target {
        ViewTarget::Main => "main".to_string(),
        ViewTarget::Texture { id, .. } => format!("texture {}", id.0),
    }
}

/// Clears `target` to `color` (linear).
fn clear_target(gpu: &GpuContext, target: &wgpu::TextureView, color: [f32; 3]) {
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("clear") });
    let [r, g, b] = color.map(f64::from);
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear_target"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    gpu.queue.submit([encoder.finish()]);
}

/// Copies a view's image into its rectangle of `target`.
fn copy_into(
    gpu: &GpuContext,
    image: &wgpu::Texture,
    target: &wgpu::Texture,
    rect: manylight_render::ViewRect,
) -> Result<(), RenderError> {
    if !target.usage().contains(wgpu::TextureUsages::COPY_DST) {
        return Err(RenderError::UnsupportedSettings(
            "a camera viewport needs a target that can be copied into (COPY_DST), which this surface is not"
                .into(),
        ));
    }
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view_rect_copy") });
    encoder.copy_texture_to_texture(
        image.as_image_copy(),
        wgpu::TexelCopyTextureInfo {
            texture: target,
            mip_level: 0,
            origin: wgpu::Origin3d { x: rect.origin.x, y: rect.origin.y, z: 0 },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::Extent3d { width: rect.size.x, height: rect.size.y, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    Ok(())
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
#[derive(Resource, Default, Clone, Debug)]
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
    if let Err(e) = renderer.0.prepare_view(&view.view, view.has_lights, options) {
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
    let accumulation = LightVolumesPass::accumulation_format(&renderer.0.gpu.device);
    let inputs = view.plan_inputs(accumulation);
    stages.0.plan_into(&inputs, &mut graph.0);
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
    match renderer.0.execute(&graph.0, &snapshot.0, &view.view, &target.view, target.format) {
        Ok(report) => outcome.report = Some(report),
        Err(e) => outcome.error = Some(e),
    }
}

/// What a sink gives back for a frame: the reports that arrived meanwhile (in pipelined use,
/// those of earlier frames), and the frame's image if asked.
#[derive(Debug, Default)]
pub struct SinkFrame {
    /// Complete reports, oldest first.
    pub reports: Vec<FrameReport>,
    /// The frame's image, when read back.
    pub image: Option<image::RgbaImage>,
}

/// A renderer on a device that can be lost: it renders a frame on its device and recreates the
/// device after a loss; [`DeviceSink::render_recovering`] puts the two together.
pub(crate) trait DeviceSink {
    /// The current device.
    fn gpu(&self) -> &GpuContext;
    /// The render world.
    fn render_world(&mut self) -> &mut RenderWorld;
    /// Recreates the device after it was lost (`reason`, found in `frame`).
    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError>;
    /// Renders one frame on the current device and finishes it; `Some` report when the frame
    /// rendered nothing (it is complete at once).
    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(Option<FrameReport>, Option<image::RgbaImage>), RenderError>;

    /// Renders one frame, recreating the device first if it was lost since the last frame, or
    /// after the frame if it was lost during it. That frame's work went to the lost device: it
    /// is reported with no passes, and rendering goes on from the next frame (frames still in
    /// flight on the lost device report nothing). With `readback` the frame's image is read
    /// and every frame in flight is waited for; without, the reports that have arrived are
    /// returned and nothing waits.
    fn render_recovering(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<SinkFrame, RenderError> {
        let frame = snapshot.frame_index;
        if let Some(reason) = self.gpu().lost() {
            self.recover(reason, frame)?;
        }
        let (viewport, pipeline) = (snapshot.viewport, snapshot.settings.pipeline);
        // The frame boundary: a wgpu call that panics because the device was lost during the
        // frame (a third-party pass, a helper outside `GpuContext`) ends the frame here, where
        // the loss can be recovered from; a panic on a device that is not lost goes on
        // unwinding to the caller.
        let rendered = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.render_on_device(snapshot, readback).and_then(|(empty, image)| {
                let mut reports = self.render_world().take_reports(readback)?;
                reports.extend(empty);
                Ok(SinkFrame { reports, image })
            })
        }));
        let result = match rendered {
            Ok(result) => result,
            Err(panic) if self.gpu().lost().is_some() => {
                Err(RenderError::Device(format!("panicked: {}", crate::backend::panic_message(&*panic))))
            }
            Err(panic) => std::panic::resume_unwind(panic),
        };
        match self.gpu().lost() {
            Some(reason) => {
                if let Err(e) = &result {
                    tracing::warn!("frame {frame} failed on the lost device: {e}");
                }
                self.recover(reason, frame)?;
                let lost_frame = report_without_passes(frame, viewport, pipeline);
                let lost_frame = self.render_world().report_empty(lost_frame);
                Ok(SinkFrame { reports: vec![lost_frame], image: None })
            }
            None => result,
        }
    }
}

/// Headless rendering: a render world plus an offscreen target that follows the snapshot's
/// viewport size.
pub struct HeadlessRenderer {
    /// The render world.
    pub render_world: RenderWorld,
    target: Option<HeadlessTarget>,
}

impl HeadlessRenderer {
    /// Creates a headless GPU context and render world with
    /// [`manylight_render::DEFAULT_FRAMES_IN_FLIGHT`] frames in flight.
    pub fn new() -> Result<HeadlessRenderer, RenderError> {
        Self::with_frames_in_flight(manylight_render::DEFAULT_FRAMES_IN_FLIGHT)
    }

    /// Creates a headless GPU context and render world; at most `frames_in_flight` frames are
    /// submitted and not yet read back.
    pub fn with_frames_in_flight(frames_in_flight: u32) -> Result<HeadlessRenderer, RenderError> {
        let render_world = RenderWorld::with_frames_in_flight(GpuContext::headless()?, frames_in_flight);
        Ok(HeadlessRenderer { render_world, target: None })
    }

    /// Renders a snapshot and waits for it (the reference path for tests and measurements: the
    /// report is complete when this returns); when `readback` is set, returns the image too. A
    /// device found lost is recreated (see [`RenderWorld::recover_device`]); the frame in
    /// which the loss is found renders nothing and says so in
    /// [`FrameReport::device_recoveries`].
    pub fn render(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let mut frame = self.render_recovering(snapshot, readback)?;
        frame.reports.extend(self.render_world.take_reports(true)?);
        let report =
            frame.reports.pop().ok_or_else(|| RenderError::Graph("the frame gave no report".into()))?;
        Ok((report, frame.image))
    }

    /// Renders a snapshot without waiting for the GPU (unless `readback` asks for the image):
    /// returns the reports that have arrived, oldest first.
    pub fn render_in_flight(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<SinkFrame, RenderError> {
        self.render_recovering(snapshot, readback)
    }
}

impl DeviceSink for HeadlessRenderer {
    fn gpu(&self) -> &GpuContext {
        self.render_world.gpu()
    }

    fn render_world(&mut self) -> &mut RenderWorld {
        &mut self.render_world
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
    ) -> Result<(Option<FrameReport>, Option<image::RgbaImage>), RenderError> {
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 || !snapshot.views.iter().any(|v| v.camera.is_valid()) {
            // Nothing to look through or at.
            let mut snapshot = snapshot;
            let invalid_cameras = snapshot.reject_invalid_camera();
            let report = FrameReport { invalid_cameras, ..empty_report(&snapshot) };
            return Ok((Some(self.render_world.report_empty(report)), None));
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
        self.render_world.finish_frame(report);
        Ok((None, image))
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

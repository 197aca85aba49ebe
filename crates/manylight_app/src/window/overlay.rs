//! The egui overlay of the window: the settings a user changes at run time (pipeline, shading,
//! G-buffer, debug view, lights, bloom and motion blur, cluster grid) and what the last frames
//! cost (per-pass GPU and CPU ms, FPS, a history plot).
//!
//! How it runs, frame by frame:
//! 1. The runner hands each window event to egui first ([`egui_winit::State`]); an event egui
//!    uses (a click on the panel, a key while a widget has focus) does not reach the app.
//! 2. Before `App::update`, `OverlayHost::run` builds the UI against the app's world. A changed
//!    setting is written to its resource or camera component there, so the same frame's extract
//!    sees it. The UI is tessellated on the main thread and left in a slot shared with the sink.
//! 3. The surface sink renders the frame, then [`OverlayPainter::paint`] draws the latest UI as
//!    one more render pass, `egui_overlay`, onto the swapchain image (loading, not clearing it)
//!    before presenting, and appends the pass to the frame's report.
//!
//! F1 (or [`Overlay::visible`]) hides it: no UI is built and no pass runs. Headless there is no
//! overlay at all: no window, no events, no pass.

use crate::components::{Bloom, Camera3d, EnvironmentMapLight, MotionBlur, Skybox};
use crate::resources::{DebugView, EnvironmentImages, FrameStats, LightControls, RenderSettings};
use bevy_ecs::prelude::*;
use egui::epaint::textures::TexturesDelta;
use egui::{ClippedPrimitive, Color32, Pos2, Stroke, Vec2};
use glam::{UVec2, UVec3};
use manylight_core::ShadingModel;
use manylight_core::cluster::{CullTest, ZSlicing};
use manylight_core::codec::NormalCodec;
use manylight_render::{
    DebugViewMode, EnvironmentHandle, GBufferLayout, GpuContext, PassTiming, PipelineKind,
};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use web_time::Instant;
use winit::window::Window;

/// Name of the overlay's pass in frame reports.
pub const OVERLAY_PASS: &str = "egui_overlay";

/// Frames kept for the history plot and the FPS average.
const HISTORY: usize = 240;

/// Whether the window overlay is shown (F1 toggles it). The window runner inserts it when
/// [`crate::window::WindowConfig::overlay`] is set; without this resource there is no overlay.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Overlay {
    /// Draw the overlay and let it take input.
    pub visible: bool,
}

impl Default for Overlay {
    fn default() -> Self {
        Overlay { visible: true }
    }
}

/// The tessellated UI handed from the main thread to the sink.
#[derive(Default)]
struct OverlayFrame {
    /// A UI newer than the one the painter holds (empty: draw nothing).
    primitives: Option<Vec<ClippedPrimitive>>,
    pixels_per_point: f32,
    /// Texture changes not yet applied, oldest first.
    textures: TexturesDelta,
}

impl Drop for OverlayFrame {
    fn drop(&mut self) {
        // Unapplied deltas at shutdown are expected (the GPU side is gone too).
        self.textures.clear();
    }
}

type SharedFrame = Arc<Mutex<OverlayFrame>>;

/// One update as the history plot shows it.
#[derive(Clone, Copy, Debug, Default)]
struct Sample {
    /// Wall time since the previous update.
    frame_ms: f64,
    /// Sum of the last report's GPU pass times.
    gpu_ms: Option<f64>,
}

/// The egui side on the main thread: context, winit input state and the UI's own memory.
pub(crate) struct OverlayHost {
    ctx: egui::Context,
    state: egui_winit::State,
    shared: SharedFrame,
    history: VecDeque<Sample>,
    last_update: Option<Instant>,
    /// Wall time of the last `App::update` (pipelined, it includes the hand-off wait).
    update_ms: f64,
    /// A light count being dragged, applied when the drag ends.
    pending_lights: Option<u32>,
    shown: bool,
}

impl OverlayHost {
    /// The host for `window` and the painter the window's sink draws with.
    pub(crate) fn new(window: &Window) -> (OverlayHost, OverlayPainter) {
        let ctx = egui::Context::default();
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let shared = SharedFrame::default();
        let painter = OverlayPainter {
            shared: shared.clone(),
            renderer: None,
            primitives: Vec::new(),
            pixels_per_point: 1.0,
            texture_log: std::collections::HashMap::new(),
        };
        let host = OverlayHost {
            ctx,
            state,
            shared,
            history: VecDeque::with_capacity(HISTORY),
            last_update: None,
            update_ms: 0.0,
            pending_lights: None,
            shown: false,
        };
        (host, painter)
    }

    /// Gives a window event to egui; true when egui used it and the app should not see it.
    pub(crate) fn on_window_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.state.on_window_event(window, event).consumed
    }

    /// Records the wall time of the update that just ran.
    pub(crate) fn record_update(&mut self, update_ms: f64) {
        self.update_ms = update_ms;
    }

    /// Builds this frame's UI against `world` (applying what the user changed) and leaves it for
    /// the painter; when the overlay is hidden, leaves an empty UI once.
    pub(crate) fn run(&mut self, window: &Window, world: &mut World) {
        let now = Instant::now();
        let frame_ms = self.last_update.map_or(0.0, |t| (now - t).as_secs_f64() * 1e3);
        self.last_update = Some(now);
        let gpu_ms = world.get_resource::<FrameStats>().and_then(|s| s.last.as_ref()?.frame_gpu_ms);
        if self.history.len() == HISTORY {
            self.history.pop_front();
        }
        if frame_ms > 0.0 {
            self.history.push_back(Sample { frame_ms, gpu_ms });
        }

        let visible = world.get_resource::<Overlay>().is_some_and(|o| o.visible);
        if !visible {
            if self.shown {
                self.publish(Vec::new(), 1.0, TexturesDelta::default());
                self.shown = false;
            }
            return;
        }
        self.shown = true;
        let input = self.state.take_egui_input(window);
        let mut output = self.ctx.run_pass(input, |ctx| {
            let height = (ctx.content_rect().height() - 48.0).max(120.0);
            egui::Window::new("manylight")
                .default_pos([8.0, 8.0])
                .default_width(320.0)
                .default_height(height)
                .vscroll(true)
                .show(ctx, |ui| panel(ui, world, &self.history, self.update_ms, &mut self.pending_lights));
        });
        self.state.handle_platform_output(window, std::mem::take(&mut output.platform_output));
        let textures = std::mem::take(&mut output.textures_delta);
        let primitives = self.ctx.tessellate(std::mem::take(&mut output.shapes), output.pixels_per_point);
        self.publish(primitives, output.pixels_per_point, textures);
    }

    fn publish(&self, primitives: Vec<ClippedPrimitive>, pixels_per_point: f32, textures: TexturesDelta) {
        let mut textures = textures;
        match self.shared.lock() {
            Ok(mut frame) => {
                frame.primitives = Some(primitives);
                frame.pixels_per_point = pixels_per_point;
                frame.textures.append(std::mem::take(&mut textures));
            }
            Err(_) => {
                tracing::warn!("overlay: the painter panicked; the overlay is no longer drawn");
                textures.clear();
            }
        }
    }
}

/// The whole panel.
fn panel(
    ui: &mut egui::Ui,
    world: &mut World,
    history: &VecDeque<Sample>,
    update_ms: f64,
    pending_lights: &mut Option<u32>,
) {
    ui.small("F1 hides this panel");
    egui::CollapsingHeader::new("Rendering").default_open(true).show(ui, |ui| settings_ui(ui, world));
    if world.contains_resource::<LightControls>() {
        egui::CollapsingHeader::new("Lights")
            .default_open(true)
            .show(ui, |ui| lights_ui(ui, world, pending_lights));
    }
    egui::CollapsingHeader::new("Shadows").default_open(true).show(ui, |ui| shadows_ui(ui, world));
    egui::CollapsingHeader::new("Environment").default_open(true).show(ui, |ui| environment_ui(ui, world));
    egui::CollapsingHeader::new("Post effects").default_open(true).show(ui, |ui| effects_ui(ui, world));
    egui::CollapsingHeader::new("Cluster grid").default_open(false).show(ui, |ui| clusters_ui(ui, world));
    egui::CollapsingHeader::new("Timings")
        .default_open(true)
        .show(ui, |ui| timings_ui(ui, world, history, update_ms));
}

/// A combo box over `all`, labelled by `name`.
fn combo<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    all: &[T],
    name: fn(T) -> &'static str,
) {
    egui::ComboBox::from_label(label).selected_text(name(*value)).show_ui(ui, |ui| {
        for &v in all {
            ui.selectable_value(value, v, name(v));
        }
    });
}

fn settings_ui(ui: &mut egui::Ui, world: &mut World) {
    if let Some(old) = world.get_resource::<RenderSettings>().copied() {
        let mut s = old;
        combo(ui, "pipeline", &mut s.pipeline, &PipelineKind::ALL, PipelineKind::name);
        combo(ui, "shading", &mut s.shading, &ShadingModel::ALL, ShadingModel::name);
        ui.add_enabled_ui(s.pipeline.is_deferred(), |ui| {
            combo(ui, "G-buffer", &mut s.gbuffer, &GBufferLayout::ALL, GBufferLayout::name);
            combo(ui, "normal codec", &mut s.normal_codec, &NormalCodec::ALL, NormalCodec::name);
        });
        ui.add(egui::Slider::new(&mut s.exposure, 0.05..=20.0).logarithmic(true).text("exposure"));
        if s != old {
            *world.resource_mut::<RenderSettings>() = s;
        }
    }
    if let Some(old) = world.get_resource::<DebugView>().copied() {
        let mut d = old;
        combo(ui, "debug view", &mut d.mode, &DebugViewMode::ALL, DebugViewMode::name);
        if matches!(d.mode, DebugViewMode::LightCount | DebugViewMode::Overflow) {
            ui.add(egui::Slider::new(&mut d.heatmap_max, 1..=1024).logarithmic(true).text("heatmap max"));
        }
        if d.mode != DebugViewMode::None {
            ui.small(d.legend());
        }
        if d != old {
            *world.resource_mut::<DebugView>() = d;
        }
    }
}

fn lights_ui(ui: &mut egui::Ui, world: &mut World, pending: &mut Option<u32>) {
    let Some(old) = world.get_resource::<LightControls>().copied() else {
        return;
    };
    let mut c = old;
    // Respawning many lights on every step of a drag would stall the frame: the count applies
    // when the drag ends (or at once for a click or typed value).
    let mut count = pending.unwrap_or(c.count);
    let r = ui.add(egui::Slider::new(&mut count, 0..=131_072).logarithmic(true).text("lights"));
    if r.dragged() {
        *pending = Some(count);
    } else if r.drag_stopped() || r.changed() {
        c.count = count;
        *pending = None;
    } else if let Some(p) = pending.take() {
        c.count = p;
    }
    ui.add(egui::Slider::new(&mut c.radius_scale, 0.1..=8.0).logarithmic(true).text("radius ×"));
    if c != old {
        *world.resource_mut::<LightControls>() = c;
    }
}

/// The camera the effect controls act on: the active one rendered first (lowest order).
fn first_camera(world: &mut World) -> Option<Entity> {
    let mut q = world.query_filtered::<(Entity, Option<&crate::Camera>), With<Camera3d>>();
    q.iter(world)
        .filter(|(_, c)| c.is_none_or(|c| c.is_active))
        .min_by_key(|(_, c)| c.map_or(0, |c| c.order))
        .map(|(e, _)| e)
}

fn effects_ui(ui: &mut egui::Ui, world: &mut World) {
    let Some(camera) = first_camera(world) else {
        ui.label("no camera");
        return;
    };
    let mut bloom = world.get::<Bloom>(camera).is_some();
    if ui.checkbox(&mut bloom, "bloom").changed() {
        if bloom {
            world.entity_mut(camera).insert(Bloom::default());
        } else {
            world.entity_mut(camera).remove::<Bloom>();
        }
    }
    if let Some(old) = world.get::<Bloom>(camera).copied() {
        let mut b = old;
        ui.add(egui::Slider::new(&mut b.threshold, 0.0..=8.0).text("threshold"));
        ui.add(egui::Slider::new(&mut b.intensity, 0.0..=2.0).text("intensity"));
        ui.add(egui::Slider::new(&mut b.iterations, 1..=6).text("iterations"));
        if b != old {
            world.entity_mut(camera).insert(b);
        }
    }
    let mut blur = world.get::<MotionBlur>(camera).is_some();
    if ui.checkbox(&mut blur, "motion blur").changed() {
        if blur {
            world.entity_mut(camera).insert(MotionBlur::default());
        } else {
            world.entity_mut(camera).remove::<MotionBlur>();
        }
    }
    if let Some(old) = world.get::<MotionBlur>(camera).copied() {
        let mut m = old;
        ui.add(egui::Slider::new(&mut m.samples, 2..=64).text("samples"));
        ui.add(egui::Slider::new(&mut m.strength, 0.0..=2.0).text("strength"));
        if m != old {
            world.entity_mut(camera).insert(m);
        }
    }
}

/// The first camera's environment: which panorama of [`EnvironmentImages`] lights it (or
/// none), its intensity, and whether it is the skybox too.
fn environment_ui(ui: &mut egui::Ui, world: &mut World) {
    let Some(camera) = first_camera(world) else {
        ui.label("no camera");
        return;
    };
    let choices: Vec<(EnvironmentHandle, String)> = match world.get_resource::<EnvironmentImages>() {
        Some(images) => images
            .iter()
            .map(|(h, _)| (h, images.name(h).map_or_else(|| format!("panorama {h:?}"), str::to_string)))
            .collect(),
        None => Vec::new(),
    };
    if choices.is_empty() {
        ui.label("no panorama loaded");
        return;
    }
    let old = world.get::<EnvironmentMapLight>(camera).copied();
    let mut chosen = old.map(|e| e.image);
    let name = |h: Option<EnvironmentHandle>| {
        h.and_then(|h| choices.iter().find(|(c, _)| *c == h)).map_or("none".to_string(), |(_, n)| n.clone())
    };
    egui::ComboBox::from_label("environment").selected_text(name(chosen)).show_ui(ui, |ui| {
        ui.selectable_value(&mut chosen, None, "none");
        for (h, n) in &choices {
            ui.selectable_value(&mut chosen, Some(*h), n);
        }
    });
    let mut light = old;
    let mut skybox = world.get::<Skybox>(camera).is_some();
    if chosen != old.map(|e| e.image) {
        light = chosen
            .map(|image| EnvironmentMapLight { image, ..old.unwrap_or(EnvironmentMapLight::new(image)) });
        skybox = chosen.is_some();
    }
    if let Some(l) = &mut light {
        ui.add(egui::Slider::new(&mut l.intensity, 0.0..=4.0).text("intensity"));
        ui.checkbox(&mut skybox, "skybox");
    }
    let mut entity = world.entity_mut(camera);
    if light != old {
        match light {
            Some(l) => entity.insert(l),
            None => entity.remove::<EnvironmentMapLight>(),
        };
    }
    let sky = light.filter(|_| skybox).map(|l| l.image);
    if sky != entity.get::<Skybox>().map(|s| s.image) {
        match sky {
            Some(image) => entity.insert(Skybox::new(image)),
            None => entity.remove::<Skybox>(),
        };
    }
}

/// The frame's shadows switch, each camera's, a switch that makes every light cast, and the
/// last frame's counters.
fn shadows_ui(ui: &mut egui::Ui, world: &mut World) {
    if let Some(old) = world.get_resource::<RenderSettings>().copied() {
        let mut s = old;
        ui.checkbox(&mut s.shadows.enabled, "shadows (lights that cast, cast)");
        if s != old {
            *world.resource_mut::<RenderSettings>() = s;
        }
    }
    // Each camera's own checkbox (its `CameraShadows`).
    let mut cameras = world.query_filtered::<(Entity, Option<&crate::CameraShadows>), With<Camera3d>>();
    let shown: Vec<(Entity, bool)> =
        cameras.iter(world).map(|(e, s)| (e, s.is_none_or(|s| s.enabled))).collect();
    for (i, (camera, enabled)) in shown.into_iter().enumerate() {
        let mut on = enabled;
        if ui.checkbox(&mut on, format!("camera {i} shows shadows")).changed() {
            world.entity_mut(camera).insert(crate::CameraShadows { enabled: on });
        }
    }
    let mut q = world.query::<(
        Option<&crate::PointLight>,
        Option<&crate::SpotLight>,
        Option<&crate::DirectionalLight>,
    )>();
    let (mut lights, mut casting) = (0usize, 0usize);
    for (p, s, d) in q.iter(world) {
        let casts =
            [p.map(|l| l.shadows_enabled), s.map(|l| l.shadows_enabled), d.map(|l| l.shadows_enabled)];
        lights += casts.iter().flatten().count();
        casting += casts.iter().flatten().filter(|c| **c).count();
    }
    let mut all = lights > 0 && casting == lights;
    if ui.checkbox(&mut all, format!("every light casts ({casting} of {lights} do)")).changed() {
        crate::scene::set_shadows(world, all);
    }
    let Some(report) = world.get_resource::<FrameStats>().and_then(|s| s.last.clone()) else {
        return;
    };
    let Some(r) = report.shadows else {
        ui.label("no shadow pass this frame");
        return;
    };
    let pass_ms = report.pass_gpu_ms::<manylight_render::passes::ShadowMapsPass>();
    ui.monospace(format!(
        "{} casting, maps {} drawn ({} cascades) / {} cached / {} stale, {} unseen lights, {} unseen faces",
        r.casting_lights,
        r.maps_rendered,
        r.cascades_rendered,
        r.maps_cached,
        r.maps_stale,
        r.unseen_lights,
        r.unseen_faces
    ));
    ui.monospace(format!(
        "atlas {0}×{0} ({1:.0} MiB) {2:.0} % used, {3} instance-faces in {4} draws, {5}",
        r.atlas_size,
        r.atlas_bytes as f64 / (1024.0 * 1024.0),
        r.atlas_occupancy * 100.0,
        r.instance_faces,
        r.draw_calls,
        pass_ms.map_or("GPU n/a".to_string(), |ms| format!("{ms:.2} ms GPU"))
    ));
    if r.downgraded_lights > 0 || r.dropped_lights > 0 || r.atlas_limited_by_device {
        ui.colored_label(
            Color32::YELLOW,
            format!(
                "{} lights got smaller maps than they asked, {} none{}",
                r.downgraded_lights,
                r.dropped_lights,
                if r.atlas_limited_by_device { "; the device's texture limit caps the atlas" } else { "" }
            ),
        );
    }
}

fn clusters_ui(ui: &mut egui::Ui, world: &mut World) {
    let Some(old) = world.get_resource::<RenderSettings>().copied() else {
        return;
    };
    let mut s = old;
    let grid = &mut s.clusters.grid;
    let mut explicit = grid.dims.is_some();
    ui.checkbox(&mut explicit, "explicit X × Y × Z");
    if explicit {
        let mut d = grid.dims.unwrap_or(UVec3::new(20, 12, 24));
        ui.horizontal(|ui| {
            for v in [&mut d.x, &mut d.y, &mut d.z] {
                ui.add(egui::DragValue::new(v).range(1..=256));
            }
        });
        grid.dims = Some(d);
    } else {
        grid.dims = None;
        ui.add(egui::Slider::new(&mut grid.tile_px, 8..=256).logarithmic(true).text("tile px"));
        ui.add(egui::Slider::new(&mut grid.z_slices, 1..=128).text("z slices"));
    }
    combo(ui, "z slicing", &mut grid.slicing, &ZSlicing::ALL, ZSlicing::name);
    combo(ui, "cull test", &mut s.clusters.cull, &CullTest::ALL, CullTest::name);
    ui.checkbox(&mut s.clusters.depth_prepass, "depth pre-pass (clustered forward)");
    ui.checkbox(&mut s.clusters.depth_bounds, "per-cluster depth bounds");
    ui.checkbox(&mut s.clusters.refined_lists, "refined light lists (4 × 4-px blocks)");
    ui.add(
        egui::Slider::new(&mut s.clusters.coarse_tiles, 0..=32)
            .text("coarse tiles (tiles per edge; 0: none)"),
    );
    if s != old {
        *world.resource_mut::<RenderSettings>() = s;
    }
    let views = world.get_resource::<FrameStats>().and_then(|st| Some(st.last.as_ref()?.views.clone()));
    let views = views.unwrap_or_default();
    if views.is_empty() {
        ui.label("last frame rendered no view");
    }
    for v in &views {
        let name = format!("view {} ({}, order {}, {}×{})", v.index, v.target, v.order, v.width, v.height);
        match &v.clusters {
            Some(c) => {
                ui.label(format!(
                    "{name}: {}×{}×{} clusters, max {} / mean {:.1} lights per non-empty cluster; \
                     list entries: {} coarse-tile, {} tile, {} cluster",
                    c.dims[0],
                    c.dims[1],
                    c.dims[2],
                    c.max_per_cluster,
                    c.mean_per_non_empty,
                    c.coarse_entries,
                    c.tile_entries,
                    c.total_entries
                ));
                if c.dropped_pairs > 0 {
                    ui.colored_label(
                        Color32::LIGHT_RED,
                        format!("{} pairs dropped by the cap", c.dropped_pairs),
                    );
                }
            }
            None => {
                ui.label(format!("{name}: built no clusters"));
            }
        }
    }
}

fn timings_ui(ui: &mut egui::Ui, world: &mut World, history: &VecDeque<Sample>, update_ms: f64) {
    let recent: Vec<f64> = history.iter().rev().take(30).map(|s| s.frame_ms).collect();
    let mean = if recent.is_empty() { 0.0 } else { recent.iter().sum::<f64>() / recent.len() as f64 };
    let fps = if mean > 0.0 { 1000.0 / mean } else { 0.0 };
    ui.monospace(format!("{fps:5.1} FPS  frame {mean:7.1} ms"));
    // Pipelined, the update includes waiting to hand the snapshot to the busy render thread.
    ui.monospace(format!("main-world update {update_ms:7.2} ms"));
    let Some(report) = world.get_resource::<FrameStats>().and_then(|s| s.last.clone()) else {
        ui.label("no frame rendered yet");
        return;
    };
    ui.monospace(format!(
        "{} lights, {} instances, {}×{}, {} transient textures alive, {:.1} MiB used this frame",
        report.light_count,
        report.instance_count,
        report.width,
        report.height,
        report.transient_textures,
        report.transient_bytes as f64 / (1024.0 * 1024.0)
    ));
    let submitted = world.get_resource::<FrameStats>().map_or(report.frame_index, |s| s.submitted);
    ui.monospace(format!(
        "frame {} ({} later): {}/{} in flight, {} GPU waits, {} buffers and {} bind groups created",
        report.frame_index,
        submitted.saturating_sub(report.frame_index),
        report.frames_in_flight,
        report.frames_in_flight_limit,
        report.blocking_waits,
        report.buffers_created,
        report.bind_groups_created
    ));
    if report.invalid_lights > 0 {
        ui.colored_label(Color32::LIGHT_RED, format!("{} invalid lights dropped", report.invalid_lights));
    }
    if let Some(n) = report.nonfinite_pixels.filter(|&n| n > 0) {
        ui.colored_label(Color32::LIGHT_RED, format!("{n} pixels with a NaN or infinite HDR colour"));
    }
    egui::Grid::new("passes").striped(true).num_columns(3).show(ui, |ui| {
        ui.strong("pass");
        ui.strong("GPU ms");
        ui.strong("CPU ms");
        ui.end_row();
        for p in &report.passes {
            ui.monospace(&p.name);
            ui.monospace(match p.gpu_ms {
                Some(ms) if p.gpu_trusted => format!("{ms:8.2}"),
                Some(ms) => format!("{ms:8.2}?"),
                None => "       –".into(),
            });
            ui.monospace(format!("{:7.2}", p.cpu_ms));
            ui.end_row();
        }
        // One row per view when the frame has several (each camera renders its own).
        if report.views.len() > 1 {
            for v in &report.views {
                ui.monospace(format!("view {} ({}, {}×{})", v.index, v.target, v.width, v.height));
                ui.monospace(v.gpu_ms.map_or("       –".into(), |ms| format!("{ms:8.2}")));
                ui.monospace(format!("{:7.2}", v.cpu_ms));
                ui.end_row();
            }
        }
        ui.strong("frame");
        ui.monospace(report.frame_gpu_ms.map_or("       –".into(), |ms| format!("{ms:8.2}")));
        ui.monospace(format!("{:7.2}", report.frame_cpu_ms));
        ui.end_row();
    });
    ui.small(format!(
        "{} view(s); lights uploaded {}× this frame ({:.1} KiB), shared by every view",
        report.views.len(),
        report.light_uploads,
        report.light_upload_bytes as f64 / 1024.0
    ));
    let cpu = report.cpu;
    ui.monospace(format!(
        "CPU ms: extract {:.2}, upload {:.2} ({:.1} KiB), prepare {:.2}, record {:.2}, submit {:.2}",
        cpu.extract_ms,
        cpu.upload_ms,
        cpu.upload_bytes as f64 / 1024.0,
        cpu.prepare_ms,
        cpu.record_ms,
        cpu.submit_ms
    ));
    ui.small("? = timestamps not trusted on this adapter (compute on lavapipe)");
    plot(ui, history);
}

/// Frame time (white) and summed GPU pass time (orange) of the last frames, scaled to the
/// largest value shown.
fn plot(ui: &mut egui::Ui, history: &VecDeque<Sample>) {
    let width = ui.available_width().max(120.0);
    let (rect, _) = ui.allocate_exact_size(Vec2::new(width, 64.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_black_alpha(160));
    let top = history.iter().map(|s| s.frame_ms.max(s.gpu_ms.unwrap_or(0.0))).fold(1.0_f64, f64::max) * 1.1;
    let point = |i: usize, v: f64| {
        let x = rect.right() - (history.len() - 1 - i) as f32 * rect.width() / (HISTORY - 1) as f32;
        Pos2::new(x, rect.bottom() - (v / top) as f32 * rect.height())
    };
    let frame: Vec<Pos2> = history.iter().enumerate().map(|(i, s)| point(i, s.frame_ms)).collect();
    let gpu: Vec<Pos2> = history.iter().enumerate().filter_map(|(i, s)| Some(point(i, s.gpu_ms?))).collect();
    if frame.len() > 1 {
        painter.add(egui::Shape::line(frame, Stroke::new(1.0, Color32::WHITE)));
    }
    if gpu.len() > 1 {
        painter.add(egui::Shape::line(gpu, Stroke::new(1.0, Color32::ORANGE)));
    }
    painter.text(
        rect.left_top() + Vec2::new(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{top:.0} ms   white: frame   orange: GPU passes"),
        egui::FontId::monospace(10.0),
        Color32::LIGHT_GRAY,
    );
}

/// Draws the overlay on the render side: an egui-wgpu renderer for the surface format.
pub struct OverlayPainter {
    shared: SharedFrame,
    renderer: Option<(egui_wgpu::Renderer, wgpu::TextureFormat)>,
    primitives: Vec<ClippedPrimitive>,
    pixels_per_point: f32,
    /// Every texture's uploads since its last full image, replayed into a new renderer after
    /// the device was recreated (egui sends its font atlas only once).
    texture_log: std::collections::HashMap<egui::TextureId, Vec<egui::epaint::ImageDelta>>,
}

impl OverlayPainter {
    /// Forgets the GPU side after the device was recreated; the next paint builds a new egui
    /// renderer on the new device and uploads every texture again.
    pub fn reset_device(&mut self) {
        self.renderer = None;
    }

    /// Draws the latest UI onto `view` (the presented image, `size` pixels) as the pass
    /// [`OVERLAY_PASS`], inside the timestamps `timer` gives (the frame's read-back slot:
    /// its GPU time arrives with the frame's report); returns its timing and whether it was
    /// timed, or `None` when nothing was drawn.
    pub fn paint(
        &mut self,
        gpu: &GpuContext,
        view: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        size: UVec2,
        timer: Option<(&wgpu::QuerySet, u32)>,
    ) -> Option<(PassTiming, bool)> {
        let start = Instant::now();
        let mut textures = TexturesDelta::default();
        if let Ok(mut frame) = self.shared.lock() {
            if let Some(p) = frame.primitives.take() {
                self.primitives = p;
                self.pixels_per_point = frame.pixels_per_point;
            }
            textures = std::mem::take(&mut frame.textures);
        }
        let (device, queue) = (&gpu.device, &gpu.queue);
        if self.renderer.as_ref().is_some_and(|(_, f)| *f != format) {
            // Textures live in the renderer; egui would not send its font atlas again.
            tracing::warn!(
                "overlay: the surface format changed to {format:?}; the overlay is no longer drawn"
            );
            textures.clear();
            return None;
        }
        let log = &mut self.texture_log;
        let (renderer, _) = self.renderer.get_or_insert_with(|| {
            let mut renderer =
                egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
            for (id, deltas) in log.iter() {
                for delta in deltas {
                    renderer.update_texture(device, queue, *id, delta);
                }
            }
            (renderer, format)
        });
        for (id, deltas) in &textures.set {
            for delta in deltas {
                renderer.update_texture(device, queue, *id, delta);
                let entry = log.entry(*id).or_default();
                if delta.is_whole() {
                    entry.clear();
                }
                entry.push(delta.clone());
            }
        }
        let drawn = !self.primitives.is_empty();
        if drawn {
            let screen = egui_wgpu::ScreenDescriptor {
                size_in_pixels: [size.x, size.y],
                pixels_per_point: self.pixels_per_point,
            };
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(OVERLAY_PASS) });
            let mut commands =
                renderer.update_buffers(device, queue, &mut encoder, &self.primitives, &screen);
            {
                let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(OVERLAY_PASS),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: timer.map(|(query_set, index)| wgpu::RenderPassTimestampWrites {
                        query_set,
                        beginning_of_pass_write_index: Some(index * 2),
                        end_of_pass_write_index: Some(index * 2 + 1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                renderer.render(&mut pass.forget_lifetime(), &self.primitives, &screen);
            }
            commands.push(encoder.finish());
            queue.submit(commands);
        }
        for id in &textures.free {
            renderer.free_texture(id);
            log.remove(id);
        }
        textures.clear();
        let timing = PassTiming {
            name: OVERLAY_PASS.into(),
            pass_type: None,
            gpu_ms: None,
            gpu_trusted: true,
            cpu_ms: start.elapsed().as_secs_f64() * 1e3,
        };
        drawn.then_some((timing, timer.is_some()))
    }
}

//! Resources a user reads or changes: settings, statistics, the clock, headless capture.

use bevy_ecs::prelude::*;
use glam::UVec2;
use manylight_render::{DebugViewMode, FrameReport, FrameSettings};

/// The panoramas cameras' [`EnvironmentMapLight`](crate::EnvironmentMapLight)s and
/// [`Skybox`](crate::Skybox)es name: the render crate's type itself, a resource the app inserts
/// when it has panoramas (the plugin adds none).
pub use manylight_render::EnvironmentImages;
pub use manylight_render::RenderSettings;

/// What views are rendered with: `settings` and the debug view of `debug` (a camera's
/// `CameraDebugView` replaces it for that camera).
pub fn frame_settings(settings: &RenderSettings, debug: &DebugView) -> FrameSettings {
    FrameSettings { render: *settings, debug_view: debug.mode, debug_heatmap_max: debug.heatmap_max }
}

/// The debug view shown instead of the tone-mapped image; systems may change it at run time
/// (it applies from the next frame). `mode: DebugViewMode::None` shows the image.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct DebugView {
    /// What to show.
    pub mode: DebugViewMode,
    /// Light count shown as the hottest colour of the light-count heatmap.
    pub heatmap_max: u32,
}

impl Default for DebugView {
    fn default() -> Self {
        let f = FrameSettings::default();
        DebugView { mode: f.debug_view, heatmap_max: f.debug_heatmap_max }
    }
}

impl DebugView {
    /// A debug view showing `mode` with the default heatmap scale.
    pub fn new(mode: DebugViewMode) -> DebugView {
        DebugView { mode, ..DebugView::default() }
    }

    /// One line saying what the view shows and how to read its colours.
    pub fn legend(&self) -> String {
        match self.mode {
            DebugViewMode::None => "image (tone-mapped)".into(),
            DebugViewMode::LightCount => format!(
                "light count per pixel: blue 0 → red {} (bar at the bottom, ticks every 1/8); black = no light",
                self.heatmap_max
            ),
            DebugViewMode::SliceX => "cluster x index (alternating colours per tile column)".into(),
            DebugViewMode::SliceY => "cluster y index (alternating colours per tile row)".into(),
            DebugViewMode::SliceZ => "cluster z index (alternating colours per depth slice)".into(),
            DebugViewMode::Albedo => "surface albedo".into(),
            DebugViewMode::Normal => "world normal: rgb = n * 0.5 + 0.5 (+x red, +y green, +z blue)".into(),
            DebugViewMode::Metallic => "PBR metalness: black 0 → white 1 (other shading models black)".into(),
            DebugViewMode::Roughness => {
                "PBR perceptual roughness: black 0 → white 1 (other shading models black)".into()
            }
            DebugViewMode::Emissive => "emitted radiance (linear, clamped to 1)".into(),
            DebugViewMode::Occlusion => "ambient occlusion: white = none, black = full".into(),
            DebugViewMode::Depth => "linear view depth, log scale: white near → black far".into(),
            DebugViewMode::ShadowAtlas => {
                "shadow atlas: each light's 3 × 2 block of cube faces (white near the light → grey at its range, black = empty)".into()
            }
            DebugViewMode::ShadowLod => {
                "shadow resolution: mean log2 face edge of the casting lights reaching the pixel, blue 16 → red 512".into()
            }
            DebugViewMode::Overflow => format!(
                "cluster overflow: red = list hit the cap; green = fill (of the cap, or of {} without one)",
                self.heatmap_max
            ),
        }
    }
}

/// The statistics of the most recently finished frame: passes in order with GPU/CPU ms, light
/// count and more (see [`FrameReport`]). A frame's GPU figures are read back without waiting,
/// so its report arrives up to `frames_in_flight` frames after it was submitted;
/// [`FrameReport::frame_index`] says which frame it is, [`FrameStats::submitted`] which frame
/// the renderer submitted last (pipelined, the main world is a frame ahead of it).
#[derive(Resource, Clone, Debug, Default)]
pub struct FrameStats {
    /// The last report (None before the first frame finished).
    pub last: Option<FrameReport>,
    /// The latest frame handed to the GPU (its report may not have arrived yet).
    pub submitted: u64,
    /// Frames rendered so far.
    pub frames_rendered: u64,
    /// CPU time of the main-world update that produced the last snapshot.
    pub simulation_cpu_ms: f64,
    /// Times the GPU device was lost and recreated since start-up.
    pub device_recoveries: u64,
    /// Sums since start-up of every reported frame's [`FrameReport::blocking_waits`],
    /// [`FrameReport::buffers_created`] and [`FrameReport::bind_groups_created`]: flat in steady
    /// state.
    pub totals: FrameTotals,
}

impl FrameStats {
    /// The statistics as a document to serialise: what `manylight render --stats-json`
    /// writes and a web page's `manylight.stats()` returns.
    pub fn document(&self) -> StatsDocument<'_> {
        StatsDocument {
            frames_rendered: self.frames_rendered,
            frames_submitted: self.submitted,
            last_frame: self.last.as_ref(),
        }
    }
}

/// [`FrameStats`] as a serialisable document ([`FrameStats::document`]).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct StatsDocument<'a> {
    /// Frames rendered so far.
    pub frames_rendered: u64,
    /// The latest frame handed to the GPU.
    pub frames_submitted: u64,
    /// The last frame whose statistics arrived: its counters (`blocking_waits`,
    /// `frames_in_flight`, `buffers_created`, `bind_groups_created`) are in it.
    pub last_frame: Option<&'a FrameReport>,
}

/// Sums over the reported frames (see [`FrameStats::totals`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameTotals {
    /// Frames reported.
    pub frames: u64,
    /// Blocking GPU waits.
    pub blocking_waits: u64,
    /// Buffers created.
    pub buffers_created: u64,
    /// Bind groups created.
    pub bind_groups_created: u64,
}

impl FrameStats {
    /// Takes a finished frame's report: the last report, frames rendered (a frame that ran no
    /// pass, such as a 0×0 viewport or the frame a lost device was found in, is not counted)
    /// and device recoveries.
    pub fn record(&mut self, report: FrameReport) {
        self.frames_rendered += u64::from(!report.passes.is_empty());
        self.device_recoveries += u64::from(report.device_recoveries);
        self.totals.frames += 1;
        self.totals.blocking_waits += report.blocking_waits;
        self.totals.buffers_created += report.buffers_created;
        self.totals.bind_groups_created += report.bind_groups_created;
        self.last = Some(report);
    }

    /// Pass names of the last frame in the order they ran.
    pub fn pass_names(&self) -> Vec<String> {
        self.last.as_ref().map(|r| r.passes.iter().map(|p| p.name.clone()).collect()).unwrap_or_default()
    }
}

/// The most frames the renderer keeps in flight (submitted, not yet read back); set by
/// [`crate::ManyLightPlugin::frames_in_flight`] and read when the renderer is created.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct FramesInFlight(pub u32);

/// Size of the render target in pixels (the window's inner size, or the headless size).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewportSize(pub UVec2);

/// Frame read-back: when `enabled`, each rendered frame is read back into `image` (headless:
/// the target; in a window: the swapchain image before the overlay is drawn, where the surface
/// allows copies).
#[derive(Resource, Clone, Debug, Default)]
pub struct HeadlessCapture {
    /// Read frames back (costs a copy and a GPU wait per frame).
    pub enabled: bool,
    /// The last frame read back.
    pub image: Option<image::RgbaImage>,
}

/// The images of the cameras that render to an offscreen image ([`RenderTarget::Image`]), from
/// the latest frame that finished (in pipelined mode, a frame after the one extracted). Each
/// such image is read back every frame it is rendered.
///
/// [`RenderTarget::Image`]: crate::components::RenderTarget::Image
#[derive(Resource, Clone, Debug, Default)]
pub struct RenderedImages {
    images: std::collections::HashMap<manylight_render::RenderTextureId, (u64, image::RgbaImage)>,
}

impl RenderedImages {
    /// The latest pixels of `image`, if it was rendered.
    pub fn get(&self, image: &crate::components::RenderImage) -> Option<&image::RgbaImage> {
        self.images.get(&image.id).map(|(_, i)| i)
    }

    /// The frame the latest pixels of `image` belong to.
    pub fn frame_of(&self, image: &crate::components::RenderImage) -> Option<u64> {
        self.images.get(&image.id).map(|(f, _)| *f)
    }

    /// Stores frame `frame`'s pixels of texture `id`.
    pub fn insert(&mut self, id: manylight_render::RenderTextureId, frame: u64, image: image::RgbaImage) {
        self.images.insert(id, (frame, image));
    }
}

/// The error that stopped rendering, if any (the app also receives `AppExit::error()`).
#[derive(Resource, Clone, Debug, Default)]
pub struct RenderFailure(pub Option<String>);

/// Where the lights with a [`LightAnimation`](crate::LightAnimation) move and flicker.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightAnimationMode {
    /// On the CPU: [`animate_lights`](crate::extract::animate_lights), an `Update` system, sets
    /// each light's `Transform` and `PointLight::color`, so every animated light is a changed
    /// light that extraction copies and the renderer uploads each frame. The light's components
    /// always say where it is.
    #[default]
    Cpu,
    /// On the GPU: the animation is extracted once (and again only when a component of the
    /// light changes), and each frame one compute pass writes every animated light's position
    /// and colour at `Time::elapsed_secs` into the light buffer; 100 000 moving lights cost the
    /// CPU nothing per frame. The light's `Transform` and `PointLight::color` are left as they
    /// are (the position and colour live on the GPU). Lights that cast shadows, spot lights and
    /// lights with a parent (`ChildOf`) still animate on the CPU: their shadow views, cones
    /// and parents' transforms are placed on the CPU.
    Gpu,
}

/// Light count and radius multiplier a user asks for at run time (the window overlay edits
/// them when this resource exists); an app that spawns lights reads them, as the `stress`
/// example does.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct LightControls {
    /// Lights the app should keep alive.
    pub count: u32,
    /// Multiplier of each light's base radius.
    pub radius_scale: f32,
}

impl Default for LightControls {
    fn default() -> Self {
        LightControls { count: 1024, radius_scale: 1.0 }
    }
}

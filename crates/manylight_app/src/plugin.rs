//! `ManyLightPlugin`: adds the components' systems, the extract step and the renderer.

use crate::backend::RenderBackend;
use crate::extract::{animate_lights, collect_results, extract_and_render};
pub use crate::headless::HeadlessConfig;
use crate::render_world::HeadlessRenderer;
use crate::resources::{
    DebugView, FrameStats, FramesInFlight, HeadlessCapture, RenderFailure, RenderSettings, ViewportSize,
};
pub use crate::stages::ManyLightSystems;
use crate::window::WindowConfig;
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::{StaticTransformOptimizations, TransformPlugin, TransformSystems};
use glam::UVec2;
use std::path::PathBuf;
use std::time::Duration;

/// How far [`bevy_time::Time`] advances per update in headless mode (1/60 s), so that
/// animated frames are the same on every run and machine. Replace the plugin's
/// `TimeUpdateStrategy` resource to change it.
pub const HEADLESS_TIME_STEP: Duration = Duration::from_nanos(16_666_667);

/// Where frames go.
#[derive(Clone, Debug, PartialEq)]
pub enum OutputMode {
    /// A window (winit); `App::run` runs its event loop.
    Window(WindowConfig),
    /// An offscreen image.
    Headless(HeadlessConfig),
}

/// The manylight plugin: windowed by default, or headless with a size.
///
/// ```no_run
/// use manylight_app::prelude::*;
/// // A window with the embedded hall and a thousand animated lights, every one casting.
/// App::new()
///     .add_plugins(ManyLightPlugin::default())
///     .add_systems(Startup, |mut commands: Commands| {
///         let hall = manylight_scene::default_scene();
///         spawn_scene(&mut commands, &hall, true, 16.0 / 9.0);
///         spawn_light_rig(&mut commands, 1000, hall.bounds(), 1).expect("a rig that fits");
///     })
///     .add_systems(PostStartup, |world: &mut World| manylight_app::scene::set_shadows(world, true))
///     .run();
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ManyLightPlugin {
    /// Window or headless.
    pub mode: OutputMode,
    /// Render on a separate thread (frame N+1 simulates while N renders). Default: true for
    /// windows, false headless (deterministic, results available right after `update`).
    pub pipelined: bool,
    /// Frames the GPU may still be working on when the next is submitted; their statistics
    /// are read back without waiting and arrive in [`FrameStats`] that many frames later.
    /// Default [`manylight_render::DEFAULT_FRAMES_IN_FLIGHT`] (2); 1 to
    /// [`manylight_render::MAX_FRAMES_IN_FLIGHT`].
    pub frames_in_flight: u32,
}

impl Default for ManyLightPlugin {
    fn default() -> Self {
        Self::window(WindowConfig::default())
    }
}

impl ManyLightPlugin {
    /// A window with the given configuration.
    pub fn window(config: WindowConfig) -> Self {
        Self {
            mode: OutputMode::Window(config),
            pipelined: true,
            frames_in_flight: manylight_render::DEFAULT_FRAMES_IN_FLIGHT,
        }
    }

    /// Headless rendering at `size` (synchronous, one frame per `App::update`).
    pub fn headless(size: UVec2) -> Self {
        Self {
            mode: OutputMode::Headless(HeadlessConfig { size, frames: 1, output: None }),
            pipelined: false,
            frames_in_flight: manylight_render::DEFAULT_FRAMES_IN_FLIGHT,
        }
    }

    /// Headless: frames `App::run` renders before it exits.
    pub fn with_frames(mut self, frames: u32) -> Self {
        if let OutputMode::Headless(h) = &mut self.mode {
            h.frames = frames.max(1);
        }
        self
    }

    /// Headless: the PNG `App::run` writes the last frame to.
    pub fn with_output(mut self, path: impl Into<PathBuf>) -> Self {
        if let OutputMode::Headless(h) = &mut self.mode {
            h.output = Some(path.into());
        }
        self
    }

    /// Sets the most frames in flight ([`ManyLightPlugin::frames_in_flight`]).
    pub fn with_frames_in_flight(mut self, frames: u32) -> Self {
        self.frames_in_flight = frames.clamp(1, manylight_render::MAX_FRAMES_IN_FLIGHT);
        self
    }

    /// Chooses pipelined (render thread) or synchronous rendering.
    pub fn with_pipelined(mut self, pipelined: bool) -> Self {
        self.pipelined = pipelined;
        self
    }
}

impl Plugin for ManyLightPlugin {
    fn build(&self, app: &mut App) {
        // Bevy's transform hierarchy (GlobalTransform from Transform and ChildOf, in
        // PostUpdate) and clock, unless the app brought them already.
        if !app.is_plugin_added::<TransformPlugin>() {
            app.add_plugins(TransformPlugin);
            // bevy_transform's serial "static scene" pass marks dirty trees by walking up from
            // every changed entity until it meets an ancestor changed but not newly added: on
            // the frame a hierarchy is spawned that is entities × depth (quadratic for a deep
            // glTF chain; docs/reliability.md), and the serial propagation it feeds visits
            // every entity with a parent anyway, so it saves nothing here.
            app.insert_resource(StaticTransformOptimizations::Disabled);
        }
        if !app.is_plugin_added::<TimePlugin>() {
            app.add_plugins(TimePlugin);
        }
        app.add_systems(
            PostUpdate,
            crate::visibility::propagate_visibility.after(TransformSystems::Propagate),
        );
        app.insert_resource(FramesInFlight(self.frames_in_flight));
        app.init_resource::<RenderSettings>()
            .init_resource::<DebugView>()
            .init_resource::<crate::resources::LightAnimationMode>()
            .init_resource::<FrameStats>()
            .init_resource::<crate::resources::RenderedImages>()
            .init_resource::<RenderFailure>()
            .init_resource::<crate::stages::RenderStages>()
            .init_resource::<crate::stages::ExtractedCameraComponents>()
            .add_message::<crate::backend::RenderFailed>()
            .init_resource::<crate::window::WindowRequests>()
            .init_resource::<crate::window::PressedKeys>()
            .configure_sets(Update, ManyLightSystems::Animate)
            .configure_sets(Last, ManyLightSystems::Extract)
            .add_systems(Update, animate_lights.in_set(ManyLightSystems::Animate))
            .add_systems(
                Last,
                (extract_and_render, collect_results).chain().in_set(ManyLightSystems::Extract),
            );
        match &self.mode {
            OutputMode::Window(config) => {
                let config = config.clone();
                let pipelined = self.pipelined;
                app.insert_resource(ViewportSize(UVec2::new(config.width, config.height)))
                    .insert_resource(HeadlessCapture::default())
                    .insert_resource(RenderBackend::Pending)
                    .set_runner(move |app| crate::window::run_window(app, config, pipelined));
            }
            OutputMode::Headless(config) => {
                let backend = match HeadlessRenderer::with_frames_in_flight(self.frames_in_flight) {
                    Ok(r) => RenderBackend::start(Box::new(r), self.pipelined),
                    Err(e) => RenderBackend::Failed(e.to_string()),
                };
                let config = config.clone();
                app.insert_resource(TimeUpdateStrategy::ManualDuration(HEADLESS_TIME_STEP))
                    .insert_resource(ViewportSize(config.size))
                    .insert_resource(HeadlessCapture { enabled: true, image: None })
                    .insert_resource(backend)
                    .set_runner(move |app| crate::headless::run_headless(app, config));
            }
        }
    }
}

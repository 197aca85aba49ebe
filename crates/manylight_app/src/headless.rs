//! The headless runner: renders a number of frames and writes the last one as PNG.

use crate::backend::RenderBackend;
use crate::resources::{FrameStats, HeadlessCapture, RenderFailure};
use bevy_app::{App, AppExit};
use glam::UVec2;
use std::path::PathBuf;

/// Headless parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadlessConfig {
    /// Target size in pixels.
    pub size: UVec2,
    /// With `App::run`: how many frames to render before exiting (default 1).
    pub frames: u32,
    /// With `App::run`: where to write the last frame as PNG.
    pub output: Option<PathBuf>,
}

/// Runs `config.frames` updates (or until a system exits), then writes the last frame to
/// `config.output` if set.
pub fn run_headless(mut app: App, config: HeadlessConfig) -> AppExit {
    finish_plugins(&mut app);
    for _ in 0..config.frames {
        app.update();
        if let Some(exit) = app.should_exit() {
            return exit;
        }
    }
    finish_frames(&mut app);
    if let Some(message) = app.world().get_resource::<RenderFailure>().and_then(|f| f.0.clone()) {
        tracing::error!("{message}");
        return AppExit::error();
    }
    if let Some(path) = &config.output {
        let Some(image) = app.world().get_resource::<HeadlessCapture>().and_then(|c| c.image.clone()) else {
            tracing::error!("no frame was captured, nothing written to {}", path.display());
            return AppExit::error();
        };
        if let Err(e) = save_png(&image, path) {
            tracing::error!("{e}");
            return AppExit::error();
        }
        tracing::info!("wrote {}", path.display());
    }
    AppExit::Success
}

/// Lets plugins finish building, as bevy's own runners do before the first update.
pub fn finish_plugins(app: &mut App) {
    if app.plugins_state() == bevy_app::PluginsState::Ready {
        app.finish();
        app.cleanup();
    }
}

/// Waits for frames still in flight (pipelined mode) and stores their results.
pub fn finish_frames(app: &mut App) {
    let world = app.world_mut();
    let results = world.resource_mut::<RenderBackend>().flush();
    crate::backend::record_results(world, results);
}

/// Writes an image as PNG, creating parent folders.
pub fn save_png(image: &image::RgbaImage, path: &std::path::Path) -> Result<(), String> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    image.save(path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The last frame of a headless run.
#[derive(Clone, Debug)]
pub struct HeadlessFrame {
    /// The tone-mapped image.
    pub image: image::RgbaImage,
    /// Statistics of the run (the report is the last frame's).
    pub stats: FrameStats,
}

/// Builds a headless app of `size`, lets `setup` add systems and resources (spawn the scene in
/// a `Startup` system), renders `frames` frames synchronously and returns the last one.
pub fn render_headless(
    size: glam::UVec2,
    frames: u32,
    setup: impl FnOnce(&mut App),
) -> Result<HeadlessFrame, String> {
    let mut app = App::new();
    app.add_plugins(crate::ManyLightPlugin::headless(size));
    setup(&mut app);
    finish_plugins(&mut app);
    for _ in 0..frames.max(1) {
        app.update();
        if let Some(message) = app.world().resource::<RenderFailure>().0.clone() {
            return Err(message);
        }
    }
    finish_frames(&mut app);
    if let Some(message) = app.world().resource::<RenderFailure>().0.clone() {
        return Err(message);
    }
    let image = app.world().resource::<HeadlessCapture>().image.clone().ok_or("no frame was rendered")?;
    Ok(HeadlessFrame { image, stats: app.world().resource::<FrameStats>().clone() })
}

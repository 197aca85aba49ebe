//! What the windowed examples share: their command line.

use clap::Parser;
use manylight::prelude::*;
use std::path::PathBuf;

/// `--headless [OUT.png]` renders headless at 1280×720 instead of opening a window and writes
/// the last frame to `OUT.png` (the example's own name without one); `--frames N` sets how many
/// frames a headless run renders (1/60 s apart).
#[derive(Clone, Debug, PartialEq, Parser)]
pub struct ExampleArgs {
    /// Render headless and write the last frame to this PNG (the example's default without a
    /// path) instead of opening a window.
    #[arg(long, num_args = 0..=1)]
    pub headless: Option<Option<PathBuf>>,
    /// Frames a headless run renders.
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
}

impl ExampleArgs {
    /// The process's arguments; exits with clap's message on a bad one.
    pub fn from_env() -> ExampleArgs {
        ExampleArgs::parse()
    }

    /// The PNG a headless run writes (`default_output` when `--headless` names none); `None`
    /// opens a window.
    pub fn output(&self, default_output: &str) -> Option<PathBuf> {
        self.headless.as_ref().map(|path| path.clone().unwrap_or_else(|| default_output.into()))
    }

    /// The plugin: headless at 1280×720 writing [`ExampleArgs::output`], or a window.
    pub fn plugin(&self, default_output: &str) -> ManyLightPlugin {
        match self.output(default_output) {
            Some(path) => {
                ManyLightPlugin::headless(UVec2::new(1280, 720)).with_frames(self.frames).with_output(path)
            }
            None => ManyLightPlugin::default(),
        }
    }
}

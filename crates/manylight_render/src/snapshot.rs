//! The plain data one frame is rendered from. The app's extract system fills it from the ECS
//! world; the render side reads it and nothing else (it never reaches back into the ECS).

use glam::{Mat4, UVec2, Vec3};
use manylight_core::{MaterialData, MeshData, Projection, ShadingModel};
use std::sync::Arc;

/// Which many-light pipeline renders the frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PipelineKind {
    /// Forward shading that evaluates every light for every fragment (the reference).
    #[default]
    NaiveForward,
}

impl PipelineKind {
    /// Every pipeline, in the order the CLI lists them.
    pub const ALL: [PipelineKind; 1] = [PipelineKind::NaiveForward];

    /// Name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            PipelineKind::NaiveForward => "naive",
        }
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<PipelineKind> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// Settings the render side needs, copied from the app's `RenderSettings` each frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// The pipeline to use.
    pub pipeline: PipelineKind,
    /// The shading model for materials that do not choose one.
    pub shading: ShadingModel,
    /// Multiplier applied before tone mapping.
    pub exposure: f32,
    /// Constant ambient term (fraction of albedo).
    pub ambient: f32,
    /// Colour the HDR target is cleared to (linear RGB).
    pub clear_color: [f32; 3],
}

impl Default for FrameSettings {
    fn default() -> Self {
        Self {
            pipeline: PipelineKind::NaiveForward,
            shading: ShadingModel::BlinnPhong,
            exposure: 1.0,
            ambient: 0.03,
            clear_color: [0.005, 0.006, 0.01],
        }
    }
}

/// The camera as the render side sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedCamera {
    /// World-from-camera transform (camera looks down its -Z).
    pub world_from_view: Mat4,
    /// Projection parameters.
    pub projection: Projection,
    /// Last frame's clip-from-world; `None` on the first frame.
    pub prev_clip_from_world: Option<Mat4>,
}

impl ExtractedCamera {
    /// View-from-world matrix.
    pub fn view_from_world(&self) -> Mat4 {
        self.world_from_view.inverse()
    }

    /// Clip-from-world for a viewport of `size`.
    pub fn clip_from_world(&self, size: UVec2) -> Mat4 {
        self.projection.matrix(aspect(size)) * self.view_from_world()
    }

    /// Camera position in world space.
    pub fn position(&self) -> Vec3 {
        self.world_from_view.w_axis.truncate()
    }
}

/// Width / height, 1 for an empty viewport.
pub fn aspect(size: UVec2) -> f32 {
    if size.x == 0 || size.y == 0 { 1.0 } else { size.x as f32 / size.y as f32 }
}

/// One drawn object.
#[derive(Clone, Debug)]
pub struct ExtractedInstance {
    /// Geometry (shared; uploaded once per distinct `Arc`).
    pub mesh: Arc<MeshData>,
    /// Material (shared; one bind group per distinct `Arc`).
    pub material: Arc<MaterialData>,
    /// World-from-object transform.
    pub world_from_local: Mat4,
}

/// One point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedPointLight {
    /// World position.
    pub position: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Multiplier of `color`.
    pub intensity: f32,
    /// Radius of influence (contribution is exactly 0 at and beyond it).
    pub radius: f32,
}

impl ExtractedPointLight {
    /// True when every parameter is finite and the radius and intensity are not negative.
    pub fn is_valid(&self) -> bool {
        self.position.is_finite()
            && self.color.is_finite()
            && self.intensity.is_finite()
            && self.radius.is_finite()
            && self.radius >= 0.0
            && self.intensity >= 0.0
    }
}

/// Everything one frame is rendered from.
#[derive(Clone, Debug, Default)]
pub struct FrameSnapshot {
    /// Frame counter, from 0.
    pub frame_index: u64,
    /// Target size in pixels (0 in either axis: nothing is rendered).
    pub viewport: UVec2,
    /// The camera; `None` renders nothing but the clear colour.
    pub camera: Option<ExtractedCamera>,
    /// Drawn objects.
    pub instances: Vec<ExtractedInstance>,
    /// Point lights.
    pub lights: Vec<ExtractedPointLight>,
    /// Settings.
    pub settings: FrameSettings,
}

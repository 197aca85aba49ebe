//! Materials and textures as plain data (what the GPU side uploads once, shared as `Arc`s).

use glam::Vec4;
use std::sync::Arc;

/// How a surface responds to light. Selected per material or globally in the render settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadingModel {
    /// Diffuse only.
    Lambert,
    /// Diffuse plus a Blinn-Phong specular lobe.
    #[default]
    BlinnPhong,
}

impl ShadingModel {
    /// Value the shaders switch on (`SHADING_*` in `shaders/common/brdf.wgsl`).
    pub fn gpu_id(self) -> u32 {
        match self {
            ShadingModel::Lambert => 0,
            ShadingModel::BlinnPhong => 1,
        }
    }

    /// Every model, in `gpu_id` order.
    pub const ALL: [ShadingModel; 2] = [ShadingModel::Lambert, ShadingModel::BlinnPhong];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ShadingModel::Lambert => "lambert",
            ShadingModel::BlinnPhong => "blinn-phong",
        }
    }
}

/// An RGBA8 image, either sRGB-encoded colour or linear data.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureData {
    /// Where it came from (file name or generator), for error messages and GPU labels.
    pub label: String,
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// `width * height * 4` bytes, rows top to bottom.
    pub rgba8: Vec<u8>,
    /// True when the bytes are sRGB-encoded colour (sampled through an `*Srgb` format).
    pub srgb: bool,
}

/// Surface parameters of a mesh instance.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialData {
    /// Name for logs and GPU labels.
    pub label: String,
    /// Linear RGBA multiplier of the base colour texture.
    pub base_color: Vec4,
    /// Optional sRGB base colour texture.
    pub base_color_texture: Option<Arc<TextureData>>,
    /// Per-material shading model; `None` uses the global one from the render settings.
    pub shading: Option<ShadingModel>,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Strength of the specular lobe (0 = none).
    pub specular: f32,
}

impl Default for MaterialData {
    fn default() -> Self {
        Self {
            label: "default".into(),
            base_color: Vec4::ONE,
            base_color_texture: None,
            shading: None,
            shininess: 32.0,
            specular: 0.25,
        }
    }
}

//! Structs and constants shared with WGSL. Each struct here has a twin in `shaders/common/`;
//! `tests/layout.rs` reflects the WGSL with naga and checks sizes and offsets agree.
//! Constants are written into every shader by [`crate::shaders::constants_preamble`], so this
//! file is their single source.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};
use manylight_core::ShadingModel;

/// `GpuMaterial::shading_model` value meaning "use the view's global model".
pub const SHADING_GLOBAL: u32 = 0xffff_ffff;

/// Constants emitted into WGSL as `const NAME: u32 = VALUE;`.
pub fn shared_u32_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("SHADING_LAMBERT", ShadingModel::Lambert.gpu_id()),
        ("SHADING_BLINN_PHONG", ShadingModel::BlinnPhong.gpu_id()),
        ("SHADING_GLOBAL", SHADING_GLOBAL),
    ]
}

/// Per-view constants (`ViewUniform` in `shaders/common/view.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ViewUniform {
    /// Clip from world (projection * view).
    pub clip_from_world: Mat4,
    /// View from world.
    pub view_from_world: Mat4,
    /// Clip from view (reverse-Z projection).
    pub clip_from_view: Mat4,
    /// World from clip (inverse of `clip_from_world`).
    pub world_from_clip: Mat4,
    /// Last frame's clip-from-world (equals this frame's on the first frame).
    pub prev_clip_from_world: Mat4,
    /// xyz: camera world position.
    pub camera_position: Vec4,
    /// Viewport width, height, 1/width, 1/height.
    pub viewport: Vec4,
    /// near, far, exposure, ambient.
    pub params: Vec4,
    /// Number of lights in the light buffer.
    pub light_count: u32,
    /// Global shading model id.
    pub shading_model: u32,
    /// Padding to 16 bytes.
    pub _pad: [u32; 2],
}

/// A point light as the shaders read it (`GpuPointLight` in `shaders/common/lights.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuPointLight {
    /// xyz: world position, w: radius.
    pub position_radius: [f32; 4],
    /// rgb: colour * intensity, a: unused.
    pub color: [f32; 4],
}

/// Per-instance transforms (`GpuInstance` in `shaders/common/mesh.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuInstance {
    /// World from object.
    pub world_from_local: Mat4,
    /// Inverse transpose of the upper 3×3 of `world_from_local`, as a Mat4.
    pub normal_from_local: Mat4,
}

impl GpuInstance {
    /// Builds the instance data for a world-from-local transform.
    pub fn new(world_from_local: Mat4) -> GpuInstance {
        let m3 = glam::Mat3::from_mat4(world_from_local);
        let det = m3.determinant();
        let normal =
            if det.abs() > f32::MIN_POSITIVE && det.is_finite() { m3.inverse().transpose() } else { m3 };
        GpuInstance { world_from_local, normal_from_local: Mat4::from_mat3(normal) }
    }
}

/// Per-material constants (`GpuMaterial` in `shaders/common/mesh.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: Vec4,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Specular strength.
    pub specular: f32,
    /// `ShadingModel::gpu_id` or [`SHADING_GLOBAL`].
    pub shading_model: u32,
    /// 1 when a base colour texture is bound.
    pub has_texture: u32,
}

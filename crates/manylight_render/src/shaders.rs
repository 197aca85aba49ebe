//! The WGSL sources, embedded at compile time, and the small include step that combines them.
//!
//! A shader names shared code with a line `//!include common/file.wgsl`; each file is pasted
//! once, in order of first mention. Every shader starts with the constants preamble generated
//! from [`crate::gpu_types::shared_u32_constants`].

use crate::gpu_types::{shared_f32_constants, shared_u32_constants};
use std::fmt::Write as _;

/// Every WGSL file under `shaders/`, by path relative to that folder.
pub const SOURCES: &[(&str, &str)] = &[
    ("common/view.wgsl", include_str!("../../../shaders/common/view.wgsl")),
    ("common/lights.wgsl", include_str!("../../../shaders/common/lights.wgsl")),
    ("common/brdf.wgsl", include_str!("../../../shaders/common/brdf.wgsl")),
    ("common/mesh.wgsl", include_str!("../../../shaders/common/mesh.wgsl")),
    ("common/fullscreen.wgsl", include_str!("../../../shaders/common/fullscreen.wgsl")),
    ("common/surface.wgsl", include_str!("../../../shaders/common/surface.wgsl")),
    ("common/mesh_pass.wgsl", include_str!("../../../shaders/common/mesh_pass.wgsl")),
    ("common/clusters.wgsl", include_str!("../../../shaders/common/clusters.wgsl")),
    ("common/packing.wgsl", include_str!("../../../shaders/common/packing.wgsl")),
    ("common/gbuffer_codec.wgsl", include_str!("../../../shaders/common/gbuffer_codec.wgsl")),
    ("common/gbuffer_read.wgsl", include_str!("../../../shaders/common/gbuffer_read.wgsl")),
    ("common/view_binding.wgsl", include_str!("../../../shaders/common/view_binding.wgsl")),
    ("common/directional_lights.wgsl", include_str!("../../../shaders/common/directional_lights.wgsl")),
    ("common/cluster_lists.wgsl", include_str!("../../../shaders/common/cluster_lists.wgsl")),
    ("common/light_lists.wgsl", include_str!("../../../shaders/common/light_lists.wgsl")),
    ("common/point_lights.wgsl", include_str!("../../../shaders/common/point_lights.wgsl")),
    ("light_volumes.wgsl", include_str!("../../../shaders/light_volumes.wgsl")),
    ("forward.wgsl", include_str!("../../../shaders/forward.wgsl")),
    ("depth_prepass.wgsl", include_str!("../../../shaders/depth_prepass.wgsl")),
    ("cluster_build.wgsl", include_str!("../../../shaders/cluster_build.wgsl")),
    ("cluster_depth.wgsl", include_str!("../../../shaders/cluster_depth.wgsl")),
    ("light_refine.wgsl", include_str!("../../../shaders/light_refine.wgsl")),
    ("clustered_forward.wgsl", include_str!("../../../shaders/clustered_forward.wgsl")),
    ("transparent.wgsl", include_str!("../../../shaders/transparent.wgsl")),
    ("debug_view.wgsl", include_str!("../../../shaders/debug_view.wgsl")),
    ("gbuffer.wgsl", include_str!("../../../shaders/gbuffer.wgsl")),
    ("deferred_lighting.wgsl", include_str!("../../../shaders/deferred_lighting.wgsl")),
    ("tiled_deferred.wgsl", include_str!("../../../shaders/tiled_deferred.wgsl")),
    ("tonemap.wgsl", include_str!("../../../shaders/tonemap.wgsl")),
    ("bloom.wgsl", include_str!("../../../shaders/bloom.wgsl")),
    ("motion_blur.wgsl", include_str!("../../../shaders/motion_blur.wgsl")),
    ("tests/codec_roundtrip.wgsl", include_str!("../../../shaders/tests/codec_roundtrip.wgsl")),
];

/// A shader could not be composed.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum ShaderError {
    /// The named file is not in [`SOURCES`].
    #[error("shader `{0}` is not embedded (add it to manylight_render::shaders::SOURCES)")]
    Unknown(String),
}

/// `const NAME: u32 = VALUE;` lines for every shared constant.
pub fn constants_preamble() -> String {
    let mut s = String::from("// generated from manylight_render::gpu_types\n");
    for (name, value) in shared_u32_constants() {
        let _ = writeln!(s, "const {name}: u32 = {value}u;");
    }
    for (name, value) in shared_f32_constants() {
        let _ = writeln!(s, "const {name}: f32 = {value:?};");
    }
    s
}

fn source(path: &str) -> Result<&'static str, ShaderError> {
    SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .ok_or_else(|| ShaderError::Unknown(path.to_string()))
}

/// The full WGSL of `path`: preamble, then its includes, then its own body.
pub fn compose(path: &str) -> Result<String, ShaderError> {
    let mut out = constants_preamble();
    let mut seen = Vec::new();
    append(path, &mut out, &mut seen)?;
    Ok(out)
}

fn append(path: &str, out: &mut String, seen: &mut Vec<String>) -> Result<(), ShaderError> {
    if seen.iter().any(|s| s == path) {
        return Ok(());
    }
    seen.push(path.to_string());
    for line in source(path)?.lines() {
        if let Some(include) = line.trim().strip_prefix("//!include ") {
            append(include.trim(), out, seen)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(())
}

/// Creates a shader module from the composed source of `path`.
pub fn create_module(device: &wgpu::Device, path: &str) -> Result<wgpu::ShaderModule, ShaderError> {
    let code = compose(path)?;
    Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(path),
        source: wgpu::ShaderSource::Wgsl(code.into()),
    }))
}

//! The WGSL sources, embedded at compile time, and the small include step that combines them.
//!
//! A shader names shared code with a line `//!include common/file.wgsl`; each file is pasted
//! once, in order of first mention. Every shader starts with the constants preamble generated
//! from [`crate::gpu_types::shared_u32_constants`].
//!
//! Lines between `//!if NAME` and `//!endif` (with an optional `//!else`) are kept only when
//! the [`ShaderDefs`] the shader is composed with turn `NAME` on: a frame whose lights cast
//! no shadow compiles shaders with no shadow binding and no shadow code at all.

use crate::gpu_types::{shared_f32_constants, shared_u32_constants};
use std::fmt::Write as _;

/// Every WGSL file under `shaders/`, by path relative to that folder.
pub const SOURCES: &[(&str, &str)] = &[
    ("common/view.wgsl", include_str!("../shaders/common/view.wgsl")),
    ("common/lights.wgsl", include_str!("../shaders/common/lights.wgsl")),
    ("common/brdf.wgsl", include_str!("../shaders/common/brdf.wgsl")),
    ("common/mesh.wgsl", include_str!("../shaders/common/mesh.wgsl")),
    ("common/fullscreen.wgsl", include_str!("../shaders/common/fullscreen.wgsl")),
    ("common/tonemap_curve.wgsl", include_str!("../shaders/common/tonemap_curve.wgsl")),
    ("common/surface.wgsl", include_str!("../shaders/common/surface.wgsl")),
    ("common/mesh_material.wgsl", include_str!("../shaders/common/mesh_material.wgsl")),
    ("common/mesh_pass.wgsl", include_str!("../shaders/common/mesh_pass.wgsl")),
    ("common/clusters.wgsl", include_str!("../shaders/common/clusters.wgsl")),
    ("common/packing.wgsl", include_str!("../shaders/common/packing.wgsl")),
    ("common/gbuffer_codec.wgsl", include_str!("../shaders/common/gbuffer_codec.wgsl")),
    ("common/gbuffer_read.wgsl", include_str!("../shaders/common/gbuffer_read.wgsl")),
    ("common/view_binding.wgsl", include_str!("../shaders/common/view_binding.wgsl")),
    ("common/directional_lights.wgsl", include_str!("../shaders/common/directional_lights.wgsl")),
    ("common/cluster_lists.wgsl", include_str!("../shaders/common/cluster_lists.wgsl")),
    ("common/forward_fragment.wgsl", include_str!("../shaders/common/forward_fragment.wgsl")),
    ("common/light_lists.wgsl", include_str!("../shaders/common/light_lists.wgsl")),
    ("common/point_lights.wgsl", include_str!("../shaders/common/point_lights.wgsl")),
    ("common/shadow_types.wgsl", include_str!("../shaders/common/shadow_types.wgsl")),
    ("common/shadows.wgsl", include_str!("../shaders/common/shadows.wgsl")),
    ("common/environment_map.wgsl", include_str!("../shaders/common/environment_map.wgsl")),
    ("common/environment.wgsl", include_str!("../shaders/common/environment.wgsl")),
    ("environment_prefilter.wgsl", include_str!("../shaders/environment_prefilter.wgsl")),
    ("skybox.wgsl", include_str!("../shaders/skybox.wgsl")),
    ("shadow_maps.wgsl", include_str!("../shaders/shadow_maps.wgsl")),
    ("shadow_probe.wgsl", include_str!("../shaders/shadow_probe.wgsl")),
    ("common/ray_bvh.wgsl", include_str!("../shaders/common/ray_bvh.wgsl")),
    ("common/ray_shadows.wgsl", include_str!("../shaders/common/ray_shadows.wgsl")),
    ("ray_probe.wgsl", include_str!("../shaders/ray_probe.wgsl")),
    ("light_volumes.wgsl", include_str!("../shaders/light_volumes.wgsl")),
    ("forward.wgsl", include_str!("../shaders/forward.wgsl")),
    ("depth_prepass.wgsl", include_str!("../shaders/depth_prepass.wgsl")),
    ("cluster_build.wgsl", include_str!("../shaders/cluster_build.wgsl")),
    ("light_spheres.wgsl", include_str!("../shaders/light_spheres.wgsl")),
    ("light_animation.wgsl", include_str!("../shaders/light_animation.wgsl")),
    ("cluster_depth.wgsl", include_str!("../shaders/cluster_depth.wgsl")),
    ("light_refine.wgsl", include_str!("../shaders/light_refine.wgsl")),
    ("clustered_forward.wgsl", include_str!("../shaders/clustered_forward.wgsl")),
    ("texture_lists.wgsl", include_str!("../shaders/texture_lists.wgsl")),
    ("transparent.wgsl", include_str!("../shaders/transparent.wgsl")),
    ("debug_view.wgsl", include_str!("../shaders/debug_view.wgsl")),
    ("gbuffer.wgsl", include_str!("../shaders/gbuffer.wgsl")),
    ("deferred_lighting.wgsl", include_str!("../shaders/deferred_lighting.wgsl")),
    ("tiled_deferred.wgsl", include_str!("../shaders/tiled_deferred.wgsl")),
    ("tonemap.wgsl", include_str!("../shaders/tonemap.wgsl")),
    ("bloom.wgsl", include_str!("../shaders/bloom.wgsl")),
    ("motion_blur.wgsl", include_str!("../shaders/motion_blur.wgsl")),
    ("tests/codec_roundtrip.wgsl", include_str!("../shaders/tests/codec_roundtrip.wgsl")),
];

/// A shader could not be composed.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum ShaderError {
    /// The named file is not in [`SOURCES`].
    #[error("shader `{0}` is not embedded (add it to manylight_render::shaders::SOURCES)")]
    Unknown(String),
    /// A `//!if`, `//!else` or `//!endif` line without its partner, or naming no known define.
    #[error("shader `{file}`: {problem}")]
    Conditional {
        /// The file holding the line.
        file: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// The switches a shader is composed with (`//!if NAME` … `//!endif` blocks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ShaderDefs {
    /// `SHADOWS`: point and spot lights read their shadow maps (`common/shadows.wgsl`): the
    /// shadow atlas, its sampler and the per-light shadow table are bound in group 0.
    pub shadows: bool,
    /// `CLIP_DISTANCES`: the device draws `@builtin(clip_distances)`
    /// (`wgpu::Features::CLIP_DISTANCES`); the shadow pass clips each face to its tile with
    /// them instead of discarding fragments.
    pub clip_distances: bool,
    /// The G-buffer layout a shader that reads or writes the G-buffer is composed for:
    /// `GBUFFER` (any layout) and one of `GBUFFER_FULL`, `GBUFFER_PACKED`, `GBUFFER_COMPACT`
    /// (`common/gbuffer_read.wgsl` gives it `gbuffer_read`, `gbuffer.wgsl` its `GBufferOut`), so
    /// each pass has one entry point whatever the layout.
    pub gbuffer: Option<crate::snapshot::GBufferLayout>,
    /// `ENVIRONMENT`: surfaces add the light of the view's environment map
    /// (`common/environment.wgsl`): its prefiltered cubes, lookup table and sampler are bound
    /// in group 0.
    pub environment: bool,
    /// `RAYS`: point, spot and directional lights that cast test their visibility with a
    /// shadow ray through the scene's BVH (`common/ray_shadows.wgsl`): the BVH's three
    /// buffers and the casting lights' bits are bound in group 0.
    pub rays: bool,
}

impl ShaderDefs {
    /// These defines composed for G-buffer `layout`.
    pub fn with_gbuffer(self, layout: crate::snapshot::GBufferLayout) -> ShaderDefs {
        ShaderDefs { gbuffer: Some(layout), ..self }
    }

    /// The defines a shader can test, with their state.
    fn flags(self) -> [(&'static str, bool); 8] {
        use crate::snapshot::GBufferLayout;
        [
            ("SHADOWS", self.shadows),
            ("RAYS", self.rays),
            ("ENVIRONMENT", self.environment),
            ("CLIP_DISTANCES", self.clip_distances),
            ("GBUFFER", self.gbuffer.is_some()),
            ("GBUFFER_FULL", self.gbuffer == Some(GBufferLayout::Full)),
            ("GBUFFER_PACKED", self.gbuffer == Some(GBufferLayout::Packed)),
            ("GBUFFER_COMPACT", self.gbuffer == Some(GBufferLayout::Compact)),
        ]
    }

    fn get(self, name: &str) -> Option<bool> {
        self.flags().iter().find(|(n, _)| *n == name).map(|(_, on)| *on)
    }
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

/// The full WGSL of `path` with every define off: preamble, then its includes, then its own
/// body.
pub fn compose(path: &str) -> Result<String, ShaderError> {
    compose_with(path, ShaderDefs::default())
}

/// The full WGSL of `path` composed with `defs`.
///
/// WGSL wants its `enable` directives before every declaration: they are moved above the
/// preamble.
pub fn compose_with(path: &str, defs: ShaderDefs) -> Result<String, ShaderError> {
    let mut body = String::new();
    let mut seen = Vec::new();
    append(path, source(path)?, defs, &mut body, &mut seen)?;
    Ok(with_preamble(&body))
}

/// The full WGSL of an app's own shader (`source`, named `label` in errors): its
/// `//!include` lines bring in the library's files (`common/fullscreen.wgsl`,
/// `common/view.wgsl`, …; [`SOURCES`]) and it gets the shared constants' preamble, as the
/// built-in shaders do.
pub fn compose_source(label: &str, source: &str) -> Result<String, ShaderError> {
    let mut body = String::new();
    let mut seen = Vec::new();
    append(label, source, ShaderDefs::default(), &mut body, &mut seen)?;
    Ok(with_preamble(&body))
}

/// `body` with its `enable` directives first, then the constants' preamble, then the rest.
fn with_preamble(body: &str) -> String {
    let mut out = String::new();
    for line in body.lines().filter(|l| l.starts_with("enable ")) {
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&constants_preamble());
    for line in body.lines().filter(|l| !l.starts_with("enable ")) {
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Appends `text` (the file `path`) to `out` with its `//!if` blocks resolved and its includes
/// expanded, each file once.
fn append(
    path: &str,
    text: &str,
    defs: ShaderDefs,
    out: &mut String,
    seen: &mut Vec<String>,
) -> Result<(), ShaderError> {
    if seen.iter().any(|s| s == path) {
        return Ok(());
    }
    seen.push(path.to_string());
    let problem = |problem: String| ShaderError::Conditional { file: path.to_string(), problem };
    // One entry per open `//!if`: whether its current branch is kept.
    let mut open: Vec<bool> = Vec::new();
    for line in text.lines() {
        let trimmed = line.trim();
        if let Some(name) = trimmed.strip_prefix("//!if ") {
            let on =
                defs.get(name.trim()).ok_or_else(|| problem(format!("unknown define `{}`", name.trim())))?;
            open.push(on);
            continue;
        }
        if trimmed == "//!else" {
            let branch = open.last_mut().ok_or_else(|| problem("`//!else` without `//!if`".into()))?;
            *branch = !*branch;
            continue;
        }
        if trimmed == "//!endif" {
            open.pop().ok_or_else(|| problem("`//!endif` without `//!if`".into()))?;
            continue;
        }
        if !open.iter().all(|&kept| kept) {
            continue;
        }
        if let Some(include) = trimmed.strip_prefix("//!include ") {
            let include = include.trim();
            append(include, source(include)?, defs, out, seen)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    if !open.is_empty() {
        return Err(problem("`//!if` without `//!endif`".into()));
    }
    Ok(())
}

/// Creates a shader module from an app's own WGSL ([`compose_source`]).
pub fn create_module_from_source(
    device: &wgpu::Device,
    label: &str,
    source: &str,
) -> Result<wgpu::ShaderModule, ShaderError> {
    let code = compose_source(label, source)?;
    Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(code.into()),
    }))
}

/// Creates a shader module from the composed source of `path` (every define off).
pub fn create_module(device: &wgpu::Device, path: &str) -> Result<wgpu::ShaderModule, ShaderError> {
    create_module_with(device, path, ShaderDefs::default())
}

/// Creates a shader module from the source of `path` composed with `defs`.
pub fn create_module_with(
    device: &wgpu::Device,
    path: &str,
    defs: ShaderDefs,
) -> Result<wgpu::ShaderModule, ShaderError> {
    let code = compose_with(path, defs)?;
    Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(path),
        source: wgpu::ShaderSource::Wgsl(code.into()),
    }))
}

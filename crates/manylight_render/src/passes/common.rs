//! What the passes share: pipeline construction for mesh, full-screen and compute passes (each
//! checks the bind group layouts it is given against [`crate::layouts::SHADER_BIND_GROUPS`]),
//! and the attachments they use.

use crate::context::RenderError;
use crate::layouts::{GroupLayout, check_pipeline, pipeline_layout};
/// Compute pipelines are made from the layouts alone (no pass type), so modules outside the
/// passes (the environment's prefilter) make theirs without importing a pass.
pub use crate::layouts::{compute_pipeline, compute_pipeline_with_defs};
use crate::resources::{DEPTH_FORMAT, SurfaceVariant};
use manylight_core::Vertex;

fn color_targets(
    formats: &[wgpu::TextureFormat],
    blend: Option<wgpu::BlendState>,
) -> Vec<Option<wgpu::ColorTargetState>> {
    formats
        .iter()
        .map(|&format| Some(wgpu::ColorTargetState { format, blend, write_mask: wgpu::ColorWrites::ALL }))
        .collect()
}

/// A pipeline that draws the scene's meshes (vertex entry `vs_main`) with a reverse-Z depth test.
pub struct MeshPipelineDesc<'a> {
    /// Label, also the pipeline's name in captures.
    pub label: &'a str,
    /// Shader file under `shaders/`.
    pub shader: &'a str,
    /// Bind group layouts, in group order.
    pub layouts: &'a [&'a GroupLayout],
    /// Fragment entry point; `None` for depth only.
    pub fragment: Option<&'a str>,
    /// Colour target formats.
    pub targets: &'a [wgpu::TextureFormat],
    /// Write depth.
    pub depth_write: bool,
    /// Depth comparison (reverse-Z: `Greater`, or `GreaterEqual` after a pre-pass).
    pub depth_compare: wgpu::CompareFunction,
    /// Culling and alpha masking of the draws it serves.
    pub variant: SurfaceVariant,
}

/// Builds a [`MeshPipelineDesc`]. Faces are culled as the variant says (single-sided
/// materials); on faces drawn from both sides the shaders light the side the camera sees.
pub fn mesh_pipeline(
    device: &wgpu::Device,
    d: &MeshPipelineDesc<'_>,
) -> Result<wgpu::RenderPipeline, RenderError> {
    mesh_pipeline_with_constants(device, d, &[])
}

/// [`mesh_pipeline`] with values for the shader's `override` constants.
pub fn mesh_pipeline_with_constants(
    device: &wgpu::Device,
    d: &MeshPipelineDesc<'_>,
    constants: &[(&str, f64)],
) -> Result<wgpu::RenderPipeline, RenderError> {
    mesh_pipeline_with_defs(device, d, constants, d.variant.defs())
}

/// [`mesh_pipeline_with_constants`] with its shader composed with `defs` (the variant's and
/// more: the G-buffer pass adds its layout).
pub fn mesh_pipeline_with_defs(
    device: &wgpu::Device,
    d: &MeshPipelineDesc<'_>,
    constants: &[(&str, f64)],
    defs: crate::shaders::ShaderDefs,
) -> Result<wgpu::RenderPipeline, RenderError> {
    let constants: Vec<(&str, f64)> = constants.iter().copied().chain(d.variant.constants()).collect();
    let options = || wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let entry_points: Vec<&str> = ["vs_main"].into_iter().chain(d.fragment).collect();
    check_pipeline(d.shader, &entry_points, d.layouts)?;
    let module = crate::shaders::create_module_with(device, d.shader, defs)?;
    let layout = pipeline_layout(device, d.label, d.layouts);
    // Blended variants draw over the target by the fragment's alpha (glTF `BLEND`).
    let targets = color_targets(d.targets, d.variant.blend.then_some(wgpu::BlendState::ALPHA_BLENDING));
    Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: options(),
            buffers: &[Some(vertex_layout())],
        },
        primitive: d.variant.primitive(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(d.depth_write),
            depth_compare: Some(d.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: d.fragment.map(|entry| wgpu::FragmentState {
            module: &module,
            entry_point: Some(entry),
            compilation_options: options(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    }))
}

/// A full-screen pipeline: vertex `fullscreen_vs` from `common/fullscreen.wgsl`, no depth.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: &str,
    layouts: &[&GroupLayout],
    fragment: &str,
    output: wgpu::TextureFormat,
) -> Result<wgpu::RenderPipeline, RenderError> {
    let desc = FullscreenPipelineDesc {
        label,
        shader,
        layouts,
        fragment,
        output,
        blend: None,
        depth: None,
        constants: &[],
    };
    fullscreen_pipeline_desc(device, &desc)
}

/// Everything of a full-screen pipeline; [`fullscreen_pipeline`] covers the common case.
pub struct FullscreenPipelineDesc<'a> {
    /// Label, also the pipeline's name in captures.
    pub label: &'a str,
    /// Shader file under `shaders/`.
    pub shader: &'a str,
    /// Bind group layouts, in group order.
    pub layouts: &'a [&'a GroupLayout],
    /// Fragment entry point.
    pub fragment: &'a str,
    /// Format of the one colour target.
    pub output: wgpu::TextureFormat,
    /// Blending into the target (`None`: overwrite).
    pub blend: Option<wgpu::BlendState>,
    /// Depth format and test when the pass has a depth attachment (`None`: no depth).
    pub depth: Option<wgpu::DepthStencilState>,
    /// Values for the shader's `override` constants.
    pub constants: &'a [(&'a str, f64)],
}

/// Builds a [`FullscreenPipelineDesc`].
pub fn fullscreen_pipeline_desc(
    device: &wgpu::Device,
    d: &FullscreenPipelineDesc<'_>,
) -> Result<wgpu::RenderPipeline, RenderError> {
    fullscreen_pipeline_with_defs(device, d, crate::shaders::ShaderDefs::default())
}

/// [`fullscreen_pipeline_desc`] with its shader composed with `defs`.
pub fn fullscreen_pipeline_with_defs(
    device: &wgpu::Device,
    d: &FullscreenPipelineDesc<'_>,
    defs: crate::shaders::ShaderDefs,
) -> Result<wgpu::RenderPipeline, RenderError> {
    check_pipeline(d.shader, &[d.fragment], d.layouts)?;
    let module = crate::shaders::create_module_with(device, d.shader, defs)?;
    Ok(fullscreen_pipeline_with_module(device, d, &module))
}

/// [`fullscreen_pipeline_desc`] with a module made already (an app's own shader:
/// [`crate::shaders::create_module_from_source`]); `d.shader` is not read, and the layouts are
/// not checked against [`crate::layouts::SHADER_BIND_GROUPS`] (an app's shader has no row).
pub fn fullscreen_pipeline_with_module(
    device: &wgpu::Device,
    d: &FullscreenPipelineDesc<'_>,
    module: &wgpu::ShaderModule,
) -> wgpu::RenderPipeline {
    let options = || wgpu::PipelineCompilationOptions { constants: d.constants, ..Default::default() };
    let layout = pipeline_layout(device, d.label, d.layouts);
    let target =
        wgpu::ColorTargetState { format: d.output, blend: d.blend, write_mask: wgpu::ColorWrites::ALL };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("fullscreen_vs"),
            compilation_options: options(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: d.depth.clone(),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(d.fragment),
            compilation_options: options(),
            targets: &[Some(target)],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A colour attachment cleared to `clear` and stored.
pub fn color_attachment(
    view: &wgpu::TextureView,
    clear: wgpu::Color,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
    })
}

/// A linear RGB clear colour.
pub fn clear_color([r, g, b]: [f32; 3]) -> wgpu::Color {
    wgpu::Color { r: r as f64, g: g as f64, b: b as f64, a: 1.0 }
}

/// The depth attachment: cleared to 0 (reverse-Z far) or, after a pre-pass, loaded.
pub fn depth_attachment(
    view: &wgpu::TextureView,
    clear: bool,
) -> Option<wgpu::RenderPassDepthStencilAttachment<'_>> {
    let load = if clear { wgpu::LoadOp::Clear(0.0) } else { wgpu::LoadOp::Load };
    Some(wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Store }),
        stencil_ops: None,
    })
}

/// Records a full-screen triangle into `target` (cleared first) with `bind_groups` as groups
/// 0, 1, … and the pass's timestamps.
pub fn draw_fullscreen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    pipeline: &wgpu::RenderPipeline,
    bind_groups: &[&wgpu::BindGroup],
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[color_attachment(target, wgpu::Color::BLACK)],
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (i, group) in bind_groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *group, &[]);
    }
    pass.draw(0..3, 0..1);
}

/// The vertex buffer layout of [`Vertex`].
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRIBUTES: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
        0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4, 4 => Float32x2
    ];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ATTRIBUTES,
    }
}

/// Workgroups `[x, y]` for `invocations` invocations of `workgroup_size`: one row while it fits
/// in `max_per_dimension` (the device's `max_compute_workgroups_per_dimension`), else rows of
/// `max_per_dimension` workgroups (the shader's `linear_index` undoes the split; invocations
/// past the end return at once). Refused, naming the limit, past `max_per_dimension²`.
pub fn dispatch_size(
    invocations: u32,
    workgroup_size: u32,
    max_per_dimension: u32,
) -> Result<[u32; 2], RenderError> {
    let groups = invocations.div_ceil(workgroup_size.max(1)).max(1);
    let max = max_per_dimension.max(1);
    if groups <= max {
        return Ok([groups, 1]);
    }
    let rows = groups.div_ceil(max);
    // The padded grid's linear indices must stay below 2^32, or they would wrap onto real ones.
    let padded = u64::from(max) * u64::from(rows) * u64::from(workgroup_size.max(1));
    if rows > max || padded > 1 << 32 {
        return Err(RenderError::UnsupportedSettings(format!(
            "a compute pass needs {groups} workgroups, more than {max}² (max_compute_workgroups_per_dimension)"
        )));
    }
    Ok([max, rows])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::offset_of;

    /// The vertex buffer layout reads each attribute where `Vertex` stores it
    /// (`VertexIn` in `shaders/common/mesh.wgsl`: locations 0..4 in field order).
    #[test]
    fn vertex_attributes_match_the_rust_vertex() {
        let layout = vertex_layout();
        let expected = [
            offset_of!(Vertex, position),
            offset_of!(Vertex, normal),
            offset_of!(Vertex, uv),
            offset_of!(Vertex, tangent),
            offset_of!(Vertex, uv1),
        ];
        assert_eq!(layout.attributes.len(), expected.len());
        for (attribute, (location, offset)) in layout.attributes.iter().zip(expected.into_iter().enumerate())
        {
            assert_eq!((attribute.shader_location, attribute.offset), (location as u32, offset as u64));
        }
        assert_eq!(layout.array_stride, std::mem::size_of::<Vertex>() as u64);
    }
}

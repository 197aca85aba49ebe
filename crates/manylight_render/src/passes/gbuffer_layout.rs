//! How the deferred passes agree on a G-buffer layout: its targets and formats, the shader
//! defines and constants of each layout and codec, and the bind group through which the
//! lighting passes read it (`shaders/common/gbuffer_read.wgsl`). Shared by the G-buffer,
//! deferred-lighting, tiled-deferred and light-volume passes; and where the passes that need
//! each pixel's shading distance before shading (`cluster_depth`, `light_refine`) read it:
//! [`DistanceSource`].

use super::common::{compute_pipeline_with_defs, texture_entry, uniform_entry};
use super::{DEPTH, SHADING_DISTANCE};
use super::{
    GBUFFER_ALBEDO, GBUFFER_COMPACT, GBUFFER_EMISSIVE, GBUFFER_NORMAL, GBUFFER_PACKED_ALBEDO,
    GBUFFER_PACKED_POSITION, GBUFFER_POSITION,
};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{PassContext, ResourceName};
use crate::shaders::ShaderDefs;
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;

/// One G-buffer target: the graph resource, its format, and where the lighting passes read it
/// (group 1 of `shaders/common/gbuffer_read.wgsl`: binding and variable name, which
/// `tests/shaders.rs` checks against the WGSL).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GBufferTarget {
    /// The graph resource.
    pub name: ResourceName,
    /// Its format (also the G-buffer pass's colour target).
    pub format: wgpu::TextureFormat,
    /// Its binding in group 1 of `gbuffer_read.wgsl`.
    pub read_binding: u32,
    /// Its variable in `gbuffer_read.wgsl`.
    pub wgsl_name: &'static str,
}

const fn target(
    name: ResourceName,
    format: wgpu::TextureFormat,
    read_binding: u32,
    wgsl_name: &'static str,
) -> GBufferTarget {
    GBufferTarget { name, format, read_binding, wgsl_name }
}

const EMISSIVE: GBufferTarget = target(GBUFFER_EMISSIVE, wgpu::TextureFormat::Rgba16Float, 8, "gb_emissive");

/// Binding of the depth buffer in group 1 of `gbuffer_read.wgsl` (`gb_depth`), every layout.
pub const GBUFFER_READ_DEPTH_BINDING: u32 = 4;
/// Binding of the clear colour uniform in group 1 of `gbuffer_read.wgsl` (`clear_color`).
pub const GBUFFER_READ_CLEAR_COLOR_BINDING: u32 = 5;

// Albedo is rgba16f, not rgba8: 8 bits (even sRGB-encoded) cost FLIP mean 0.015 against naive
// forward where 16-bit floats give 0.0035 (docs/accuracy.md).
const FULL: [GBufferTarget; 4] = [
    target(GBUFFER_POSITION, wgpu::TextureFormat::Rgba32Float, 0, "gb_position"),
    target(GBUFFER_NORMAL, wgpu::TextureFormat::Rgba16Float, 1, "gb_normal"),
    target(GBUFFER_ALBEDO, wgpu::TextureFormat::Rgba16Float, 2, "gb_albedo"),
    EMISSIVE,
];
const PACKED: [GBufferTarget; 3] = [
    target(GBUFFER_PACKED_ALBEDO, wgpu::TextureFormat::Rgba32Float, 6, "gb_packed_albedo"),
    target(GBUFFER_PACKED_POSITION, wgpu::TextureFormat::Rgba32Float, 7, "gb_packed_position"),
    EMISSIVE,
];
const COMPACT: [GBufferTarget; 2] =
    [target(GBUFFER_COMPACT, wgpu::TextureFormat::Rgba32Uint, 3, "gb_compact"), EMISSIVE];

/// The G-buffer targets of a layout, in the G-buffer pass's colour-target order. Every layout
/// ends with [`GBUFFER_EMISSIVE`] (rgba16f: emitted radiance and ambient occlusion).
pub fn targets(layout: GBufferLayout) -> &'static [GBufferTarget] {
    match layout {
        GBufferLayout::Full => &FULL,
        GBufferLayout::Packed => &PACKED,
        GBufferLayout::Compact => &COMPACT,
    }
}

/// What a pass that reads the G-buffer of `layout` reads: its targets and [`DEPTH`].
pub fn gbuffer_reads(layout: GBufferLayout) -> impl Iterator<Item = ResourceName> {
    targets(layout).iter().map(|t| t.name).chain([DEPTH])
}

/// The `override` constants selecting `codec` in the G-buffer shaders.
pub fn codec_constants(codec: NormalCodec) -> [(&'static str, f64); 1] {
    [("NORMAL_CODEC", codec.gpu_id() as f64)]
}

/// Group 1 of `common/gbuffer_read.wgsl` for a layout: its targets, depth and the clear colour.
pub fn gbuffer_read_layout(device: &wgpu::Device, layout: GBufferLayout) -> wgpu::BindGroupLayout {
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = targets(layout)
        .iter()
        .map(|t| {
            let uint = t.format == wgpu::TextureFormat::Rgba32Uint;
            texture_entry(t.read_binding, if uint { wgpu::TextureSampleType::Uint } else { float })
        })
        .collect();
    entries.push(texture_entry(GBUFFER_READ_DEPTH_BINDING, wgpu::TextureSampleType::Depth));
    let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    entries.push(uniform_entry(GBUFFER_READ_CLEAR_COLOR_BINDING, stages));
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gbuffer_read"),
        entries: &entries,
    })
}

/// A bind group for [`gbuffer_read_layout`]: the frame's G-buffer targets, depth and
/// `clear_color` (linear RGB).
pub fn gbuffer_read_bind_group(
    ctx: &PassContext<'_>,
    bind_group_layout: &wgpu::BindGroupLayout,
    layout: GBufferLayout,
    clear_color: [f32; 3],
) -> Result<wgpu::BindGroup, RenderError> {
    let [r, g, b] = clear_color;
    let clear = ctx.uniform(("gbuffer_clear_color", 0), bytemuck::cast_slice(&[r, g, b, 1.0f32]));
    let mut bindings = Vec::new();
    for t in targets(layout) {
        bindings.push((t.read_binding, Binding::Texture(ctx.texture(t.name)?)));
    }
    bindings.push((GBUFFER_READ_DEPTH_BINDING, Binding::Texture(ctx.texture(DEPTH)?)));
    bindings.push((GBUFFER_READ_CLEAR_COLOR_BINDING, Binding::Buffer(&clear)));
    Ok(ctx.bind_group_numbered("gbuffer_read", bind_group_layout, &bindings))
}

/// Where a pass reads each pixel's shading distance (the `cluster_depth` and `light_refine`
/// passes; their shaders have one entry point per source: `cs_forward`, and `cs_gbuffer`
/// composed for the layout).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DistanceSource {
    /// The depth pre-pass's [`SHADING_DISTANCE`] (forward pipelines).
    Prepass,
    /// The G-buffer's stored position (deferred pipelines), in this layout and normal codec.
    GBuffer(GBufferLayout, NormalCodec),
}

impl DistanceSource {
    /// The source of a view: the G-buffer when it shades deferred, else the depth pre-pass.
    pub fn of(p: &crate::plan::PlanInputs<'_>) -> DistanceSource {
        let s = p.settings();
        if p.shades_deferred() {
            DistanceSource::GBuffer(s.gbuffer, s.normal_codec)
        } else {
            DistanceSource::Prepass
        }
    }

    /// What a pass reading this source reads.
    pub fn reads(self) -> Vec<ResourceName> {
        match self {
            DistanceSource::Prepass => vec![SHADING_DISTANCE, DEPTH],
            DistanceSource::GBuffer(layout, _) => gbuffer_reads(layout).collect(),
        }
    }

    /// The layout of the source's bind group (group 1), the shader entry point and its
    /// pipeline constants and defines.
    pub fn layout(
        self,
        device: &wgpu::Device,
    ) -> (wgpu::BindGroupLayout, &'static str, [(&'static str, f64); 1], ShaderDefs) {
        match self {
            DistanceSource::Prepass => {
                let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("shading_distance"),
                    entries: &[texture_entry(9, unfilterable)],
                });
                (layout, "cs_forward", codec_constants(NormalCodec::Octa16), ShaderDefs::default())
            }
            DistanceSource::GBuffer(layout, codec) => (
                gbuffer_read_layout(device, layout),
                "cs_gbuffer",
                codec_constants(codec),
                ShaderDefs::default().with_gbuffer(layout),
            ),
        }
    }

    /// The source's bind group for `layout` (from [`Self::layout`]); `clear_color` is the
    /// view's (the G-buffer read group holds it).
    pub fn bind_group(
        self,
        ctx: &PassContext<'_>,
        layout: &wgpu::BindGroupLayout,
        clear_color: [f32; 3],
    ) -> Result<wgpu::BindGroup, RenderError> {
        match self {
            DistanceSource::Prepass => Ok(ctx.bind_group_numbered(
                "shading_distance",
                layout,
                &[(9, Binding::Texture(ctx.texture(SHADING_DISTANCE)?))],
            )),
            DistanceSource::GBuffer(g, _) => gbuffer_read_bind_group(ctx, layout, g, clear_color),
        }
    }
}

/// A compute pipeline over one [`DistanceSource`]: group 0 the view, group 1 the source, group 2
/// the pass's own; and the layout of its group 1 (the `cluster_depth` and `light_refine`
/// passes).
pub struct DistancePipeline {
    /// The pipeline.
    pub pipeline: wgpu::ComputePipeline,
    /// Layout of group 1 (the source).
    pub source_layout: wgpu::BindGroupLayout,
}

impl DistancePipeline {
    /// The pipeline of `shader`'s entry point for `source` (`label` names both).
    pub fn new(
        device: &wgpu::Device,
        shader: &str,
        label: &str,
        [view_layout, pass_layout]: [&wgpu::BindGroupLayout; 2],
        source: DistanceSource,
    ) -> Result<Self, RenderError> {
        let (source_layout, entry, constants, defs) = source.layout(device);
        let layouts = [view_layout, &source_layout, pass_layout];
        let pipeline = compute_pipeline_with_defs(device, label, shader, &layouts, entry, &constants, defs)?;
        Ok(DistancePipeline { pipeline, source_layout })
    }
}

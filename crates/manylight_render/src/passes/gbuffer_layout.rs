//! How the deferred passes agree on a G-buffer layout: its targets and formats, the shader
//! defines and constants of each layout and codec, and the bind group through which the
//! lighting passes read it (`shaders/common/gbuffer_read.wgsl`). Shared by the G-buffer,
//! deferred-lighting, tiled-deferred and light-volume passes; and where the passes that need
//! each pixel's shading distance before shading (`cluster_depth`, `light_refine`) read it:
//! [`DistanceSource`].

use super::common::compute_pipeline_with_defs;
use super::{DEPTH, SHADING_DISTANCE};
use super::{
    GBUFFER_ALBEDO, GBUFFER_COMPACT, GBUFFER_EMISSIVE, GBUFFER_NORMAL, GBUFFER_PACKED_ALBEDO,
    GBUFFER_PACKED_POSITION, GBUFFER_POSITION,
};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{PassContext, ResourceName};
use crate::layouts::{
    BindingDecl, GB_ALBEDO, GB_COMPACT, GB_EMISSIVE, GB_NORMAL, GB_PACKED_ALBEDO, GB_PACKED_POSITION,
    GB_POSITION, GBUFFER_READ_GROUP, GroupLayout, SHADING_DISTANCE_GROUP,
};
use crate::shaders::ShaderDefs;
use crate::snapshot::GBufferLayout;
use manylight_core::codec::NormalCodec;

/// One G-buffer target: the graph resource, its format, and its binding in the group through
/// which the lighting passes read it ([`crate::layouts::GBUFFER_READ_GROUP`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GBufferTarget {
    /// The graph resource.
    pub name: ResourceName,
    /// Its format (also the G-buffer pass's colour target).
    pub format: wgpu::TextureFormat,
    /// Its binding in group 1 of `gbuffer_read.wgsl`, present in the layouts that have it.
    pub read: BindingDecl,
}

const fn target(name: ResourceName, format: wgpu::TextureFormat, read: BindingDecl) -> GBufferTarget {
    GBufferTarget { name, format, read }
}

const EMISSIVE: GBufferTarget = target(GBUFFER_EMISSIVE, wgpu::TextureFormat::Rgba16Float, GB_EMISSIVE);

// Albedo is rgba16f, not rgba8: 8 bits (even sRGB-encoded) cost FLIP mean 0.015 against naive
// forward where 16-bit floats give 0.0035 (docs/accuracy.md).
const FULL: [GBufferTarget; 4] = [
    target(GBUFFER_POSITION, wgpu::TextureFormat::Rgba32Float, GB_POSITION),
    target(GBUFFER_NORMAL, wgpu::TextureFormat::Rgba16Float, GB_NORMAL),
    target(GBUFFER_ALBEDO, wgpu::TextureFormat::Rgba16Float, GB_ALBEDO),
    EMISSIVE,
];
const PACKED: [GBufferTarget; 3] = [
    target(GBUFFER_PACKED_ALBEDO, wgpu::TextureFormat::Rgba32Float, GB_PACKED_ALBEDO),
    target(GBUFFER_PACKED_POSITION, wgpu::TextureFormat::Rgba32Float, GB_PACKED_POSITION),
    EMISSIVE,
];
const COMPACT: [GBufferTarget; 2] =
    [target(GBUFFER_COMPACT, wgpu::TextureFormat::Rgba32Uint, GB_COMPACT), EMISSIVE];

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

/// The layout of [`GBUFFER_READ_GROUP`] for G-buffer `layout`.
pub fn gbuffer_read_layout(device: &wgpu::Device, layout: GBufferLayout) -> GroupLayout {
    GBUFFER_READ_GROUP.create_layout(device, ShaderDefs::default().with_gbuffer(layout))
}

/// A bind group for [`gbuffer_read_layout`]: the frame's G-buffer targets, depth and
/// `clear_color` (linear RGB).
pub fn gbuffer_read_bind_group(
    ctx: &PassContext<'_>,
    bind_group_layout: &GroupLayout,
    layout: GBufferLayout,
    clear_color: [f32; 3],
) -> Result<wgpu::BindGroup, RenderError> {
    let [r, g, b] = clear_color;
    let clear = ctx.uniform(&[r, g, b, 1.0f32]);
    let mut resources = Vec::new();
    for t in targets(layout) {
        resources.push(Binding::Texture(ctx.texture(t.name)?));
    }
    resources.extend([Binding::Texture(ctx.texture(DEPTH)?), Binding::Buffer(&clear)]);
    Ok(ctx.bind_group(bind_group_layout, &resources))
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
    ) -> (GroupLayout, &'static str, [(&'static str, f64); 1], ShaderDefs) {
        match self {
            DistanceSource::Prepass => {
                let layout = SHADING_DISTANCE_GROUP.create_layout(device, ShaderDefs::default());
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
        layout: &GroupLayout,
        clear_color: [f32; 3],
    ) -> Result<wgpu::BindGroup, RenderError> {
        match self {
            DistanceSource::Prepass => {
                Ok(ctx.bind_group(layout, &[Binding::Texture(ctx.texture(SHADING_DISTANCE)?)]))
            }
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
    pub source_layout: GroupLayout,
}

impl DistancePipeline {
    /// The pipeline of `shader`'s entry point for `source` (`label` names both).
    pub fn new(
        device: &wgpu::Device,
        shader: &str,
        label: &str,
        [view_layout, pass_layout]: [&GroupLayout; 2],
        source: DistanceSource,
    ) -> Result<Self, RenderError> {
        let (source_layout, entry, constants, defs) = source.layout(device);
        let layouts = [view_layout, &source_layout, pass_layout];
        let pipeline = compute_pipeline_with_defs(device, label, shader, &layouts, entry, &constants, defs)?;
        Ok(DistancePipeline { pipeline, source_layout })
    }
}

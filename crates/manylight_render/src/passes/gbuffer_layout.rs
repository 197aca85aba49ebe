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

/// The G-buffer targets of a layout: name and format. Every layout ends with
/// [`GBUFFER_EMISSIVE`] (rgba16f: emitted radiance and ambient occlusion).
pub fn targets(layout: GBufferLayout) -> &'static [(ResourceName, wgpu::TextureFormat)] {
    match layout {
        // Albedo is rgba16f, not rgba8: with 8 bits (even sRGB-encoded)
        // the image differed from naive forward by FLIP mean 0.015, with 16-bit floats 0.0035.
        GBufferLayout::Full => &[
            (GBUFFER_POSITION, wgpu::TextureFormat::Rgba32Float),
            (GBUFFER_NORMAL, wgpu::TextureFormat::Rgba16Float),
            (GBUFFER_ALBEDO, wgpu::TextureFormat::Rgba16Float),
            (GBUFFER_EMISSIVE, wgpu::TextureFormat::Rgba16Float),
        ],
        GBufferLayout::Packed => &[
            (GBUFFER_PACKED_ALBEDO, wgpu::TextureFormat::Rgba32Float),
            (GBUFFER_PACKED_POSITION, wgpu::TextureFormat::Rgba32Float),
            (GBUFFER_EMISSIVE, wgpu::TextureFormat::Rgba16Float),
        ],
        GBufferLayout::Compact => &[
            (GBUFFER_COMPACT, wgpu::TextureFormat::Rgba32Uint),
            (GBUFFER_EMISSIVE, wgpu::TextureFormat::Rgba16Float),
        ],
    }
}

/// What a pass that reads the G-buffer of `layout` reads: its targets and [`DEPTH`].
pub fn gbuffer_reads(layout: GBufferLayout) -> impl Iterator<Item = ResourceName> {
    targets(layout).iter().map(|&(name, _)| name).chain([DEPTH])
}

/// The `override` constants selecting `codec` in the G-buffer shaders.
pub fn codec_constants(codec: NormalCodec) -> [(&'static str, f64); 1] {
    [("NORMAL_CODEC", codec.gpu_id() as f64)]
}

/// Binding number of each G-buffer target in `shaders/common/gbuffer_read.wgsl`, group 1.
fn binding_of(name: ResourceName) -> u32 {
    match name {
        GBUFFER_POSITION => 0,
        GBUFFER_NORMAL => 1,
        GBUFFER_ALBEDO => 2,
        GBUFFER_PACKED_ALBEDO => 6,
        GBUFFER_PACKED_POSITION => 7,
        GBUFFER_EMISSIVE => 8,
        _ => 3,
    }
}

/// Group 1 of `common/gbuffer_read.wgsl` for a layout: its targets, depth and the clear colour.
pub fn gbuffer_read_layout(device: &wgpu::Device, layout: GBufferLayout) -> wgpu::BindGroupLayout {
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = targets(layout)
        .iter()
        .map(|&(name, _)| {
            let sample = if name == GBUFFER_COMPACT { wgpu::TextureSampleType::Uint } else { float };
            texture_entry(binding_of(name), sample)
        })
        .collect();
    entries.push(texture_entry(4, wgpu::TextureSampleType::Depth));
    entries.push(uniform_entry(5, wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE));
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
    for &(name, _) in targets(layout) {
        bindings.push((binding_of(name), Binding::Texture(ctx.texture(name)?)));
    }
    bindings.push((4, Binding::Texture(ctx.texture(DEPTH)?)));
    bindings.push((5, Binding::Buffer(&clear)));
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

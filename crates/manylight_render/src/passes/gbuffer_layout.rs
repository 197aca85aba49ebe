//! How the deferred passes agree on a G-buffer layout: its targets and formats, the shader
//! entry points and constants of each layout and codec, and the bind group through which the
//! lighting passes read it (`shaders/common/gbuffer_read.wgsl`). Shared by the G-buffer,
//! deferred-lighting, tiled-deferred and light-volume passes.

use super::DEPTH;
use super::common::{texture_entry, uniform_entry};
use super::{
    GBUFFER_ALBEDO, GBUFFER_COMPACT, GBUFFER_EMISSIVE, GBUFFER_NORMAL, GBUFFER_PACKED_ALBEDO,
    GBUFFER_PACKED_POSITION, GBUFFER_POSITION,
};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{PassContext, ResourceName};
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

/// The fragment entry point of `gbuffer.wgsl` and `deferred_lighting.wgsl` for a layout.
pub fn fragment_entry(layout: GBufferLayout) -> &'static str {
    match layout {
        GBufferLayout::Full => "fs_full",
        GBufferLayout::Packed => "fs_packed",
        GBufferLayout::Compact => "fs_compact",
    }
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

//! One module per pass. Each pass declares its reads and writes and records itself; its
//! pipeline is created on first use through the [`crate::pipelines::PipelineCache`]. What
//! several passes share lives in shared modules, never in a pass: [`common`] (pipeline,
//! attachment and layout helpers), [`scene_draw`] (drawing the scene's instances) and
//! [`gbuffer_layout`] (G-buffer targets and the bind group that reads them). No pass module
//! imports another.

pub mod bloom;
pub mod cluster_build;
pub mod cluster_depth;
pub mod clustered_forward;
pub mod common;
pub mod debug_view;
pub mod deferred_lighting;
pub mod depth_prepass;
pub mod forward;
pub mod gbuffer;
pub mod gbuffer_layout;
pub mod light_animation;
pub mod light_refine;
pub mod light_volumes;
pub mod motion_blur;
pub mod scene_draw;
pub mod shadow_maps;
pub mod skybox;
pub mod tiled_deferred;
pub mod tonemap;
pub mod transparent;

pub use bloom::{BloomBlurPass, BloomBrightPass, BloomCompositePass, BloomUpsamplePass};
pub use cluster_build::ClusterBuildPass;
pub use cluster_depth::ClusterDepthPass;
pub use clustered_forward::ClusteredForwardPass;
pub use debug_view::DebugViewPass;
pub use deferred_lighting::DeferredLightingPass;
pub use depth_prepass::DepthPrepass;
pub use forward::ForwardPass;
pub use gbuffer::GBufferPass;
pub use light_refine::LightRefinePass;
pub use light_volumes::LightVolumesPass;
pub use motion_blur::MotionBlurPass;
pub use shadow_maps::ShadowMapsPass;
pub use skybox::SkyboxPass;
pub use tiled_deferred::TiledDeferredPass;
pub use tonemap::TonemapPass;
pub use transparent::TransparentPass;

pub use crate::graph::{HDR, HDR_SWAP};

/// The texture a post-processing pass lists in [`crate::Pass::creates`] to filter the HDR image
/// with [`crate::PassContext::post_process_write`]: [`HDR_SWAP`], as the shading passes create
/// [`HDR`].
pub fn post_process_texture() -> crate::graph::TextureSpec {
    crate::graph::TextureSpec {
        name: HDR_SWAP,
        format: crate::resources::HDR_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        scale: 1.0,
    }
}
/// Graph resource: the depth buffer (reverse-Z).
pub const DEPTH: crate::graph::ResourceName = crate::resource!("depth");
/// Graph resource: G-buffer position (Full layout).
pub const GBUFFER_POSITION: crate::graph::ResourceName = crate::resource!("gbuffer_position");
/// Graph resource: G-buffer normal (Full layout).
pub const GBUFFER_NORMAL: crate::graph::ResourceName = crate::resource!("gbuffer_normal");
/// Graph resource: G-buffer albedo (Full layout).
pub const GBUFFER_ALBEDO: crate::graph::ResourceName = crate::resource!("gbuffer_albedo");
/// Graph resource: the single G-buffer target of the Compact layout.
pub const GBUFFER_COMPACT: crate::graph::ResourceName = crate::resource!("gbuffer_compact");
/// Packed G-buffer: albedo + material parameters + first normal component (rgba32f).
pub const GBUFFER_PACKED_ALBEDO: crate::graph::ResourceName = crate::resource!("gbuffer_packed_albedo");
/// Packed G-buffer: world position + second normal component (rgba32f).
pub const GBUFFER_PACKED_POSITION: crate::graph::ResourceName = crate::resource!("gbuffer_packed_position");
/// Emitted radiance (rgb) and ambient occlusion (a) of every G-buffer layout.
pub const GBUFFER_EMISSIVE: crate::graph::ResourceName = crate::resource!("gbuffer_emissive");
/// Light volumes: the sum of the lights, in f32 where the device can blend it.
pub const LIGHT_ACCUM: crate::graph::ResourceName = crate::resource!("light_accum");
/// Graph resource: the shadow atlas (a persistent texture, [`crate::shadows`]), written by the
/// shadow pass and read by every shading pass of a frame whose lights cast shadows.
pub const SHADOW_ATLAS: crate::graph::ResourceName = crate::resource!("shadow_atlas");
/// Graph resource: the cluster light lists (persistent buffers, ordered through the graph).
pub const CLUSTERS: crate::graph::ResourceName = crate::resource!("clusters");
/// Graph resource: each pixel's view distance as forward shading computes it (the depth
/// pre-pass writes it for per-cluster depth bounds and refined light lists).
pub const SHADING_DISTANCE: crate::graph::ResourceName = crate::resource!("shading_distance");
/// Graph resource: the depth range of every cluster's pixels (after the cluster ranges, in the
/// same buffer), which the cluster build cuts clusters to.
pub const CLUSTER_DEPTHS: crate::graph::ResourceName = crate::resource!("cluster_depths");

/// Usages of the depth buffer: attachment, sampled by debug views, copied for readback.
pub const DEPTH_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

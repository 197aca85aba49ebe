//! One module per pass. Each pass declares its reads and writes and records itself; its
//! pipeline is created on first use through the [`crate::pipelines::PipelineCache`].

pub mod forward;
pub mod tonemap;

pub use forward::ForwardPass;
pub use tonemap::TonemapPass;

/// Graph resource: the HDR scene colour.
pub const HDR: crate::graph::ResourceName = "hdr";
/// Graph resource: the depth buffer (reverse-Z).
pub const DEPTH: crate::graph::ResourceName = "depth";

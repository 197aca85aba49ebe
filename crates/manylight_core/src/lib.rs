//! Pure math and plain data for manylight: no GPU, no ECS.
//!
//! Everything here is unit- and property-tested without a device; the WGSL in `shaders/`
//! mirrors these functions and GPU tests compare the two.
#![warn(missing_docs)]

pub mod animation;
pub mod attenuation;
pub mod brdf;
pub mod camera;
pub mod cluster;
pub mod codec;
pub mod efficiency;
pub mod environment;
pub mod icosphere;
#[cfg(not(target_arch = "wasm32"))]
pub mod image_metrics;
pub mod light_count;
pub mod material;
pub mod mesh;
pub mod ray_bvh;
pub mod shadow_oracle;
pub mod spot;
pub mod tonemap;

pub use animation::{AngleRate, AnimatedLight, MotionAngles};
pub use attenuation::{
    LIGHT_MIN_DISTANCE, attenuation, candela_from_lumens, lumens_from_candela, radius_for_intensity,
};
/// Bevy's colour types, which materials use (`bevy_color`, a standalone crate).
pub use bevy_color::{Color, ColorToComponents, LinearRgba};
pub use camera::{Projection, ProjectionKind, linearize_depth_reverse_z};
pub use light_count::{LightCountError, LightLimit, MAX_LIGHTS, check_light_count};
pub use material::{
    AlphaMode, ImageAddressMode, ImageFilterMode, MaterialData, MaterialTexture, ShadingModel, TextureData,
    TextureSampler, UvChannel,
};
pub use mesh::{Aabb, MeshData, MeshError, Vertex};
pub use spot::{LightShape, SpotCone};

//! Shadows of point and spot lights: one depth atlas holds a cube of six square face tiles for
//! every casting light, each light's tile edge chosen every frame from the size of its sphere on
//! screen under the atlas's room.
//!
//! Per frame ([`ShadowResources::prepare`], once whatever the views):
//! 1. every valid light with a [`ShadowBias`](crate::snapshot::ShadowBias) asks for a face edge
//!    ([`requested_edge`]): its sphere's projected radius in pixels times
//!    [`ShadowSettings::resolution_scale`], as a power of two in
//!    [`ShadowSettings::min_face_size`]..=[`ShadowSettings::max_face_size`];
//! 2. [`plan_atlas`] packs the blocks (3 × 2 tiles) in rows, largest first; when they do not fit,
//!    every edge halves until they do (the room left goes back to the lights largest on
//!    screen), and at the smallest edge the least important
//!    lights (smallest on screen) go without a shadow: both are counted
//!    ([`ShadowReport::downgraded_lights`], [`ShadowReport::dropped_lights`]), never silent;
//! 3. each opaque instance whose bounds meet a light's sphere is drawn into each face whose
//!    frustum its bounds meet: one instanced draw per mesh for all the pairs
//!    (`passes::shadow_maps`), so a thousand lights are a few dozen draw calls;
//! 4. the shading passes read the light's face at the shaded point with a 2×2 comparison filter
//!    (`shaders/common/shadows.wgsl`).
//!
//! A frame without a casting light has no atlas, no shadow pass and no shadow binding: the
//! shaders are composed without `SHADOWS` ([`crate::shaders::ShaderDefs`]).
//!
//! One file per question:
//! - `cube.rs`: how a light's six cube faces project, and the depth they store;
//! - `requests.rs`: which lights ask for a map this frame, and how large a face each asks for;
//! - `plan.rs`: where each light's maps lie in the atlas (its size, each light's edge and block);
//! - `frustum.rs`: what a view or a map can see (conservative culling tests);
//! - `cascades.rs`: how a directional light's cascade is fitted to its slice of the view;
//! - `gather.rs`: what each placed map holds this frame (its faces, casters and content hash);
//! - `cache.rs`: which maps are drawn, kept from the frame before, or left stale;
//! - `resources.rs`: the atlas and the buffers of the shadow pass, and a frame's preparation.

mod cache;
mod cascades;
mod cube;
mod frustum;
mod gather;
mod plan;
mod requests;
mod resources;

pub use crate::settings::{ShadowReport, ShadowSettings};
pub use cascades::{CascadeFit, ViewSlice, fit_cascade};
pub use cube::{SHADOW_NEAR_FRACTION, face_axis, face_clip_from_world, face_depth};
pub use frustum::{
    box_meets_clip, box_meets_face, face_in_view, frustum_planes, sphere_in_view, view_frustums,
};
pub use plan::{
    AtlasPlan, MIN_ATLAS_SIZE, SHADOW_TILE_ROWS, ShadowPlacement, atlas_limit, place_stably, plan_atlas,
    tile_transform,
};
pub use requests::{ShadowCaster, ShadowRequest, projected_radius, requested_edge};
pub use resources::{SHADOW_ATLAS_FORMAT, ShadowMeshDraws, ShadowResources};

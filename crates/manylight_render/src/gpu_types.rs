//! Structs and constants shared with WGSL. Each struct here has a twin in `shaders/common/`;
//! `crates/manylight_render/tests/shaders.rs` (`shared_structs_match_rust`) reflects the WGSL
//! with naga and checks that sizes and offsets agree.
//! Constants are written into every shader by [`crate::shaders::constants_preamble`], so this
//! file is their single source.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};
use manylight_core::ShadingModel;
use manylight_core::codec::NormalCodec;

/// `GpuMaterial::shading_model` value meaning "use the view's global model".
pub const SHADING_GLOBAL: u32 = 0xffff_ffff;

/// `GpuClusterParams::cap` value meaning "no cap" (exact assignment).
pub const CLUSTER_NO_CAP: u32 = 0xffff_ffff;
/// Lights one invocation of the cluster build's level 1 tests against its tile. Each
/// invocation handles one (tile, chunk of lights) pair, because lavapipe (Mesa 22.3's llvmpipe)
/// silently stops a shader invocation after 65 535 loop iterations in total: a loop over all
/// lights lost every light past the ~16 000th. 4096 iterations (the plane test has no loop)
/// stay well below that.
pub const TILE_LIGHT_CHUNK: u32 = 4096;
/// Most coarse tiles for which level 0 of the cluster build runs from the lights' side (each
/// light loops over the coarse tiles of its rectangle, `light_marks` in
/// `shaders/cluster_build.wgsl`), which keeps that loop far below [`LAVAPIPE_LOOP_LIMIT`]; a
/// grid with more (only with very small coarse tiles on a huge view) tests every light per
/// coarse tile instead.
pub const COARSE_SCATTER_TILES: u32 = 16_384;
/// The value the cluster build's saturating sums stop at: a total of light–cluster (or
/// light–tile) pairs that reaches it did not fit in the u32 counters, and the frame is refused
/// ([`crate::RenderError::TooManyPairs`]) instead of being built from a wrapped total.
pub const PAIR_COUNT_SATURATED: u32 = u32::MAX;
/// Loop iterations after which lavapipe (Mesa 22.3's llvmpipe) silently ends a shader
/// invocation. A list that long would lose lights there, so frames that need it are refused on
/// such an adapter ([`crate::RenderError::LoopLimit`]).
pub const LAVAPIPE_LOOP_LIMIT: u32 = 65_535;

/// True when `adapter` stops shader invocations after [`LAVAPIPE_LOOP_LIMIT`] loop
/// iterations (Mesa's llvmpipe, which lavapipe runs on).
pub fn has_loop_limit(adapter: &wgpu::AdapterInfo) -> bool {
    adapter.device_type == wgpu::DeviceType::Cpu && adapter.name.contains("llvmpipe")
}

/// Tiled deferred lighting: pixels along each edge of its workgroup (one workgroup per tile;
/// tiles wider than this are visited in steps of it).
pub const TILED_EDGE: u32 = 16;
/// Tiled deferred lighting: light indices a tile keeps in workgroup memory (4 bytes each); a
/// tile that keeps more shades from its column's whole list.
pub const TILED_LIST_CAPACITY: u32 = 2048;
/// Tiled deferred lighting: cells of a tile's depth range in its 2.5D mask (bits of a u32).
pub const TILED_DEPTH_CELLS: u32 = 32;

/// Relative slack of a pixel's view distance in the per-cluster depth bounds
/// (`shaders/cluster_depth.wgsl`): the depth buffer's distance and the one a shading pass
/// computes from the surface position agree to rounding (about 1e-6 relative); a pixel marks
/// `d ± CLUSTER_DEPTH_SLACK · d`.
pub const CLUSTER_DEPTH_SLACK: f32 = 1e-3;

/// Refined light lists (`shaders/light_refine.wgsl`): pixels along each edge of a block, the
/// unit a refined list is kept for.
pub const REFINE_EDGE: u32 = 4;
/// Refined light lists: the most lights a block's list holds; a block whose pixels need more
/// shades from its pixels' cluster lists ([`REFINED_FALLBACK`]).
pub const REFINED_LIST_SLOTS: u32 = 16;
/// Refined light lists: blocks along each axis that one `light_refine` invocation refines.
/// Blocks of a group whose pixels all fall in one cluster, the same for all, read its list
/// once (at 16-px tiles most groups); the others are refined one after the other within one
/// budget of [`REFINE_CANDIDATE_LIMIT`] × [`REFINE_MAX_CLUSTERS`] list entries × clusters.
pub const REFINE_GROUP_EDGE: u32 = 2;
/// Refined light lists: the most cluster-list entries a block tests (all the clusters its
/// pixels fall in together); a block with more shades from its cluster lists. Keeps an
/// invocation well inside lavapipe's loop limit ([`LAVAPIPE_LOOP_LIMIT`]) with the duplicate
/// checks across up to [`REFINE_MAX_CLUSTERS`] lists.
pub const REFINE_CANDIDATE_LIMIT: u32 = 1024;
/// Refined light lists: the most clusters a block's pixels may fall in; a block spanning more
/// shades from its cluster lists.
pub const REFINE_MAX_CLUSTERS: u32 = 4;
/// Refined light lists: a block's box around its pixels' positions is widened on every axis by
/// `REFINE_SLACK · (d + |camera|)` (`d` a pixel's view distance, `|camera|` the camera's
/// distance from the world origin): the shading pass computes each position again, in world
/// space, from the same data, which agrees to rounding of those magnitudes (a few 1e-7
/// relative); this is about 80 times that.
pub const REFINE_SLACK: f32 = 1e-5;
/// The count of a block's refined range that sends its pixels to their cluster lists.
pub const REFINED_FALLBACK: u32 = u32::MAX;

/// The count of a cluster's range when its list did not fit the frame's lists (or its tile
/// list was longer than the loop limit): its pixels shade from every light, which is exact
/// and needs no list memory, only slower (`shaders/cluster_build.wgsl`, `fill`). The build's
/// counters count such clusters (`GpuClusterCounters::fallback_clusters`) and the lists grow
/// for the following frames from them.
pub const LIST_EVERY_LIGHT: u32 = u32::MAX;

/// Workgroup size of the prefix-sum step of the cluster build (one workgroup scans all).
pub const SCAN_WORKGROUP_SIZE: u32 = 256;
/// `GpuClusterParams::cull_test` values.
pub const CULL_AABB: u32 = 0;
/// See [`CULL_AABB`].
pub const CULL_PLANES: u32 = 1;
/// See [`CULL_AABB`]: both tests must accept.
pub const CULL_BOTH: u32 = 2;

/// Constants emitted into WGSL as `const NAME: u32 = VALUE;`.
pub fn shared_u32_constants() -> Vec<(&'static str, u32)> {
    use crate::settings::DebugViewMode as DebugView;
    use manylight_core::cluster::ZSlicing;
    use manylight_core::ray_bvh;
    vec![
        ("MAX_DIRECTIONAL_LIGHTS", MAX_DIRECTIONAL_LIGHTS),
        ("SHADOW_FACES", SHADOW_FACES),
        ("SHADOW_TILE_COLUMNS", SHADOW_TILE_COLUMNS),
        ("MAX_CASCADES", MAX_CASCADES as u32),
        ("MATERIAL_TEXTURE_SLOTS", MATERIAL_TEXTURE_SLOTS),
        ("TEXTURE_SLOT_BASE_COLOR", TEXTURE_SLOT_BASE_COLOR),
        ("TEXTURE_SLOT_METALLIC_ROUGHNESS", TEXTURE_SLOT_METALLIC_ROUGHNESS),
        ("TEXTURE_SLOT_NORMAL", TEXTURE_SLOT_NORMAL),
        ("TEXTURE_SLOT_OCCLUSION", TEXTURE_SLOT_OCCLUSION),
        ("TEXTURE_SLOT_EMISSIVE", TEXTURE_SLOT_EMISSIVE),
        ("SHADING_LAMBERT", ShadingModel::Lambert.gpu_id()),
        ("SHADING_BLINN_PHONG", ShadingModel::BlinnPhong.gpu_id()),
        ("SHADING_TOON", ShadingModel::Toon.gpu_id()),
        ("SHADING_PBR", ShadingModel::Pbr.gpu_id()),
        ("TOON_BANDS", manylight_core::material::TOON_BANDS),
        ("NORMAL_CODEC_XYZ", NormalCodec::Xyz.gpu_id()),
        ("NORMAL_CODEC_SPHERICAL", NormalCodec::Spherical.gpu_id()),
        ("NORMAL_CODEC_OCTA16", NormalCodec::Octa16.gpu_id()),
        ("NORMAL_CODEC_OCTA8", NormalCodec::Octa8.gpu_id()),
        ("SHADING_GLOBAL", SHADING_GLOBAL),
        ("CLUSTER_NO_CAP", CLUSTER_NO_CAP),
        ("PAIR_COUNT_SATURATED", PAIR_COUNT_SATURATED),
        ("SCAN_WORKGROUP_SIZE", SCAN_WORKGROUP_SIZE),
        ("TILE_LIGHT_CHUNK", TILE_LIGHT_CHUNK),
        ("TILED_EDGE", TILED_EDGE),
        ("TILED_LIST_CAPACITY", TILED_LIST_CAPACITY),
        ("TILED_DEPTH_CELLS", TILED_DEPTH_CELLS),
        ("REFINE_EDGE", REFINE_EDGE),
        ("REFINED_LIST_SLOTS", REFINED_LIST_SLOTS),
        ("REFINE_GROUP_EDGE", REFINE_GROUP_EDGE),
        ("REFINE_CANDIDATE_LIMIT", REFINE_CANDIDATE_LIMIT),
        ("REFINE_MAX_CLUSTERS", REFINE_MAX_CLUSTERS),
        ("REFINED_FALLBACK", REFINED_FALLBACK),
        ("LIST_EVERY_LIGHT", LIST_EVERY_LIGHT),
        ("CULL_AABB", CULL_AABB),
        ("CULL_PLANES", CULL_PLANES),
        ("CULL_BOTH", CULL_BOTH),
        ("Z_SLICING_LINEAR", ZSlicing::Linear.gpu_id()),
        ("Z_SLICING_EXPONENTIAL", ZSlicing::Exponential.gpu_id()),
        ("DEBUG_LIGHT_COUNT", DebugView::LightCount.gpu_id()),
        ("DEBUG_SLICE_X", DebugView::SliceX.gpu_id()),
        ("DEBUG_SLICE_Y", DebugView::SliceY.gpu_id()),
        ("DEBUG_SLICE_Z", DebugView::SliceZ.gpu_id()),
        ("DEBUG_ALBEDO", DebugView::Albedo.gpu_id()),
        ("DEBUG_NORMAL", DebugView::Normal.gpu_id()),
        ("DEBUG_DEPTH", DebugView::Depth.gpu_id()),
        ("DEBUG_OVERFLOW", DebugView::Overflow.gpu_id()),
        ("DEBUG_SHADOW_ATLAS", DebugView::ShadowAtlas.gpu_id()),
        ("DEBUG_SHADOW_LOD", DebugView::ShadowLod.gpu_id()),
        ("DEBUG_METALLIC", DebugView::Metallic.gpu_id()),
        ("DEBUG_ROUGHNESS", DebugView::Roughness.gpu_id()),
        ("DEBUG_EMISSIVE", DebugView::Emissive.gpu_id()),
        ("DEBUG_OCCLUSION", DebugView::Occlusion.gpu_id()),
        ("RAY_STACK_SIZE", ray_bvh::RAY_STACK_SIZE),
        ("RAY_MAX_STEPS", ray_bvh::RAY_MAX_STEPS),
        ("RAY_NO_NODE", ray_bvh::RAY_NO_NODE),
        ("RAY_VISIBLE", ray_bvh::RayOutcome::Visible.code()),
        ("RAY_BLOCKED", ray_bvh::RayOutcome::Blocked.code()),
        ("RAY_EXHAUSTED", ray_bvh::RayOutcome::Exhausted.code()),
        ("RAY_STACK_FULL", ray_bvh::RayOutcome::StackFull.code()),
    ]
}

/// Per-view constants (`ViewUniform` in `shaders/common/view.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ViewUniform {
    /// Clip from world (projection * view).
    pub clip_from_world: Mat4,
    /// View from world.
    pub view_from_world: Mat4,
    /// Clip from view (reverse-Z projection).
    pub clip_from_view: Mat4,
    /// World from clip (inverse of `clip_from_world`).
    pub world_from_clip: Mat4,
    /// Last frame's clip-from-world (equals this frame's on the first frame).
    pub prev_clip_from_world: Mat4,
    /// xyz: camera world position.
    pub camera_position: Vec4,
    /// Viewport width, height, 1/width, 1/height.
    pub viewport: Vec4,
    /// near, near / far (0 without a far plane), exposure, ambient.
    pub params: Vec4,
    /// The environment's axes from world axes (its `EnvironmentMapLight::rotation`, inverted).
    pub env_from_world: Mat4,
    /// The skybox's axes from world axes (its `Skybox::rotation`, inverted).
    pub sky_from_world: Mat4,
    /// x: environment intensity, y: the specular cube's largest mip level, z: skybox
    /// brightness, w: unused.
    pub environment: Vec4,
    /// The shadow rays' geometry (`shaders/common/ray_bvh.wgsl`): x the instance level's root
    /// (`manylight_core::ray_bvh::RAY_NO_NODE` when the frame traces no ray), y the first
    /// `ray_prims` entry of the instances, z that of the casting lights' bits, w unused.
    pub rays: [u32; 4],
    /// Number of lights in the light buffer.
    pub light_count: u32,
    /// Global shading model id.
    pub shading_model: u32,
    /// Directional lights in `directional` (at most [`MAX_DIRECTIONAL_LIGHTS`]).
    pub directional_count: u32,
    /// Padding to 16 bytes.
    pub _pad: u32,
    /// The frame's directional lights, each reaching every pixel (not clustered).
    pub directional: [GpuDirectionalLight; MAX_DIRECTIONAL_LIGHTS as usize],
}

/// Directional lights a view carries (in its uniform; more are dropped and counted in
/// `FrameReport::dropped_directional_lights`).
pub const MAX_DIRECTIONAL_LIGHTS: u32 = 8;

/// A directional light as the shaders read it (`GpuDirectionalLight` in
/// `shaders/common/view.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuDirectionalLight {
    /// xyz: unit direction the light travels, w: 1 when the light casts a shadow, else 0.
    pub direction: [f32; 4],
    /// rgb: colour × illuminance, a: unused.
    pub color: [f32; 4],
}

/// A point or spot light as the shaders read it (`GpuPointLight` in `shaders/common/lights.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuPointLight {
    /// xyz: world position, w: radius.
    pub position_radius: [f32; 4],
    /// rgb: colour * intensity, a: the spot falloff's offset (1 for a point light).
    pub color: [f32; 4],
    /// xyz: a spot light's unit direction (0 for a point light), w: the falloff's scale (0).
    pub spot: [f32; 4],
}

/// An animated light's motion as the light animation pass reads it (`GpuLightMotion` in
/// `shaders/light_animation.wgsl`; one per light of the light buffer, at the same index):
/// the parameters of [`manylight_core::AnimatedLight`], its five angles at `epoch` and their
/// speeds ([`crate::lights::gpu_light_motion`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLightMotion {
    /// Centre of the orbit.
    pub center: [f32; 3],
    /// Orbit radius in the XZ plane.
    pub orbit_radius: f32,
    /// Base linear RGB colour.
    pub color: [f32; 3],
    /// Vertical bob amplitude.
    pub bob_amplitude: f32,
    /// Radians per second of the orbit, the bob, the hue drift and the first flicker wave.
    pub speeds: [f32; 4],
    /// Those four angles at `epoch`, in [0, 2π).
    pub angles: [f32; 4],
    /// Radians per second of the second flicker wave.
    pub flicker2_speed: f32,
    /// Its angle at `epoch`.
    pub flicker2_angle: f32,
    /// Seconds at which the angles were taken.
    pub epoch: f32,
    /// Candela, multiplying the colour.
    pub intensity: f32,
    /// 1: the pass writes this light's position and colour; 0: it leaves the light as uploaded.
    pub animated: u32,
    /// Keeps the size a multiple of 16 bytes.
    pub pad: [u32; 3],
}

/// The light animation pass's parameters (`LightAnimationParams` in
/// `shaders/light_animation.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLightAnimationParams {
    /// The frame's time in seconds ([`crate::FrameSnapshot::elapsed_secs`]).
    pub elapsed_secs: f32,
    /// Lights in the light buffer.
    pub light_count: u32,
    /// Keeps the size a multiple of 16 bytes.
    pub pad: [u32; 2],
}

pub use crate::settings::{MAX_CASCADES, SHADOW_FACES, SHADOW_TILE_COLUMNS};

/// One cascade of a directional light's shadow (`GpuCascade` in
/// `shaders/common/shadows.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuCascade {
    /// The cascade's orthographic projection: x, y ∈ [-1, 1] across its square, reverse depth z
    /// from 1 at the near side (towards the light) to 0 at the far side of the view's slice.
    pub clip_from_world: Mat4,
    /// x, y: the atlas texel at the tile's top left; z: its edge in texels; w: the filter
    /// (`ShadowFilteringMethod::gpu_id`).
    pub tile: [u32; 4],
    /// x: the far bound (view distance) up to which it is used; y: a texel's width in world
    /// units; z: its depth range in world units; w: 0.
    pub params: [f32; 4],
}

/// A directional light's shadow (`GpuDirectionalShadow` in `shaders/common/shadows.wgsl`),
/// one per entry of `ViewUniform::directional`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuDirectionalShadow {
    /// The cascades, nearest first.
    pub cascades: [GpuCascade; MAX_CASCADES],
    /// x: cascades in use (0: the light casts no shadow); y, z, w: 0.
    pub count: [u32; 4],
    /// x: depth bias (world units), y: normal bias (texels of the cascade); z, w: 0.
    pub bias: [f32; 4],
}

/// A light's shadow map as the shading passes read it (`GpuShadowLight` in
/// `shaders/common/shadows.wgsl`): one entry per uploaded point or spot light, in light-buffer
/// order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuShadowLight {
    /// x, y: the atlas texel at the top left of the light's block of face tiles; z: a face
    /// tile's edge in texels, 0 when the light has no shadow map this frame; w: the filter
    /// (`ShadowFilteringMethod::gpu_id`).
    pub tile: [u32; 4],
    /// x: the faces' near plane, y: their far plane (the light's range), z: depth bias (world
    /// units along the ray), w: normal bias (texels of the face at the receiver).
    pub params: [f32; 4],
    /// xyz: where the light was when its map was drawn, the origin of the test (an earlier
    /// frame's position for a map kept past `ShadowSettings::max_redrawn_maps`); w: 0.
    pub origin: [f32; 4],
}

/// One cube face of a shadow map as the shadow pass draws it (`GpuShadowFace` in
/// `shaders/shadow_maps.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuShadowFace {
    /// The face's projection: x, y in [-w, w] inside the face, z / w its reverse depth (1 at
    /// the near plane, 0 at the far one).
    pub clip_from_world: Mat4,
    /// (sx, ox, sy, oy): the face's tile in atlas clip space is x·sx + w·ox, y·sy + w·oy.
    pub atlas: [f32; 4],
}

/// One instance of the shadow pass's draws: a scene instance drawn into one face
/// (`GpuShadowDraw` in `shaders/shadow_maps.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuShadowDraw {
    /// Index into the instance buffer.
    pub instance: u32,
    /// Index into the frame's faces.
    pub face: u32,
}

/// One light–point pair whose shadow test `shaders/shadow_probe.wgsl` reads back
/// (`GpuShadowProbe` there): a measurement, not part of a frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuShadowProbe {
    /// The surface point, in world space.
    pub position: [f32; 3],
    /// The light's index in the light buffer.
    pub light: u32,
    /// The surface's normal (any length).
    pub normal: [f32; 3],
    /// Padding to 32 bytes.
    pub pad: f32,
}

/// Per-instance transforms (`GpuInstance` in `shaders/common/mesh.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuInstance {
    /// World from object.
    pub world_from_local: Mat4,
    /// Inverse transpose of the upper 3×3 of `world_from_local`, as a Mat4.
    pub normal_from_local: Mat4,
}

impl GpuInstance {
    /// Builds the instance data for a world-from-local transform.
    pub fn new(world_from_local: Mat4) -> GpuInstance {
        GpuInstance { world_from_local, normal_from_local: Mat4::from_mat3(normal_matrix(world_from_local)) }
    }

    /// The instance data, or `None` when `world_from_local` flattens every triangle to a line
    /// or a point (its 3×3 part has rank 1 or 0, e.g. a zero scale on two axes): such an
    /// instance covers no pixel.
    pub fn drawable(world_from_local: Mat4) -> Option<GpuInstance> {
        let m3 = glam::Mat3::from_mat4(world_from_local);
        let c = cofactor(m3);
        (c != glam::Mat3::ZERO).then(|| GpuInstance {
            world_from_local,
            normal_from_local: Mat4::from_mat3(normal_from_cofactor(m3, c)),
        })
    }
}

/// The cofactor matrix of `m`: columns `b × c`, `c × a`, `a × b` (`det(m) · m⁻ᵀ` when `m` is
/// invertible, and still the map of normals when it is not).
fn cofactor(m: glam::Mat3) -> glam::Mat3 {
    glam::Mat3::from_cols(m.y_axis.cross(m.z_axis), m.z_axis.cross(m.x_axis), m.x_axis.cross(m.y_axis))
}

/// The matrix that carries object-space normals to world space: the inverse transpose of the
/// 3×3 part, or, when that part is singular (a zero scale on one axis flattens the mesh to a
/// plane), its cofactor matrix scaled to a largest element of 1, which still gives the plane's
/// normal where the inverse transpose would be infinite. Shaders normalise the result.
pub fn normal_matrix(world_from_local: Mat4) -> glam::Mat3 {
    let m3 = glam::Mat3::from_mat4(world_from_local);
    normal_from_cofactor(m3, cofactor(m3))
}

/// [`normal_matrix`] of `m` from its cofactor matrix `c`: `c / det(m)` (what
/// `m.inverse().transpose()` computes) when that is finite, else `c` scaled.
fn normal_from_cofactor(m: glam::Mat3, c: glam::Mat3) -> glam::Mat3 {
    let det = m.x_axis.dot(c.x_axis);
    if det.is_finite() && det.abs() > f32::MIN_POSITIVE {
        let n = c * (1.0 / det);
        if n.is_finite() {
            return n;
        }
    }
    let largest = c.to_cols_array().iter().fold(0.0f32, |a, v| a.max(v.abs()));
    if largest > 0.0 && largest.is_finite() { c * (1.0 / largest) } else { c }
}

/// Per-material constants (`GpuMaterial` in `shaders/common/mesh.wgsl`). Over 15 fields
/// because it mirrors the WGSL struct field for field (one uniform per material; the layout
/// test in `tests/shaders.rs` holds the two together).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: Vec4,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Specular strength.
    pub specular: f32,
    /// `ShadingModel::gpu_id` or [`SHADING_GLOBAL`].
    pub shading_model: u32,
    /// 1 when a base colour texture is bound.
    pub has_texture: u32,
    /// PBR metalness factor.
    pub metallic: f32,
    /// PBR perceptual roughness factor.
    pub roughness: f32,
    /// 1 when a metallic-roughness texture is bound.
    pub has_metallic_roughness_texture: u32,
    /// Scale of the normal map's x and y.
    pub normal_scale: f32,
    /// Linear emitted radiance.
    pub emissive: Vec3,
    /// How much of the occlusion texture applies (0..1).
    pub occlusion_strength: f32,
    /// 1 when a normal map is bound.
    pub has_normal_texture: u32,
    /// 1 when an occlusion texture is bound.
    pub has_occlusion_texture: u32,
    /// 1 when an emissive texture is bound.
    pub has_emissive_texture: u32,
    /// Alpha below which the alpha-mask pipelines discard a fragment.
    pub alpha_cutoff: f32,
    /// How each texture slot (`TEXTURE_SLOT_*`) reads its uvs.
    pub texture_uv: [GpuTextureUv; MATERIAL_TEXTURE_SLOTS as usize],
}

/// Material texture slots, in [`GpuMaterial::texture_uv`] and `material.texture_uv` order.
pub const MATERIAL_TEXTURE_SLOTS: u32 = 5;
/// See [`MATERIAL_TEXTURE_SLOTS`].
pub const TEXTURE_SLOT_BASE_COLOR: u32 = 0;
/// See [`MATERIAL_TEXTURE_SLOTS`].
pub const TEXTURE_SLOT_METALLIC_ROUGHNESS: u32 = 1;
/// See [`MATERIAL_TEXTURE_SLOTS`].
pub const TEXTURE_SLOT_NORMAL: u32 = 2;
/// See [`MATERIAL_TEXTURE_SLOTS`].
pub const TEXTURE_SLOT_OCCLUSION: u32 = 3;
/// See [`MATERIAL_TEXTURE_SLOTS`].
pub const TEXTURE_SLOT_EMISSIVE: u32 = 4;

/// Which uv set a material texture reads and its uv transform (`GpuTextureUv` in
/// `shaders/common/mesh.wgsl`): `uv' = (dot(row0.xyz, (uv, 1)), dot(row1.xyz, (uv, 1)))`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuTextureUv {
    /// First row of the affine transform (xyz); w is 1 to read `TEXCOORD_1`, else 0.
    pub row0: Vec4,
    /// Second row of the affine transform (xyz); w unused.
    pub row1: Vec4,
}

impl GpuTextureUv {
    /// `TEXCOORD_0`, untransformed (also for empty slots).
    pub const IDENTITY: GpuTextureUv = GpuTextureUv { row0: Vec4::X, row1: Vec4::Y };

    /// The slot of `texture` (identity when there is none).
    pub fn of(texture: Option<&manylight_core::MaterialTexture>) -> GpuTextureUv {
        let Some(t) = texture else { return GpuTextureUv::IDENTITY };
        let m = t.uv_transform;
        let finite = m.matrix2.is_finite() && m.translation.is_finite();
        let (c0, c1, c2) = if finite {
            (m.matrix2.x_axis, m.matrix2.y_axis, m.translation)
        } else {
            (Vec2::X, Vec2::Y, Vec2::ZERO)
        };
        let channel = match t.uv_channel {
            manylight_core::UvChannel::Uv0 => 0.0,
            manylight_core::UvChannel::Uv1 => 1.0,
        };
        GpuTextureUv { row0: Vec4::new(c0.x, c1.x, c2.x, channel), row1: Vec4::new(c0.y, c1.y, c2.y, 0.0) }
    }
}

/// Constants emitted into WGSL as `const NAME: f32 = VALUE;` (printed so they round-trip).
pub fn shared_f32_constants() -> Vec<(&'static str, f32)> {
    vec![
        ("RADIUS_INFLATION", manylight_core::cluster::RADIUS_INFLATION),
        ("CLUSTER_DEPTH_SLACK", CLUSTER_DEPTH_SLACK),
        ("REFINE_SLACK", REFINE_SLACK),
        ("LIGHT_MIN_DISTANCE", manylight_core::attenuation::LIGHT_MIN_DISTANCE),
        ("TILE_PREFILTER_INFLATION", manylight_core::cluster::TILE_PREFILTER_INFLATION),
        ("RECT_SLACK", manylight_core::cluster::RECT_SLACK),
        ("RECT_PAD", manylight_core::cluster::RECT_PAD),
        ("RECT_MAGNITUDE", manylight_core::cluster::RECT_MAGNITUDE),
        ("TOON_RIM_STRENGTH", manylight_core::material::TOON_RIM_STRENGTH),
        ("PBR_MIN_ROUGHNESS", manylight_core::brdf::PBR_MIN_ROUGHNESS),
        ("PBR_MIN_N_DOT_V", manylight_core::brdf::PBR_MIN_N_DOT_V),
        ("PBR_DIELECTRIC_F0", manylight_core::brdf::PBR_DIELECTRIC_F0),
        ("BRDF_PI", std::f32::consts::PI),
        ("BRDF_FRAC_1_PI", std::f32::consts::FRAC_1_PI),
        ("RAY_MISS", manylight_core::ray_bvh::RAY_MISS),
        ("RAY_FAR", manylight_core::ray_bvh::RAY_FAR),
        ("RAY_EDGE_TOLERANCE", manylight_core::shadow_oracle::EDGE_TOLERANCE),
        ("RAY_SURFACE_OFFSET", manylight_core::shadow_oracle::SURFACE_OFFSET_STEPS),
    ]
}

/// Cluster-grid constants (`ClusterParams` in `shaders/common/clusters.wgsl`). Over 15 fields
/// because it mirrors the WGSL struct field for field (one uniform the whole build reads; the
/// layout test in `tests/shaders.rs` holds the two together).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuClusterParams {
    /// Grid size x, y, z and the cluster count.
    pub dims: [u32; 4],
    /// Viewport width, height (pixels), near and far (view distances).
    pub viewport: [f32; 4],
    /// Lights in the light buffers.
    pub light_count: u32,
    /// Per-cluster cap or [`CLUSTER_NO_CAP`].
    pub cap: u32,
    /// [`CULL_AABB`], [`CULL_PLANES`] or [`CULL_BOTH`].
    pub cull_test: u32,
    /// Entries the index list can hold.
    pub index_capacity: u32,
    /// `ZSlicing::gpu_id`.
    pub slicing: u32,
    /// ln(far / near), precomputed for exponential slicing.
    pub log_far_over_near: f32,
    /// Entries the per-tile light lists (first level of the build) can hold.
    pub tile_index_capacity: u32,
    /// Candidate chunks of level 1 (its invocations per tile), at least 1: `light_chunks`, as
    /// many as the longest coarse list can take (chunks past a tile's list return at once).
    pub tile_chunks: u32,
    /// Coarse tiles across and down (level 0 of the build).
    pub coarse_dims: [u32; 2],
    /// Entries the coarse-tile lists can hold; they follow the `tile_index_capacity` entries of
    /// the per-tile lists in the same buffer.
    pub coarse_index_capacity: u32,
    /// Tiles per coarse-tile edge, or 0 without a coarse level (level 1 then tests every light).
    pub coarse_span: u32,
    /// 1 when the cluster level cuts each cluster to its pixels' depth range (written after the
    /// cluster ranges by `shaders/cluster_depth.wgsl`), 0 for whole slices.
    pub depth_bounds: u32,
    /// Blocks across of the refined light lists (`shaders/light_refine.wgsl`), 0 when the view
    /// does not refine its lists.
    pub refine_blocks_x: u32,
    /// Blocks down of the refined light lists, 0 when the view does not refine its lists.
    pub refine_blocks_y: u32,
    /// Index in the ranges buffer of block 0's refined range (after the cluster ranges and,
    /// with depth bounds, their depth ranges); the blocks' lists follow the `index_capacity`
    /// entries of the cluster lists, [`REFINED_LIST_SLOTS`] entries each.
    pub refined_first: u32,
    /// What each light's tile rectangle needs of the grid (`light_rect` in
    /// `shaders/cluster_build.wgsl`; `manylight_core::cluster::rect_frustum`): `(tan_x, tan_y,
    /// 0, margin)` in perspective, `(half_x, half_y, 1, margin)` orthographic.
    pub frustum: [f32; 4],
    /// Light chunks of level 0 (its invocations per coarse tile), at least 1:
    /// `ceil(light_count / TILE_LIGHT_CHUNK)`.
    pub light_chunks: u32,
    /// 1 when level 0 runs from the lights' side (`light_marks` in
    /// `shaders/cluster_build.wgsl`: one invocation per light), 0 per coarse tile.
    pub from_lights: u32,
    /// The longest tile list the build loops over in one invocation: [`LAVAPIPE_LOOP_LIMIT`]
    /// on an adapter that stops invocations there, else `u32::MAX`. A cluster whose tile list
    /// is longer shades from every light ([`LIST_EVERY_LIGHT`]).
    pub loop_limit: u32,
    /// Padding to 16 bytes.
    pub _pad: u32,
    /// The view's world-to-view transform (columns): `shaders/light_spheres.wgsl` moves the
    /// lights' spheres into view space with it.
    pub view_from_world: [[f32; 4]; 4],
}

/// Bounds of one cluster in view space (`GpuClusterBounds` in `shaders/common/clusters.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuClusterBounds {
    /// AABB minimum (xyz).
    pub aabb_min: [f32; 4],
    /// AABB maximum (xyz).
    pub aabb_max: [f32; 4],
    /// Six planes (n.xyz, w), inward normals.
    pub planes: [[f32; 4]; 6],
}

/// Counters the cluster build writes (`ClusterCounters` in `shaders/cluster_build.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuClusterCounters {
    /// Entries the index list needed (after the cap).
    pub total_entries: u32,
    /// Light–cluster pairs dropped by the cap.
    pub dropped_pairs: u32,
    /// Clusters that hit the cap.
    pub clusters_overflowed: u32,
    /// Largest per-cluster count before the cap.
    pub max_count: u32,
    /// Clusters with at least one light.
    pub non_empty: u32,
    /// Entries the per-tile lists needed.
    pub tile_entries: u32,
    /// Longest per-tile list: the per-cluster loops of the build run this many iterations.
    pub max_tile_lights: u32,
    /// Entries the coarse-tile lists needed (level 0; 0 without a coarse level).
    pub coarse_entries: u32,
    /// Clusters whose list did not fit this frame's lists (or whose tile list was longer than
    /// `GpuClusterParams::loop_limit`): their range is `(0, LIST_EVERY_LIGHT)` and they shade
    /// from every light.
    pub fallback_clusters: u32,
}

#[cfg(test)]
mod tests {
    use super::{GpuInstance, normal_matrix};
    use glam::{Mat3, Mat4, Quat, Vec3};

    #[test]
    fn normal_matrix_is_the_inverse_transpose_and_finite_when_singular() {
        let rotation = Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 1.1);
        for scale in [Vec3::ONE, Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 4.0), Vec3::splat(1e-3)] {
            let m = Mat4::from_scale_rotation_translation(scale, rotation, Vec3::new(1.0, 2.0, 3.0));
            // Bit for bit what the inverse transpose gives.
            assert_eq!(normal_matrix(m), Mat3::from_mat4(m).inverse().transpose(), "{scale}");
        }
        // Flattened to the xz plane: normals along y stay along y.
        let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
        let n = normal_matrix(flat) * Vec3::Y;
        assert!(n.is_finite() && n.normalize().abs_diff_eq(Vec3::Y, 1e-6), "{n}");
        assert!(GpuInstance::drawable(flat).is_some());
        assert!(GpuInstance::drawable(Mat4::from_scale(Vec3::new(2.0, 0.0, 0.0))).is_none());
        assert!(GpuInstance::drawable(Mat4::from_scale(Vec3::ZERO)).is_none());
    }
}

//! Every bind group of the library's shaders, declared once, and which of them each pipeline
//! binds ([`SHADER_BIND_GROUPS`]). The passes make their layouts and bind groups from these
//! declarations; `tests/shaders.rs` checks them against the WGSL with naga.

use super::{BindGroupDecl, BindingDecl, BindingKind, Presence, SHADING, ShaderBindGroups, UNFILTERED};
use crate::snapshot::GBufferLayout;
use wgpu::ShaderStages;

const VERTEX: ShaderStages = ShaderStages::VERTEX;
const FRAGMENT: ShaderStages = ShaderStages::FRAGMENT;
const COMPUTE: ShaderStages = ShaderStages::COMPUTE;
const EVERY_STAGE: ShaderStages = VERTEX.union(SHADING);
const FILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };
const DEPTH: wgpu::TextureSampleType = wgpu::TextureSampleType::Depth;
const FILTERING: BindingKind = BindingKind::Sampler(wgpu::SamplerBindingType::Filtering);

// ---- Scene passes ----

/// The shadow bindings of group 0 (`shaders/common/shadows.wgsl`): the shadow atlas, its
/// comparison sampler, the lights' shadow table and the directional lights' cascades.
pub const SHADOW_BINDINGS: [BindingDecl; 4] = [
    BindingDecl::texture(3, "shadow_atlas", DEPTH, SHADING),
    BindingDecl::new(
        4,
        "shadow_sampler",
        BindingKind::Sampler(wgpu::SamplerBindingType::Comparison),
        SHADING,
    ),
    BindingDecl::storage(5, "shadow_lights", SHADING),
    BindingDecl::storage(6, "directional_shadows", SHADING),
];

/// The environment bindings of group 0 (`shaders/common/environment.wgsl`): the prefiltered
/// specular cube, the irradiance cube, the split-sum lookup table and their sampler.
pub const ENVIRONMENT_BINDINGS: [BindingDecl; 4] = [
    BindingDecl::new(7, "env_specular", BindingKind::Cube(FILTERABLE), SHADING),
    BindingDecl::new(8, "env_irradiance", BindingKind::Cube(FILTERABLE), SHADING),
    BindingDecl::texture(9, "env_brdf_lut", FILTERABLE, SHADING),
    BindingDecl::new(10, "env_sampler", FILTERING, SHADING),
];

/// The shadow rays' bindings of group 0 (`shaders/common/ray_bvh.wgsl`): the scene's two-level
/// BVH's nodes, and its triangles, instances and casting lights' bits in one buffer
/// (`ray_geometry::RayGeometry`; two storage buffers, as many as the shadow maps' table and
/// cascades, so every pipeline stays within WebGPU's 8 a stage).
pub const RAY_GEOMETRY_BINDINGS: [BindingDecl; 2] =
    [BindingDecl::storage(11, "ray_nodes", SHADING), BindingDecl::storage(12, "ray_prims", SHADING)];

/// Group 0 of every scene pass: the view uniform (`common/view_binding.wgsl`), the point and
/// spot lights (`common/point_lights.wgsl`), the instances (`common/mesh_pass.wgsl`), in a
/// frame whose lights cast shadows [`SHADOW_BINDINGS`], and for a view with an environment
/// [`ENVIRONMENT_BINDINGS`].
pub static SCENE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "scene",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "view", EVERY_STAGE),
        BindingDecl::storage(1, "lights", EVERY_STAGE),
        BindingDecl::storage(2, "instances", VERTEX),
        SHADOW_BINDINGS[0].only(Presence::Shadows),
        SHADOW_BINDINGS[1].only(Presence::Shadows),
        SHADOW_BINDINGS[2].only(Presence::Shadows),
        SHADOW_BINDINGS[3].only(Presence::Shadows),
        ENVIRONMENT_BINDINGS[0].only(Presence::Environment),
        ENVIRONMENT_BINDINGS[1].only(Presence::Environment),
        ENVIRONMENT_BINDINGS[2].only(Presence::Environment),
        ENVIRONMENT_BINDINGS[3].only(Presence::Environment),
        RAY_GEOMETRY_BINDINGS[0].only(Presence::Rays),
        RAY_GEOMETRY_BINDINGS[1].only(Presence::Rays),
    ],
};

// ---- Environment prefiltering and the skybox ----

const ENV_OUT: BindingDecl = BindingDecl::new(
    3,
    "out_cube",
    BindingKind::StorageTextureArray(wgpu::TextureFormat::Rgba16Float),
    COMPUTE,
);

/// Group 0 of `cs_from_equirect` (`shaders/environment_prefilter.wgsl`): the parameters, the
/// panorama (rgba32f) and the source cube's mip 0 it writes.
pub static ENV_FROM_EQUIRECT_GROUP: BindGroupDecl = BindGroupDecl {
    label: "env_from_equirect",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::texture(1, "equirect", UNFILTERED, COMPUTE),
        ENV_OUT,
    ],
};

/// Group 0 of `cs_downsample`, `cs_specular` and `cs_irradiance`: the parameters, the cube
/// they read with its sampler, and the cube mip they write.
pub static ENV_FILTER_GROUP: BindGroupDecl = BindGroupDecl {
    label: "env_filter",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::new(2, "source", BindingKind::Cube(FILTERABLE), COMPUTE),
        BindingDecl::new(4, "source_sampler", FILTERING, COMPUTE),
        ENV_OUT,
    ],
};

/// Group 0 of `cs_brdf_lut`: the parameters and the split-sum lookup table it writes.
pub static ENV_LUT_GROUP: BindGroupDecl = BindGroupDecl {
    label: "env_lut",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::new(
            5,
            "out_lut",
            BindingKind::StorageTexture(wgpu::TextureFormat::Rgba16Float),
            COMPUTE,
        ),
    ],
};

/// Group 0 of the skybox pass (`shaders/skybox.wgsl`): the view uniform, the environment's
/// cube and its sampler.
pub static SKYBOX_GROUP: BindGroupDecl = BindGroupDecl {
    label: "skybox",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "view", FRAGMENT),
        BindingDecl::new(1, "sky", BindingKind::Cube(FILTERABLE), FRAGMENT),
        BindingDecl::new(2, "sky_sampler", FILTERING, FRAGMENT),
    ],
};

/// Group 1 of the mesh passes (`shaders/common/mesh_pass.wgsl`): the material uniform, then
/// each of its five textures followed by its sampler.
pub static MATERIAL_GROUP: BindGroupDecl = BindGroupDecl {
    label: "material",
    index: 1,
    entries: &[
        BindingDecl::uniform(0, "material", FRAGMENT),
        BindingDecl::texture(1, "base_color_texture", FILTERABLE, FRAGMENT),
        BindingDecl::new(2, "base_color_sampler", FILTERING, FRAGMENT),
        BindingDecl::texture(3, "metallic_roughness_texture", FILTERABLE, FRAGMENT),
        BindingDecl::new(4, "metallic_roughness_sampler", FILTERING, FRAGMENT),
        BindingDecl::texture(5, "normal_texture", FILTERABLE, FRAGMENT),
        BindingDecl::new(6, "normal_sampler", FILTERING, FRAGMENT),
        BindingDecl::texture(7, "occlusion_texture", FILTERABLE, FRAGMENT),
        BindingDecl::new(8, "occlusion_sampler", FILTERING, FRAGMENT),
        BindingDecl::texture(9, "emissive_texture", FILTERABLE, FRAGMENT),
        BindingDecl::new(10, "emissive_sampler", FILTERING, FRAGMENT),
    ],
};

// ---- Cluster build and lists ----

/// Group 0 of the cluster build (`shaders/cluster_build.wgsl`): the parameters, the cluster
/// bounds and light spheres it reads, the lists it writes, its counters, and the per-tile
/// bounds and lists.
pub static CLUSTER_BUILD_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_build",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(1, "bounds", COMPUTE),
        BindingDecl::storage(2, "spheres", COMPUTE),
        BindingDecl::storage_rw(3, "ranges", COMPUTE),
        BindingDecl::storage_rw(4, "indices", COMPUTE),
        BindingDecl::storage_rw(5, "build", COMPUTE),
        BindingDecl::storage(6, "tile_bounds", COMPUTE),
        BindingDecl::storage_rw(7, "tile_ranges", COMPUTE),
        BindingDecl::storage_rw(8, "tile_indices", COMPUTE),
    ],
};

/// Group 0 of the first dispatch of the cluster build (`shaders/light_spheres.wgsl`): the
/// parameters (with the view's transform), the light buffer it reads and the view-space
/// spheres it writes.
pub static LIGHT_SPHERES_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_spheres",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(1, "lights", COMPUTE),
        BindingDecl::storage_rw(2, "spheres", COMPUTE),
    ],
};

/// Group 0 of the light animation pass (`shaders/light_animation.wgsl`): its parameters (the
/// frame's time; a storage binding, as a uniform that changes every frame makes lavapipe compile
/// the shader again), the lights' motions it reads and the light buffer it writes.
pub static LIGHT_ANIMATION_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_animation",
    index: 0,
    entries: &[
        BindingDecl::storage(0, "params", COMPUTE),
        BindingDecl::storage(1, "motions", COMPUTE),
        BindingDecl::storage_rw(2, "lights", COMPUTE),
    ],
};

/// Group 2 of the passes that shade through the cluster lists (`common/cluster_lists.wgsl`,
/// `tiled_deferred.wgsl`): the parameters, each cluster's range and the light indices.
pub static CLUSTER_LISTS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_lists",
    index: 2,
    entries: &[
        BindingDecl::uniform(0, "cluster_params", SHADING),
        BindingDecl::storage(1, "cluster_ranges", SHADING),
        BindingDecl::storage(2, "cluster_indices", SHADING),
    ],
};

/// Group 2 of the `cluster_depth` pass (`shaders/cluster_depth.wgsl`): the parameters, and the
/// ranges buffer, whose per-cluster depth ranges it writes after the cluster ranges.
pub static CLUSTER_DEPTH_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_depth",
    index: 2,
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage_rw(1, "cluster_depths", COMPUTE),
    ],
};

/// Group 2 of the `light_refine` pass (`shaders/light_refine.wgsl`): the parameters, the light
/// spheres, and the ranges and index buffers, whose refined part it writes.
pub static LIGHT_REFINE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_refine",
    index: 2,
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage(1, "spheres", COMPUTE),
        BindingDecl::storage_rw(2, "ranges", COMPUTE),
        BindingDecl::storage_rw(3, "indices", COMPUTE),
    ],
};

// ---- G-buffer ----

const fn gbuffer_target(binding: u32, name: &'static str, layout: GBufferLayout) -> BindingDecl {
    BindingDecl::texture(binding, name, UNFILTERED, SHADING).only(Presence::GBuffer(layout))
}

/// Where the lighting passes read the Full layout's position (rgba32f).
pub const GB_POSITION: BindingDecl = gbuffer_target(0, "gb_position", GBufferLayout::Full);
/// … the Full layout's normal (rgba16f).
pub const GB_NORMAL: BindingDecl = gbuffer_target(1, "gb_normal", GBufferLayout::Full);
/// … the Full layout's albedo (rgba16f).
pub const GB_ALBEDO: BindingDecl = gbuffer_target(2, "gb_albedo", GBufferLayout::Full);
/// … the Packed layout's albedo and packed normal (rgba32f).
pub const GB_PACKED_ALBEDO: BindingDecl = gbuffer_target(6, "gb_packed_albedo", GBufferLayout::Packed);
/// … the Packed layout's position and material (rgba32f).
pub const GB_PACKED_POSITION: BindingDecl = gbuffer_target(7, "gb_packed_position", GBufferLayout::Packed);
/// … the Compact layout's one target (rgba32uint).
pub const GB_COMPACT: BindingDecl =
    BindingDecl::texture(3, "gb_compact", wgpu::TextureSampleType::Uint, SHADING)
        .only(Presence::GBuffer(GBufferLayout::Compact));
/// … every layout's emission and occlusion (rgba16f).
pub const GB_EMISSIVE: BindingDecl = BindingDecl::texture(8, "gb_emissive", UNFILTERED, SHADING);

/// Group 1 of the passes that read the G-buffer (`shaders/common/gbuffer_read.wgsl`): the
/// targets of the layout the shader is composed for (in `passes::gbuffer_layout::targets`
/// order), then depth and the view's clear colour.
pub static GBUFFER_READ_GROUP: BindGroupDecl = BindGroupDecl {
    label: "gbuffer_read",
    index: 1,
    entries: &[
        GB_POSITION,
        GB_NORMAL,
        GB_ALBEDO,
        GB_PACKED_ALBEDO,
        GB_PACKED_POSITION,
        GB_COMPACT,
        GB_EMISSIVE,
        BindingDecl::texture(4, "gb_depth", DEPTH, SHADING),
        BindingDecl::uniform(5, "clear_color", SHADING),
    ],
};

/// Group 1 of the passes that read each pixel's shading distance from the depth pre-pass
/// (`cs_forward` of `cluster_depth.wgsl` and `light_refine.wgsl`).
pub static SHADING_DISTANCE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "shading_distance",
    index: 1,
    entries: &[BindingDecl::texture(9, "shading_distance", UNFILTERED, COMPUTE)],
};

/// Group 3 of tiled deferred (`shaders/tiled_deferred.wgsl`): the HDR image it writes
/// (`resources::HDR_FORMAT`, checked by `tests/shaders.rs`).
pub static TILED_DEFERRED_OUTPUT_GROUP: BindGroupDecl = BindGroupDecl {
    label: "tiled_deferred_output",
    index: 3,
    entries: &[BindingDecl::new(
        0,
        "hdr_out",
        BindingKind::StorageTexture(wgpu::TextureFormat::Rgba16Float),
        COMPUTE,
    )],
};

/// Group 2 of the light-volume resolve (`fs_resolve` of `shaders/light_volumes.wgsl`): the f32
/// sum of the lights.
pub static LIGHT_ACCUM_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_accum",
    index: 2,
    entries: &[BindingDecl::texture(0, "light_accum", UNFILTERED, FRAGMENT)],
};

// ---- Shadows ----

/// The shadow pass's bind group (`shaders/shadow_maps.wgsl`): the faces drawn, the draws (an
/// instance's faces) and the instances.
pub static SHADOW_MAPS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "shadow_maps",
    index: 0,
    entries: &[
        BindingDecl::storage(0, "shadow_faces", VERTEX),
        BindingDecl::storage(1, "shadow_draws", VERTEX),
        BindingDecl::storage(2, "instances", VERTEX),
    ],
};

/// Group 0 of the shadow probe (`shaders/shadow_probe.wgsl`): [`SHADOW_BINDINGS`], as
/// `common/shadows.wgsl` declares them.
pub static SHADOW_PROBE_SHADOWS_GROUP: BindGroupDecl =
    BindGroupDecl { label: "shadow_probe_shadows", index: 0, entries: &SHADOW_BINDINGS };

/// Group 1 of the shadow probe: the frame's lights, the probes and what it writes for each.
pub static SHADOW_PROBE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "shadow_probe",
    index: 1,
    entries: &[
        BindingDecl::storage(0, "lights", COMPUTE),
        BindingDecl::storage(1, "probes", COMPUTE),
        BindingDecl::storage_rw(2, "probed", COMPUTE),
    ],
};

/// Group 0 of the ray probe (`shaders/ray_probe.wgsl`): [`RAY_GEOMETRY_BINDINGS`], as
/// `common/ray_bvh.wgsl` declares them.
pub static RAY_SHADOW_GROUP: BindGroupDecl =
    BindGroupDecl { label: "ray_shadows", index: 0, entries: &RAY_GEOMETRY_BINDINGS };

/// Group 1 of the ray probe's `main`: its parameters, the segments and what it writes for each.
pub static RAY_PROBE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "ray_probe",
    index: 1,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(1, "segments", COMPUTE),
        BindingDecl::storage_rw(2, "traced", COMPUTE),
    ],
};

/// Group 1 of the ray probe's `probe_lights`: its parameters, the frame's lights, the
/// light–point pairs and the visibility it writes for each.
pub static RAY_LIGHT_PROBE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "ray_light_probe",
    index: 1,
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(3, "lights", COMPUTE),
        BindingDecl::storage(4, "probes", COMPUTE),
        BindingDecl::storage_rw(5, "probed", COMPUTE),
    ],
};

// ---- Post and debug ----

/// The tone map's bind group (`shaders/tonemap.wgsl`): the view uniform (exposure), the HDR
/// image and the counter of non-finite pixels.
pub static TONEMAP_GROUP: BindGroupDecl = BindGroupDecl {
    label: "tonemap",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "view", FRAGMENT),
        BindingDecl::texture(1, "hdr", UNFILTERED, FRAGMENT),
        BindingDecl::storage_rw(2, "nonfinite_pixels", FRAGMENT),
    ],
};

/// Bloom's bind group (`shaders/bloom.wgsl`): the stage's parameters, a bilinear sampler and
/// the level it reads.
pub static BLOOM_GROUP: BindGroupDecl = BindGroupDecl {
    label: "bloom",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", FRAGMENT),
        BindingDecl::new(1, "linear_sampler", FILTERING, FRAGMENT),
        BindingDecl::texture(2, "source", FILTERABLE, FRAGMENT),
    ],
};

/// Motion blur's bind group (`shaders/motion_blur.wgsl`): the view uniform (this and last
/// frame's matrices), the blur's parameters, the HDR image and depth.
pub static MOTION_BLUR_GROUP: BindGroupDecl = BindGroupDecl {
    label: "motion_blur",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "view", FRAGMENT),
        BindingDecl::uniform(1, "params", FRAGMENT),
        BindingDecl::texture(2, "hdr", UNFILTERED, FRAGMENT),
        BindingDecl::texture(3, "depth", DEPTH, FRAGMENT),
    ],
};

const DEBUG_VIEW: BindingDecl = BindingDecl::uniform(0, "view", FRAGMENT);
const DEBUG_DEPTH: BindingDecl = BindingDecl::texture(1, "depth", DEPTH, FRAGMENT);
const DEBUG_PARAMS: BindingDecl = BindingDecl::uniform(4, "debug", FRAGMENT);

/// The bind group of the cluster debug views (`shaders/debug_view.wgsl`): view, depth,
/// parameters, then the cluster parameters and ranges.
pub static DEBUG_CLUSTERS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "debug_view_clusters",
    index: 0,
    entries: &[
        DEBUG_VIEW,
        DEBUG_DEPTH,
        DEBUG_PARAMS,
        BindingDecl::uniform(2, "cluster_params", FRAGMENT),
        BindingDecl::storage(3, "cluster_ranges", FRAGMENT),
    ],
};
/// The bind group of the depth debug view: view, depth and parameters.
pub static DEBUG_DEPTH_GROUP: BindGroupDecl =
    BindGroupDecl { label: "debug_view_depth", index: 0, entries: &[DEBUG_VIEW, DEBUG_DEPTH, DEBUG_PARAMS] };
/// The bind group of the surface debug views: view, depth, parameters, then the Full G-buffer.
pub static DEBUG_SURFACE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "debug_view_surface",
    index: 0,
    entries: &[
        DEBUG_VIEW,
        DEBUG_DEPTH,
        DEBUG_PARAMS,
        BindingDecl::texture(5, "gbuffer_albedo", UNFILTERED, FRAGMENT),
        BindingDecl::texture(6, "gbuffer_normal", UNFILTERED, FRAGMENT),
        BindingDecl::texture(7, "gbuffer_emissive", UNFILTERED, FRAGMENT),
        BindingDecl::texture(8, "gbuffer_position", UNFILTERED, FRAGMENT),
    ],
};
/// The bind group of the shadow-atlas debug view: view, depth, parameters, then the atlas.
pub static DEBUG_SHADOW_ATLAS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "debug_view_shadow_atlas",
    index: 0,
    entries: &[
        DEBUG_VIEW,
        DEBUG_DEPTH,
        DEBUG_PARAMS,
        BindingDecl::texture(12, "debug_shadow_atlas", DEPTH, FRAGMENT),
    ],
};
/// The bind group of the shadow-LOD debug view: view, depth, parameters, then the lights and
/// their shadow table.
pub static DEBUG_SHADOW_LOD_GROUP: BindGroupDecl = BindGroupDecl {
    label: "debug_view_shadow_lod",
    index: 0,
    entries: &[
        DEBUG_VIEW,
        DEBUG_DEPTH,
        DEBUG_PARAMS,
        BindingDecl::storage(10, "debug_lights", FRAGMENT),
        BindingDecl::storage(11, "debug_shadow_lights", FRAGMENT),
    ],
};

// ---- Which pipeline binds what ----

// ---- The WebGL2 path (`texture_lists`) ----

/// Group 0 of `texture_lists.wgsl`: the view uniform (`common/view_binding.wgsl`). The shadow
/// maps' and rays' bindings are declared for the compositions with `SHADOWS` and `RAYS` (the
/// directional lights' code reads them there); the path composes its shader without either,
/// as WebGL2 has no storage buffers.
pub static TEXTURE_LISTS_VIEW_GROUP: BindGroupDecl = BindGroupDecl {
    label: "texture_lists_view",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "view", VERTEX.union(FRAGMENT)),
        SHADOW_BINDINGS[0].only(Presence::Shadows),
        SHADOW_BINDINGS[1].only(Presence::Shadows),
        SHADOW_BINDINGS[2].only(Presence::Shadows),
        SHADOW_BINDINGS[3].only(Presence::Shadows),
        RAY_GEOMETRY_BINDINGS[0].only(Presence::Rays),
        RAY_GEOMETRY_BINDINGS[1].only(Presence::Rays),
    ],
};

/// Group 2 of `texture_lists.wgsl`: the cluster grid, the lights, each cluster's range and the
/// light indices.
pub static TEXTURE_LISTS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "texture_lists",
    index: 2,
    entries: &[
        BindingDecl::uniform(0, "cluster_params", FRAGMENT),
        BindingDecl::texture(1, "light_texture", UNFILTERED, FRAGMENT),
        BindingDecl::texture(2, "cluster_range_texture", wgpu::TextureSampleType::Uint, FRAGMENT),
        BindingDecl::texture(3, "light_index_texture", wgpu::TextureSampleType::Uint, FRAGMENT),
    ],
};

/// Shorthand for a row of [`SHADER_BIND_GROUPS`].
const fn row(
    shader: &'static str,
    entry_points: &'static [&'static str],
    groups: &'static [&'static BindGroupDecl],
) -> ShaderBindGroups {
    ShaderBindGroups { shader, entry_points, groups }
}

const SCENE: &BindGroupDecl = &SCENE_GROUP;
const MATERIAL: &BindGroupDecl = &MATERIAL_GROUP;
const LISTS: &BindGroupDecl = &CLUSTER_LISTS_GROUP;
const GBUFFER: &BindGroupDecl = &GBUFFER_READ_GROUP;

/// Which declaration each pipeline of each library shader reads at each group: a row covers the
/// entry points it lists (all of the shader's when it lists none), and a pipeline's entry
/// points are all covered by one row. Every entry point of every shader under `shaders/` that
/// binds anything has a row (`tests/shaders.rs`).
pub static SHADER_BIND_GROUPS: &[ShaderBindGroups] = &[
    row("forward.wgsl", &[], &[SCENE, MATERIAL]),
    row("environment_prefilter.wgsl", &["cs_from_equirect"], &[&ENV_FROM_EQUIRECT_GROUP]),
    row(
        "environment_prefilter.wgsl",
        &["cs_downsample", "cs_specular", "cs_irradiance"],
        &[&ENV_FILTER_GROUP],
    ),
    row("environment_prefilter.wgsl", &["cs_brdf_lut"], &[&ENV_LUT_GROUP]),
    row("skybox.wgsl", &[], &[&SKYBOX_GROUP]),
    row("transparent.wgsl", &["vs_main", "fs_every_light"], &[SCENE, MATERIAL]),
    row("transparent.wgsl", &["vs_main", "fs_clusters"], &[SCENE, MATERIAL, LISTS]),
    row("depth_prepass.wgsl", &[], &[SCENE, MATERIAL]),
    row("clustered_forward.wgsl", &[], &[SCENE, MATERIAL, LISTS]),
    row("texture_lists.wgsl", &[], &[&TEXTURE_LISTS_VIEW_GROUP, MATERIAL, &TEXTURE_LISTS_GROUP]),
    row("gbuffer.wgsl", &[], &[SCENE, MATERIAL]),
    row("deferred_lighting.wgsl", &[], &[SCENE, GBUFFER, LISTS]),
    row("tiled_deferred.wgsl", &[], &[SCENE, GBUFFER, LISTS, &TILED_DEFERRED_OUTPUT_GROUP]),
    row("light_volumes.wgsl", &["vs_volume", "fs_ambient", "fs_volume"], &[SCENE, GBUFFER]),
    row("light_volumes.wgsl", &["fs_resolve"], &[SCENE, GBUFFER, &LIGHT_ACCUM_GROUP]),
    row("cluster_build.wgsl", &[], &[&CLUSTER_BUILD_GROUP]),
    row("light_spheres.wgsl", &[], &[&LIGHT_SPHERES_GROUP]),
    row("light_animation.wgsl", &[], &[&LIGHT_ANIMATION_GROUP]),
    row("cluster_depth.wgsl", &["cs_forward"], &[SCENE, &SHADING_DISTANCE_GROUP, &CLUSTER_DEPTH_GROUP]),
    row("cluster_depth.wgsl", &["cs_gbuffer"], &[SCENE, GBUFFER, &CLUSTER_DEPTH_GROUP]),
    row("light_refine.wgsl", &["cs_forward"], &[SCENE, &SHADING_DISTANCE_GROUP, &LIGHT_REFINE_GROUP]),
    row("light_refine.wgsl", &["cs_gbuffer"], &[SCENE, GBUFFER, &LIGHT_REFINE_GROUP]),
    row("shadow_maps.wgsl", &[], &[&SHADOW_MAPS_GROUP]),
    row("shadow_probe.wgsl", &[], &[&SHADOW_PROBE_SHADOWS_GROUP, &SHADOW_PROBE_GROUP]),
    row("ray_probe.wgsl", &["main"], &[&RAY_SHADOW_GROUP, &RAY_PROBE_GROUP]),
    row("ray_probe.wgsl", &["probe_lights"], &[&RAY_SHADOW_GROUP, &RAY_LIGHT_PROBE_GROUP]),
    row("bloom.wgsl", &[], &[&BLOOM_GROUP]),
    row("motion_blur.wgsl", &[], &[&MOTION_BLUR_GROUP]),
    row("tonemap.wgsl", &[], &[&TONEMAP_GROUP]),
    row("debug_view.wgsl", &["fs_clusters"], &[&DEBUG_CLUSTERS_GROUP]),
    row("debug_view.wgsl", &["fs_depth"], &[&DEBUG_DEPTH_GROUP]),
    row("debug_view.wgsl", &["fs_surface"], &[&DEBUG_SURFACE_GROUP]),
    row("debug_view.wgsl", &["fs_shadow_atlas"], &[&DEBUG_SHADOW_ATLAS_GROUP]),
    row("debug_view.wgsl", &["fs_shadow_lod"], &[&DEBUG_SHADOW_LOD_GROUP]),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_declaration_sits_at_its_own_index_in_every_pipeline() {
        for row in SHADER_BIND_GROUPS {
            for (at, group) in row.groups.iter().enumerate() {
                assert_eq!(
                    group.index, at as u32,
                    "`{}` {:?}: group `{}` is bound at {at}, declared at {}",
                    row.shader, row.entry_points, group.label, group.index
                );
            }
        }
    }
}

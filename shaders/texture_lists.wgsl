// Clustered forward shading for devices without storage buffers or compute shaders (WebGL2;
// Rust: `manylight_render::texture_lists`), as the WebGL clustered demos do it: the CPU assigns
// the lights to clusters (`manylight_core::cluster::assign_lights`) and hands the frame's lights
// and lists over in textures read with `textureLoad`; each draw's instance transforms arrive as
// per-instance vertex attributes. The pass tone maps as it shades (the target is the sRGB
// output) and writes alpha 0 where the HDR colour was NaN or infinite: the CPU counts those
// pixels when it reads the frame back.
//!include common/forward_fragment.wgsl
//!include common/clusters.wgsl
//!include common/tonemap_curve.wgsl

// Group 2 (Rust: `texture_lists::LISTS_GROUP`).
@group(2) @binding(0) var<uniform> cluster_params: ClusterParams;
// The point and spot lights (`GpuPointLight`), three texels each (position_radius, color,
// spot) side by side, a whole number of lights per row.
@group(2) @binding(1) var light_texture: texture_2d<f32>;
// Each cluster's (offset, count) in the light index list, in cluster order, row after row.
@group(2) @binding(2) var cluster_range_texture: texture_2d<u32>;
// Every cluster's light indices, back to back, row after row.
@group(2) @binding(3) var light_index_texture: texture_2d<u32>;

// An instance's transforms (Rust: `GpuInstance`, one per draw in an instance-rate vertex
// buffer): the columns of `world_from_local`, then of `normal_from_local`.
struct InstanceIn {
    @location(5) world_0: vec4<f32>,
    @location(6) world_1: vec4<f32>,
    @location(7) world_2: vec4<f32>,
    @location(8) world_3: vec4<f32>,
    @location(9) normal_0: vec4<f32>,
    @location(10) normal_1: vec4<f32>,
    @location(11) normal_2: vec4<f32>,
    @location(12) normal_3: vec4<f32>,
};

@vertex
fn vs_main(v: VertexIn, i: InstanceIn) -> SurfaceVertexOut {
    let inst = GpuInstance(
        mat4x4<f32>(i.world_0, i.world_1, i.world_2, i.world_3),
        mat4x4<f32>(i.normal_0, i.normal_1, i.normal_2, i.normal_3),
    );
    return surface_vertex(v, inst, view.clip_from_world, view.camera_position.xyz);
}

// The texel of entry `i` of a list texture `width` texels wide.
fn list_texel(i: u32, width: u32) -> vec2<u32> {
    let row = i / width;
    return vec2<u32>(i - row * width, row);
}

// Field `field` (0: position_radius, 1: color, 2: spot) of light `k`.
fn light_field(k: u32, field: u32) -> vec4<f32> {
    let t = list_texel(k, textureDimensions(light_texture).x / 3u);
    return textureLoad(light_texture, vec2<u32>(t.x * 3u + field, t.y), 0);
}

// Radiance light `k` adds at `position` seen from `view_dir`: `shade_light` of
// `common/point_lights.wgsl` with the light read from its texture (its colour and spot texels
// only when it reaches the point).
fn shade_texture_light(s: SurfaceParams, position: vec3<f32>, view_dir: vec3<f32>, k: u32) -> vec3<f32> {
    let reach = light_reach(light_field(k, 0u), position);
    if reach.attenuation <= 0.0 {
        return vec3<f32>(0.0);
    }
    return shade_reached_light(s, reach, view_dir, light_field(k, 1u), light_field(k, 2u));
}

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let f = forward_fragment(in, front_facing);
    let cluster = cluster_index(cluster_params, in.clip_position.xy, f.p.view_depth);
    let range_width = textureDimensions(cluster_range_texture).x;
    let range = textureLoad(cluster_range_texture, list_texel(cluster, range_width), 0).xy;
    let index_width = textureDimensions(light_index_texture).x;
    var color = f.color;
    for (var i = 0u; i < range.y; i++) {
        let k = textureLoad(light_index_texture, list_texel(range.x + i, index_width), 0).x;
        color += shade_texture_light(f.m.params, f.p.world_position, f.view_dir, k);
    }
    // As `tonemap.wgsl`: NaN fails `x == x`, ±inf fails `abs(x) <= max f32`; such a pixel is
    // shown black, with alpha 0 so that the read-back counts it.
    let finite = abs(color) <= vec3<f32>(3.40282346e38);
    let safe = select(vec3<f32>(0.0), color, finite);
    let mapped = aces_fitted(max(safe, vec3<f32>(0.0)) * view.params.z);
    return vec4<f32>(mapped, select(0.0, 1.0, all(finite)));
}

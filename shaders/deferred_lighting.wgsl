// Clustered deferred lighting: one full-screen pass reads the G-buffer (Full or Compact layout,
// see gbuffer.wgsl) and walks the pixel's cluster list, with the same shading code as the
// forward pipelines.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl
//!include common/packing.wgsl
//!include common/fullscreen.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;

// Full layout (fs_full) or Compact layout (fs_compact); depth for both.
@group(1) @binding(0) var gb_position: texture_2d<f32>;
@group(1) @binding(1) var gb_normal: texture_2d<f32>;
@group(1) @binding(2) var gb_albedo: texture_2d<f32>;
@group(1) @binding(3) var gb_compact: texture_2d<u32>;
@group(1) @binding(4) var gb_depth: texture_depth_2d;
@group(1) @binding(5) var<uniform> clear_color: vec4<f32>;

@group(2) @binding(0) var<uniform> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read> cluster_ranges: array<vec2<u32>>;
@group(2) @binding(2) var<storage, read> cluster_indices: array<u32>;

fn shade(s: SurfaceParams, world_position: vec3<f32>, frag: vec2<f32>) -> vec4<f32> {
    let view_dir = normalize(view.camera_position.xyz - world_position);
    let view_distance = -(view.view_from_world * vec4<f32>(world_position, 1.0)).z;
    let range = cluster_ranges[cluster_index(cluster_params, frag, view_distance)];
    var color = s.albedo * view.params.w;
    for (var i = 0u; i < range.y; i++) {
        color += shade_point_light(s, world_position, view_dir, lights[cluster_indices[range.x + i]]);
    }
    return vec4<f32>(color, 1.0);
}

@fragment
fn fs_full(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    if textureLoad(gb_depth, px, 0) <= 0.0 {
        return clear_color; // background (reverse-Z: cleared to 0)
    }
    let p = textureLoad(gb_position, px, 0);
    let n = textureLoad(gb_normal, px, 0);
    let a = textureLoad(gb_albedo, px, 0);
    var s: SurfaceParams;
    s.albedo = a.rgb;
    s.normal = normalize(n.xyz);
    s.shininess = n.w;
    s.specular = a.a;
    s.model = u32(p.w + 0.5);
    return shade(s, p.xyz, in.position.xy);
}

@fragment
fn fs_compact(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    let depth = textureLoad(gb_depth, px, 0);
    if depth <= 0.0 {
        return clear_color;
    }
    let g = textureLoad(gb_compact, px, 0);
    // Position from depth: the pixel centre's clip position through world_from_clip.
    let ndc = vec2<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0);
    let world = view.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    let params = unpack2x16float(g.z);
    var s: SurfaceParams;
    s.albedo = srgb_to_linear(unpack4x8unorm(g.x).rgb);
    s.normal = unpack_octa16(g.y);
    s.shininess = params.x;
    s.specular = params.y;
    s.model = g.w;
    return shade(s, world.xyz / world.w, in.position.xy);
}

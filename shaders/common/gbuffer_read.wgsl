// Reading the G-buffer back (clustered deferred lighting, tiled deferred, light volumes and the
// passes that bound or refine the light lists by its depth). Group 1 holds the targets of the
// pipeline's layout; a shader is composed for one layout (the define GBUFFER_FULL,
// GBUFFER_PACKED or GBUFFER_COMPACT, with GBUFFER), which gives it `gbuffer_read` for that
// layout, touching only that layout's bindings.
// Includes the view uniform (group 0, binding 0) too, which decoding needs.
//!include common/view_binding.wgsl
//!include common/gbuffer_codec.wgsl
//!include common/directional_lights.wgsl

// Full layout
@group(1) @binding(0) var gb_position: texture_2d<f32>;
@group(1) @binding(1) var gb_normal: texture_2d<f32>;
@group(1) @binding(2) var gb_albedo: texture_2d<f32>;
// Compact layout
@group(1) @binding(3) var gb_compact: texture_2d<u32>;
// Every layout
@group(1) @binding(4) var gb_depth: texture_depth_2d;
@group(1) @binding(5) var<uniform> clear_color: vec4<f32>;
// Packed layout
@group(1) @binding(6) var gb_packed_albedo: texture_2d<f32>;
@group(1) @binding(7) var gb_packed_position: texture_2d<f32>;
// Every layout: emitted radiance (rgb) and ambient occlusion (a)
@group(1) @binding(8) var gb_emissive: texture_2d<f32>;

// A surface read back from the G-buffer.
struct GSurface {
    params: SurfaceParams,
    world_position: vec3<f32>,
    emissive: vec3<f32>,
    occlusion: f32,
};

// `g` with the emissive target's radiance and occlusion at `px`.
fn with_emissive(g: GSurface, px: vec2<i32>) -> GSurface {
    let e = textureLoad(gb_emissive, px, 0);
    var out = g;
    out.emissive = e.rgb;
    out.occlusion = e.a;
    return out;
}

// What the surface sends back whatever the point lights (common/surface.wgsl's
// `surface_base_radiance`, from the G-buffer).
fn gbuffer_base_radiance(g: GSurface) -> vec3<f32> {
    return g.params.albedo * view.params.w * g.occlusion + g.emissive;
}

// View distance of a stored position (view-space -z), as the deferred passes compute it: the
// lighting passes pick the cluster with it, `cluster_depth.wgsl` bounds the clusters by it.
fn gbuffer_view_distance(p: vec3<f32>) -> f32 {
    return -(view.view_from_world * vec4<f32>(p, 1.0)).z;
}

// Reverse-Z depth of the pixel (0: nothing was drawn there).
fn gbuffer_depth(px: vec2<i32>) -> f32 {
    return textureLoad(gb_depth, px, 0);
}

//!if GBUFFER_FULL
// The surface at `px`, from the Full layout.
fn gbuffer_read(px: vec2<i32>) -> GSurface {
    let p = textureLoad(gb_position, px, 0);
    let n = textureLoad(gb_normal, px, 0);
    let a = textureLoad(gb_albedo, px, 0);
    var g: GSurface;
    g.params.albedo = a.rgb;
    g.params.normal = normalize(n.xyz);
    g.params.model = u32(p.w + 0.5);
    g.params = with_material_slots(g.params, vec2<f32>(n.w, a.a));
    g.world_position = p.xyz;
    return with_emissive(g, px);
}
//!endif

//!if GBUFFER_PACKED
// The surface at `px`, from the Packed layout.
fn gbuffer_read(px: vec2<i32>) -> GSurface {
    let a = textureLoad(gb_packed_albedo, px, 0);
    let p = textureLoad(gb_packed_position, px, 0);
    var g: GSurface;
    g.params = gbuffer_unpack_albedo_params(a.rgb);
    g.params.normal = gbuffer_decode_components(vec2<f32>(a.a, p.a), view.view_from_world);
    g.world_position = p.xyz;
    return with_emissive(g, px);
}
//!endif

// World position of the pixel centre at `uv` (0..1, top-left origin) and reverse-Z `depth`.
fn gbuffer_position_from_depth(uv: vec2<f32>, depth: f32) -> vec3<f32> {
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let world = view.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    return world.xyz / world.w;
}

//!if GBUFFER_COMPACT
// The surface at `px`, from the Compact layout; its position comes from the depth it stores
// (the shading position's, which the depth buffer only approximates on very large triangles).
fn gbuffer_read(px: vec2<i32>) -> GSurface {
    let g = textureLoad(gb_compact, px, 0);
    let params = unpack2x16float(g.z);
    var out: GSurface;
    out.params.albedo = gbuffer_unpack_albedo(g.x);
    out.params.normal = gbuffer_decode_word(g.y);
    out.params.model = gbuffer_unpack_model(g.x);
    out.params = with_material_slots(out.params, params);
    let uv = (vec2<f32>(px) + 0.5) * view.viewport.zw;
    out.world_position = gbuffer_position_from_depth(uv, bitcast<f32>(g.w));
    return with_emissive(out, px);
}
//!endif

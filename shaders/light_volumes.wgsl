// Deferred light volumes. After the G-buffer pass, one render pass into HDR:
// 1. a full-screen triangle writes the clear colour behind the geometry and the ambient term
//    (with emission and the directional lights)
//    on it (fs_ambient_*);
// 2. every light is drawn as an instanced sphere proxy (vs_volume: an icosphere that contains
//    the light's sphere) whose pixels add that one light (fs_volume_*, additive blending).
// Only back faces are drawn, with the test "back face at or behind the stored surface"
// (reverse-Z: LessEqual, depth read-only), so a pixel is lit once per light, also when the
// camera is inside the sphere (its front faces are behind the camera, its back faces are not).
// With depth clamping (DEPTH_CLIP_CONTROL) back faces beyond the far plane are clamped to it
// instead of clipped; without it the pass draws them with no depth test (still correct:
// the light's attenuation is exactly 0 outside its radius).
// Where the device can blend rgba32f, steps 1-2 go into an f32 target and fs_resolve copies it
// to HDR: summed in f16, a thousand small additions lose FLIP 0.004 against naive forward.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/fullscreen.wgsl

// group 0, binding 0: `view` (common/view_binding.wgsl, through common/gbuffer_read.wgsl)
//!include common/point_lights.wgsl

//!include common/gbuffer_read.wgsl

// Only with an f32 accumulation target: the sum, read by fs_resolve.
@group(2) @binding(0) var light_accum: texture_2d<f32>;

@fragment
fn fs_resolve(in: FullscreenOut) -> @location(0) vec4<f32> {
    return textureLoad(light_accum, vec2<i32>(in.position.xy), 0);
}

struct VolumeOut {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(flat) light_index: u32,
};

@vertex
fn vs_volume(@location(0) position: vec3<f32>, @builtin(instance_index) light_index: u32) -> VolumeOut {
    // The proxy bounds what the light reaches: a spot light's sphere is its cone's.
    let bounds = light_bounds(lights[light_index]);
    let world = bounds.xyz + position * bounds.w;
    var out: VolumeOut;
    out.clip_position = view.clip_from_world * vec4<f32>(world, 1.0);
    out.light_index = light_index;
    return out;
}

// What reaches the pixel whatever the point lights: ambient, emission and the directional
// lights (which no volume bounds).
fn ambient(g: GSurface) -> vec4<f32> {
    let view_dir = direction_to_eye(view, g.world_position);
    return vec4<f32>(gbuffer_base_radiance(g) + shade_directional_lights(g.params, g.world_position, view_dir), 1.0);
}

fn one_light(g: GSurface, light_index: u32) -> vec4<f32> {
    let view_dir = direction_to_eye(view, g.world_position);
    return vec4<f32>(shade_light(g.params, g.world_position, view_dir, light_index), 0.0);
}

// Both read the G-buffer of the layout the shader is composed for (`gbuffer_read`).
//!if GBUFFER
@fragment
fn fs_ambient(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    if gbuffer_depth(px) <= 0.0 {
        return clear_color;
    }
    return ambient(gbuffer_read(px));
}
//!endif

//!if GBUFFER
@fragment
fn fs_volume(in: VolumeOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.clip_position.xy);
    if gbuffer_depth(px) <= 0.0 {
        return vec4<f32>(0.0); // background: nothing to light
    }
    return one_light(gbuffer_read(px), in.light_index);
}
//!endif

// Camera-motion blur (GPU Gems 3, ch. 27; Rust: crates/manylight_render/src/passes/motion_blur.rs):
// the pixel's position is rebuilt from depth, projected with last frame's clip-from-world, and
// the HDR colour is averaged along the screen-space difference, into the second HDR image (the
// pass swaps the two: `PassContext::post_process_write`).
//
// The tap count is a pipeline-override constant, not a uniform: lavapipe (Mesa 22.3) compiles a
// fresh copy of a shader whose loop count it can read from a uniform buffer at every draw, and
// never frees the copies (0.84 MB per frame).
//!include common/view.wgsl

// Taps along the motion (2 to 64; Rust: `MotionBlurSettings::samples`).
override SAMPLES: u32 = 8u;
//!include common/fullscreen.wgsl

struct MotionBlurParams {
    strength: f32,
    max_pixels: f32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var<uniform> params: MotionBlurParams;
@group(0) @binding(2) var hdr: texture_2d<f32>;
@group(0) @binding(3) var depth: texture_depth_2d;

// Screen velocity of the surface at `px` in pixels (current minus previous position).
fn pixel_velocity(px: vec2<i32>, uv: vec2<f32>) -> vec2<f32> {
    let z = textureLoad(depth, px, 0);
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    // Homogeneous world position (not divided: w may be ~0 on the far plane, and projecting
    // the homogeneous point with the previous matrix is exact either way).
    let world = view.world_from_clip * vec4<f32>(ndc, z, 1.0);
    let prev_clip = view.prev_clip_from_world * world;
    let curr_clip = view.clip_from_world * world;
    if !(prev_clip.w > 0.0) || !(curr_clip.w > 0.0) {
        return vec2<f32>(0.0); // behind last frame's camera (or NaN): no blur
    }
    let delta_ndc = curr_clip.xy / curr_clip.w - prev_clip.xy / prev_clip.w;
    let v = delta_ndc * vec2<f32>(0.5, -0.5) * view.viewport.xy * params.strength;
    let len = length(v);
    if !(len == len) {
        return vec2<f32>(0.0);
    }
    return select(v, v * (params.max_pixels / len), len > params.max_pixels);
}

@fragment
fn fs_blur(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    let centre = textureLoad(hdr, px, 0);
    let v = pixel_velocity(px, in.uv);
    // Less than half a pixel of motion: the exact colour (a still camera changes nothing).
    if dot(v, v) < 0.25 {
        return centre;
    }
    let max_px = vec2<i32>(view.viewport.xy) - vec2<i32>(1);
    let n = max(SAMPLES, 2u);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        // Taps spread evenly over [-v/2, +v/2], centred on the pixel.
        let t = f32(i) / f32(n - 1u) - 0.5;
        let p = clamp(vec2<i32>(round(in.position.xy + v * t)), vec2<i32>(0), max_px);
        sum += textureLoad(hdr, p, 0).rgb;
    }
    return vec4<f32>(sum / f32(n), centre.a);
}

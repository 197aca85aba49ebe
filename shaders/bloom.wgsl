// Bloom (Rust: crates/manylight_render/src/passes/bloom.rs), three stages:
// - fs_bright: the HDR colour above a soft threshold (bilinear taps box-filter it down when
//   the target is smaller than the source);
// - fs_blur: one direction of a separable 9-tap gaussian (sigma ~ 2 texels of the target);
// - fs_upsample: a smaller level, bilinearly upsampled, blended additively into the next larger;
// - fs_composite: level 0 (the sum of the levels) / level count x intensity, blended
//   additively into HDR.
//!include common/fullscreen.wgsl

struct BloomParams {
    // blur: one texel of the target along the blur direction, in uv units
    direction: vec2<f32>,
    threshold: f32,
    knee: f32,
    intensity: f32,
    level_count: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> params: BloomParams;
@group(0) @binding(1) var linear_sampler: sampler;
@group(0) @binding(2) var source: texture_2d<f32>;

// Largest HDR value that takes part (keeps single bright pixels from flickering into huge
// blobs and keeps f16 from overflowing when levels are summed).
const BLOOM_MAX_VALUE: f32 = 1024.0;

@fragment
fn fs_bright(in: FullscreenOut) -> @location(0) vec4<f32> {
    let raw = textureSampleLevel(source, linear_sampler, in.uv, 0.0).rgb;
    // Non-finite values (never expected) take no part.
    let c = clamp(select(vec3<f32>(0.0), raw, raw == raw), vec3<f32>(0.0), vec3<f32>(BLOOM_MAX_VALUE));
    let brightness = max(c.r, max(c.g, c.b));
    // Soft knee: quadratic from threshold - knee to threshold + knee, linear above.
    let knee = max(params.knee, 1e-4);
    let soft = clamp(brightness - params.threshold + knee, 0.0, 2.0 * knee);
    let curve = soft * soft / (4.0 * knee);
    let contribution = max(curve, brightness - params.threshold) / max(brightness, 1e-4);
    return vec4<f32>(c * contribution, 1.0);
}

// Gaussian weights of the 9-tap kernel (centre, then +-1 .. +-4 texels); they sum to 1.
const BLOOM_WEIGHTS = array<f32, 5>(0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216);

@fragment
fn fs_blur(in: FullscreenOut) -> @location(0) vec4<f32> {
    var sum = textureSampleLevel(source, linear_sampler, in.uv, 0.0).rgb * BLOOM_WEIGHTS[0];
    for (var i = 1; i < 5; i++) {
        let offset = params.direction * f32(i);
        sum += textureSampleLevel(source, linear_sampler, in.uv + offset, 0.0).rgb * BLOOM_WEIGHTS[i];
        sum += textureSampleLevel(source, linear_sampler, in.uv - offset, 0.0).rgb * BLOOM_WEIGHTS[i];
    }
    return vec4<f32>(sum, 1.0);
}

@fragment
fn fs_upsample(in: FullscreenOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSampleLevel(source, linear_sampler, in.uv, 0.0).rgb, 0.0);
}

@fragment
fn fs_composite(in: FullscreenOut) -> @location(0) vec4<f32> {
    let sum = textureSampleLevel(source, linear_sampler, in.uv, 0.0).rgb;
    return vec4<f32>(sum / f32(max(params.level_count, 1u)) * params.intensity, 0.0);
}

// The custom_pass example's vignette (Rust: examples/custom_pass.rs): darkens the HDR image
// towards its corners, before tone mapping. Its vertex stage is the library's full-screen
// triangle, brought in by the include below.
//!include common/fullscreen.wgsl

// `VignettePass::Params` in examples/custom_pass.rs.
struct VignetteParams {
    // How dark the corners get: 0 none, 1 black.
    strength: f32,
    // Where the darkening starts, as a fraction of the centre-to-corner distance.
    radius: f32,
    _pad0: f32,
    _pad1: f32,
};

@group(0) @binding(0) var<uniform> params: VignetteParams;
@group(0) @binding(1) var source: texture_2d<f32>;

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let colour = textureLoad(source, vec2<i32>(in.position.xy), 0);
    // 0 at the centre, 1 in the corners, whatever the aspect ratio.
    let d = length(in.uv * 2.0 - 1.0) / sqrt(2.0);
    let falloff = 1.0 - params.strength * smoothstep(params.radius, 1.0, d);
    return vec4<f32>(colour.rgb * falloff, colour.a);
}

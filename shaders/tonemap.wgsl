// Tone map: HDR scene colour * exposure -> ACES filmic curve (Narkowicz 2015 fit) -> the sRGB
// target (the hardware applies the sRGB encoding when the target format is *Srgb).
//!include common/view.wgsl
//!include common/fullscreen.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var hdr: texture_2d<f32>;

fn aces_fitted(x: vec3<f32>) -> vec3<f32> {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return saturate((x * (a * x + b)) / (x * (c * x + d) + e));
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let color = textureLoad(hdr, vec2<i32>(in.position.xy), 0).rgb;
    // Non-finite HDR values (never expected) are shown as black rather than propagating.
    let safe = select(vec3<f32>(0.0), color, color == color);
    return vec4<f32>(aces_fitted(max(safe, vec3<f32>(0.0)) * view.params.z), 1.0);
}

// Tone map: HDR scene colour * exposure -> ACES filmic curve (Narkowicz 2015 fit) -> the sRGB
// target (the hardware applies the sRGB encoding when the target format is *Srgb).
//!include common/view.wgsl
//!include common/fullscreen.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var hdr: texture_2d<f32>;
// Pixels whose HDR colour is NaN or infinite this frame (cleared before the pass, read back
// into the frame report): a renderer that promises "no NaN" has to count them, not hide them.
@group(0) @binding(2) var<storage, read_write> nonfinite_pixels: atomic<u32>;

//!include common/tonemap_curve.wgsl

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let color = textureLoad(hdr, vec2<i32>(in.position.xy), 0).rgb;
    // NaN fails `x == x`; ±inf fails `abs(x) <= max f32` (as does NaN). 3.40282346e38 rounds
    // to max f32; a literal above it (3.40282347e38) is refused by browsers' WGSL compilers.
    let finite = abs(color) <= vec3<f32>(3.40282346e38);
    if !all(finite) {
        atomicAdd(&nonfinite_pixels, 1u);
    }
    // Non-finite HDR values (never expected; counted above) are shown as black.
    let safe = select(vec3<f32>(0.0), color, finite);
    return vec4<f32>(aces_fitted(max(safe, vec3<f32>(0.0)) * view.params.z), 1.0);
}

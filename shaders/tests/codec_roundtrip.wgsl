// Test-only kernel (crates/manylight_render/tests/codec_gpu.rs): runs every normal codec of
// common/packing.wgsl on one input per invocation, so the test can compare the GPU with
// manylight_core::codec. Encoders get `n`; decoders get the codes and points the CPU encoder
// produced (`words`, `e`), so decoding is compared on identical input; `roundtrip_*` decode the
// GPU's own codes (for the no-NaN and unit-length checks).

//!include common/packing.wgsl

struct CodecIn {
    // xyz: the vector to encode (any bits: non-unit, NaN, inf, subnormal).
    n: vec4<f32>,
    // xy: a point for octa_decode, zw: a pair for xyz_decode.
    e: vec4<f32>,
    // x: word for unpack_octa16, y: unpack_octa8, z: unpack_spherical16.
    words: vec4<u32>,
}

struct CodecOut {
    // pack_octa16(n), pack_octa8(n), pack_spherical16(n), 0.
    codes: vec4<u32>,
    // xy: octa_encode(n), zw: xyz_encode(n).
    encoded: vec4<f32>,
    // xy: spherical_encode(n), zw: 0.
    spherical: vec4<f32>,
    unpack_octa16: vec4<f32>,
    unpack_octa8: vec4<f32>,
    unpack_spherical16: vec4<f32>,
    octa_decode: vec4<f32>,
    xyz_decode: vec4<f32>,
    roundtrip_octa16: vec4<f32>,
    roundtrip_octa8: vec4<f32>,
    roundtrip_spherical16: vec4<f32>,
    roundtrip_xyz: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> inputs: array<CodecIn>;
@group(0) @binding(1) var<storage, read_write> outputs: array<CodecOut>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&inputs) {
        return;
    }
    let input = inputs[i];
    let n = input.n.xyz;
    var out: CodecOut;
    out.codes = vec4<u32>(pack_octa16(n), pack_octa8(n), pack_spherical16(n), 0u);
    out.encoded = vec4<f32>(octa_encode(n), xyz_encode(n));
    out.spherical = vec4<f32>(spherical_encode(n), 0.0, 0.0);
    out.unpack_octa16 = vec4<f32>(unpack_octa16(input.words.x), 0.0);
    out.unpack_octa8 = vec4<f32>(unpack_octa8(input.words.y), 0.0);
    out.unpack_spherical16 = vec4<f32>(unpack_spherical16(input.words.z), 0.0);
    out.octa_decode = vec4<f32>(octa_decode(input.e.xy), 0.0);
    out.xyz_decode = vec4<f32>(xyz_decode(input.e.zw), 0.0);
    out.roundtrip_octa16 = vec4<f32>(unpack_octa16(out.codes.x), 0.0);
    out.roundtrip_octa8 = vec4<f32>(unpack_octa8(out.codes.y), 0.0);
    out.roundtrip_spherical16 = vec4<f32>(unpack_spherical16(out.codes.z), 0.0);
    out.roundtrip_xyz = vec4<f32>(xyz_decode(out.encoded.zw), 0.0);
    outputs[i] = out;
}

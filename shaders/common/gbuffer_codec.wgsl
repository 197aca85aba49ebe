// How the Packed and Compact G-buffer layouts store a surface (Rust: `GBufferLayout`,
// `NormalCodec`). The codec is a pipeline-override constant, so each (layout, codec) pair is
// its own pipeline and the shader has no run-time switch.
//!include common/packing.wgsl
//!include common/brdf.wgsl

override NORMAL_CODEC: u32 = NORMAL_CODEC_OCTA16;

// ---- The normal as a 32-bit word (Compact; Packed splits it into two components) ----

// Bits per component of the codec's word: spherical and octa16 2 x 16, octa8 2 x 8.
fn gbuffer_component_bits() -> u32 {
    return select(16u, 8u, NORMAL_CODEC == NORMAL_CODEC_OCTA8);
}

// The word of a word codec (spherical, octa16, octa8). The xyz codec has no 32-bit word;
// Rust rejects Compact + xyz (`GBufferLayout::supports`), and here it falls back to octa16.
fn gbuffer_encode_word(n: vec3<f32>) -> u32 {
    if NORMAL_CODEC == NORMAL_CODEC_SPHERICAL {
        return pack_spherical16(n);
    } else if NORMAL_CODEC == NORMAL_CODEC_OCTA8 {
        return pack_octa8(n);
    }
    return pack_octa16(n);
}

fn gbuffer_decode_word(w: u32) -> vec3<f32> {
    if NORMAL_CODEC == NORMAL_CODEC_SPHERICAL {
        return unpack_spherical16(w);
    } else if NORMAL_CODEC == NORMAL_CODEC_OCTA8 {
        return unpack_octa8(w);
    }
    return unpack_octa16(w);
}

// ---- The normal as two f32 components (Packed: n.a and n.b) ----

// World-space normal to (n.a, n.b). xyz stores the view-space x and y (z is rebuilt as
// +sqrt(1 - x^2 - y^2), so normals facing away from the camera come back mirrored); the word
// codecs store their two integer fields as exact small integers.
fn gbuffer_encode_components(n: vec3<f32>, view_from_world: mat4x4<f32>) -> vec2<f32> {
    if NORMAL_CODEC == NORMAL_CODEC_XYZ {
        return xyz_encode((view_from_world * vec4<f32>(n, 0.0)).xyz);
    }
    let bits = gbuffer_component_bits();
    let mask = (1u << bits) - 1u;
    let w = gbuffer_encode_word(n);
    return vec2<f32>(f32(w & mask), f32((w >> bits) & mask));
}

fn gbuffer_decode_components(c: vec2<f32>, view_from_world: mat4x4<f32>) -> vec3<f32> {
    if NORMAL_CODEC == NORMAL_CODEC_XYZ {
        let n_view = xyz_decode(c);
        // The view is a rotation (and translation): its inverse rotation is the transpose.
        let r = mat3x3<f32>(view_from_world[0].xyz, view_from_world[1].xyz, view_from_world[2].xyz);
        return normalize(transpose(r) * n_view);
    }
    let bits = gbuffer_component_bits();
    let mask = (1u << bits) - 1u;
    let a = u32(clamp(c.x, 0.0, f32(mask)) + 0.5);
    let b = u32(clamp(c.y, 0.0, f32(mask)) + 0.5);
    return gbuffer_decode_word(a | (b << bits));
}

// ---- Packed: material parameters in the integer parts of the albedo channels ----
// Each albedo channel stores a + 2k with a = saturate(albedo) in [0, 1] and k a small integer:
//   r: k = shading model (0..3)
//   g: k = round(saturate(specular) * 1023)             (PBR: round(metallic * 1023))
//   b: k = round(clamp(log2(shininess), 0, 13) * 64)   (shininess 1..8192, steps of 0.54 %;
//                                                       PBR: round(roughness * 1023))
// With k <= 1023 the value stays below 2048, where f32 keeps the albedo to 2^-12 (better than
// the f16 albedo of the Full layout); decoding is floor(v / 2) and an exact subtraction.

fn gbuffer_pack_albedo_params(s: SurfaceParams) -> vec3<f32> {
    let a = saturate(s.albedo);
    let pbr = s.model == SHADING_PBR;
    let k = vec3<f32>(
        f32(min(s.model, 3u)),
        round(saturate(select(s.specular, s.metallic, pbr)) * 1023.0),
        select(round(clamp(log2(max(s.shininess, 1.0)), 0.0, 13.0) * 64.0), round(saturate(s.roughness) * 1023.0), pbr),
    );
    return a + 2.0 * k;
}

// Albedo, specular, shininess and model of a packed albedo (the normal is left zero).
fn gbuffer_unpack_albedo_params(v: vec3<f32>) -> SurfaceParams {
    let k = floor(max(v, vec3<f32>(0.0)) * 0.5);
    var s: SurfaceParams;
    s.albedo = clamp(v - 2.0 * k, vec3<f32>(0.0), vec3<f32>(1.0));
    s.model = u32(k.x);
    s.specular = k.y * (1.0 / 1023.0);
    s.shininess = exp2(k.z * (1.0 / 64.0));
    s.metallic = k.y * (1.0 / 1023.0);
    s.roughness = k.z * (1.0 / 1023.0);
    return s;
}

// ---- Compact: albedo and shading model in one word ----

// Albedo as rgb8 (sRGB-encoded) in bits 0-23, the shading model in bits 24-31.
fn gbuffer_pack_albedo_model(albedo: vec3<f32>, model: u32) -> u32 {
    return (pack4x8unorm(vec4<f32>(linear_to_srgb(albedo), 0.0)) & 0x00ffffffu) | (min(model, 255u) << 24u);
}

fn gbuffer_unpack_albedo(word: u32) -> vec3<f32> {
    return srgb_to_linear(unpack4x8unorm(word).rgb);
}

fn gbuffer_unpack_model(word: u32) -> u32 {
    return word >> 24u;
}

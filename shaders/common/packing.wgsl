// Normal codecs for the G-buffer: WGSL twins of crates/manylight_core/src/codec, with the same
// operations in the same order (see that module for the maths and the rules for bad input).
//
//   WGSL                                    Rust (manylight_core::codec)
//   packing_sanitize(n)                     sanitize_normal
//   octa_encode(n) -> vec2 in [-1, 1]       octa_encode
//   octa_decode(e)                          octa_decode
//   pack_octa16(n) / unpack_octa16(p)       pack_octa16 / unpack_octa16 (x bits 0-15, y 16-31)
//   pack_octa8(n) / unpack_octa8(p)         pack_octa8 / unpack_octa8 (x bits 0-7, y 8-15)
//   spherical_encode(n) -> vec2 in [0, 1]   spherical_encode
//   spherical_decode(e)                     spherical_decode
//   pack_spherical16 / unpack_spherical16   pack_spherical16 / unpack_spherical16
//   xyz_encode(n) -> vec2                   encode_xy
//   xyz_decode(e)                           decode_xy
//
// Same on both sides: `round` (half to even here, `f32::round_ties_even` in Rust), `floor`,
// `min`, `max`, `clamp`, `abs`, `+ - *`, conversions and bit operations are exact or
// correctly rounded in WGSL; constants are the Rust f32 values, written out (a Rust test
// checks them); decoding multiplies by stored reciprocals rather than dividing.
// Where the GPU may differ (a GPU comparison must allow for these):
// - `/` (2.5 ulp) and `sqrt` (from 1/inverseSqrt, about 2.5 ulp) are correctly rounded only
//   in Rust, so normalised vectors may differ by a few ulp.
// - `atan2` may be off by 4096 ulp and `sin`/`cos` by 2^-11 absolute on [-pi, pi] under the
//   WGSL spec: a GPU at those limits adds up to ~0.03-0.04 degrees to the spherical codec,
//   ten times its 16-bit quantisation error. Real drivers are usually far closer.
// - Drivers may fuse `a * b + c` into one rounding (Rust never does).
// - Subnormals may be flushed to zero; the sanitise rule (largest |component| below
//   PACKING_MIN_POSITIVE -> +Z) makes that harmless for whole vectors, and a flushed
//   component can only change the sign of a zero on a seam, where both codes decode to the
//   same direction.
// So quantised codes match Rust bit for bit except where the exact value lies within those
// few ulp of a rounding boundary, or two precise-encoding candidates tie as closely.

const PACKING_MIN_POSITIVE: f32 = 1.1754944e-38f;
const PACKING_OCTA16_MAX: f32 = 32767.0f;
const PACKING_OCTA16_INV_MAX: f32 = 3.051851e-5f;
const PACKING_OCTA8_MAX: f32 = 127.0f;
const PACKING_OCTA8_INV_MAX: f32 = 0.007874016f;
const PACKING_SPHERICAL16_MAX: f32 = 65535.0f;
const PACKING_SPHERICAL16_INV_MAX: f32 = 1.5259022e-5f;
const PACKING_PI: f32 = 3.1415927f;
const PACKING_TAU: f32 = 6.2831855f;
const PACKING_FRAC_1_PI: f32 = 0.31830987f;
const PACKING_FRAC_1_TAU: f32 = 0.15915494f;

// NaN or +-inf: exponent bits all ones (codec::non_finite). A bit test, because WGSL may
// assume floats are finite and fold away `v != v`.
fn packing_non_finite(v: f32) -> bool {
    return (bitcast<u32>(v) & 0x7f800000u) == 0x7f800000u;
}

// +1 for v >= 0 (both zeros), else -1 (codec::sign_not_zero; WGSL `sign` returns 0 at 0).
fn packing_sign_not_zero(v: f32) -> f32 {
    return select(-1.0, 1.0, v >= 0.0);
}

// v / |v| for a finite v well away from zero (codec::normalize_nonzero).
fn packing_normalize_nonzero(v: vec3<f32>) -> vec3<f32> {
    let inv = 1.0 / sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return vec3<f32>(v.x * inv, v.y * inv, v.z * inv);
}

// 2^k for k in [-126, 127], from its bits (codec::pow2).
fn packing_pow2(k: i32) -> f32 {
    return bitcast<f32>(u32(k + 127) << 23u);
}

// The unit vector every codec encodes for n (codec::sanitize_normal): +Z for NaN/inf or when
// the largest |component| is below PACKING_MIN_POSITIVE; otherwise scaled exactly by a power
// of two into [1, 2) (in two halves, so no factor is subnormal), then normalised.
fn packing_sanitize(n: vec3<f32>) -> vec3<f32> {
    if packing_non_finite(n.x) || packing_non_finite(n.y) || packing_non_finite(n.z) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let m = max(max(abs(n.x), abs(n.y)), abs(n.z));
    if m < PACKING_MIN_POSITIVE {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let k = 127 - i32((bitcast<u32>(m) >> 23u) & 0xffu);
    let k1 = k / 2;
    let a = packing_pow2(k1);
    let b = packing_pow2(k - k1);
    return packing_normalize_nonzero(vec3<f32>(n.x * a * b, n.y * a * b, n.z * a * b));
}

// ---- Octahedral (codec/octa.rs) ----

// A sanitised unit vector onto the octahedral square (octa::square_of_unit).
fn packing_octa_square(n: vec3<f32>) -> vec2<f32> {
    let inv_l1 = 1.0 / (abs(n.x) + abs(n.y) + abs(n.z));
    let px = n.x * inv_l1;
    let py = n.y * inv_l1;
    var e = vec2<f32>(px, py);
    if n.z < 0.0 {
        e = vec2<f32>((1.0 - abs(py)) * packing_sign_not_zero(px), (1.0 - abs(px)) * packing_sign_not_zero(py));
    }
    return clamp(e, vec2<f32>(-1.0), vec2<f32>(1.0));
}

// Any vector onto the octahedral square, in [-1, 1] (octa_encode). Unquantised.
fn octa_encode(n: vec3<f32>) -> vec2<f32> {
    return packing_octa_square(packing_sanitize(n));
}

// A point of [-1, 1]^2 back to the sphere (octa::decode_square).
fn packing_octa_decode_square(ex: f32, ey: f32) -> vec3<f32> {
    let z = 1.0 - abs(ex) - abs(ey);
    if z < 0.0 {
        return packing_normalize_nonzero(
            vec3<f32>((1.0 - abs(ey)) * packing_sign_not_zero(ex), (1.0 - abs(ex)) * packing_sign_not_zero(ey), z),
        );
    }
    return packing_normalize_nonzero(vec3<f32>(ex, ey, z));
}

// Any point (NaN/inf -> +Z, others clamped to [-1, 1]) to a unit vector (octa_decode).
fn octa_decode(e: vec2<f32>) -> vec3<f32> {
    if packing_non_finite(e.x) || packing_non_finite(e.y) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let c = clamp(e, vec2<f32>(-1.0), vec2<f32>(1.0));
    return packing_octa_decode_square(c.x, c.y);
}

// An integer-valued code to a unit vector (octa::dequantise).
fn packing_octa_dequantise(q: vec2<f32>, inv_max: f32) -> vec3<f32> {
    let e = clamp(q * inv_max, vec2<f32>(-1.0), vec2<f32>(1.0));
    return packing_octa_decode_square(e.x, e.y);
}

// |a - b|^2 (octa::distance_squared): precise for tiny angles, unlike a cosine.
fn packing_distance_squared(a: vec3<f32>, b: vec3<f32>) -> f32 {
    let d = a - b;
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

// Precise quantisation (octa::quantise_precise): of floor(s * M) + (0,0), (0,1), (1,0), (1,1),
// clamped to M, the first closest to n.
fn packing_octa_quantise(n_in: vec3<f32>, max_code: f32, inv_max: f32) -> vec2<i32> {
    let n = packing_sanitize(n_in);
    let s = packing_octa_square(n);
    let b = floor(s * max_code);
    var best = b;
    var best_dist = packing_distance_squared(packing_octa_dequantise(b, inv_max), n);
    for (var k = 1u; k < 4u; k += 1u) {
        let c = min(b + vec2<f32>(f32(k >> 1u), f32(k & 1u)), vec2<f32>(max_code));
        let dist = packing_distance_squared(packing_octa_dequantise(c, inv_max), n);
        if dist < best_dist {
            best = c;
            best_dist = dist;
        }
    }
    return vec2<i32>(best);
}

// 2 x 16-bit snorm octahedral code, x in bits 0-15, y in bits 16-31 (pack_octa16).
fn pack_octa16(n: vec3<f32>) -> u32 {
    let q = packing_octa_quantise(n, PACKING_OCTA16_MAX, PACKING_OCTA16_INV_MAX);
    return (bitcast<u32>(q.x) & 0xffffu) | ((bitcast<u32>(q.y) & 0xffffu) << 16u);
}

// Any word to a unit vector; -32768 acts as -32767 (unpack_octa16).
fn unpack_octa16(p: u32) -> vec3<f32> {
    let qx = bitcast<i32>(p << 16u) >> 16u;
    let qy = bitcast<i32>(p) >> 16u;
    return packing_octa_dequantise(vec2<f32>(f32(qx), f32(qy)), PACKING_OCTA16_INV_MAX);
}

// 2 x 8-bit snorm octahedral code in the low 16 bits, x in bits 0-7, y in 8-15 (pack_octa8).
fn pack_octa8(n: vec3<f32>) -> u32 {
    let q = packing_octa_quantise(n, PACKING_OCTA8_MAX, PACKING_OCTA8_INV_MAX);
    return (bitcast<u32>(q.x) & 0xffu) | ((bitcast<u32>(q.y) & 0xffu) << 8u);
}

// Any word to a unit vector; bits 16-31 ignored, -128 acts as -127 (unpack_octa8).
fn unpack_octa8(p: u32) -> vec3<f32> {
    let qx = bitcast<i32>(p << 24u) >> 24u;
    let qy = bitcast<i32>(p << 16u) >> 24u;
    return packing_octa_dequantise(vec2<f32>(f32(qx), f32(qy)), PACKING_OCTA8_INV_MAX);
}

// ---- Spherical (codec/spherical.rs) ----

// (theta / pi, phi / 2pi + 1/2) of any vector, both in [0, 1] (spherical_encode). theta is
// atan2(sqrt(x^2 + y^2), z), not acos(z); phi is 0 at the poles (atan2(0, 0) is undefined).
fn spherical_encode(n_in: vec3<f32>) -> vec2<f32> {
    let n = packing_sanitize(n_in);
    let r = sqrt(n.x * n.x + n.y * n.y);
    let theta = atan2(r, n.z);
    var phi = 0.0;
    if r > 0.0 {
        phi = atan2(n.y, n.x);
    }
    return vec2<f32>(clamp(theta * PACKING_FRAC_1_PI, 0.0, 1.0), clamp(phi * PACKING_FRAC_1_TAU + 0.5, 0.0, 1.0));
}

// u, v in [0, 1] to a unit vector (spherical::decode_unit).
fn packing_spherical_decode_unit(u: f32, v: f32) -> vec3<f32> {
    let theta = u * PACKING_PI;
    let phi = v * PACKING_TAU - PACKING_PI;
    let st = sin(theta);
    return packing_normalize_nonzero(vec3<f32>(st * cos(phi), st * sin(phi), cos(theta)));
}

// Any (u, v) (NaN/inf -> +Z, others clamped to [0, 1]) to a unit vector (spherical_decode).
fn spherical_decode(e: vec2<f32>) -> vec3<f32> {
    if packing_non_finite(e.x) || packing_non_finite(e.y) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    return packing_spherical_decode_unit(clamp(e.x, 0.0, 1.0), clamp(e.y, 0.0, 1.0));
}

// 2 x 16-bit unorm (theta, phi), theta in bits 0-15, phi in 16-31, rounded half to even
// (pack_spherical16).
fn pack_spherical16(n: vec3<f32>) -> u32 {
    let q = vec2<u32>(round(spherical_encode(n) * PACKING_SPHERICAL16_MAX));
    return q.x | (q.y << 16u);
}

// Any word to a unit vector (unpack_spherical16).
fn unpack_spherical16(p: u32) -> vec3<f32> {
    let u = min(f32(p & 0xffffu) * PACKING_SPHERICAL16_INV_MAX, 1.0);
    let v = min(f32(p >> 16u) * PACKING_SPHERICAL16_INV_MAX, 1.0);
    return packing_spherical_decode_unit(u, v);
}

// ---- Naive view-space xy (codec/xyz.rs) ----

// (x, y) of the sanitised vector (encode_xy). The caller picks the storage precision.
fn xyz_encode(n: vec3<f32>) -> vec2<f32> {
    let s = packing_sanitize(n);
    return vec2<f32>(s.x, s.y);
}

// (x, y, +sqrt(max(0, 1 - x^2 - y^2))), sanitised (decode_xy): the sign of z is lost, so
// normals facing away from the camera come back mirrored. NaN/inf -> +Z.
fn xyz_decode(e: vec2<f32>) -> vec3<f32> {
    if packing_non_finite(e.x) || packing_non_finite(e.y) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let z = sqrt(max(1.0 - e.x * e.x - e.y * e.y, 0.0));
    return packing_sanitize(vec3<f32>(e.x, e.y, z));
}

// sRGB transfer function (IEC 61966-2-1), for 8-bit colour storage in packed G-buffers.
fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = saturate(c);
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, x * 12.92, x <= vec3<f32>(0.0031308));
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

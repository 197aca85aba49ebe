//! Octahedral normals (Cigolle et al. 2014): the unit sphere → the octahedron
//! `|x|+|y|+|z| = 1` → the square `[-1, 1]²`, the lower half folded over the square's corners.
//!
//! Steps of the quantised encoding ([`octa16_encode`], [`octa8_encode`]):
//!
//! 1. Sanitise `n` to a unit vector ([`sanitize_normal`]).
//! 2. Map it onto the square ([`octa_encode`]): `p = n.xy / (|x|+|y|+|z|)`; for `z < 0`
//!    fold: `p = (1 - |p.yx|) · signNotZero(p)`.
//! 3. Take the grid point below: `b = floor(p · M)`, `M = 2^(bits-1) - 1`.
//! 4. Of `b`, `b + (0,1)`, `b + (1,0)`, `b + (1,1)` (in that order, clamped to `M`) keep the
//!    first whose decoded direction is closest to `n` (the paper's `float32x3_to_octn_precise`).
//!    Closest means the smallest `|d - n|²`, not the largest cosine `d · n` as in the paper: at
//!    16 bits neighbouring candidates differ in cosine by about 1e-9, below f32 resolution near
//!    1, and the cosine comparison measured a worst error of 0.0074° instead of 0.0025°.
//!
//! Decoding: `e = clamp(q · (1/M), -1, 1)`, `v = (e.x, e.y, 1 - |e.x| - |e.y|)`; for `v.z < 0`
//! unfold: `v.xy = (1 - |e.yx|) · signNotZero(e)`; normalise. `q = -2^(bits-1)`, which the
//! encoder never writes, decodes like `-M`.

use super::{non_finite, normalize_nonzero, sanitize_normal, sign_not_zero};
use glam::Vec3;

/// Largest 16-bit snorm code, as a float (`PACKING_OCTA16_MAX` in WGSL).
pub const OCTA16_MAX: f32 = 32767.0;
/// `1 / OCTA16_MAX` rounded to f32; decoding multiplies by it (`PACKING_OCTA16_INV_MAX`).
pub const OCTA16_INV_MAX: f32 = 1.0 / 32767.0;
/// Largest 8-bit snorm code, as a float (`PACKING_OCTA8_MAX` in WGSL).
pub const OCTA8_MAX: f32 = 127.0;
/// `1 / OCTA8_MAX` rounded to f32 (`PACKING_OCTA8_INV_MAX`).
pub const OCTA8_INV_MAX: f32 = 1.0 / 127.0;

/// Maps `n` (any vector, sanitised first) onto the octahedral square: both results in
/// `[-1, 1]`. Unquantised; WGSL `octa_encode`.
pub fn octa_encode(n: Vec3) -> [f32; 2] {
    square_of_unit(sanitize_normal(n))
}

/// Step 2 for a vector already sanitised.
#[inline]
fn square_of_unit(n: Vec3) -> [f32; 2] {
    let inv_l1 = 1.0 / (n.x.abs() + n.y.abs() + n.z.abs());
    let px = n.x * inv_l1;
    let py = n.y * inv_l1;
    let (ex, ey) = if n.z < 0.0 {
        ((1.0 - py.abs()) * sign_not_zero(px), (1.0 - px.abs()) * sign_not_zero(py))
    } else {
        (px, py)
    };
    [ex.clamp(-1.0, 1.0), ey.clamp(-1.0, 1.0)]
}

/// The unit vector of a point of the octahedral square. Any input: NaN or infinite
/// components give `+Z`, others are clamped to `[-1, 1]`. WGSL `octa_decode`.
pub fn octa_decode(e: [f32; 2]) -> Vec3 {
    if non_finite(e[0]) || non_finite(e[1]) {
        return Vec3::Z;
    }
    decode_square(e[0].clamp(-1.0, 1.0), e[1].clamp(-1.0, 1.0))
}

/// Decodes a point of `[-1, 1]²`. The unfolded vector lies on the octahedron, so its length
/// is at least `1/√3` and the normalisation is safe.
#[inline]
fn decode_square(ex: f32, ey: f32) -> Vec3 {
    let z = 1.0 - ex.abs() - ey.abs();
    if z < 0.0 {
        normalize_nonzero((1.0 - ey.abs()) * sign_not_zero(ex), (1.0 - ex.abs()) * sign_not_zero(ey), z)
    } else {
        normalize_nonzero(ex, ey, z)
    }
}

/// Decodes an integer-valued code `q` (as f32, any value in `[-M-1, M]`).
#[inline]
fn dequantise(qx: f32, qy: f32, inv_max: f32) -> Vec3 {
    decode_square((qx * inv_max).clamp(-1.0, 1.0), (qy * inv_max).clamp(-1.0, 1.0))
}

/// Steps 1–4 of the module docs: the code (as integer-valued f32) of the grid point nearest
/// to `n` in angle among the four around it.
fn quantise_precise(n: Vec3, max: f32, inv_max: f32) -> [f32; 2] {
    let n = sanitize_normal(n);
    let s = square_of_unit(n);
    let bx = (s[0] * max).floor();
    let by = (s[1] * max).floor();
    let mut best = [bx, by];
    let mut best_dist = distance_squared(dequantise(bx, by, inv_max), n);
    for k in 1..4u32 {
        let cx = (bx + (k >> 1) as f32).min(max);
        let cy = (by + (k & 1) as f32).min(max);
        let dist = distance_squared(dequantise(cx, cy, inv_max), n);
        if dist < best_dist {
            best = [cx, cy];
            best_dist = dist;
        }
    }
    best
}

/// `|a - b|²`, which for unit vectors is `2 - 2·cos(angle)` but, unlike the cosine, keeps its
/// precision for tiny angles: the differences of nearby components are exact.
#[inline]
fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    let (dx, dy, dz) = (a.x - b.x, a.y - b.y, a.z - b.z);
    dx * dx + dy * dy + dz * dz
}

/// 2 × 16-bit snorm octahedral code of `n` (precise encoding; any input).
pub fn octa16_encode(n: Vec3) -> [i16; 2] {
    quantise_precise(n, OCTA16_MAX, OCTA16_INV_MAX).map(|q| q as i16)
}

/// Unit vector of a 2 × 16-bit snorm octahedral code (any code; `-32768` acts as `-32767`).
pub fn octa16_decode(q: [i16; 2]) -> Vec3 {
    dequantise(f32::from(q[0]), f32::from(q[1]), OCTA16_INV_MAX)
}

/// 2 × 8-bit snorm octahedral code of `n` (precise encoding; any input).
pub fn octa8_encode(n: Vec3) -> [i8; 2] {
    quantise_precise(n, OCTA8_MAX, OCTA8_INV_MAX).map(|q| q as i8)
}

/// Unit vector of a 2 × 8-bit snorm octahedral code (any code; `-128` acts as `-127`).
pub fn octa8_decode(q: [i8; 2]) -> Vec3 {
    dequantise(f32::from(q[0]), f32::from(q[1]), OCTA8_INV_MAX)
}

/// [`octa16_encode`] in one word: x in bits 0–15, y in bits 16–31 (the layout of WGSL's
/// `pack2x16snorm`). The Compact G-buffer stores normals this way.
pub fn pack_octa16(n: Vec3) -> u32 {
    let [x, y] = octa16_encode(n);
    u32::from(x as u16) | u32::from(y as u16) << 16
}

/// Inverse of [`pack_octa16`]; every word decodes to a unit vector.
pub fn unpack_octa16(p: u32) -> Vec3 {
    octa16_decode([p as u16 as i16, (p >> 16) as u16 as i16])
}

/// [`octa8_encode`] in the low 16 bits of a word: x in bits 0–7, y in bits 8–15, the rest 0.
pub fn pack_octa8(n: Vec3) -> u32 {
    let [x, y] = octa8_encode(n);
    u32::from(x as u8) | u32::from(y as u8) << 8
}

/// Inverse of [`pack_octa8`]; bits 16–31 are ignored, every word decodes to a unit vector.
pub fn unpack_octa8(p: u32) -> Vec3 {
    octa8_decode([p as u8 as i8, (p >> 8) as u8 as i8])
}

//! Spherical normals: polar angle `θ ∈ [0, π]` from `+Z` and azimuth `φ ∈ [-π, π]` from `+X`,
//! stored as `u = θ/π` and `v = φ/2π + ½`, both in `[0, 1]`, then as 16-bit unorm codes.
//!
//! `θ` is computed as `atan2(sqrt(x² + y²), z)`, not `acos(z)`: the same angle, but `acos`
//! of an f32 `z` near ±1 cannot resolve angles below about `sqrt(2 · 2^-24)` rad (0.02°),
//! which would dominate the 16-bit quantisation error at the poles. At the poles themselves
//! (`x = y = 0`) `φ` is set to 0, since `atan2(0, 0)` is not defined in WGSL.
//!
//! Quantisation rounds half to even ([`f32::round_ties_even`], WGSL `round`). The seam
//! `φ = ±π` has two codes (`v = 0` and `v = 1`) for the same directions.

use super::{non_finite, normalize_nonzero, sanitize_normal};
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Largest 16-bit unorm code, as a float (`PACKING_SPHERICAL16_MAX` in WGSL).
pub const SPHERICAL16_MAX: f32 = 65535.0;
/// `1 / SPHERICAL16_MAX` rounded to f32; decoding multiplies by it.
pub const SPHERICAL16_INV_MAX: f32 = 1.0 / 65535.0;
/// `1 / 2π` as f32 (exactly half of `FRAC_1_PI`).
pub(crate) const FRAC_1_TAU: f32 = FRAC_1_PI * 0.5;

/// `(θ/π, φ/2π + ½)` of `n` (any vector, sanitised first), both in `[0, 1]`. Unquantised;
/// WGSL `spherical_encode`.
pub fn spherical_encode(n: Vec3) -> [f32; 2] {
    let n = sanitize_normal(n);
    let r = (n.x * n.x + n.y * n.y).sqrt();
    let theta = r.atan2(n.z);
    let phi = if r > 0.0 { n.y.atan2(n.x) } else { 0.0 };
    [(theta * FRAC_1_PI).clamp(0.0, 1.0), (phi * FRAC_1_TAU + 0.5).clamp(0.0, 1.0)]
}

/// The unit vector of `(θ/π, φ/2π + ½)`. Any input: NaN or infinite components give `+Z`,
/// others are clamped to `[0, 1]`. WGSL `spherical_decode`.
pub fn spherical_decode(e: [f32; 2]) -> Vec3 {
    if non_finite(e[0]) || non_finite(e[1]) {
        return Vec3::Z;
    }
    decode_unit(e[0].clamp(0.0, 1.0), e[1].clamp(0.0, 1.0))
}

/// Decodes `u, v` in `[0, 1]`. The result is normalised so that it is unit length even where
/// `sin`/`cos` are approximate (as WGSL allows); its length before that is within a few ulp
/// of 1 on the CPU.
#[inline]
fn decode_unit(u: f32, v: f32) -> Vec3 {
    let theta = u * PI;
    let phi = v * TAU - PI;
    let st = theta.sin();
    normalize_nonzero(st * phi.cos(), st * phi.sin(), theta.cos())
}

/// 2 × 16-bit unorm code `(θ, φ)` of `n` (any input).
pub fn spherical16_encode(n: Vec3) -> [u16; 2] {
    spherical_encode(n).map(|u| (u * SPHERICAL16_MAX).round_ties_even() as u16)
}

/// Unit vector of a 2 × 16-bit unorm `(θ, φ)` code (every code is valid).
pub fn spherical16_decode(q: [u16; 2]) -> Vec3 {
    decode_unit(
        (f32::from(q[0]) * SPHERICAL16_INV_MAX).min(1.0),
        (f32::from(q[1]) * SPHERICAL16_INV_MAX).min(1.0),
    )
}

/// [`spherical16_encode`] in one word: θ in bits 0–15, φ in bits 16–31.
pub fn pack_spherical16(n: Vec3) -> u32 {
    let [t, p] = spherical16_encode(n);
    u32::from(t) | u32::from(p) << 16
}

/// Inverse of [`pack_spherical16`]; every word decodes to a unit vector.
pub fn unpack_spherical16(p: u32) -> Vec3 {
    spherical16_decode([p as u16, (p >> 16) as u16])
}

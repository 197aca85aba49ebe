//! Normal codecs for the G-buffer: how a unit normal is squeezed into fewer bits, and what that
//! costs in accuracy. `shaders/common/packing.wgsl` mirrors every function here with the same
//! operations in the same order.
//!
//! The codecs ([`NormalCodec`]), from most to fewest bits per normal:
//!
//! 1. **`Xyz`** (`xyz.rs`, 2 × f32): the naive "store x, y; rebuild z" of view-space normals,
//!    `z = sqrt(max(0, 1 - x² - y²))`. It assumes every normal faces the camera (`z ≥ 0`); a
//!    back-facing normal comes back mirrored to `+|z|`, an error of up to 180°. That is the
//!    known flaw of this codec and [`measure_error_in`] measures it.
//! 2. **`Spherical`** (`spherical.rs`, 2 × 16-bit unorm): polar angle `θ ∈ [0, π]` and azimuth
//!    `φ ∈ [-π, π]`, each mapped to `[0, 1]` and rounded to 16 bits, so it spends exactly the
//!    bits of `Octa16` and the two compare directly.
//! 3. **`Octa16`**, **`Octa8`** (`octa.rs`, 2 × 16-bit or 2 × 8-bit snorm): the octahedral map
//!    of Cigolle et al. 2014 ("A Survey of Efficient Representations for Independent Unit
//!    Vectors", JCGT 3(2)): project onto the octahedron `|x|+|y|+|z| = 1`, unfold the lower half
//!    over the corners of the square, quantise. Encoding is the paper's *precise* variant: of
//!    the four grid points around the exact position it keeps the one whose decoded direction
//!    is closest, which makes the worst error as small as the grid allows. (Closest by
//!    `|d - n|²`, not by the paper's cosine: at 16 bits f32 cosines cannot tell the candidates
//!    apart, which triples the worst error; see `octa.rs`.)
//!
//! Every codec works in the same steps:
//!
//! 1. **Sanitise** ([`sanitize_normal`]): non-finite input, or input with no usable length,
//!    becomes `+Z`; anything else is scaled to unit length.
//! 2. **Map** to two numbers (`xyz`: x, y; `spherical`: θ/π, φ/2π + ½; `octa`: the square).
//! 3. **Quantise** where the codec has fixed-point storage (round half to even for unorm, the
//!    best of floor/ceil for octahedral snorm).
//! 4. **Decode** accepts *any* bit pattern (NaN and infinite floats, the unused snorm value
//!    `-2^(b-1)`, values outside the range) and always returns a finite unit vector.
//!
//! Measured errors (worst and mean angle over the whole sphere) are produced by
//! [`measure_error`] and listed in `docs/accuracy.md`.
//!
//! # Rules for awkward inputs
//!
//! - A component that is NaN or ±∞ makes the whole vector `+Z`.
//! - A vector whose largest `|component|` is below `f32::MIN_POSITIVE` (all zero, `±0.0`, or
//!   all subnormal) has no usable direction and becomes `+Z`. Subnormals are judged this way
//!   rather than rescaled because GPUs may flush them to zero, and CPU and GPU must agree.
//! - Any other vector is scaled by a power of two that brings its largest `|component|` into
//!   `[1, 2)` (exact, and `f32::MAX` components cannot overflow `x²`), then normalised.
//! - `±0.0` behave alike: signs are taken with "`v >= 0` is positive", so `-0.0` counts as
//!   positive, as in the paper's `signNotZero`. On the octahedral and spherical seams two codes
//!   name the same direction; which one a signed zero picks does not change the decoded normal.
//!
//! # CPU and GPU
//!
//! WGSL guarantees correct rounding only for `+ - *`, `floor`, `round`, `abs`, `min`, `max`
//! and conversions; `/`, `sqrt` are within a few ulp, and `atan2`, `sin`, `cos` are much looser
//! (see `packing.wgsl`). The Rust side spells out every step as scalar operations in the order
//! the WGSL uses, multiplies by stored reciprocals instead of dividing by constants, and uses
//! [`f32::round_ties_even`] because WGSL `round` rounds half to even. Quantised codes therefore
//! agree bit for bit except where the exact value lies within a few ulp of a rounding
//! boundary or two precise-encoding candidates tie to within a few ulp. (On lavapipe the
//! octahedral and xyz results were bit-identical over 556 000 inputs; spherical codes differed
//! by one step in 4.6 % of them, from its `atan2`. See `docs/accuracy.md`.)

mod measure;
mod octa;
mod spherical;
mod xyz;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_hard;

pub use measure::{
    CodecError, SphereRegion, angle_deg, fibonacci_sphere, hard_normals, measure_error, measure_error_in,
};
pub use octa::{
    OCTA8_INV_MAX, OCTA8_MAX, OCTA16_INV_MAX, OCTA16_MAX, octa_decode, octa_encode, octa8_decode,
    octa8_encode, octa16_decode, octa16_encode, pack_octa8, pack_octa16, unpack_octa8, unpack_octa16,
};
pub use spherical::{
    SPHERICAL16_INV_MAX, SPHERICAL16_MAX, pack_spherical16, spherical_decode, spherical_encode,
    spherical16_decode, spherical16_encode, unpack_spherical16,
};
pub use xyz::{decode_xy, encode_xy};

use glam::Vec3;

/// A way of storing a unit normal in a G-buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NormalCodec {
    /// View-space x and y as two f32; z rebuilt as `+sqrt(1 - x² - y²)` (loses the sign of z).
    Xyz,
    /// Polar and azimuth angles, each as a 16-bit unorm.
    Spherical,
    /// Octahedral map, 2 × 16-bit snorm (precise encoding).
    Octa16,
    /// Octahedral map, 2 × 8-bit snorm (precise encoding).
    Octa8,
}

impl NormalCodec {
    /// Every codec, in `gpu_id` order.
    pub const ALL: [NormalCodec; 4] =
        [NormalCodec::Xyz, NormalCodec::Spherical, NormalCodec::Octa16, NormalCodec::Octa8];

    /// Lower-case name used in configs, reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            NormalCodec::Xyz => "xyz",
            NormalCodec::Spherical => "spherical",
            NormalCodec::Octa16 => "octa16",
            NormalCodec::Octa8 => "octa8",
        }
    }

    /// Parses a name written by [`NormalCodec::name`] (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The value WGSL receives for this codec: `Xyz` 0, `Spherical` 1, `Octa16` 2, `Octa8` 3.
    pub fn gpu_id(self) -> u32 {
        match self {
            NormalCodec::Xyz => 0,
            NormalCodec::Spherical => 1,
            NormalCodec::Octa16 => 2,
            NormalCodec::Octa8 => 3,
        }
    }

    /// Storage one normal needs, in bits.
    pub fn bits_per_normal(self) -> u32 {
        match self {
            NormalCodec::Xyz => 64,
            NormalCodec::Spherical | NormalCodec::Octa16 => 32,
            NormalCodec::Octa8 => 16,
        }
    }
}

/// Encodes `n` (any vector; see the module's rules) as two raw words:
///
/// - `Xyz`: the f32 bit patterns of x and y;
/// - `Spherical`: the two 16-bit unorm codes (θ, φ) in the low 16 bits;
/// - `Octa16`, `Octa8`: the two's-complement snorm codes (x, y) in the low 16 or 8 bits.
pub fn encode(codec: NormalCodec, n: Vec3) -> [u32; 2] {
    match codec {
        NormalCodec::Xyz => encode_xy(n).map(f32::to_bits),
        NormalCodec::Spherical => spherical16_encode(n).map(u32::from),
        NormalCodec::Octa16 => octa16_encode(n).map(|q| u32::from(q as u16)),
        NormalCodec::Octa8 => octa8_encode(n).map(|q| u32::from(q as u8)),
    }
}

/// Decodes two raw words written by [`encode`]. Accepts any bits (words are truncated to the
/// codec's width; NaN or infinite floats decode to `+Z`) and always returns a finite unit
/// vector.
pub fn decode(codec: NormalCodec, e: [u32; 2]) -> Vec3 {
    match codec {
        NormalCodec::Xyz => decode_xy(e.map(f32::from_bits)),
        NormalCodec::Spherical => spherical16_decode(e.map(|w| w as u16)),
        NormalCodec::Octa16 => octa16_decode(e.map(|w| w as u16 as i16)),
        NormalCodec::Octa8 => octa8_decode(e.map(|w| w as u8 as i8)),
    }
}

/// True when `v` is NaN or ±∞: the exponent bits are all ones. (A bit test, so the WGSL twin
/// can use the same test: WGSL may assume floats are finite and fold away `v != v`.)
#[inline]
pub(crate) fn non_finite(v: f32) -> bool {
    v.to_bits() & 0x7f80_0000 == 0x7f80_0000
}

/// `+1` for `v >= 0` (including `-0.0`), else `-1`: the paper's `signNotZero`. Unlike
/// [`f32::signum`] it treats both zeros alike, as WGSL's `select` below does.
#[inline]
pub(crate) fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 { 1.0 } else { -1.0 }
}

/// `v / |v|` for a vector known to be finite with length well away from zero, spelled out in
/// the order the WGSL uses.
#[inline]
pub(crate) fn normalize_nonzero(x: f32, y: f32, z: f32) -> Vec3 {
    let inv = 1.0 / (x * x + y * y + z * z).sqrt();
    Vec3::new(x * inv, y * inv, z * inv)
}

/// The unit vector every codec encodes for `n`: `+Z` for non-finite input or input whose
/// largest `|component|` is below `f32::MIN_POSITIVE`; otherwise `n` scaled by a power of
/// two into `[1, 2)` and then normalised. Mirrored by `packing_sanitize` in WGSL.
pub fn sanitize_normal(n: Vec3) -> Vec3 {
    if non_finite(n.x) || non_finite(n.y) || non_finite(n.z) {
        return Vec3::Z;
    }
    let m = n.x.abs().max(n.y.abs()).max(n.z.abs());
    if m < f32::MIN_POSITIVE {
        return Vec3::Z;
    }
    // Scale by the power of two that brings `m` into [1, 2): exact, and never a division by
    // a huge or tiny `m`. The factor 2^k, k in [-127, 126], is applied as two normal halves.
    let k = 127 - ((m.to_bits() >> 23) & 0xff) as i32;
    let k1 = k / 2;
    let (a, b) = (pow2(k1), pow2(k - k1));
    normalize_nonzero(n.x * a * b, n.y * a * b, n.z * a * b)
}

/// `2^k` for `k` in `[-126, 127]`, built from its bits.
#[inline]
fn pow2(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

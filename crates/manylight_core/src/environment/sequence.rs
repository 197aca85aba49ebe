//! Deterministic sample points for the environment integrals: the Hammersley set, a per-pixel
//! scramble of it, cosine-weighted directions and the tangent frame they are placed in.
//!
//! Every function here is a plain formula the prefilter shaders can repeat.

use glam::{Vec2, Vec3};
use std::f32::consts::TAU;

/// `2^-24`: radical inverses keep 24 bits, so they stay below 1 after rounding to `f32`.
const INV_2_POW_24: f32 = 1.0 / 16_777_216.0;

/// The base-2 radical inverse (van der Corput) of `bits` in `[0, 1)`: the bits mirrored about
/// the binary point, truncated to the 24 an `f32` holds so that it never rounds up to 1.
pub fn radical_inverse(bits: u32) -> f32 {
    (bits.reverse_bits() >> 8) as f32 * INV_2_POW_24
}

/// Point `i` of the `n`-point Hammersley set in `[0, 1)^2`: `(i / n, radical_inverse(i))`.
pub fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(i as f32 / n.max(1) as f32, radical_inverse(i))
}

/// A per-pixel randomisation of the Hammersley set that keeps its stratification: a
/// Cranley-Patterson shift of the first coordinate and a random digit scramble (an XOR of the
/// mirrored bits) of the second. Different seeds give independent, equally good point sets, so
/// neighbouring pixels of a reference image do not share one error pattern.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scramble {
    /// Added to the first coordinate, modulo 1.
    pub shift: f32,
    /// XORed into the mirrored bits of the second coordinate.
    pub xor: u32,
}

impl Scramble {
    /// The scramble of `seed` (a pixel index, for example), hashed with SplitMix64.
    pub fn from_seed(seed: u64) -> Scramble {
        let bits = splitmix64(seed);
        Scramble { shift: radical_inverse((bits >> 32) as u32).fract(), xor: bits as u32 }
    }

    /// Point `i` of the `n`-point Hammersley set under this scramble, in `[0, 1)^2`.
    pub fn hammersley(&self, i: u32, n: u32) -> Vec2 {
        let x = (i as f32 / n.max(1) as f32 + self.shift).fract();
        let y = ((i.reverse_bits() ^ self.xor) >> 8) as f32 * INV_2_POW_24;
        Vec2::new(x, y)
    }
}

/// SplitMix64's output function: a well-mixed 64-bit hash of `x`.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A cosine-distributed direction about +Z from `xi` in `[0, 1)^2` (Malley's method: a uniform
/// point on the unit disc lifted onto the hemisphere). Its density is `z / pi`.
pub fn cosine_hemisphere(xi: Vec2) -> Vec3 {
    let r = xi.x.sqrt();
    let phi = TAU * xi.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - xi.x).max(0.0).sqrt())
}

/// An orthonormal frame whose +Z is a given unit normal: directions sampled about +Z are
/// placed around the normal with [`TangentFrame::to_world`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentFrame {
    /// The first tangent (local +X).
    pub tangent: Vec3,
    /// The second tangent (local +Y).
    pub bitangent: Vec3,
    /// The normal (local +Z).
    pub normal: Vec3,
}

impl TangentFrame {
    /// The frame about unit `normal` (Duff et al.'s branchless construction, via glam).
    pub fn new(normal: Vec3) -> TangentFrame {
        let (tangent, bitangent) = normal.any_orthonormal_pair();
        TangentFrame { tangent, bitangent, normal }
    }

    /// World direction of `local` (x, y along the tangents, z along the normal).
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.tangent * local.x + self.bitangent * local.y + self.normal * local.z
    }

    /// Local coordinates of world direction `world` (the inverse of [`TangentFrame::to_world`]).
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        Vec3::new(world.dot(self.tangent), world.dot(self.bitangent), world.dot(self.normal))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn radical_inverse_mirrors_the_bits() {
        assert_eq!(radical_inverse(0), 0.0);
        assert_eq!(radical_inverse(1), 0.5);
        assert_eq!(radical_inverse(2), 0.25);
        assert_eq!(radical_inverse(3), 0.75);
        assert!(radical_inverse(u32::MAX) < 1.0);
    }

    #[test]
    fn the_frame_is_orthonormal_and_round_trips() {
        for n in [Vec3::Z, Vec3::NEG_Z, Vec3::Y, Vec3::new(0.3, -0.8, 0.52).normalize()] {
            let f = TangentFrame::new(n);
            assert!((f.to_world(Vec3::Z) - n).length() < 1e-6);
            assert!(f.tangent.dot(f.bitangent).abs() < 1e-6 && f.tangent.dot(n).abs() < 1e-6);
            let d = Vec3::new(0.2, 0.4, 0.89).normalize();
            assert!((f.to_local(f.to_world(d)) - d).length() < 1e-6);
        }
    }

    proptest! {
        /// A scrambled set stays in the unit square and keeps one point in each of the `n`
        /// columns and each of the `n` rows (its stratification), for any seed.
        #[test]
        fn scrambled_hammersley_stays_stratified(seed in any::<u64>(), log_n in 0u32..9) {
            let n = 1u32 << log_n;
            let s = Scramble::from_seed(seed);
            let mut columns = vec![0u32; n as usize];
            let mut rows = vec![0u32; n as usize];
            for i in 0..n {
                let p = s.hammersley(i, n);
                prop_assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y), "{p}");
                columns[((p.x * n as f32) as usize).min(n as usize - 1)] += 1;
                rows[(p.y * n as f32) as usize] += 1;
            }
            prop_assert!(rows.iter().all(|&c| c == 1), "rows {rows:?}");
            // The shift can move a point across a column edge by rounding; allow that.
            prop_assert!(columns.iter().all(|&c| c <= 2), "columns {columns:?}");
        }

        /// Cosine samples are unit and above the horizon.
        #[test]
        fn cosine_samples_are_unit_and_above(x in 0.0f32..1.0, y in 0.0f32..1.0) {
            let d = cosine_hemisphere(Vec2::new(x, y));
            prop_assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0, "{d}");
        }
    }
}

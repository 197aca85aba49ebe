//! The hard cases, one by one: degenerate input, poles and axes, signed zeros, subnormals,
//! huge components, the octahedral seams and fold, the spherical seam, every 8-bit code.

use super::tests::{assert_unit, bound_deg, bounded_region, round_trip};
use super::*;
use glam::Vec3;

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;

#[test]
fn degenerate_inputs_encode_as_plus_z() {
    let bad = [
        Vec3::ZERO,
        Vec3::splat(-0.0),
        Vec3::new(NAN, 0.0, 1.0),
        Vec3::new(0.0, NAN, 1.0),
        Vec3::new(1.0, 0.0, NAN),
        Vec3::new(INF, 0.0, 0.0),
        Vec3::new(-INF, 1.0, 1.0),
        Vec3::new(1.0, 1.0, -INF),
        Vec3::splat(NAN),
        Vec3::new(f32::from_bits(0x7fc0_0001), 0.0, 0.0),
        Vec3::new(f32::from_bits(0xffff_ffff), 0.0, 0.0),
        // Largest |component| subnormal: no direction we can trust on a GPU.
        Vec3::new(1e-40, 0.0, 0.0),
        Vec3::new(-1e-45, 1e-45, -1e-39),
        Vec3::new(0.0, 0.0, -1e-41),
    ];
    for n in bad {
        assert_eq!(sanitize_normal(n), Vec3::Z, "{n:?}");
        for codec in NormalCodec::ALL {
            assert_eq!(round_trip(codec, n), Vec3::Z, "{} {n:?}", codec.name());
        }
        assert_eq!(unpack_octa16(pack_octa16(n)), Vec3::Z);
        assert_eq!(unpack_octa8(pack_octa8(n)), Vec3::Z);
        assert_eq!(unpack_spherical16(pack_spherical16(n)), Vec3::Z);
        assert_eq!(octa_decode(octa_encode(n)), Vec3::Z);
        assert_eq!(decode_xy(encode_xy(n)), Vec3::Z);
    }
    // The smallest normal f32 is enough to have a direction.
    assert_eq!(sanitize_normal(Vec3::new(0.0, -f32::MIN_POSITIVE, 0.0)), -Vec3::Y);
}

#[test]
fn poles_and_axes_are_exact_in_the_octahedral_codecs() {
    for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
        for codec in [NormalCodec::Octa16, NormalCodec::Octa8] {
            assert_eq!(round_trip(codec, axis), axis, "{} {axis:?}", codec.name());
            assert_eq!(round_trip(codec, axis * 1e30), axis, "{} {axis:?}", codec.name());
        }
        assert_eq!(octa_decode(octa_encode(axis)), axis);
        assert!(
            angle_deg(axis, round_trip(NormalCodec::Spherical, axis)) <= bound_deg(NormalCodec::Spherical)
        );
    }
    // The codes themselves: +Z is the centre, -Z a corner, the equator the inner diamond.
    assert_eq!(octa16_encode(Vec3::Z), [0, 0]);
    assert_eq!(octa16_encode(-Vec3::Z), [32767, 32767]);
    assert_eq!(octa16_encode(Vec3::X), [32767, 0]);
    assert_eq!(octa8_encode(-Vec3::Y), [0, -127]);
    assert_eq!(spherical16_encode(Vec3::Z), [0, 32768]);
    assert_eq!(spherical16_encode(-Vec3::Z), [65535, 32768]);
    assert_eq!(round_trip(NormalCodec::Spherical, Vec3::Z), Vec3::Z);
    assert_eq!(round_trip(NormalCodec::Xyz, Vec3::Z), Vec3::Z);
    for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y] {
        assert_eq!(round_trip(NormalCodec::Xyz, axis), axis);
    }
}

#[test]
fn signed_zeros_give_the_same_direction() {
    for z in [1.0f32, -1.0, 0.6, -0.6] {
        let r = (1.0 - z * z).sqrt();
        let variants = [
            Vec3::new(0.0, r, z),
            Vec3::new(-0.0, r, z),
            Vec3::new(r, 0.0, z),
            Vec3::new(r, -0.0, z),
            Vec3::new(-r, 0.0, z),
            Vec3::new(-r, -0.0, z),
        ];
        for n in variants {
            for codec in NormalCodec::ALL {
                if bounded_region(codec).contains(n) {
                    let e = angle_deg(n, round_trip(codec, n));
                    assert!(e <= bound_deg(codec), "{} {n:?}: {e}°", codec.name());
                }
            }
        }
    }
    // -0.0 counts as positive, like +0.0.
    assert_eq!(octa16_encode(Vec3::new(-0.0, -0.0, -1.0)), octa16_encode(-Vec3::Z));
    assert_eq!(spherical16_encode(Vec3::new(-0.0, -0.0, 1.0)), spherical16_encode(Vec3::Z));
    assert_eq!(octa_decode([-0.0, -0.0]), Vec3::Z);
}

#[test]
fn huge_and_tiny_inputs_keep_their_direction() {
    let cases = [
        (Vec3::splat(f32::MAX), Vec3::ONE),
        (Vec3::new(f32::MAX, -f32::MAX, 0.0), Vec3::new(1.0, -1.0, 0.0)),
        (Vec3::new(f32::MIN, 0.0, f32::MAX), Vec3::new(-1.0, 0.0, 1.0)),
        (Vec3::new(3e38, 1e38, -2e38), Vec3::new(3.0, 1.0, -2.0)),
        (Vec3::new(f32::MIN_POSITIVE, f32::MIN_POSITIVE, 0.0), Vec3::new(1.0, 1.0, 0.0)),
        (Vec3::new(2e-38, -4e-38, 4e-38), Vec3::new(1.0, -2.0, 2.0)),
        (Vec3::new(1.2e-38, 0.0, 1.2e-38), Vec3::new(1.0, 0.0, 1.0)),
    ];
    for (n, direction) in cases {
        let s = sanitize_normal(n);
        assert_unit(s, "sanitize");
        assert!(angle_deg(s, direction) < 1e-5, "{n:?} -> {s:?}");
        for codec in NormalCodec::ALL {
            if bounded_region(codec).contains(direction) {
                let e = angle_deg(direction, round_trip(codec, n));
                assert!(e <= bound_deg(codec), "{} {n:?}: {e}°", codec.name());
            }
        }
    }
    // Components far below the largest one (subnormal after scaling) are harmless.
    let n = Vec3::new(1.0, 1e-40, -1e-45);
    assert_eq!(round_trip(NormalCodec::Octa16, n), Vec3::X);
}

#[test]
fn octahedral_seams_and_fold() {
    // The square's edges (lower hemisphere, x = 0 or y = 0) are covered twice: (1, t) and
    // (1, -t) name the same direction.
    for t in [0.0f32, 0.25, 0.5, 0.999, 1.0] {
        for (a, b) in [([1.0, t], [1.0, -t]), ([t, 1.0], [-t, 1.0]), ([-1.0, t], [-1.0, -t])] {
            assert!(angle_deg(octa_decode(a), octa_decode(b)) < 1e-5, "{a:?} {b:?}");
        }
    }
    // The fold line |x| + |y| = 1 is the equator; either side of it decodes continuously.
    for i in 0..=64 {
        let x = i as f32 / 64.0;
        let on = octa_decode([x, 1.0 - x]);
        assert!(on.z.abs() < 1e-6, "{on:?}");
        for eps in [1e-3f32, 1e-6] {
            let inside = octa_decode([x * (1.0 - eps), (1.0 - x) * (1.0 - eps)]);
            let outside = octa_decode([(x + eps).min(1.0), (1.0 - x + eps).min(1.0)]);
            assert!(inside.z > 0.0 && outside.z < 0.0 || x == 0.0 || x == 1.0);
            assert!(angle_deg(on, inside) < 0.2 && angle_deg(on, outside) < 0.2);
        }
    }
    // Round trips right at and next to the seams, in every codec.
    for n in hard_normals() {
        for codec in NormalCodec::ALL {
            if bounded_region(codec).contains(n) {
                let e = angle_deg(n, round_trip(codec, n));
                assert!(e <= bound_deg(codec), "{} {n:?}: {e}°", codec.name());
            }
        }
    }
}

#[test]
fn spherical_seam_and_poles() {
    // φ = ±π has two codes (v = 0 and v = 1); both decode to the same direction.
    for t in [0u16, 1, 100, 32768, 65534, 65535] {
        let a = spherical16_decode([t, 0]);
        let b = spherical16_decode([t, 65535]);
        assert!(angle_deg(a, b) < 1e-4, "{t}: {a:?} {b:?}");
    }
    // At the poles φ is irrelevant.
    for p in [0u16, 1, 12345, 65535] {
        assert_eq!(spherical16_decode([0, p]), Vec3::Z);
        assert!(angle_deg(spherical16_decode([65535, p]), -Vec3::Z) < 1e-5);
    }
    // Next to the seam, on both sides.
    for y in [1e-7f32, -1e-7, 0.0, -0.0] {
        let n = Vec3::new(-0.8, y, 0.6);
        assert!(angle_deg(n, round_trip(NormalCodec::Spherical, n)) <= bound_deg(NormalCodec::Spherical));
    }
}

#[test]
fn every_octa8_code_decodes_and_re_encodes() {
    for p in 0..=u16::MAX as u32 {
        let n = unpack_octa8(p);
        assert_unit(n, "octa8");
        // Bits 16-31 are ignored.
        assert_eq!(unpack_octa8(p | 0xabcd_0000), n);
        let again = unpack_octa8(pack_octa8(n));
        assert!(angle_deg(n, again) < 1e-4, "{p:#06x}: {n:?} -> {again:?}");
    }
    // The unused code -128 acts as -127.
    assert_eq!(octa8_decode([-128, 5]), octa8_decode([-127, 5]));
    assert_eq!(octa16_decode([3, i16::MIN]), octa16_decode([3, -i16::MAX]));
}

#[test]
fn special_float_codes_decode_to_plus_z_or_clamp() {
    for bad in [NAN, INF, -INF, f32::from_bits(0x7f80_0001)] {
        for e in [[bad, 0.0], [0.0, bad], [bad, bad]] {
            assert_eq!(octa_decode(e), Vec3::Z);
            assert_eq!(spherical_decode(e), Vec3::Z);
            assert_eq!(decode_xy(e), Vec3::Z);
            assert_eq!(decode(NormalCodec::Xyz, e.map(f32::to_bits)), Vec3::Z);
        }
    }
    // Out of range values clamp.
    assert_eq!(octa_decode([5.0, 0.0]), Vec3::X);
    assert_eq!(octa_decode([-1e30, -1e30]), -Vec3::Z);
    assert_eq!(spherical_decode([-3.0, 0.5]), Vec3::Z);
    // x² + y² > 1 lands on the z = 0 plane; huge values do not overflow.
    assert!(angle_deg(decode_xy([3.0, 4.0]), Vec3::new(0.6, 0.8, 0.0)) < 1e-5);
    assert!(angle_deg(decode_xy([f32::MAX, f32::MAX]), Vec3::new(1.0, 1.0, 0.0)) < 1e-5);
    assert_eq!(decode_xy([1e-40, -1e-45]), Vec3::new(1e-40, -1e-45, 1.0));
}

//! Round-trip properties and measured error bounds of the normal codecs, and the check that
//! `shaders/common/packing.wgsl` uses the Rust constants.

use super::*;
use glam::Vec3;
use proptest::prelude::*;

/// Asserted worst-case errors in degrees: the measured value (4M Fibonacci points + hard
/// points + local search, `manylight codec-accuracy`) plus a little slack.
///
/// - `Octa16`: measured 0.00247°; the analytic worst, `√2 / 32767` rad = 0.002473° at the
///   octahedron's face centres, is below the bound, well within 0.01°.
/// - `Octa8`: measured 0.63799°, analytic `√2 / 127` rad = 0.63800°.
/// - `Spherical` (16 bits): measured 0.00309°; half a step in θ and φ at the equator is
///   0.00307°, the rest is f32 trigonometry.
/// - `Xyz` on `z ≥ 0`: measured 0.0328°, from cancellation in `1 - x² - y²` near `z = 0`.
pub(super) fn bound_deg(codec: NormalCodec) -> f64 {
    match codec {
        NormalCodec::Xyz => 0.04,
        NormalCodec::Spherical => 0.0032,
        NormalCodec::Octa16 => 0.0025,
        NormalCodec::Octa8 => 0.64,
    }
}

/// The region where `codec`'s bound holds: front-facing for `Xyz`, the whole sphere else.
pub(super) fn bounded_region(codec: NormalCodec) -> SphereRegion {
    if codec == NormalCodec::Xyz { SphereRegion::FrontFacing } else { SphereRegion::Whole }
}

/// Round trip through the uniform API.
pub(super) fn round_trip(codec: NormalCodec, n: Vec3) -> Vec3 {
    decode(codec, encode(codec, n))
}

/// Unit length to within a few f32 ulp, and finite.
pub(super) fn assert_unit(v: Vec3, what: &str) {
    assert!(v.is_finite(), "{what}: {v:?} is not finite");
    assert!((v.length() - 1.0).abs() <= 1e-6, "{what}: |{v:?}| = {}", v.length());
}

fn cases(n: u32) -> ProptestConfig {
    ProptestConfig { cases: n, failure_persistence: None, ..ProptestConfig::default() }
}

/// Any f32, weighted towards the awkward ones.
fn any_component() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => -2.0f32..2.0,
        2 => proptest::num::f32::ANY,
        1 => prop::sample::select(vec![
            0.0, -0.0, 1.0, -1.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-40, -1e-45, f32::MAX,
            f32::MIN, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::EPSILON,
        ]),
    ]
}

fn any_vec3() -> impl Strategy<Value = Vec3> {
    (any_component(), any_component(), any_component()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A direction, uniform on the sphere (uniform z and azimuth, after Archimedes).
fn unit_vec3() -> impl Strategy<Value = Vec3> {
    (-1.0f64..=1.0, -std::f64::consts::PI..std::f64::consts::PI).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        glam::DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3()
    })
}

#[test]
fn names_ids_and_bits() {
    for (i, codec) in NormalCodec::ALL.into_iter().enumerate() {
        assert_eq!(codec.gpu_id(), i as u32);
        assert_eq!(NormalCodec::from_name(codec.name()), Some(codec));
        assert_eq!(NormalCodec::from_name(&codec.name().to_uppercase()), Some(codec));
    }
    assert_eq!(NormalCodec::ALL.map(NormalCodec::name), ["xyz", "spherical", "octa16", "octa8"]);
    assert_eq!(NormalCodec::ALL.map(NormalCodec::bits_per_normal), [64, 32, 32, 16]);
    assert_eq!(NormalCodec::from_name("octa"), None);
}

#[test]
fn measured_errors_within_bounds() {
    // A smaller sweep than the table's; the hard points and the local search still run.
    for codec in NormalCodec::ALL {
        let e = measure_error_in(codec, 100_000, bounded_region(codec));
        assert!(e.worst_deg <= bound_deg(codec), "{}: {e:?}", codec.name());
        assert!(e.mean_deg > 0.0 && e.mean_deg < e.worst_deg, "{}: {e:?}", codec.name());
    }
    assert!(measure_error(NormalCodec::Octa16, 100_000).worst_deg <= 0.01);
}

#[test]
fn xyz_loses_the_sign_of_back_facing_normals() {
    let n = Vec3::new(0.6, 0.0, -0.8);
    assert!(round_trip(NormalCodec::Xyz, n).abs_diff_eq(Vec3::new(0.6, 0.0, 0.8), 1e-6));
    assert_eq!(round_trip(NormalCodec::Xyz, -Vec3::Z), Vec3::Z);
    let back = measure_error_in(NormalCodec::Xyz, 100_000, SphereRegion::BackFacing);
    assert_eq!(back.worst_deg, 180.0);
    // Mean of 2·asin(|z|) for z uniform in [0, 1]: 2·(π/2 - 1) rad = 65.4°.
    assert!((back.mean_deg - (std::f64::consts::PI - 2.0).to_degrees()).abs() < 0.05, "{back:?}");
}

#[test]
fn uniform_api_matches_typed_and_packed_forms() {
    for i in 0..2000 {
        let n = fibonacci_sphere(i, 2000) * (1.0 + i as f32);
        let [x, y] = octa16_encode(n);
        assert_eq!(encode(NormalCodec::Octa16, n), [u32::from(x as u16), u32::from(y as u16)]);
        let e = encode(NormalCodec::Octa16, n);
        assert_eq!(pack_octa16(n), e[0] | e[1] << 16);
        assert_eq!(unpack_octa16(pack_octa16(n)), decode(NormalCodec::Octa16, e));

        let e = encode(NormalCodec::Octa8, n);
        assert_eq!(octa8_encode(n).map(|q| u32::from(q as u8)), e);
        assert_eq!(pack_octa8(n), e[0] | e[1] << 8);
        assert_eq!(unpack_octa8(pack_octa8(n)), decode(NormalCodec::Octa8, e));

        let e = encode(NormalCodec::Spherical, n);
        assert_eq!(spherical16_encode(n).map(u32::from), e);
        assert_eq!(pack_spherical16(n), e[0] | e[1] << 16);
        assert_eq!(unpack_spherical16(pack_spherical16(n)), decode(NormalCodec::Spherical, e));

        assert_eq!(encode(NormalCodec::Xyz, n), encode_xy(n).map(f32::to_bits));
        assert_eq!(decode(NormalCodec::Xyz, encode(NormalCodec::Xyz, n)), decode_xy(encode_xy(n)));
    }
}

#[test]
fn unquantised_forms_are_nearly_exact() {
    for i in 0..20_000 {
        let n = fibonacci_sphere(i, 20_000);
        assert!(angle_deg(n, octa_decode(octa_encode(n))) < 1e-4, "{n:?}");
        assert!(angle_deg(n, spherical_decode(spherical_encode(n))) < 1e-4, "{n:?}");
        if n.z >= 0.0 {
            assert!(angle_deg(n, decode_xy(encode_xy(n))) < bound_deg(NormalCodec::Xyz), "{n:?}");
        }
    }
}

#[test]
fn wgsl_twin_uses_the_rust_constants_and_names() {
    let wgsl = include_str!("../../../../shaders/common/packing.wgsl");
    use std::f32::consts::{FRAC_1_PI, PI, TAU};
    let constants = [
        ("PACKING_MIN_POSITIVE", f32::MIN_POSITIVE),
        ("PACKING_OCTA16_MAX", OCTA16_MAX),
        ("PACKING_OCTA16_INV_MAX", OCTA16_INV_MAX),
        ("PACKING_OCTA8_MAX", OCTA8_MAX),
        ("PACKING_OCTA8_INV_MAX", OCTA8_INV_MAX),
        ("PACKING_SPHERICAL16_MAX", SPHERICAL16_MAX),
        ("PACKING_SPHERICAL16_INV_MAX", SPHERICAL16_INV_MAX),
        ("PACKING_PI", PI),
        ("PACKING_TAU", TAU),
        ("PACKING_FRAC_1_PI", FRAC_1_PI),
        ("PACKING_FRAC_1_TAU", spherical::FRAC_1_TAU),
    ];
    for (name, value) in constants {
        let line = format!("const {name}: f32 = {value:?}f;");
        assert!(wgsl.contains(&line), "packing.wgsl lacks `{line}`");
    }
    for f in [
        "octa_encode(n: vec3<f32>) -> vec2<f32>",
        "octa_decode(e: vec2<f32>) -> vec3<f32>",
        "pack_octa16(n: vec3<f32>) -> u32",
        "unpack_octa16(p: u32) -> vec3<f32>",
        "pack_octa8(n: vec3<f32>) -> u32",
        "unpack_octa8(p: u32) -> vec3<f32>",
        "spherical_encode(n_in: vec3<f32>) -> vec2<f32>",
        "spherical_decode(e: vec2<f32>) -> vec3<f32>",
        "pack_spherical16(n: vec3<f32>) -> u32",
        "unpack_spherical16(p: u32) -> vec3<f32>",
        "xyz_encode(n: vec3<f32>) -> vec2<f32>",
        "xyz_decode(e: vec2<f32>) -> vec3<f32>",
    ] {
        assert!(wgsl.contains(&format!("fn {f}")), "packing.wgsl lacks `fn {f}`");
    }
}

proptest! {
    #![proptest_config(cases(5000))]

    /// Every input, however bad, round-trips to a finite unit vector in every codec and form.
    #[test]
    fn any_input_round_trips_to_a_unit_vector(n in any_vec3()) {
        for codec in NormalCodec::ALL {
            assert_unit(round_trip(codec, n), codec.name());
        }
        assert_unit(sanitize_normal(n), "sanitize");
        assert_unit(unpack_octa16(pack_octa16(n)), "octa16 packed");
        assert_unit(unpack_octa8(pack_octa8(n)), "octa8 packed");
        assert_unit(unpack_spherical16(pack_spherical16(n)), "spherical16 packed");
        let o = octa_encode(n);
        prop_assert!(o.iter().all(|c| (-1.0..=1.0).contains(c)), "{o:?}");
        assert_unit(octa_decode(o), "octa float");
        let s = spherical_encode(n);
        prop_assert!(s.iter().all(|c| (0.0..=1.0).contains(c)), "{s:?}");
        assert_unit(spherical_decode(s), "spherical float");
        let xy = encode_xy(n);
        prop_assert!(xy.iter().all(|c| (-1.0..=1.0).contains(c)), "{xy:?}");
        assert_unit(decode_xy(xy), "xy float");
    }

    /// Every finite input with a usable length keeps its direction within the codec's bound
    /// (`Xyz`: when it faces the camera), whatever its length.
    #[test]
    fn finite_inputs_within_bounds(d in unit_vec3(), log_scale in -37.0f32..38.0) {
        let n = d * 10f32.powf(log_scale);
        prop_assume!(n.is_finite() && n.abs().max_element() >= f32::MIN_POSITIVE);
        for codec in NormalCodec::ALL {
            if bounded_region(codec).contains(n) {
                let e = angle_deg(n, round_trip(codec, n));
                prop_assert!(e <= bound_deg(codec), "{}: {n:?} off by {e}°", codec.name());
            }
        }
    }

    /// Unit directions: the bounds, and `Xyz` mirrors back-facing normals exactly.
    #[test]
    fn unit_inputs_within_bounds(n in unit_vec3()) {
        for codec in NormalCodec::ALL {
            let out = round_trip(codec, n);
            if bounded_region(codec).contains(n) {
                let e = angle_deg(n, out);
                prop_assert!(e <= bound_deg(codec), "{}: {n:?} off by {e}°", codec.name());
            }
        }
        if n.z < 0.0 {
            let mirrored = Vec3::new(n.x, n.y, -n.z);
            prop_assert!(angle_deg(mirrored, round_trip(NormalCodec::Xyz, n)) <= bound_deg(NormalCodec::Xyz));
        }
    }

    /// The precise octahedral encoding is never worse than rounding each coordinate.
    #[test]
    fn precise_octa_beats_rounding(n in unit_vec3()) {
        for (max, codec) in [(OCTA16_MAX, NormalCodec::Octa16), (OCTA8_MAX, NormalCodec::Octa8)] {
            let rounded = octa_encode(n).map(|c| (c * max).round());
            let rounded = octa_decode(rounded.map(|q| q * (1.0 / max)));
            let precise = round_trip(codec, n);
            prop_assert!(angle_deg(n, precise) <= angle_deg(n, rounded) + 1e-5, "{n:?}");
        }
    }

    /// Any raw words decode to a finite unit vector in every codec (NaN and infinite f32 bit
    /// patterns included: 1 in 256 random words is one).
    #[test]
    fn any_bits_decode_to_a_unit_vector(a in any::<u32>(), b in any::<u32>()) {
        for codec in NormalCodec::ALL {
            assert_unit(decode(codec, [a, b]), codec.name());
        }
        assert_unit(unpack_octa16(a), "octa16");
        assert_unit(unpack_octa8(a), "octa8");
        assert_unit(unpack_spherical16(a), "spherical16");
        let (fa, fb) = (f32::from_bits(a), f32::from_bits(b));
        assert_unit(octa_decode([fa, fb]), "octa float");
        assert_unit(spherical_decode([fa, fb]), "spherical float");
        assert_unit(decode_xy([fa, fb]), "xy float");
    }

    /// Re-encoding a decoded code gives back a code for the same direction.
    #[test]
    fn decoded_codes_re_encode_to_themselves(p in any::<u32>()) {
        let n = unpack_octa16(p);
        prop_assert!(angle_deg(n, unpack_octa16(pack_octa16(n))) < 1e-4);
        let n = unpack_spherical16(p);
        prop_assert!(angle_deg(n, unpack_spherical16(pack_spherical16(n))) < 1e-4);
    }
}

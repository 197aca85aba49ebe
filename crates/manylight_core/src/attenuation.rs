//! Point-light attenuation: inverse-square falloff with a window that reaches exactly zero at
//! the light's radius.
//!
//! `attenuation(d, r) = saturate(1 - (d/r)^4)^2 / max(d^2, LIGHT_MIN_DISTANCE^2)`, the windowed
//! inverse-square falloff of Karis 2013 ("Real Shading in Unreal Engine 4") in metres, as
//! Filament and Bevy write it. A light's intensity is in candela (glTF `KHR_lights_punctual`):
//! `intensity * attenuation(d, r)` is the illuminance in lux on a surface facing the light, exact
//! inverse square from [`LIGHT_MIN_DISTANCE`] until the window starts to bend it (within 1 % up
//! to 0.26 r). Because it is exactly zero at and beyond `r`, a light only affects the clusters
//! its sphere touches, so a clustered image can equal the naive one.
//! `shaders/common/lights.wgsl` implements the same expression.

/// Distance (metres) under which the inverse-square falloff stops growing: a light this close
/// to a surface lights it as if it were this far (1 cm, Filament's and Bevy's value). Keeps a
/// light inside a surface or at the camera finite: at most `1 / LIGHT_MIN_DISTANCE²` = 10 000
/// times its intensity. Shared with WGSL.
pub const LIGHT_MIN_DISTANCE: f32 = 0.01;

/// Largest value [`attenuation`] takes (at distances up to [`LIGHT_MIN_DISTANCE`]).
pub const MAX_ATTENUATION: f32 = 1.0 / (LIGHT_MIN_DISTANCE * LIGHT_MIN_DISTANCE);

/// Distance falloff of a point light of radius `radius` at distance `distance`.
///
/// Defined for every input: it is `0` for `distance >= radius`, for `radius <= 0` and for
/// non-finite inputs; it is finite (at most [`MAX_ATTENUATION`]) at `distance == 0`; it never
/// increases with distance.
#[inline]
pub fn attenuation(distance: f32, radius: f32) -> f32 {
    // `is_finite` rejects NaN and infinities; a radius that is not positive lights nothing.
    if !distance.is_finite() || !radius.is_finite() || radius <= 0.0 {
        return 0.0;
    }
    let d = distance.abs();
    if d >= radius {
        return 0.0;
    }
    let ratio = d / radius;
    let ratio2 = ratio * ratio;
    let window = (1.0 - ratio2 * ratio2).clamp(0.0, 1.0);
    window * window / (d * d).max(LIGHT_MIN_DISTANCE * LIGHT_MIN_DISTANCE)
}

/// The fraction of its intensity (its brightest channel's) at which a light that comes without a
/// range is cut off: glTF `KHR_lights_punctual` lights with `range` unset reach infinitely far,
/// and get the range [`radius_for_intensity`]`(intensity, RANGELESS_LIGHT_CUTOFF)`.
/// `manylight report` (its "lights without a range" table) measures what this cut-off costs in
/// error and time against the unbounded sum.
pub const RANGELESS_LIGHT_CUTOFF: f32 = 0.003;

/// Radius at which a light of `intensity` (candela) falls below `threshold` (lux) under plain
/// inverse-square falloff (used for lights that come without a range, e.g. glTF `KHR_lights_punctual` lights
/// with `range` unset: see [`RANGELESS_LIGHT_CUTOFF`]). Always finite and non-negative.
pub fn radius_for_intensity(intensity: f32, threshold: f32) -> f32 {
    if !intensity.is_finite() || !threshold.is_finite() || intensity <= 0.0 || threshold <= 0.0 {
        return 0.0;
    }
    (intensity / threshold).sqrt().min(1.0e6)
}

/// Luminous intensity (candela) of a light that emits `lumens` evenly in every direction:
/// `lumens / 4π`. Bevy's `PointLight` and `SpotLight` give their intensity in lumens and
/// convert it so (a spot light as if it were a point light, so its cone's angle does not change
/// its brightness); glTF gives candela.
pub fn candela_from_lumens(lumens: f32) -> f32 {
    lumens / (4.0 * std::f32::consts::PI)
}

/// Luminous power (lumens) of a light of `candela` emitting evenly in every direction: the
/// inverse of [`candela_from_lumens`].
pub fn lumens_from_candela(candela: f32) -> f32 {
    candela * (4.0 * std::f32::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn zero_at_radius_and_beyond() {
        assert_eq!(attenuation(1.0, 1.0), 0.0);
        assert_eq!(attenuation(2.0, 1.0), 0.0);
        assert_eq!(attenuation(1e30, 1.0), 0.0);
    }

    #[test]
    fn finite_at_zero_distance() {
        assert_eq!(attenuation(0.0, 1.0), MAX_ATTENUATION);
        assert_eq!(attenuation(-0.0, 5.0), MAX_ATTENUATION);
        assert_eq!(attenuation(LIGHT_MIN_DISTANCE * 0.5, 5.0), MAX_ATTENUATION);
    }

    #[test]
    fn inverse_square_in_candela() {
        // A 100 cd light 2 m away gives 25 lux, less the window's 1 - (2/100)^4 squared.
        let window = (1.0f32 - 0.02f32.powi(4)).powi(2);
        assert!((100.0 * attenuation(2.0, 100.0) - 25.0 * window).abs() < 1e-4);
        // The glTF cut-off radius is where plain inverse square reaches the threshold.
        let r = radius_for_intensity(30.0, 0.003);
        assert!((30.0 / (r * r) - 0.003).abs() < 1e-6);
    }

    #[test]
    fn degenerate_inputs_are_zero() {
        assert_eq!(attenuation(0.0, 0.0), 0.0);
        assert_eq!(attenuation(0.5, -1.0), 0.0);
        assert_eq!(attenuation(f32::NAN, 1.0), 0.0);
        assert_eq!(attenuation(0.5, f32::NAN), 0.0);
        assert_eq!(attenuation(0.5, f32::INFINITY), 0.0);
        assert_eq!(radius_for_intensity(f32::NAN, 0.01), 0.0);
        assert_eq!(radius_for_intensity(100.0, 0.01), 100.0);
    }

    proptest! {
        #[test]
        fn bounded_and_finite(d in -1e6f32..1e6, r in 0.0f32..1e6) {
            let a = attenuation(d, r);
            prop_assert!(a.is_finite());
            prop_assert!((0.0..=MAX_ATTENUATION).contains(&a));
            if d.abs() >= r { prop_assert_eq!(a, 0.0); }
        }

        #[test]
        fn monotone_in_distance(d0 in 0.0f32..1e4, dd in 0.0f32..1e4, r in 1e-4f32..1e4) {
            let d1 = d0 + dd;
            prop_assert!(attenuation(d1, r) <= attenuation(d0, r));
        }
    }
}

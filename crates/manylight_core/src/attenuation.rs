//! Point-light attenuation with a window that reaches exactly zero at the light's radius.
//!
//! `attenuation(d, r) = saturate(1 - (d/r)^4)^2 / (d^2 + 1)`, the windowed inverse-square
//! falloff of Karis 2013 ("Real Shading in Unreal Engine 4"). Because it is exactly zero at and
//! beyond `r`, a light only affects the clusters its sphere touches, so a clustered image can
//! equal the naive one. `shaders/common/lights.wgsl` implements the same expression.

/// Distance falloff of a point light of radius `radius` at distance `distance`.
///
/// Defined for every input: it is `0` for `distance >= radius`, for `radius <= 0` and for
/// non-finite inputs; it is finite (at most `1`) at `distance == 0`; it never increases with
/// distance.
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
    window * window / (d * d + 1.0)
}

/// The fraction of its intensity (its brightest channel's) at which a light that comes without a
/// range is cut off: glTF `KHR_lights_punctual` lights with `range` unset reach infinitely far,
/// and get the range [`radius_for_intensity`]`(intensity, RANGELESS_LIGHT_CUTOFF)`.
/// `manylight report` (its "lights without a range" table) measures what this cut-off costs in
/// error and time against the unbounded sum.
pub const RANGELESS_LIGHT_CUTOFF: f32 = 0.003;

/// Radius at which a light of `intensity` falls below `threshold` under plain inverse-square
/// falloff (used for lights that come without a range, e.g. glTF `KHR_lights_punctual` lights
/// with `range` unset: see [`RANGELESS_LIGHT_CUTOFF`]). Always finite and non-negative.
pub fn radius_for_intensity(intensity: f32, threshold: f32) -> f32 {
    if !intensity.is_finite() || !threshold.is_finite() || intensity <= 0.0 || threshold <= 0.0 {
        return 0.0;
    }
    (intensity / threshold).sqrt().min(1.0e6)
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
        assert_eq!(attenuation(0.0, 1.0), 1.0);
        assert_eq!(attenuation(-0.0, 5.0), 1.0);
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
            prop_assert!((0.0..=1.0).contains(&a));
            if d.abs() >= r { prop_assert_eq!(a, 0.0); }
        }

        #[test]
        fn monotone_in_distance(d0 in 0.0f32..1e4, dd in 0.0f32..1e4, r in 1e-4f32..1e4) {
            let d1 = d0 + dd;
            prop_assert!(attenuation(d1, r) <= attenuation(d0, r));
        }
    }
}

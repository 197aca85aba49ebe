//! Animated lights: a point light that orbits a centre, bobs and flickers in colour, evaluated
//! at a time in seconds. The renderer can run the same animation in a compute pass
//! (`shaders/light_animation.wgsl`, from [`AnimatedLight::angles_at`]'s angles at an epoch),
//! so a light's motion costs the CPU nothing per frame; the GPU tests compare both.
//!
//! Every position and colour is finite for every finite or non-finite time.

use glam::Vec3;
use std::f64::consts::TAU;

/// A point light that orbits a centre in XZ, bobs in Y and slowly shifts hue and flickers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnimatedLight {
    /// Centre of the orbit.
    pub center: Vec3,
    /// Orbit radius in the XZ plane.
    pub orbit_radius: f32,
    /// Orbit angular speed in radians per second (sign = direction).
    pub orbit_speed: f32,
    /// Phase offset in radians (orbit, bob and flicker).
    pub phase: f32,
    /// Vertical bobbing amplitude.
    pub bob_amplitude: f32,
    /// Bobbing angular speed in radians per second.
    pub bob_speed: f32,
    /// Base linear RGB colour.
    pub color: Vec3,
    /// Flicker angular speed in radians per second (hue drift is ten times slower).
    pub flicker_speed: f32,
    /// Luminous intensity in candela (multiplies the colour).
    pub intensity: f32,
    /// Distance at which the light's contribution reaches zero.
    pub radius: f32,
}

/// The five angles an [`AnimatedLight`] is evaluated from, each `(phase + speed · t) mod 2π` in
/// `[0, 2π)`: the orbit, the bob, the hue drift and the two flicker waves.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionAngles {
    /// Angle along the orbit.
    pub orbit: f32,
    /// Angle of the bob.
    pub bob: f32,
    /// Angle of the hue drift.
    pub drift: f32,
    /// Angle of the first flicker wave.
    pub flicker: f32,
    /// Angle of the second flicker wave.
    pub flicker2: f32,
}

impl MotionAngles {
    /// The angles as an array, in declaration order.
    pub fn to_array(self) -> [f32; 5] {
        [self.orbit, self.bob, self.drift, self.flicker, self.flicker2]
    }
}

/// One angle's phase (radians) and speed (radians per second).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleRate {
    /// The angle at time 0.
    pub phase: f32,
    /// Radians per second.
    pub speed: f32,
}

impl AngleRate {
    /// `(phase + speed · t) mod 2π`, computed in f64 so that a large `t` keeps its precision
    /// and never overflows; non-finite inputs give 0.
    pub fn at(self, t: f32) -> f32 {
        let a = (self.phase as f64 + self.speed as f64 * t as f64).rem_euclid(TAU);
        // `rem_euclid` of a value just below 0 can round up to 2π itself.
        if a.is_finite() && (a as f32) < std::f32::consts::TAU { a as f32 } else { 0.0 }
    }
}

/// Rotates an RGB colour around the grey axis by `theta` (a hue shift), clamped to >= 0.
fn hue_rotate(c: Vec3, theta: f32) -> Vec3 {
    let k = Vec3::ONE.normalize();
    let (s, co) = theta.sin_cos();
    (c * co + k.cross(c) * s + k * k.dot(c) * (1.0 - co)).max(Vec3::ZERO)
}

impl AnimatedLight {
    /// The phase and speed of each of the five angles, in [`MotionAngles`] order: the orbit and
    /// the bob at their speeds, the hue drift at a tenth of the flicker speed, and the two
    /// flicker waves (phase × 3 at the flicker speed, phase at 2.7 × the flicker speed).
    pub fn rates(&self) -> [AngleRate; 5] {
        let rate = |phase, speed| AngleRate { phase, speed };
        [
            rate(self.phase, self.orbit_speed),
            rate(self.phase, self.bob_speed),
            rate(self.phase, 0.1 * self.flicker_speed),
            rate(3.0 * self.phase, self.flicker_speed),
            rate(self.phase, 2.7 * self.flicker_speed),
        ]
    }

    /// The five angles at time `t` seconds.
    pub fn angles_at(&self, t: f32) -> MotionAngles {
        let [orbit, bob, drift, flicker, flicker2] = self.rates().map(|r| r.at(t));
        MotionAngles { orbit, bob, drift, flicker, flicker2 }
    }

    /// World position at time `t` seconds: orbit in XZ around `center`, bob in Y.
    pub fn position_at(&self, t: f32) -> Vec3 {
        self.position_from(self.angles_at(t))
    }

    /// The position at `angles`: `center + (orbit_radius cos orbit, bob_amplitude sin bob,
    /// orbit_radius sin orbit)`; the centre when that is not finite, or the origin.
    pub fn position_from(&self, angles: MotionAngles) -> Vec3 {
        let p = self.center
            + Vec3::new(
                self.orbit_radius * angles.orbit.cos(),
                self.bob_amplitude * angles.bob.sin(),
                self.orbit_radius * angles.orbit.sin(),
            );
        if p.is_finite() {
            p
        } else if self.center.is_finite() {
            self.center
        } else {
            Vec3::ZERO
        }
    }

    /// Colour at time `t` (to be scaled by `intensity`): the base colour
    /// with a slow hue drift of ±20° and a ±15 % flicker. Finite and non-negative.
    pub fn color_at(&self, t: f32) -> Vec3 {
        self.color_from(self.angles_at(t))
    }

    /// The colour at `angles`: the base colour turned about the grey axis by
    /// `0.35 sin drift` and scaled by `0.85 + 0.15 (0.6 sin flicker + 0.4 sin flicker2)`; black
    /// when that is not finite.
    pub fn color_from(&self, angles: MotionAngles) -> Vec3 {
        let drift = angles.drift.sin() * 0.35;
        let flicker = 0.85 + 0.15 * (0.6 * angles.flicker.sin() + 0.4 * angles.flicker2.sin());
        let c = hue_rotate(self.color.max(Vec3::ZERO), drift) * flicker;
        if c.is_finite() { c } else { Vec3::ZERO }
    }

    /// The box the light's position stays in at every time: the centre ± the orbit radius in
    /// X and Z and ± the bob amplitude in Y (`None` when that is not finite).
    pub fn position_bounds(&self) -> Option<(Vec3, Vec3)> {
        let half = Vec3::new(self.orbit_radius, self.bob_amplitude, self.orbit_radius).abs();
        let (lo, hi) = (self.center - half, self.center + half);
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light() -> AnimatedLight {
        AnimatedLight {
            center: Vec3::new(1.0, 2.0, 3.0),
            orbit_radius: 0.7,
            orbit_speed: -0.6,
            phase: 1.3,
            bob_amplitude: 0.4,
            bob_speed: 1.7,
            color: Vec3::new(1.0, 0.3, 0.1),
            flicker_speed: 2.2,
            intensity: 5.0,
            radius: 2.0,
        }
    }

    #[test]
    fn angles_advance_at_their_rates_and_stay_in_range() {
        let l = light();
        for t in [0.0, 0.5, 17.25, 1.0e6, -3.0] {
            let a = l.angles_at(t);
            for (angle, rate) in a.to_array().into_iter().zip(l.rates()) {
                assert!((0.0..std::f32::consts::TAU).contains(&angle), "{angle} at {t}");
                let expected = (rate.phase as f64 + rate.speed as f64 * t as f64).rem_euclid(TAU);
                assert!((angle as f64 - expected).abs() < 1e-6, "{angle} vs {expected} at {t}");
            }
        }
        for t in [f32::NAN, f32::INFINITY] {
            assert_eq!(l.angles_at(t), MotionAngles::default());
        }
    }

    #[test]
    fn positions_stay_in_the_bounds() {
        let l = light();
        let (lo, hi) = l.position_bounds().expect("finite");
        for i in 0..1000 {
            let p = l.position_at(i as f32 * 0.037);
            assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all(), "{p}");
        }
        let bad = AnimatedLight { center: Vec3::NAN, ..l };
        assert_eq!(bad.position_at(1.0), Vec3::ZERO);
        assert_eq!(bad.position_bounds(), None);
    }
}

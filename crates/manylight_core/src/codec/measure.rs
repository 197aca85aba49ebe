//! Measured accuracy of the normal codecs: angle between a direction and its round trip.
//!
//! [`measure_error_in`] works in three steps:
//!
//! 1. **Dense sampling**: `samples` Fibonacci points over the whole sphere (area-uniform, so
//!    their mean error is the mean over the sphere), those outside the region dropped.
//! 2. **Hard points** ([`hard_normals`]): poles, axes with both signs of zero, octahedron
//!    vertices, edges and face centres, the equator and the octahedral and spherical seams,
//!    near-pole and near-equator points down to subnormal offsets. They count for the worst
//!    case only.
//! 3. **Refinement**: a deterministic local search (random steps of shrinking size) around
//!    the worst samples, since a grid of codes has its worst spots between sample points.
//!
//! Errors are computed in f64 as `atan2(|a × b|, a · b)`, accurate for tiny angles, against the
//! exact direction of the f32 input.

use super::{NormalCodec, decode, encode};
use glam::{DVec3, Vec3};

/// Angular round-trip error of a codec over a region of the sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CodecError {
    /// Largest error found, in degrees.
    pub worst_deg: f64,
    /// Mean error over the area-uniform samples, in degrees.
    pub mean_deg: f64,
    /// The input direction with the largest error.
    pub worst_at: Vec3,
    /// Number of area-uniform samples behind `mean_deg`.
    pub samples: usize,
}

/// Which directions a measurement covers (view space: `+Z` faces the camera).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum SphereRegion {
    /// The whole sphere.
    #[default]
    Whole,
    /// `z >= 0` (including `-0.0`): normals facing the camera.
    FrontFacing,
    /// `z < 0`: normals facing away from the camera.
    BackFacing,
}

impl SphereRegion {
    /// True when direction `n` belongs to the region.
    pub fn contains(self, n: Vec3) -> bool {
        match self {
            SphereRegion::Whole => true,
            SphereRegion::FrontFacing => n.z >= 0.0,
            SphereRegion::BackFacing => n.z < 0.0,
        }
    }
}

/// Angle in degrees between the directions of `a` and `b` (neither needs to be unit length),
/// computed in f64 so that errors of 1e-6° are still resolved.
pub fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Point `i` of `count` Fibonacci points on the unit sphere (area-uniform; `i < count`).
pub fn fibonacci_sphere(i: usize, count: usize) -> Vec3 {
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = i as f64 * golden_angle;
    DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3()
}

/// Directions (not all of unit length) where codecs tend to break: exact axes and poles (with `±0.0`), octahedron
/// vertices, edge midpoints and face centres, the equator (octahedral fold line) and
/// points just above and below it, the meridians `x = ±0` and `y = ±0` (octahedral square
/// edges for `z < 0`, spherical seam `φ = ±π` for `x < 0`), and points a tiny (down to
/// subnormal) distance from the poles.
pub fn hard_normals() -> Vec<Vec3> {
    let mut v = Vec::new();
    for s in [1.0f32, -1.0] {
        for z in [0.0f32, -0.0] {
            v.extend([Vec3::new(s, z, z), Vec3::new(z, s, z), Vec3::new(z, z, s)]);
        }
    }
    let signs = [1.0f32, -1.0];
    for a in signs {
        for b in signs {
            v.extend([Vec3::new(a, b, 0.0), Vec3::new(a, 0.0, b), Vec3::new(0.0, a, b)]);
            for c in signs {
                v.push(Vec3::new(a, b, c));
            }
        }
    }
    for eps in [1e-2f32, 1e-3, 1e-4, 1e-5, 1e-7, 1e-12, 1e-20, 1e-30, 1e-38, 1e-40, 1e-45] {
        for z in signs {
            for (x, y) in [(eps, 0.0), (0.0, eps), (-eps, 0.0), (0.0, -eps), (eps, eps), (-eps, eps)] {
                v.push(Vec3::new(x, y, z));
            }
        }
        // Just off the spherical seam (φ = ±π) and the equator.
        v.extend([Vec3::new(-1.0, eps, 0.5), Vec3::new(-1.0, -eps, 0.5), Vec3::new(-1.0, eps, -0.5)]);
        v.extend([Vec3::new(0.6, 0.8, eps), Vec3::new(0.6, 0.8, -eps), Vec3::new(-0.8, 0.6, -eps)]);
    }
    let steps = 720;
    for k in 0..steps {
        let a = k as f32 / steps as f32 * std::f32::consts::TAU;
        let (s, c) = a.sin_cos();
        v.extend([
            Vec3::new(c, s, 0.0),
            Vec3::new(c, s, -0.0),
            Vec3::new(c, s, 1e-6),
            Vec3::new(c, s, -1e-6),
        ]);
        for zero in [0.0f32, -0.0] {
            v.extend([Vec3::new(zero, s, c), Vec3::new(s, zero, c)]);
        }
    }
    v
}

/// [`measure_error_in`] over the whole sphere.
pub fn measure_error(codec: NormalCodec, samples: usize) -> CodecError {
    measure_error_in(codec, samples, SphereRegion::Whole)
}

/// Worst and mean round-trip angle of `codec` over `region`: `samples` Fibonacci points over
/// the whole sphere (those in the region are used), plus [`hard_normals`], plus a local
/// search around the worst points. Use ≥ 1 000 000 samples (release build) for published
/// numbers.
pub fn measure_error_in(codec: NormalCodec, samples: usize, region: SphereRegion) -> CodecError {
    let error = |n: Vec3| angle_deg(n, decode(codec, encode(codec, n)));

    // 1. Dense sampling; keep the worst few as seeds for step 3.
    const SEEDS: usize = 32;
    let mut seeds: Vec<(f64, Vec3)> = Vec::with_capacity(SEEDS + 1);
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..samples {
        let n = fibonacci_sphere(i, samples);
        if !region.contains(n) {
            continue;
        }
        let e = error(n);
        sum += e;
        count += 1;
        if seeds.len() < SEEDS || e > seeds[SEEDS - 1].0 {
            let at = seeds.partition_point(|s| s.0 >= e);
            seeds.insert(at, (e, n));
            seeds.truncate(SEEDS);
        }
    }

    // 2. Hard points.
    let mut worst = seeds.first().copied().unwrap_or((0.0, Vec3::Z));
    for n in hard_normals() {
        if region.contains(n) {
            let e = error(n);
            if e > worst.0 {
                worst = (e, n);
            }
        }
    }

    // 3. Local search around each seed, steps from ~2 sample spacings down to ~1e-6 rad.
    let spacing = (4.0 * std::f32::consts::PI / samples.max(1) as f32).sqrt();
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    let mut unit = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    for &(mut best_e, mut best_n) in &seeds {
        let mut step = 2.0 * spacing;
        for _ in 0..400 {
            if step < 1e-6 {
                break;
            }
            let mut improved = false;
            for _ in 0..40 {
                let candidate = (best_n + step * Vec3::new(unit(), unit(), unit())).normalize_or_zero();
                if candidate == Vec3::ZERO || !region.contains(candidate) {
                    continue;
                }
                let e = error(candidate);
                if e > best_e {
                    (best_e, best_n, improved) = (e, candidate, true);
                }
            }
            if !improved {
                step *= 0.5;
            }
        }
        if best_e > worst.0 {
            worst = (best_e, best_n);
        }
    }

    CodecError {
        worst_deg: worst.0,
        mean_deg: if count > 0 { sum / count as f64 } else { 0.0 },
        worst_at: worst.1,
        samples: count,
    }
}

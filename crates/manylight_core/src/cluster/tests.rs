//! Property tests: invariants of the grid and the assignment swept over random grids and
//! scenes (modelled on Bevy's `bevy_light/cluster/test.rs`). Each case draws a seed; a small
//! deterministic generator turns it into a grid and lights that mix ordinary lights with
//! adversarial ones (on tile planes, slice planes and corners, behind or around the camera,
//! huge, zero, invalid).

use glam::{UVec2, UVec3, Vec2, Vec3};
use proptest::prelude::*;

use super::assign::assign_lights_brute_force;
use super::*;
use crate::Projection;

/// splitmix64: tiny, deterministic, good enough for test scenes.
pub(super) struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed ^ 0x9E37_79B9_7F4A_7C15)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    pub fn log_range(&mut self, lo: f32, hi: f32) -> f32 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u32) -> u32 {
        (self.next_u64() % u64::from(n)) as u32
    }
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

/// A random grid small enough for all-pairs checks.
pub(super) fn random_grid(rng: &mut Rng) -> ClusterGrid {
    let viewport = match rng.below(6) {
        0 => UVec2::ONE,
        1 => UVec2::new(8191, 17),
        2 => UVec2::new(1, 4096),
        3 => UVec2::new(1280, 720),
        _ => UVec2::new(1 + rng.below(2500), 1 + rng.below(2500)),
    };
    let fov_y = match rng.below(6) {
        0 => 0.01f32.to_radians(),
        1 => 179f32.to_radians(),
        _ => rng.range(0.1, 3.0),
    };
    let near = rng.log_range(1e-4, 10.0);
    let far = near * rng.log_range(1.01, 1e10);
    let dims = UVec3::new(1 + rng.below(10), 1 + rng.below(8), 1 + rng.below(12));
    let slicing = if rng.chance(0.5) { ZSlicing::Linear } else { ZSlicing::Exponential };
    let config = GridConfig { dims: Some(dims), slicing, ..Default::default() };
    // One grid in four is orthographic (boxes, linear slices).
    let projection = if rng.chance(0.25) {
        Projection::orthographic(rng.log_range(1e-3, 1e4), near, far)
    } else {
        Projection::perspective(fov_y, near, far)
    };
    ClusterGrid::new(viewport, &projection, &config)
}

/// View-space point at NDC `(nx, ny)` and view distance `d`.
pub(super) fn view_point(grid: &ClusterGrid, nx: f32, ny: f32, d: f32) -> Vec3 {
    let half = grid.half_extent_at(d);
    Vec3::new(nx * half.x, ny * half.y, -d)
}

/// A random light; about half are ordinary, the rest adversarial.
pub(super) fn random_light(rng: &mut Rng, grid: &ClusterGrid) -> ViewSphere {
    let [nx, ny, nz] = grid.dims.to_array();
    let depth = |rng: &mut Rng| rng.log_range(grid.near * 0.01, grid.far * 2.0);
    let center = match rng.below(10) {
        // On a cluster corner, edge or face: exact tile edges and slice boundaries.
        0..=2 => {
            let mut p = view_point(
                grid,
                grid.ndc_x_edge(rng.below(nx + 1)),
                grid.ndc_y_edge(rng.below(ny + 1)),
                grid.slice_boundary(rng.below(nz + 1)),
            );
            match rng.below(4) {
                0 => p.x = rng.range(-1.0, 1.0) * grid.half_extent_at(p.z.abs()).x,
                1 => p.z = -depth(rng),
                _ => {}
            }
            p
        }
        // Behind the camera or beside it.
        3 => Vec3::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), rng.range(-1.0, 1.0)) * depth(rng),
        // Around the camera.
        4 => Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * grid.near,
        _ => view_point(grid, rng.range(-1.5, 1.5), rng.range(-1.5, 1.5), depth(rng)),
    };
    let scale = center.length().max(grid.near);
    let radius = match rng.below(20) {
        0 => 0.0,
        1 => -1.0,
        2 => f32::NAN,
        3 => grid.far * 10.0,
        4 => scale * 1e-6,
        5 => f32::MIN_POSITIVE,
        _ => scale * rng.log_range(1e-4, 3.0),
    };
    let center = if rng.below(50) == 0 { Vec3::new(f32::NAN, 0.0, -1.0) } else { center };
    ViewSphere { center, radius }
}

pub(super) fn random_lights(rng: &mut Rng, grid: &ClusterGrid, n: usize) -> Vec<ViewSphere> {
    (0..n).map(|_| random_light(rng, grid)).collect()
}

/// Structural invariants every assignment satisfies.
pub(super) fn check_invariants(grid: &ClusterGrid, a: &ClusterAssignment, light_count: usize) {
    assert_eq!(a.ranges.len(), grid.cluster_count() as usize);
    let mut next = 0u32;
    for (i, &[offset, count]) in a.ranges.iter().enumerate() {
        assert_eq!(offset, next, "cluster {i}: ranges must partition the index list");
        next += count;
        let list = a.lights_of(i as u32);
        assert!(list.windows(2).all(|w| w[0] < w[1]), "cluster {i}: not ascending: {list:?}");
        assert!(list.iter().all(|&l| (l as usize) < light_count));
    }
    assert_eq!(next as usize, a.indices.len());
}

fn first_difference(a: &ClusterAssignment, b: &ClusterAssignment, grid: &ClusterGrid) -> String {
    (0..grid.cluster_count())
        .find(|&i| a.lights_of(i) != b.lights_of(i))
        .map(|i| format!("cluster {i} {:?}: {:?} vs {:?}", grid.coords(i), a.lights_of(i), b.lights_of(i)))
        .unwrap_or_default()
}

fn cases(n: u32) -> ProptestConfig {
    ProptestConfig { cases: n, failure_persistence: None, ..ProptestConfig::default() }
}

proptest! {
    #![proptest_config(cases(3000))]

    #[test]
    fn accelerated_equals_brute_force(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let count = rng.below(24) as usize;
        let lights = random_lights(&mut rng, &grid, count);
        for test in CullTest::ALL {
            let fast = assign_lights(&grid, &lights, test, None);
            let brute = assign_lights_brute_force(&grid, &lights, test, None);
            check_invariants(&grid, &fast, lights.len());
            prop_assert_eq!(fast.dropped_pairs, 0);
            prop_assert_eq!(fast.clusters_overflowed, 0);
            prop_assert!(fast == brute, "{test:?} {grid:?}\n{}\nlights {lights:?}",
                first_difference(&fast, &brute, &grid));
        }
    }

    #[test]
    fn cap_keeps_the_lowest_lights_and_counts_the_rest(seed in any::<u64>(), cap in 0u32..6) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let count = 1 + rng.below(30) as usize;
        let lights = random_lights(&mut rng, &grid, count);
        let test = CullTest::ALL[rng.below(3) as usize];
        let full = assign_lights(&grid, &lights, test, None);
        let capped = assign_lights(&grid, &lights, test, Some(cap));
        check_invariants(&grid, &capped, lights.len());
        prop_assert_eq!(&capped, &assign_lights_brute_force(&grid, &lights, test, Some(cap)));
        let (mut dropped, mut overflowed) = (0u64, 0u32);
        for i in 0..grid.cluster_count() {
            let (all, kept) = (full.lights_of(i), capped.lights_of(i));
            prop_assert_eq!(kept, &all[..all.len().min(cap as usize)]);
            dropped += (all.len() - kept.len()) as u64;
            overflowed += u32::from(all.len() > kept.len());
        }
        prop_assert_eq!(capped.dropped_pairs, dropped);
        prop_assert_eq!(capped.clusters_overflowed, overflowed);
    }

    /// A point of a cluster inside a sphere makes both tests accept the pair, and the light
    /// appears in the list of the cluster `cluster_of` finds for that pixel and depth.
    #[test]
    fn sampled_points_inside_a_sphere_are_never_culled(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let mut lights = random_lights(&mut rng, &grid, 6);
        // Sample fragments, and add a light around each so many samples are inside one.
        let samples: Vec<(Vec2, f32, Vec3)> = (0..6).map(|_| {
            let px = Vec2::new(rng.unit(), rng.unit()) * grid.viewport.as_vec2();
            let k = rng.below(grid.dims.z);
            let (b0, b1) = (grid.slice_boundary(k), grid.slice_boundary(k + 1));
            let d = (b0 + (b1 - b0) * rng.unit()).min(b1);
            let ndc = Vec2::new(2.0 * px.x / grid.viewport.x as f32 - 1.0,
                                1.0 - 2.0 * px.y / grid.viewport.y as f32);
            (px, d, view_point(&grid, ndc.x, ndc.y, d))
        }).collect();
        for &(_, _, p) in &samples {
            let r = p.length().max(grid.near) * rng.log_range(1e-5, 2.0);
            let dir = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            lights.push(ViewSphere { center: p + dir.normalize_or_zero() * r * rng.unit(), radius: r });
        }
        let assigned = CullTest::ALL.map(|t| assign_lights(&grid, &lights, t, None));
        for &(px, d, p) in &samples {
            let cluster = grid.cluster_of(px, d);
            let c = grid.coords(cluster);
            let (min, max) = grid.cluster_aabb(c.x, c.y, c.z);
            let planes = grid.cluster_planes(c.x, c.y, c.z);
            for (l, s) in lights.iter().enumerate() {
                if !(s.is_valid() && (p - s.center).length_squared() <= s.radius * s.radius) {
                    continue;
                }
                prop_assert!(sphere_intersects_aabb(s.center, s.radius, min, max),
                    "aabb culls light {s:?} at {p:?} in {c:?} of {grid:?}");
                prop_assert!(sphere_intersects_planes(s.center, s.radius, &planes),
                    "planes cull light {s:?} at {p:?} in {c:?} of {grid:?}");
                for a in &assigned {
                    prop_assert!(a.lights_of(cluster).contains(&(l as u32)));
                }
            }
        }
    }

    /// Whatever the exact test finds, both conservative tests find too.
    #[test]
    fn tests_are_never_less_conservative_than_exact(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let lights = random_lights(&mut rng, &grid, 8);
        for i in 0..grid.cluster_count() {
            let c = grid.coords(i);
            let (min, max) = grid.cluster_aabb(c.x, c.y, c.z);
            let planes = grid.cluster_planes(c.x, c.y, c.z);
            for s in &lights {
                if sphere_touches_cluster_exact(&grid, s, c.x, c.y, c.z) {
                    prop_assert!(sphere_intersects_aabb(s.center, s.radius, min, max), "{s:?} {c:?} {grid:?}");
                    prop_assert!(sphere_intersects_planes(s.center, s.radius, &planes), "{s:?} {c:?} {grid:?}");
                }
            }
        }
    }

    /// Slices: boundaries finite and non-decreasing, exact at the ends, and `slice_of_depth`
    /// inverts them for any input.
    #[test]
    fn slices_are_monotone_and_consistent(seed in any::<u64>(), d in any::<f32>()) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let z = grid.dims.z;
        prop_assert_eq!(grid.slice_boundary(0), grid.near);
        prop_assert_eq!(grid.slice_boundary(z), grid.far);
        let b: Vec<f32> = (0..=z).map(|k| grid.slice_boundary(k)).collect();
        prop_assert!(b.iter().all(|v| v.is_finite()));
        prop_assert!(b.windows(2).all(|w| w[0] <= w[1]), "{b:?}");
        for d in [d, rng.log_range(grid.near * 0.5, grid.far * 2.0)] {
            let k = grid.slice_of_depth(d);
            prop_assert!(k < z);
            if d > grid.near && d < grid.far {
                prop_assert!(b[k as usize] <= d && (d < b[k as usize + 1] || k == z - 1), "{d} {k} {b:?}");
            }
        }
    }

    #[test]
    fn indices_and_coords_round_trip(seed in any::<u64>(), px in any::<(f32, f32)>(), d in any::<f32>()) {
        let mut rng = Rng::new(seed);
        let grid = random_grid(&mut rng);
        let i = rng.below(grid.cluster_count());
        let c = grid.coords(i);
        prop_assert!(c.cmplt(grid.dims).all());
        prop_assert_eq!(grid.index(c.x, c.y, c.z), i);
        prop_assert!(grid.cluster_of(Vec2::new(px.0, px.1), d) < grid.cluster_count());
        let (min, max) = grid.cluster_aabb(c.x, c.y, c.z);
        prop_assert!(min.is_finite() && max.is_finite() && min.cmple(max).all());
        prop_assert!(grid.cluster_planes(c.x, c.y, c.z).iter().all(|p| p.is_finite()));
    }
}

//! Fixed cases: configuration, extreme projections and viewports, lights placed exactly on
//! planes, around the camera, behind it, covering everything; plus the false-positive
//! measurement and a timing run.

use glam::{UVec2, UVec3, Vec2, Vec3};

use super::assign::assign_lights_brute_force;
use super::tests::{Rng, check_invariants, random_lights, view_point};
use super::*;
use crate::Projection;

fn grid(viewport: UVec2, fov_deg: f32, near: f32, far: f32, dims: UVec3, slicing: ZSlicing) -> ClusterGrid {
    let config = GridConfig { dims: Some(dims), slicing, ..Default::default() };
    ClusterGrid::new(viewport, &Projection::perspective(fov_deg.to_radians(), near, far), &config)
}

fn default_grid() -> ClusterGrid {
    ClusterGrid::new(UVec2::new(1280, 720), &Projection::default(), &GridConfig::default())
}

/// Clusters `light` is assigned to under `test`, checked against brute force.
fn clusters_of(grid: &ClusterGrid, light: ViewSphere, test: CullTest) -> Vec<u32> {
    let lights = [light];
    let a = assign_lights(grid, &lights, test, None);
    check_invariants(grid, &a, 1);
    assert_eq!(a, assign_lights_brute_force(grid, &lights, test, None), "{light:?} {test:?}");
    (0..grid.cluster_count()).filter(|&i| !a.lights_of(i).is_empty()).collect()
}

#[test]
fn names_round_trip_and_defaults() {
    for s in ZSlicing::ALL {
        assert_eq!(ZSlicing::from_name(s.name()), Some(s));
    }
    for t in CullTest::ALL {
        assert_eq!(CullTest::from_name(t.name()), Some(t));
    }
    assert_eq!(ZSlicing::from_name("Exponential"), Some(ZSlicing::Exponential));
    assert_eq!(ZSlicing::from_name("log"), None);
    assert_eq!(CullTest::from_name("sphere"), None);
    assert_eq!((ZSlicing::Linear.gpu_id(), ZSlicing::Exponential.gpu_id()), (0, 1));
    assert_eq!(ZSlicing::default(), ZSlicing::Exponential);
    assert_eq!(CullTest::default(), CullTest::Both);
    let c = GridConfig::default();
    assert_eq!((c.tile_px, c.z_slices, c.dims), (16, 24, None));
}

#[test]
fn auto_dims_and_clamps() {
    assert_eq!(default_grid().dims, UVec3::new(80, 45, 24));
    let auto =
        |w, h, config: GridConfig| ClusterGrid::new(UVec2::new(w, h), &Projection::default(), &config).dims;
    let c = GridConfig::default();
    assert_eq!(auto(1, 1, c), UVec3::new(1, 1, 24));
    assert_eq!(auto(0, 0, c), UVec3::new(1, 1, 24));
    assert_eq!(auto(8191, 17, c), UVec3::new(512, 2, 24));
    assert_eq!(auto(1, 4096, c), UVec3::new(1, 256, 24));
    let d = auto(1000, 1000, GridConfig { tile_px: 0, ..c });
    assert!(d.x == d.y && d.x * d.y * d.z <= MAX_CLUSTERS && d.x * d.y * d.z > MAX_CLUSTERS / 2, "{d}");
    let huge = GridConfig { dims: Some(UVec3::new(100_000, 4096, 0)), ..c };
    let d = auto(1280, 720, huge);
    assert!(d.x <= MAX_GRID_DIM && d.y <= MAX_GRID_DIM && d.z == 1 && d.x * d.y * d.z <= MAX_CLUSTERS);
    let d = auto(1280, 720, GridConfig { dims: Some(UVec3::splat(u32::MAX)), ..c });
    assert!(d.cmpge(UVec3::splat(64)).all() && d.x * d.y * d.z <= MAX_CLUSTERS, "{d}");
    let g = ClusterGrid::new(UVec2::ZERO, &Projection::default(), &c);
    assert_eq!((g.viewport, g.aspect), (UVec2::ONE, 1.0));
}

#[test]
fn pixels_map_to_tiles_top_left_first() {
    let g = default_grid();
    assert_eq!(g.tile_of_pixel(Vec2::new(0.5, 0.5)), UVec2::ZERO);
    assert_eq!(g.tile_of_pixel(Vec2::new(1279.5, 719.5)), UVec2::new(79, 44));
    // 80 × 45 tiles: 16 px wide and high.
    assert_eq!(g.tile_of_pixel(Vec2::new(16.0, 15.9)), UVec2::new(1, 0));
    for px in [Vec2::splat(-5.0), Vec2::splat(1e9), Vec2::NAN, Vec2::splat(f32::INFINITY)] {
        assert!(g.tile_of_pixel(px).cmplt(UVec2::new(80, 45)).all());
    }
    // Tile y = 0 is the top of the screen: its AABB has positive view-space y.
    let (min, _) = g.cluster_aabb(0, 0, 3);
    assert!(min.y > 0.0 && min.x < 0.0);
    assert_eq!(g.cluster_of(Vec2::new(0.5, 719.5), 0.05), g.index(0, 44, 0));
}

#[test]
fn extreme_depth_range_stays_finite() {
    for slicing in ZSlicing::ALL {
        let g = grid(UVec2::new(1280, 720), 60.0, 1e-4, 1e6, UVec3::new(20, 12, 24), slicing);
        let b: Vec<f32> = (0..=24).map(|k| g.slice_boundary(k)).collect();
        assert!(b.iter().all(|v| v.is_finite()) && b.windows(2).all(|w| w[0] < w[1]), "{b:?}");
        assert_eq!((b[0], b[24]), (1e-4, 1e6));
        for (d, want) in [(1e-4, 0), (0.0, 0), (-1.0, 0), (f32::NAN, 0), (f32::NEG_INFINITY, 0)] {
            assert_eq!(g.slice_of_depth(d), want, "{d}");
        }
        for d in [1e6, 2e6, f32::INFINITY, f32::MAX] {
            assert_eq!(g.slice_of_depth(d), 23, "{d}");
        }
        for (k, &boundary) in b[..24].iter().enumerate() {
            assert_eq!(g.slice_of_depth(boundary), k as u32, "boundary {k} belongs to the slice above");
        }
        for i in 0..g.cluster_count() {
            let c = g.coords(i);
            let (min, max) = g.cluster_aabb(c.x, c.y, c.z);
            assert!(min.is_finite() && max.is_finite());
            assert!(g.cluster_planes(c.x, c.y, c.z).iter().all(|p| p.is_finite()));
        }
    }
}

#[test]
fn lights_on_planes_and_corners_reach_both_sides() {
    let g = grid(UVec2::new(1280, 720), 60.0, 0.1, 100.0, UVec3::new(8, 4, 6), ZSlicing::Exponential);
    let d = g.slice_boundary(3);
    // Tiny light exactly on the corner shared by clusters (3..=4, 1..=2, 2..=3).
    let corner = view_point(&g, g.ndc_x_edge(4), g.ndc_y_edge(2), d);
    for test in CullTest::ALL {
        let got = clusters_of(&g, ViewSphere { center: corner, radius: 1e-6 }, test);
        for (x, y, z) in
            [(3, 1, 2), (4, 1, 2), (3, 2, 2), (4, 2, 2), (3, 1, 3), (4, 1, 3), (3, 2, 3), (4, 2, 3)]
        {
            assert!(got.contains(&g.index(x, y, z)), "{test:?} misses ({x},{y},{z}): {got:?}");
        }
        // On a slice plane at a tile centre: both slices of that tile.
        let on_slice = view_point(&g, (g.ndc_x_edge(1) + g.ndc_x_edge(2)) / 2.0, 0.25, d);
        let got = clusters_of(&g, ViewSphere { center: on_slice, radius: 1e-6 }, test);
        assert!(got.contains(&g.index(1, 1, 2)) && got.contains(&g.index(1, 1, 3)), "{got:?}");
        // On a tile plane: both columns.
        let on_tile = view_point(&g, g.ndc_x_edge(6), 0.25, (d + g.slice_boundary(4)) / 2.0);
        let got = clusters_of(&g, ViewSphere { center: on_tile, radius: 1e-6 }, test);
        assert!(got.contains(&g.index(5, 1, 3)) && got.contains(&g.index(6, 1, 3)), "{got:?}");
    }
}

#[test]
fn lights_behind_around_and_covering_the_camera() {
    let g = grid(UVec2::new(640, 480), 70.0, 0.5, 200.0, UVec3::new(10, 8, 16), ZSlicing::Exponential);
    for test in CullTest::ALL {
        // Behind the camera, not reaching the near plane: nothing.
        assert!(
            clusters_of(&g, ViewSphere { center: Vec3::new(0.0, 0.0, 3.0), radius: 3.4 }, test).is_empty()
        );
        // Behind, but reaching past the near plane: the first slice, centre tiles only.
        let got = clusters_of(&g, ViewSphere { center: Vec3::new(0.0, 0.0, 3.0), radius: 3.6 }, test);
        assert!(got.contains(&g.index(4, 3, 0)) && got.contains(&g.index(5, 4, 0)), "{got:?}");
        assert!(got.iter().all(|&i| g.coords(i).z == 0), "{got:?}");
        // Straddling the near plane.
        let got = clusters_of(&g, ViewSphere { center: Vec3::new(0.0, 0.0, -0.5), radius: 0.1 }, test);
        assert!(got.contains(&g.index(4, 3, 0)) && got.contains(&g.index(5, 4, 0)), "{got:?}");
        // Containing the camera: every cluster of the slices it reaches.
        let (center, r) = (Vec3::new(0.1, -0.1, 0.2), 2.0);
        let got = clusters_of(&g, ViewSphere { center, radius: r }, test);
        // The farthest point of a slice's near face is its corner, at `b · |(tan_x, tan_y, 1)|`.
        let reach = g.slice_of_depth((r - center.length()) / g.tan_half_fov().extend(1.0).length());
        assert!(reach >= 1);
        for z in 0..=reach {
            for y in 0..8 {
                for x in 0..10 {
                    assert!(got.contains(&g.index(x, y, z)), "{test:?} misses ({x},{y},{z})");
                }
            }
        }
        // Zero, negative, NaN: nothing. Huge: everything.
        for radius in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(
                clusters_of(&g, ViewSphere { center: Vec3::new(0.0, 0.0, -5.0), radius }, test).is_empty()
            );
        }
        assert!(clusters_of(&g, ViewSphere { center: Vec3::NAN, radius: 1.0 }, test).is_empty());
        let all = clusters_of(&g, ViewSphere { center: Vec3::new(3.0, 1.0, -50.0), radius: 1e4 }, test);
        assert_eq!(all.len(), g.cluster_count() as usize);
        let all = clusters_of(&g, ViewSphere { center: Vec3::ZERO, radius: f32::MAX }, test);
        assert_eq!(all.len(), g.cluster_count() as usize);
    }
}

#[test]
fn extreme_viewports_and_fields_of_view() {
    let mut rng = Rng::new(7);
    for viewport in [UVec2::ONE, UVec2::new(8191, 17), UVec2::new(1280, 720), UVec2::new(1, 4096)] {
        for fov in [0.01, 60.0, 179.0] {
            for slicing in ZSlicing::ALL {
                let config = GridConfig { slicing, ..Default::default() };
                let projection = Projection::perspective(f32::to_radians(fov), 0.05, 500.0);
                let g = ClusterGrid::new(viewport, &projection, &config);
                let lights = random_lights(&mut rng, &g, 40);
                for test in CullTest::ALL {
                    let a = assign_lights(&g, &lights, test, None);
                    check_invariants(&g, &a, lights.len());
                    if g.cluster_count() <= 4096 {
                        assert_eq!(a, assign_lights_brute_force(&g, &lights, test, None), "{g:?} {test:?}");
                    }
                }
            }
        }
    }
}

#[test]
fn view_spheres_transform_positions_and_keep_radii() {
    let view = glam::Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0));
    let s = view_spheres(&view, [(Vec3::ZERO, 2.0), (Vec3::new(1.0, 0.0, 5.0), 0.5)].into_iter());
    assert!((s[0].center - Vec3::new(0.0, 0.0, -5.0)).length() < 1e-6 && s[0].radius == 2.0);
    assert!((s[1].center - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-6 && s[1].radius == 0.5);
}

#[test]
fn stats_summarise_the_lists() {
    let a = ClusterAssignment {
        ranges: vec![[0, 2], [2, 0], [2, 1], [3, 0]],
        indices: vec![0, 4, 1],
        ..Default::default()
    };
    let s = a.stats();
    assert_eq!((s.clusters, s.non_empty, s.total_entries, s.max_per_cluster), (4, 2, 3, 2));
    assert_eq!((s.mean_per_cluster, s.mean_per_non_empty), (0.75, 1.5));
    assert_eq!(a.lights_of(0), &[0, 4]);
    assert!(a.lights_of(99).is_empty());
    assert_eq!(ClusterAssignment::default().stats(), ClusterStats::default());
}

/// A 1024-light scene in a 1280×720 view with the default grid: lights spread over the first
/// 100 units of depth, radii 0.5–5.
fn fp_scene(rng: &mut Rng, g: &ClusterGrid, n: usize) -> Vec<ViewSphere> {
    (0..n)
        .map(|_| {
            let d = rng.range(0.5, 100.0);
            let center = view_point(g, rng.range(-1.1, 1.1), rng.range(-1.1, 1.1), d);
            ViewSphere { center, radius: rng.range(0.5, 5.0) }
        })
        .collect()
}

/// Every test accepts each truly intersecting pair, and requiring both tests is the tightest
/// (the rates themselves: `manylight culling-tests`).
#[test]
fn false_positive_rates_are_ordered() {
    let g = ClusterGrid::new(
        UVec2::new(1280, 720),
        &Projection::perspective(60f32.to_radians(), 0.1, 100.0),
        &GridConfig::default(),
    );
    let lights = fp_scene(&mut Rng::new(1), &g, 1024);
    let counts: Vec<(u64, u64)> =
        CullTest::ALL.iter().map(|&t| false_positive_counts(&g, &lights, t)).collect();
    for &(accepted, truly) in &counts {
        assert!(truly <= accepted && accepted > 0, "{counts:?}");
        // Conservative: every test finds every truly intersecting pair.
        assert_eq!(truly, counts[0].1, "{counts:?}");
    }
    let rate = |test: CullTest| {
        let (accepted, truly) = counts[CullTest::ALL.iter().position(|&t| t == test).unwrap_or(0)];
        1.0 - truly as f64 / accepted as f64
    };
    assert!(
        rate(CullTest::Both) <= rate(CullTest::Aabb) && rate(CullTest::Both) <= rate(CullTest::Planes),
        "{counts:?}"
    );
}

#[test]
fn default_grid_matches_brute_force() {
    let mut rng = Rng::new(11);
    for (near, far) in [(0.1, 1000.0), (1e-4, 1e6)] {
        let projection = Projection::perspective(60f32.to_radians(), near, far);
        for slicing in ZSlicing::ALL {
            let g = ClusterGrid::new(
                UVec2::new(1280, 720),
                &projection,
                &GridConfig { slicing, ..Default::default() },
            );
            let mut lights = random_lights(&mut rng, &g, 150);
            lights.extend(fp_scene(&mut rng, &g, 150));
            for test in CullTest::ALL {
                let a = assign_lights(&g, &lights, test, None);
                check_invariants(&g, &a, lights.len());
                assert_eq!(a, assign_lights_brute_force(&g, &lights, test, None), "{slicing:?} {test:?}");
            }
        }
    }
}

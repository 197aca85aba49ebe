//! The GPU cluster build keeps, per coarse tile, the lights that can reach one of its tiles
//! (level 0); then, per screen tile, those of its coarse tile that pass the chosen test against
//! the tile's whole column (one slice from near to far, radius × 1.001); then tests only those
//! against each cluster. That is exact only if every light a cluster accepts is also accepted
//! by its column, and every light a column accepts by its coarse tile; this checks both on
//! random lights. Level 0 also keeps a light only for the coarse tiles of its screen rectangle
//! (`RectGrid::light_tile_rect`), which must hold every tile whose column accepts it; the last test checks
//! that.

use glam::{UVec2, UVec3, Vec3};
use manylight_core::Projection;
use manylight_core::cluster::{
    ClusterGrid, CullTest, GridConfig, ViewSphere, ZSlicing, coarse_dims, coarse_tile_accepts, coarse_tiles,
    sphere_intersects_aabb, sphere_intersects_planes,
};

/// The GPU build's tile-level inflation (emitted into shaders/cluster_build.wgsl).
const INFLATION: f32 = manylight_core::cluster::TILE_PREFILTER_INFLATION;

/// Uniform numbers in [0, 1) from a linear congruential generator seeded with `seed`.
fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
    move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The default grid of `viewport` and `projection`, and its one-slice grid of columns.
fn grid_and_columns(viewport: UVec2, projection: &Projection) -> (ClusterGrid, ClusterGrid) {
    let grid = ClusterGrid::new(viewport, projection, &GridConfig::default());
    let dims = UVec3::new(grid.dims.x, grid.dims.y, 1);
    let column =
        ClusterGrid::new(viewport, projection, &GridConfig { dims: Some(dims), ..GridConfig::default() });
    (grid, column)
}

#[test]
fn a_column_accepts_every_light_its_clusters_accept() {
    let mut rnd = uniform(0x9e37_79b9_7f4a_7c15);
    let cases = [
        (UVec2::new(200, 120), Projection::perspective(1.0, 0.1, 200.0), ZSlicing::Exponential),
        (UVec2::new(96, 64), Projection::perspective(1.0, 0.1, 200.0), ZSlicing::Linear),
        (UVec2::new(1, 1), Projection::perspective(3.1, 1e-4, 1e6), ZSlicing::Exponential),
        (UVec2::new(640, 17), Projection::perspective(0.01, 0.5, 50.0), ZSlicing::Exponential),
        (UVec2::new(200, 120), Projection::orthographic(30.0, 0.5, 100.0), ZSlicing::Linear),
    ];
    for (viewport, projection, slicing) in cases {
        let config = GridConfig { slicing, ..GridConfig::default() };
        let grid = ClusterGrid::new(viewport, &projection, &config);
        let dims = UVec3::new(grid.dims.x, grid.dims.y, 1);
        let column = ClusterGrid::new(viewport, &projection, &GridConfig { dims: Some(dims), ..config });
        let extent = projection.far.min(100.0);
        for _ in 0..400 {
            let d = rnd() * extent;
            let s = ViewSphere {
                center: Vec3::new((rnd() - 0.5) * d * 2.0, (rnd() - 0.5) * d * 2.0, -d),
                radius: rnd() * extent * 0.05,
            };
            for c in 0..grid.cluster_count() {
                let k = grid.coords(c);
                let (min, max) = grid.cluster_aabb(k.x, k.y, k.z);
                let planes = grid.cluster_planes(k.x, k.y, k.z);
                let (cmin, cmax) = column.cluster_aabb(k.x, k.y, 0);
                let cplanes = column.cluster_planes(k.x, k.y, 0);
                let r = s.radius * INFLATION;
                if sphere_intersects_aabb(s.center, s.radius, min, max) {
                    assert!(sphere_intersects_aabb(s.center, r, cmin, cmax), "aabb: {s:?} in {k:?}");
                }
                if sphere_intersects_planes(s.center, s.radius, &planes) {
                    assert!(sphere_intersects_planes(s.center, r, &cplanes), "planes: {s:?} in {k:?}");
                }
            }
        }
    }
}

/// Level 0 of the build keeps, per coarse tile of `span × span` columns, the lights that
/// `coarse_tile_accepts`; level 1 tests only those. Exact only if a coarse tile accepts every
/// light one of its columns accepts (the tile level's test, radius × 1.001), for the AABB test
/// and for both tests; checked on random lights, many of them around and behind the eye, where
/// the side planes of a narrow and a wide column disagree.
#[test]
fn a_coarse_tile_accepts_every_light_its_columns_accept() {
    let mut rnd = uniform(0x2545_f491_4f6c_dd1d);
    let cases = [
        (UVec2::new(200, 120), Projection::perspective(1.0, 0.1, 200.0)),
        (UVec2::new(1280, 720), Projection::perspective(0.8, 0.1, 1000.0)),
        (UVec2::new(96, 64), Projection::perspective(2.8, 0.01, 50.0)),
        (UVec2::new(640, 17), Projection::perspective(0.01, 0.5, 50.0)),
        (UVec2::new(200, 120), Projection::orthographic(30.0, 0.5, 100.0)),
    ];
    for (viewport, projection) in cases {
        let (_, column) = grid_and_columns(viewport, &projection);
        let dims = column.dims;
        let extent = projection.far.min(100.0);
        // The planes must make the coarse test tighter than the hull alone (perspective).
        let mut planes_rejected = 0u32;
        for span in [2, 3, 8] {
            let coarse = coarse_tiles(&column, span);
            let across = coarse_dims(dims.truncate(), span).x;
            for i in 0..600 {
                // A third of the lights within a few radii of the eye, some behind it.
                let d = if i % 3 == 0 { (rnd() - 0.3) * 2.0 } else { rnd() * extent };
                let spread = d.abs().max(1.0) * 2.0;
                let s = ViewSphere {
                    center: Vec3::new((rnd() - 0.5) * spread, (rnd() - 0.5) * spread, -d),
                    radius: rnd() * if i % 3 == 0 { 2.0 } else { extent * 0.05 },
                };
                for tile in &coarse {
                    let tighter = coarse_tile_accepts(tile, &s, CullTest::Aabb)
                        && !coarse_tile_accepts(tile, &s, CullTest::Both);
                    planes_rejected += u32::from(tighter);
                }
                let r = s.radius * INFLATION;
                for t in 0..column.cluster_count() {
                    let k = column.coords(t);
                    let (min, max) = column.cluster_aabb(k.x, k.y, 0);
                    let planes = column.cluster_planes(k.x, k.y, 0);
                    let aabb = sphere_intersects_aabb(s.center, r, min, max);
                    let both = aabb && sphere_intersects_planes(s.center, r, &planes);
                    let tile = &coarse[(k.x / span + k.y / span * across) as usize];
                    if aabb {
                        assert!(
                            coarse_tile_accepts(tile, &s, CullTest::Aabb),
                            "aabb: {s:?} in {k:?}, span {span}"
                        );
                    }
                    if both {
                        assert!(
                            coarse_tile_accepts(tile, &s, CullTest::Both),
                            "both: {s:?} in {k:?}, span {span}"
                        );
                    }
                }
            }
        }
        if projection.orthographic_half_extent(1.0).is_none() {
            assert!(planes_rejected > 0, "the planes never cut: {viewport:?} {projection:?}");
        }
    }
}

/// Level 0 of the build marks a light only in the coarse tiles of its rectangle
/// (`RectGrid::light_tile_rect`, computed once per light on the GPU): exact only if the rectangle holds
/// every tile whose column accepts the light (each test, radius × 1.001); the coarse tile of
/// such a column then lies in the rectangle divided by the span, and accepts the light (the
/// test above). Checked on random lights in front of, around and behind
/// the eye, huge and tiny ones, in wide, narrow, extreme and orthographic views; the rectangles
/// must also be small where they can be, or the build gains nothing.
#[test]
fn a_light_rectangle_holds_every_tile_that_accepts_the_light() {
    use manylight_core::cluster::{RectGrid, sphere_passes};
    let mut rnd = uniform(0x51_7cc1_b727_220a);
    let cases = [
        (UVec2::new(1280, 720), Projection::perspective(0.8, 0.1, 1000.0)),
        (UVec2::new(200, 120), Projection::perspective(1.0, 0.1, 200.0)),
        (UVec2::new(96, 64), Projection::perspective(2.8, 0.01, 50.0)),
        (UVec2::new(640, 17), Projection::perspective(0.01, 0.5, 50.0)),
        (UVec2::new(1, 1), Projection::perspective(3.1, 1e-4, 1e6)),
        (UVec2::new(200, 120), Projection::orthographic(30.0, 0.5, 100.0)),
    ];
    for (viewport, projection) in cases {
        let (grid, column) = grid_and_columns(viewport, &projection);
        let dims = column.dims;
        let rects = RectGrid::of(&grid);
        assert_eq!(rects, RectGrid::of(&column), "the grid and its columns share the rectangles");
        let extent = projection.far.min(100.0);
        let (mut area, mut in_view) = (0u64, 0u64);
        for i in 0..800 {
            // A third of the lights within a few radii of the eye, some behind it; some beside
            // it, far off the axis (a shell of lights around the camera); a few huge.
            let beside = i % 7 == 0;
            let d = match () {
                _ if beside => (rnd() - 0.5) * 0.5,
                _ if i % 3 == 0 => (rnd() - 0.3) * 2.0,
                _ => rnd() * extent,
            };
            let spread = if beside { extent } else { d.abs().max(1.0) * 2.0 };
            let radius = match i % 50 {
                0 => 1e6,
                1 => 0.0,
                2 => f32::NAN,
                _ => rnd() * if i % 3 == 0 { 2.0 } else { extent * 0.05 },
            };
            let s =
                ViewSphere { center: Vec3::new((rnd() - 0.5) * spread, (rnd() - 0.5) * spread, -d), radius };
            for test in CullTest::ALL {
                let rect = rects.light_tile_rect(s.center.extend(s.radius), test);
                let inside = |x: u32, y: u32| {
                    rect.is_some_and(|[x0, y0, x1, y1]| (x0..=x1).contains(&x) && (y0..=y1).contains(&y))
                };
                let wide = ViewSphere { radius: s.radius * INFLATION, ..s };
                let mut accepted = false;
                for t in 0..column.cluster_count() {
                    let k = column.coords(t);
                    let bounds = (column.cluster_aabb(k.x, k.y, 0), column.cluster_planes(k.x, k.y, 0));
                    if sphere_passes(test, &wide, bounds.0, &bounds.1) {
                        accepted = true;
                        assert!(
                            inside(k.x, k.y),
                            "{test:?}: {s:?} in column {k:?} outside {rect:?}, {viewport:?} {projection:?}"
                        );
                    }
                }
                if test == CullTest::Both && accepted && d > 4.0 * s.radius {
                    let [x0, y0, x1, y1] = rect.expect("accepted");
                    area += u64::from(x1 - x0 + 1) * u64::from(y1 - y0 + 1);
                    in_view += 1;
                }
            }
        }
        // A light beside the eye, off the screen, reaches no tile's planes.
        if projection.orthographic_half_extent(1.0).is_none() && grid.fov_y < 3.0 {
            let beside = Vec3::new(0.2, extent * 0.5, 0.1).extend(0.3);
            for test in [CullTest::Planes, CullTest::Both] {
                assert_eq!(rects.light_tile_rect(beside, test), None);
            }
        }
        // Lights well in front of the eye cover a few tiles, not the screen (where it has many).
        let tiles = u64::from(dims.x * dims.y);
        if tiles >= 100 && projection.orthographic_half_extent(1.0).is_none() && in_view > 0 {
            assert!(
                area < in_view * tiles / 4,
                "{area} tiles in {in_view} rectangles of {tiles}: {viewport:?} {projection:?}"
            );
        }
    }
}

//! The GPU cluster build first keeps, per screen tile, the lights that pass the chosen test
//! against the tile's whole column (one slice from near to far, radius × 1.001), then tests
//! only those against each cluster. That is exact only if every light a cluster accepts is
//! also accepted by its column, for each test on its own; this checks it on random lights.

use glam::{UVec2, UVec3, Vec3};
use manylight_core::Projection;
use manylight_core::cluster::{
    ClusterGrid, GridConfig, ViewSphere, ZSlicing, sphere_intersects_aabb, sphere_intersects_planes,
};

/// The GPU build's tile-level inflation (emitted into shaders/cluster_build.wgsl).
const INFLATION: f32 = manylight_core::cluster::TILE_PREFILTER_INFLATION;

#[test]
fn a_column_accepts_every_light_its_clusters_accept() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
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

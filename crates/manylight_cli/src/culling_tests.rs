//! `manylight culling-tests`: false-positive rates of the sphere–cluster tests. Random lights
//! in a 1280×720 view with the default grid are tested against every cluster with each test;
//! the pairs each accepts are compared with an exact sphere–frustum-piece test. CPU only.

use glam::{UVec2, Vec3};
use manylight_core::Projection;
use manylight_core::cluster::{ClusterGrid, CullTest, GridConfig, ViewSphere, false_positive_counts};
use manylight_scene::SplitMix64;
use std::fmt::Write as _;

/// `lights` random lights spread over the first 100 units of depth (radius 0.5–5), a little
/// beyond the view's sides, as view-space spheres.
pub fn scene(grid: &ClusterGrid, lights: usize, seed: u64) -> Vec<ViewSphere> {
    let mut rng = SplitMix64(seed ^ 0x9E37_79B9_7F4A_7C15);
    let tan = grid.tan_half_fov();
    (0..lights)
        .map(|_| {
            let d = rng.range(0.5, 100.0);
            let (nx, ny) = (rng.range(-1.1, 1.1), rng.range(-1.1, 1.1));
            ViewSphere { center: Vec3::new(nx * tan.x * d, ny * tan.y * d, -d), radius: rng.range(0.5, 5.0) }
        })
        .collect()
}

/// The grid every figure uses: 1280×720, 60° vertical fov, near 0.1, far 100, default config.
pub fn grid() -> ClusterGrid {
    ClusterGrid::new(
        UVec2::new(1280, 720),
        &Projection::perspective(60f32.to_radians(), 0.1, 100.0),
        &GridConfig::default(),
    )
}

/// Accepted and truly intersecting pairs of each test, as a markdown table.
pub fn table(lights: usize, seed: u64) -> String {
    let g = grid();
    let spheres = scene(&g, lights, seed);
    let mut out = format!(
        "1280×720, {}×{}×{} grid, 60° fov, near 0.1, far 100, {lights} random lights (radius 0.5–5):\n\n\
         | test | accepted | truly intersecting | false positives |\n|---|---:|---:|---:|\n",
        g.dims.x, g.dims.y, g.dims.z
    );
    for test in CullTest::ALL {
        let (accepted, truly) = false_positive_counts(&g, &spheres, test);
        let rate = if accepted == 0 { 0.0 } else { 1.0 - truly as f64 / accepted as f64 };
        let _ = writeln!(out, "| {} | {accepted} | {truly} | {:.1} % |", test.name(), rate * 100.0);
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_table_has_a_row_per_test() {
        let t = super::table(64, 1);
        assert_eq!(t.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| test")).count(), 3, "{t}");
    }
}

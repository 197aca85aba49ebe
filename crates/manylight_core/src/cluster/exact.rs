//! Exact sphere–cluster intersection (in `f64`, no margins, no inflation) and the false-positive
//! measurement of the conservative tests.
//!
//! The cluster's frustum piece is convex, bounded by six planes. The distance from a point `c`
//! to it is:
//!
//! 1. `0` if `c` is inside all six planes;
//! 2. otherwise the smallest of: the distance to each face plane whose foot point `q` lies
//!    inside the other five planes (then `q` is on that face), and the distance to each of the
//!    12 edges as segments (which covers the 8 corners).
//!
//! The sphere touches the cluster when that distance is `<= r`.

use glam::DVec3;

use super::candidates::ClusterTables;
use super::cull::ViewSphere;
use super::{ClusterGrid, CullTest};

/// The exact frustum piece of one cluster: corners and unit inward planes, in `f64`.
struct Piece {
    /// Corner `i` has x from bit 0, y from bit 1, depth from bit 2 of `i`.
    corners: [DVec3; 8],
    planes: [(DVec3, f64); 6],
}

impl Piece {
    fn new(grid: &ClusterGrid, x: u32, y: u32, z: u32) -> Piece {
        let [nx, ny, _] = grid.dims.to_array().map(f64::from);
        let ndc_x = [2.0 * f64::from(x) / nx - 1.0, 2.0 * f64::from(x + 1) / nx - 1.0];
        // Bottom edge first (row y + 1), then top (row y).
        let ndc_y = [1.0 - 2.0 * f64::from(y + 1) / ny, 1.0 - 2.0 * f64::from(y) / ny];
        let d = [f64::from(grid.slice_boundary(z)), f64::from(grid.slice_boundary(z + 1))];
        let depth_planes = [(DVec3::new(0.0, 0.0, -1.0), -d[0]), (DVec3::new(0.0, 0.0, 1.0), d[1])];
        if let Some(h) = grid.ortho_half {
            // A box: edges at ndc × half-extent, at any depth.
            let ax = ndc_x.map(|a| a * f64::from(h.x));
            let ay = ndc_y.map(|a| a * f64::from(h.y));
            let corners = std::array::from_fn(|i| DVec3::new(ax[i & 1], ay[(i >> 1) & 1], -d[i >> 2]));
            let planes = [
                (DVec3::X, -ax[0]),
                (DVec3::NEG_X, ax[1]),
                (DVec3::Y, -ay[0]),
                (DVec3::NEG_Y, ay[1]),
                depth_planes[0],
                depth_planes[1],
            ];
            return Piece { corners, planes };
        }
        let tan_y = (0.5 * f64::from(grid.fov_y)).tan();
        let tan_x = tan_y * f64::from(grid.aspect);
        let ax = ndc_x.map(|a| a * tan_x);
        let ay = ndc_y.map(|a| a * tan_y);
        let corners = std::array::from_fn(|i| {
            DVec3::new(ax[i & 1] * d[i >> 2], ay[(i >> 1) & 1] * d[i >> 2], -d[i >> 2])
        });
        let planes = [
            (DVec3::new(1.0, 0.0, ax[0]).normalize(), 0.0),
            (DVec3::new(-1.0, 0.0, -ax[1]).normalize(), 0.0),
            (DVec3::new(0.0, 1.0, ay[0]).normalize(), 0.0),
            (DVec3::new(0.0, -1.0, -ay[1]).normalize(), 0.0),
            depth_planes[0],
            depth_planes[1],
        ];
        Piece { corners, planes }
    }

    /// Distance from `c` to the piece (module docs).
    fn distance(&self, c: DVec3) -> f64 {
        let signed: [f64; 6] = self.planes.map(|(n, w)| n.dot(c) + w);
        if signed.iter().all(|&s| s >= 0.0) {
            return 0.0;
        }
        let scale = self.corners.iter().fold(c.abs().max_element(), |m, p| m.max(p.abs().max_element()));
        let tolerance = 1e-12 * scale;
        let mut best = f64::INFINITY;
        for (i, &(n, _)) in self.planes.iter().enumerate() {
            if signed[i] >= 0.0 {
                continue;
            }
            let q = c - signed[i] * n;
            let on_face =
                self.planes.iter().enumerate().all(|(j, &(m, w))| j == i || m.dot(q) + w >= -tolerance);
            if on_face {
                best = best.min(-signed[i]);
            }
        }
        for a in 0..8usize {
            for bit in [1usize, 2, 4] {
                if a & bit == 0 {
                    best = best.min(segment_distance(c, self.corners[a], self.corners[a | bit]));
                }
            }
        }
        best
    }
}

/// Distance from `c` to the segment `[a, b]`.
fn segment_distance(c: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 { ((c - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + t * ab).distance(c)
}

/// Exact test: does the sphere meet the frustum piece of cluster `(x, y, z)` (no margin, no
/// inflation, `f64`)? False for invalid spheres.
pub fn sphere_touches_cluster_exact(grid: &ClusterGrid, light: &ViewSphere, x: u32, y: u32, z: u32) -> bool {
    light.is_valid() && Piece::new(grid, x, y, z).distance(light.center.as_dvec3()) <= f64::from(light.radius)
}

/// How many (light, cluster) pairs `test` accepts, and how many of those truly intersect by the
/// exact test: `(accepted_pairs, truly_intersecting_pairs)`. The false-positive rate is
/// `1 - truly / accepted`.
pub fn false_positive_counts(grid: &ClusterGrid, lights: &[ViewSphere], test: CullTest) -> (u64, u64) {
    let tables = ClusterTables::new(grid);
    let (mut accepted, mut truly) = (0u64, 0u64);
    for light in lights {
        tables.for_each_touched(light, test, |cluster| {
            accepted += 1;
            let c = grid.coords(cluster);
            truly += u64::from(sphere_touches_cluster_exact(grid, light, c.x, c.y, c.z));
        });
    }
    (accepted, truly)
}

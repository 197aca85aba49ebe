//! Culling efficiency of a light assignment for one rendered frame: how many light–pixel pairs
//! the shader evaluates (every light in each pixel's cluster list) against how many of them
//! contribute (the pixel lies strictly inside the light's sphere, where attenuation > 0).
//!
//! 1. reconstruct each covered pixel's view-space position from its pixel centre and the
//!    reverse-Z depth buffer;
//! 2. find its cluster and count the list's lights (evaluated) and those whose sphere contains
//!    the point (contributing);
//! 3. on a sample of pixels, also test every light, to catch a contributing light missing from
//!    the list (must be zero for a conservative assignment).

use crate::Projection;
use crate::cluster::{ClusterAssignment, ClusterGrid, ViewSphere};
use glam::{Vec2, Vec3};

/// The result of [`culling_efficiency`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CullingEfficiency {
    /// Pixels covered by geometry.
    pub pixels: u64,
    /// Light–pixel pairs the shader evaluates.
    pub evaluated_pairs: u64,
    /// Light–pixel pairs with a non-zero contribution.
    pub contributing_pairs: u64,
    /// Pixels checked against every light.
    pub sampled_pixels: u64,
    /// Contributing light–pixel pairs missing from the lists on the sampled pixels (a bug if
    /// not zero).
    pub missed_pairs: u64,
}

impl CullingEfficiency {
    /// Evaluated ÷ contributing pairs (1 is perfect; `inf` when nothing contributes).
    pub fn ratio(&self) -> f64 {
        self.evaluated_pairs as f64 / self.contributing_pairs as f64
    }
}

/// Measures the efficiency of `assignment` for a frame whose depth buffer (reverse-Z, row-major,
/// `size.x * size.y` values, 0 = background) is `depth`. Every `sample_stride`-th covered
/// pixel is also checked against all lights.
pub fn culling_efficiency(
    grid: &ClusterGrid,
    projection: &Projection,
    assignment: &ClusterAssignment,
    lights: &[ViewSphere],
    depth: &[f32],
    sample_stride: usize,
) -> CullingEfficiency {
    let p = projection.sanitized();
    let (w, h) = (grid.viewport.x.max(1), grid.viewport.y.max(1));
    let aspect = w as f32 / h as f32;
    let inside = |s: &ViewSphere, q: Vec3| s.is_valid() && s.center.distance_squared(q) < s.radius * s.radius;
    let mut out = CullingEfficiency::default();
    for y in 0..h {
        for x in 0..w {
            let z = depth.get((y * w + x) as usize).copied().unwrap_or(0.0);
            if z <= 0.0 || !z.is_finite() {
                continue;
            }
            let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ndc = Vec2::new(px.x / w as f32 * 2.0 - 1.0, 1.0 - px.y / h as f32 * 2.0);
            let q = p.view_position(ndc, z, aspect);
            let d = -q.z;
            let list = assignment.lights_of(grid.cluster_of(px, d));
            out.pixels += 1;
            out.evaluated_pairs += list.len() as u64;
            let hits = list.iter().filter(|&&l| lights.get(l as usize).is_some_and(|s| inside(s, q))).count();
            out.contributing_pairs += hits as u64;
            if sample_stride > 0 && (out.pixels as usize).is_multiple_of(sample_stride) {
                out.sampled_pixels += 1;
                let all = lights.iter().filter(|s| inside(s, q)).count();
                out.missed_pairs += all.saturating_sub(hits) as u64;
            }
        }
    }
    out
}

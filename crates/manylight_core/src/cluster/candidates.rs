//! Per-grid tables and per-light candidate ranges: which clusters a light *could* pass a test
//! for, so the exact test runs on a few clusters instead of all of them.
//!
//! 1. **Tables** ([`ClusterTables::new`]): slice boundaries, margins, the AABB extents per
//!    column/row/slice and the plane normals per column/row, built with the very helpers
//!    [`ClusterGrid::cluster_aabb`] and [`ClusterGrid::cluster_planes`] use, so a test on the
//!    tables gives the same answer bit for bit as a test on the grid's own bounds.
//! 2. **Slices**: a test can only pass in slice `z` if `b(z) - 2m(z) <= d + r'` and
//!    `b(z+1) + 2m(z) >= d - r'` (`d = -c.z`, `m` the margin, `r'` the inflated radius, plus a
//!    slack for rounding); both sides are made monotone in `z`, so two binary searches give the
//!    slice range.
//! 3. **Tiles**, with `R = r' + 2m(z_hi) + slack` (bigger than anything the margins and rounding
//!    can add):
//!    - AABB test: the sphere's box `c ± R` must overlap the cluster's box; over the slice range
//!      `[D0, D1]` that bounds the tile's NDC edges by `(c ± R) / D0` or `/ D1`.
//!    - planes test: if the sphere lies in front of the camera (`d > R`), a tile's side planes
//!      pass exactly when its edges straddle the sphere's tangent slopes `x/d` (a contiguous
//!      range). Otherwise the offset planes can pass in disjoint tiles (e.g. a sphere beside the
//!      camera passes the far-left and far-right columns), so the whole screen is a candidate.
//!    - both tests: the intersection of the two ranges (the box range alone is loose for deep
//!      slices, such as the one-slice columns of the GPU build's first level).
//! 4. NDC ranges become tile ranges with a small pad for the rounding of the tile edges.

use glam::{DVec3, Vec3, Vec4};

use super::cull::{ViewSphere, inflated_radius, sphere_intersects_aabb, sphere_intersects_planes};
use super::{ClusterGrid, CullTest};

/// Relative slack for rounding in the tests, applied to `|c|₁ + r'`.
const SLACK: f64 = 4e-6;

/// Inclusive ranges of tile columns, tile rows and slices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Candidates {
    pub x: [u32; 2],
    pub y: [u32; 2],
    pub z: [u32; 2],
}

/// Everything about a grid that the per-light loop reads (module docs, step 1).
pub(crate) struct ClusterTables {
    grid: ClusterGrid,
    boundary: Vec<f32>,
    margin: Vec<f32>,
    x_ext: Vec<(f32, f32)>,
    y_ext: Vec<(f32, f32)>,
    z_ext: Vec<(f32, f32)>,
    x_planes: Vec<(Vec4, Vec4)>,
    y_planes: Vec<(Vec4, Vec4)>,
    /// Suffix minimum of `b(z) - 2m(z)`.
    lo_eff: Vec<f64>,
    /// Prefix maximum of `b(z+1) + 2m(z)`.
    hi_eff: Vec<f64>,
    tan: [f64; 2],
}

impl ClusterTables {
    /// Precomputes the tables for `grid`.
    pub fn new(grid: &ClusterGrid) -> Self {
        let [nx, ny, nz] = grid.dims.to_array();
        let boundary: Vec<f32> = (0..=nz).map(|k| grid.slice_boundary(k)).collect();
        let margin: Vec<f32> = (0..nz).map(|z| grid.cluster_margin(z)).collect();
        let grid_of = |n: u32, f: &dyn Fn(u32, u32) -> (f32, f32)| {
            (0..nz).flat_map(|z| (0..n).map(move |i| (i, z))).map(|(i, z)| f(i, z)).collect::<Vec<_>>()
        };
        let x_ext = grid_of(nx, &|x, z| grid.x_extent(x, z));
        let y_ext = grid_of(ny, &|y, z| grid.y_extent(y, z));
        let mut lo_eff: Vec<f64> =
            (0..nz as usize).map(|z| f64::from(boundary[z]) - 2.0 * f64::from(margin[z])).collect();
        for z in (0..lo_eff.len().saturating_sub(1)).rev() {
            lo_eff[z] = lo_eff[z].min(lo_eff[z + 1]);
        }
        let mut hi_eff: Vec<f64> =
            (0..nz as usize).map(|z| f64::from(boundary[z + 1]) + 2.0 * f64::from(margin[z])).collect();
        for z in 1..hi_eff.len() {
            hi_eff[z] = hi_eff[z].max(hi_eff[z - 1]);
        }
        let tan = grid.tan_half_fov();
        ClusterTables {
            grid: *grid,
            z_ext: (0..nz).map(|z| grid.z_extent(z)).collect(),
            x_planes: (0..nx).map(|x| grid.x_planes(x)).collect(),
            y_planes: (0..ny).map(|y| grid.y_planes(y)).collect(),
            boundary,
            margin,
            x_ext,
            y_ext,
            lo_eff,
            hi_eff,
            tan: [f64::from(tan.x), f64::from(tan.y)],
        }
    }

    /// The chosen test for `light` against cluster `(x, y, z)`; identical to testing against
    /// `grid.cluster_aabb` / `grid.cluster_planes`.
    #[inline]
    pub fn touches(&self, light: &ViewSphere, x: u32, y: u32, z: u32, test: CullTest) -> bool {
        match test {
            CullTest::Aabb => self.touches_aabb(light, x, y, z),
            CullTest::Planes => self.touches_planes(light, x, y, z),
            CullTest::Both => self.touches_aabb(light, x, y, z) && self.touches_planes(light, x, y, z),
        }
    }

    fn touches_aabb(&self, light: &ViewSphere, x: u32, y: u32, z: u32) -> bool {
        let (zu, dx, dy) = (z as usize, self.grid.dims.x as usize, self.grid.dims.y as usize);
        let xe = self.x_ext[zu * dx + x as usize];
        let ye = self.y_ext[zu * dy + y as usize];
        let ze = self.z_ext[zu];
        let min = Vec3::new(xe.0, ye.0, ze.0);
        let max = Vec3::new(xe.1, ye.1, ze.1);
        sphere_intersects_aabb(light.center, light.radius, min, max)
    }

    fn touches_planes(&self, light: &ViewSphere, x: u32, y: u32, z: u32) -> bool {
        let zu = z as usize;
        let m = self.margin[zu];
        let (left, right) = self.x_planes[x as usize];
        let (bottom, top) = self.y_planes[y as usize];
        let margin = Vec4::new(0.0, 0.0, 0.0, m);
        let planes = [
            left + margin,
            right + margin,
            bottom + margin,
            top + margin,
            Vec4::new(0.0, 0.0, -1.0, m - self.boundary[zu]),
            Vec4::new(0.0, 0.0, 1.0, m + self.boundary[zu + 1]),
        ];
        sphere_intersects_planes(light.center, light.radius, &planes)
    }

    /// Calls `f(cluster_index)` for every cluster `light` passes `test` for, in index order.
    pub fn for_each_touched(&self, light: &ViewSphere, test: CullTest, mut f: impl FnMut(u32)) {
        let Some(c) = self.candidates(light, test) else { return };
        for z in c.z[0]..=c.z[1] {
            for y in c.y[0]..=c.y[1] {
                for x in c.x[0]..=c.x[1] {
                    if self.touches(light, x, y, z, test) {
                        f(self.grid.index(x, y, z));
                    }
                }
            }
        }
    }

    /// Conservative cluster ranges for `light` under `test` (module docs, steps 2–4); `None`
    /// when it can touch no cluster.
    pub fn candidates(&self, light: &ViewSphere, test: CullTest) -> Option<Candidates> {
        if !light.is_valid() {
            return None;
        }
        let c: DVec3 = light.center.as_dvec3();
        let r = f64::from(inflated_radius(light.radius));
        let slack = SLACK * (c.x.abs() + c.y.abs() + c.z.abs() + r);
        let d = -c.z;

        // Step 2: slices.
        let z_lo = self.hi_eff.partition_point(|&h| h < d - r - slack);
        let z_end = self.lo_eff.partition_point(|&l| l <= d + r + slack);
        if z_lo >= z_end {
            return None;
        }
        let z_hi = z_end - 1;

        // Step 3: tiles.
        let big_r = r + 2.0 * f64::from(self.margin[z_hi]) + slack;
        let (x, y) = match (self.grid.ortho_half, test) {
            // Orthographic: the clusters are boxes whose side planes are their box faces, so
            // every test needs the sphere's box to overlap the tile's x and y ranges.
            (Some(h), _) => {
                let (hx, hy) = (f64::from(h.x), f64::from(h.y));
                let x = [(c.x - big_r) / hx, (c.x + big_r) / hx];
                let y = [(c.y - big_r) / hy, (c.y + big_r) / hy];
                return self.tile_candidates(x, y, [z_lo as u32, z_hi as u32]);
            }
            (None, test) => match test {
                // Both: both tests must accept, so a cluster lies in both search ranges.
                CullTest::Aabb | CullTest::Both => {
                    let (d0, d1) = (f64::from(self.boundary[z_lo]), f64::from(self.boundary[z_hi + 1]));
                    let boxed = (box_ndc(c.x, big_r, d0, d1), box_ndc(c.y, big_r, d0, d1));
                    if test == CullTest::Both && d > big_r * (1.0 + 1e-6) {
                        let meet = |a: [f64; 2], b: [f64; 2]| [a[0].max(b[0]), a[1].min(b[1])];
                        (meet(boxed.0, tangent_ndc(c.x, d, big_r)), meet(boxed.1, tangent_ndc(c.y, d, big_r)))
                    } else {
                        boxed
                    }
                }
                CullTest::Planes if d > big_r * (1.0 + 1e-6) => {
                    (tangent_ndc(c.x, d, big_r), tangent_ndc(c.y, d, big_r))
                }
                CullTest::Planes => ([f64::NEG_INFINITY, f64::INFINITY], [f64::NEG_INFINITY, f64::INFINITY]),
            },
        };
        let x = x.map(|s| s / self.tan[0]);
        let y = y.map(|s| s / self.tan[1]);
        self.tile_candidates(x, y, [z_lo as u32, z_hi as u32])
    }

    /// Step 4: NDC ranges → tiles. Column k spans NDC [-1 + 2k/X, -1 + 2(k+1)/X]; row k spans
    /// [1 - 2(k+1)/Y, 1 - 2k/Y].
    fn tile_candidates(&self, x: [f64; 2], y: [f64; 2], z: [u32; 2]) -> Option<Candidates> {
        let [nx, ny, _] = self.grid.dims.to_array();
        let x_range = tile_range((x[0] + 1.0) * 0.5 * f64::from(nx), (x[1] + 1.0) * 0.5 * f64::from(nx), nx)?;
        let y_range = tile_range((1.0 - y[1]) * 0.5 * f64::from(ny), (1.0 - y[0]) * 0.5 * f64::from(ny), ny)?;
        Some(Candidates { x: x_range, y: y_range, z })
    }
}

/// NDC-slope range `[lo, hi]` (`x/d`) a tile's edges must straddle for the box test: the
/// cluster box over depths `[d0, d1]` must overlap `[a - r, a + r]`.
fn box_ndc(a: f64, r: f64, d0: f64, d1: f64) -> [f64; 2] {
    let hi = a + r;
    let lo = a - r;
    [lo / if lo <= 0.0 { d0 } else { d1 }, hi / if hi >= 0.0 { d0 } else { d1 }]
}

/// Slopes `x/d` of the two lines through the origin tangent to the circle of radius `r` around
/// `(a, d)` (requires `d > r`): `(a d ∓ r √(a² + d² - r²)) / (d² - r²)`.
fn tangent_ndc(a: f64, d: f64, r: f64) -> [f64; 2] {
    let den = (d - r) * (d + r);
    let root = r * (a * a + den).sqrt();
    [(a * d - root) / den, (a * d + root) / den]
}

/// Tiles `k` whose span `[k, k+1]` (in tile units) meets `[lo, hi]`, padded for rounding of the
/// tile edges, clamped to `0..n`; `None` when it misses the screen. NaN gives the full range.
fn tile_range(lo: f64, hi: f64, n: u32) -> Option<[u32; 2]> {
    if lo.is_nan() || hi.is_nan() {
        return Some([0, n - 1]);
    }
    let pad = 1e-3 + 1e-6 * f64::from(n);
    let last = f64::from(n - 1);
    let first = (lo - pad).ceil() - 1.0;
    let end = (hi + pad).floor();
    if first > last || end < 0.0 || first > end {
        return None;
    }
    Some([first.clamp(0.0, last) as u32, end.clamp(0.0, last) as u32])
}

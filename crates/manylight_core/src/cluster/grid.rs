//! The cluster grid: screen tiles × depth slices, and each cluster's view-space bounds.
//!
//! Conventions (view space is right-handed, the camera looks down -Z, `d = -z` is the positive
//! view distance; framebuffer pixels have their origin at the top left):
//!
//! 1. **Frustum**: `tan_y = tan(fov_y / 2)`, `tan_x = tan_y * aspect`; a point with NDC
//!    `(nx, ny)` at distance `d` is `(nx * tan_x * d, ny * tan_y * d, -d)`.
//! 2. **Tiles**: tile `x` spans NDC x `[-1 + 2x/X, -1 + 2(x+1)/X]` (pixels
//!    `[x·W/X, (x+1)·W/X)`); tile `y = 0` is at the **top**: NDC y `[1 - 2(y+1)/Y, 1 - 2y/Y]`.
//! 3. **Slices**: boundary `k ∈ 0..=Z` is `slice_boundary(k)` (linear or exponential), exactly
//!    `near` at `k = 0` and `far` at `k = Z`, never decreasing.
//! 4. **Margin**: every bound of every cluster in slice `z` is widened outwards by
//!    `cluster_margin(z) = CLUSTER_MARGIN * slice_boundary(z + 1) * max(1, tan_x, tan_y)`, the
//!    largest coordinate any point of the slice can have times `1e-5`. Float error in a view
//!    position (CPU or GPU) is relative to that magnitude, so the margin absorbs it.
//! 5. **Bounds**: the AABB is the box of the 8 corners of the frustum piece, then ± margin; the
//!    planes are the tile's four edge planes through the origin plus `z = -boundary`, with unit
//!    inward normals and the margin added to `w`.
//! 6. **Orthographic** views: a point with NDC `(nx, ny)` is `(nx * half_x, ny * half_y, -d)` at
//!    any distance, so a cluster is a box; its side planes are axis-aligned with offsets
//!    (`x >= a0` is `(1, 0, 0) · p - a0 >= 0`), the margin is `CLUSTER_MARGIN * max(boundary,
//!    half_x, half_y)`, and the slices are always linear in depth.

use glam::{UVec2, UVec3, Vec2, Vec3, Vec4};

use super::ZSlicing;
use crate::Projection;

/// Largest number of tiles or slices along one axis.
pub const MAX_GRID_DIM: u32 = 4096;
/// Largest number of clusters in a grid; larger requests are shrunk to fit.
pub const MAX_CLUSTERS: u32 = 1 << 20;
/// Relative widening of cluster bounds (see the module docs, step 4).
pub const CLUSTER_MARGIN: f32 = 1e-5;

/// Sizes a grid: tiles of about `tile_px` pixels, `z_slices` slices, or explicit dims.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridConfig {
    /// Target tile edge in pixels (0 is treated as 1).
    pub tile_px: u32,
    /// Number of depth slices.
    pub z_slices: u32,
    /// Explicit `X × Y × Z`, overriding `tile_px` and `z_slices`.
    pub dims: Option<UVec3>,
    /// How slice boundaries are spaced.
    pub slicing: ZSlicing,
}

impl Default for GridConfig {
    fn default() -> Self {
        Self { tile_px: 16, z_slices: 24, dims: None, slicing: ZSlicing::default() }
    }
}

impl GridConfig {
    /// Grid dimensions for a viewport: auto or override, each axis in `1..=MAX_GRID_DIM`, and
    /// the product at most `MAX_CLUSTERS` (the largest axis shrinks first).
    pub fn dims_for(&self, viewport: UVec2) -> UVec3 {
        let viewport = viewport.max(UVec2::ONE);
        let tile = self.tile_px.max(1);
        let wanted = self.dims.unwrap_or(UVec3::new(
            viewport.x.div_ceil(tile),
            viewport.y.div_ceil(tile),
            self.z_slices,
        ));
        let mut d = wanted.clamp(UVec3::ONE, UVec3::splat(MAX_GRID_DIM)).to_array();
        while d.iter().map(|&v| u64::from(v)).product::<u64>() > u64::from(MAX_CLUSTERS) {
            // Shrink the largest axis (x first on ties) by about 6 %: keeps tiles roughly square.
            let axis = (0..3).max_by_key(|&i| (d[i], 3 - i)).unwrap_or(0);
            d[axis] -= (d[axis] / 16).max(1);
        }
        UVec3::from_array(d)
    }
}

/// A cluster grid for one view: dimensions plus the frustum it divides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterGrid {
    /// Tiles in x and y, slices in z.
    pub dims: UVec3,
    /// Framebuffer size in pixels (each axis at least 1).
    pub viewport: UVec2,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near, finite).
    pub far: f32,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// `viewport.x / viewport.y`.
    pub aspect: f32,
    /// How slice boundaries are spaced (always linear for an orthographic view).
    pub slicing: ZSlicing,
    /// Half the visible width and height of an orthographic view; `None` for perspective.
    pub ortho_half: Option<Vec2>,
}

impl ClusterGrid {
    /// Builds the grid for a viewport and projection; every input is sanitized, so the grid is
    /// always usable (dims ≥ 1, finite `0 < near < far`, fov in `(0, π)`).
    ///
    /// The grid needs a finite far plane. Pass an infinite projection through
    /// [`Projection::finite_for`] with the lights' reach first (the renderer does); one passed
    /// as it is gets `near × 10⁴`, and a light beyond that would reach no cluster.
    pub fn new(viewport: UVec2, projection: &Projection, config: &GridConfig) -> ClusterGrid {
        let viewport = viewport.max(UVec2::ONE);
        let p = projection.sanitized();
        // `sanitized` can overflow `far` for an absurd near plane; keep both finite.
        let near = p.near.min(1e30);
        let far = if p.far.is_finite() && p.far > near { p.far } else { near * 1e4 };
        let aspect = viewport.x as f32 / viewport.y as f32;
        let ortho_half = p.orthographic_half_extent(aspect);
        ClusterGrid {
            dims: config.dims_for(viewport),
            viewport,
            near,
            far,
            fov_y: p.fov_y,
            aspect,
            // Depth is linear in an orthographic view, and so are its slices.
            slicing: if ortho_half.is_some() { ZSlicing::Linear } else { config.slicing },
            ortho_half,
        }
    }

    /// Number of clusters, `X * Y * Z`.
    pub fn cluster_count(&self) -> u32 {
        self.dims.x * self.dims.y * self.dims.z
    }

    /// Linear cluster index `x + y*X + z*X*Y`.
    pub fn index(&self, x: u32, y: u32, z: u32) -> u32 {
        x + y * self.dims.x + z * self.dims.x * self.dims.y
    }

    /// Inverse of [`ClusterGrid::index`].
    pub fn coords(&self, index: u32) -> UVec3 {
        let layer = self.dims.x * self.dims.y;
        UVec3::new(index % self.dims.x, (index % layer) / self.dims.x, index / layer)
    }

    /// Half-extent `(x, y)` of the view at view distance `d`: `tan_half_fov() * d`, or the
    /// orthographic half-extent at any distance.
    pub fn half_extent_at(&self, d: f32) -> Vec2 {
        self.ortho_half.unwrap_or_else(|| self.tan_half_fov() * d)
    }

    /// `(tan_x, tan_y)`: half-extent of the frustum per unit of view distance (perspective).
    pub fn tan_half_fov(&self) -> Vec2 {
        let tan_y = (0.5 * self.fov_y).tan();
        Vec2::new(tan_y * self.aspect, tan_y)
    }

    /// `ln(far / near)`, the exponent range of exponential slicing.
    fn log_ratio(&self) -> f32 {
        let l = (self.far / self.near).ln();
        if l.is_finite() { l } else { self.far.ln() - self.near.ln() }
    }

    /// View distance (positive) of slice boundary `k ∈ 0..=Z` (clamped): exactly `near` at 0 and
    /// `far` at `Z`, never decreasing in `k`. In between, with `t = f32(k) / f32(Z)`:
    /// linear `near + (far - near) * t`, exponential `near * exp(log(far / near) * t)`, both
    /// clamped to `[near, far]`.
    pub fn slice_boundary(&self, k: u32) -> f32 {
        let z = self.dims.z;
        if k == 0 {
            return self.near;
        }
        if k >= z {
            return self.far;
        }
        let t = k as f32 / z as f32;
        let b = match self.slicing {
            ZSlicing::Linear => self.near + (self.far - self.near) * t,
            ZSlicing::Exponential => self.near * (self.log_ratio() * t).exp(),
        };
        b.clamp(self.near, self.far)
    }

    /// Slice holding view distance `d`: the `k` with `slice_boundary(k) <= d <
    /// slice_boundary(k + 1)`, clamped to `0..Z` (`d <= near` and NaN give 0, `d >= far` gives
    /// `Z - 1`).
    pub fn slice_of_depth(&self, d: f32) -> u32 {
        let last = self.dims.z - 1;
        if d.is_nan() || d <= self.near {
            return 0;
        }
        if d >= self.far {
            return last;
        }
        // 1. Closed-form estimate; 2. step to the exact slice so the result agrees bit for bit
        //    with `slice_boundary` (the estimate is off by at most one in practice).
        let estimate = match self.slicing {
            ZSlicing::Linear => (d - self.near) / (self.far - self.near),
            ZSlicing::Exponential => (d.ln() - self.near.ln()) / self.log_ratio(),
        } * self.dims.z as f32;
        let mut k = (estimate as u32).min(last); // `as` saturates; NaN becomes 0
        while k > 0 && d < self.slice_boundary(k) {
            k -= 1;
        }
        while k < last && d >= self.slice_boundary(k + 1) {
            k += 1;
        }
        k
    }

    /// Tile of a framebuffer position (origin top left, pixel centres at +0.5):
    /// `floor(px * dims.xy / viewport)`, clamped into the grid (NaN gives 0).
    pub fn tile_of_pixel(&self, px: Vec2) -> UVec2 {
        let t = px * self.dims.truncate().as_vec2() / self.viewport.as_vec2();
        UVec2::new(t.x.floor() as u32, t.y.floor() as u32).min(self.dims.truncate() - UVec2::ONE)
    }

    /// Cluster of a fragment at framebuffer position `px` with view distance `d`.
    pub fn cluster_of(&self, px: Vec2, d: f32) -> u32 {
        let t = self.tile_of_pixel(px);
        self.index(t.x, t.y, self.slice_of_depth(d))
    }

    /// Outward widening of every bound of the clusters in slice `z` (module docs, step 4).
    pub fn cluster_margin(&self, z: u32) -> f32 {
        let b = self.slice_boundary(z.min(self.dims.z - 1) + 1);
        if let Some(h) = self.ortho_half {
            return CLUSTER_MARGIN * b.max(h.x).max(h.y);
        }
        let tan = self.tan_half_fov();
        CLUSTER_MARGIN * b * tan.x.max(tan.y).max(1.0)
    }

    /// NDC x of the left edge of tile column `k ∈ 0..=X` (`k = X` is the right screen edge).
    pub(crate) fn ndc_x_edge(&self, k: u32) -> f32 {
        2.0 * k as f32 / self.dims.x as f32 - 1.0
    }

    /// NDC y of the top edge of tile row `k ∈ 0..=Y` (`k = Y` is the bottom screen edge).
    pub(crate) fn ndc_y_edge(&self, k: u32) -> f32 {
        1.0 - 2.0 * k as f32 / self.dims.y as f32
    }

    /// View-space x range of column `x` over slice `z`, widened by the margin.
    pub(crate) fn x_extent(&self, x: u32, z: u32) -> (f32, f32) {
        self.x_extent_between(x, self.slice_boundary(z), self.slice_boundary(z + 1), self.cluster_margin(z))
    }

    /// View-space y range of row `y` over slice `z`, widened by the margin.
    pub(crate) fn y_extent(&self, y: u32, z: u32) -> (f32, f32) {
        self.y_extent_between(y, self.slice_boundary(z), self.slice_boundary(z + 1), self.cluster_margin(z))
    }

    /// View-space x range of column `x` between view distances `d0` and `d1`, widened by `m`
    /// (orthographic: the column's edges, at any distance).
    pub(crate) fn x_extent_between(&self, x: u32, d0: f32, d1: f32, m: f32) -> (f32, f32) {
        if let Some(h) = self.ortho_half {
            return (self.ndc_x_edge(x) * h.x - m, self.ndc_x_edge(x + 1) * h.x + m);
        }
        let tan_x = self.tan_half_fov().x;
        let (a0, a1) = (self.ndc_x_edge(x) * tan_x, self.ndc_x_edge(x + 1) * tan_x);
        extent(a0, a1, d0, d1, m)
    }

    /// View-space y range of row `y` between view distances `d0` and `d1`, widened by `m`
    /// (orthographic: the row's edges, at any distance).
    pub(crate) fn y_extent_between(&self, y: u32, d0: f32, d1: f32, m: f32) -> (f32, f32) {
        if let Some(h) = self.ortho_half {
            return (self.ndc_y_edge(y + 1) * h.y - m, self.ndc_y_edge(y) * h.y + m);
        }
        let tan_y = self.tan_half_fov().y;
        let (a0, a1) = (self.ndc_y_edge(y + 1) * tan_y, self.ndc_y_edge(y) * tan_y);
        extent(a0, a1, d0, d1, m)
    }

    /// View-space z range of slice `z`, widened by the margin.
    pub(crate) fn z_extent(&self, z: u32) -> (f32, f32) {
        let m = self.cluster_margin(z);
        (-self.slice_boundary(z + 1) - m, -self.slice_boundary(z) + m)
    }

    /// Column `x`'s left and right planes `(n, w)` without the margin: unit inward normals,
    /// through the origin (`w = 0`) in perspective, axis-aligned with offsets in orthographic.
    pub(crate) fn x_planes(&self, x: u32) -> (Vec4, Vec4) {
        if let Some(h) = self.ortho_half {
            let (a0, a1) = (self.ndc_x_edge(x) * h.x, self.ndc_x_edge(x + 1) * h.x);
            // Left: x - a0 >= 0.  Right: a1 - x >= 0.
            return (Vec4::new(1.0, 0.0, 0.0, -a0), Vec4::new(-1.0, 0.0, 0.0, a1));
        }
        let tan_x = self.tan_half_fov().x;
        let (a0, a1) = (self.ndc_x_edge(x) * tan_x, self.ndc_x_edge(x + 1) * tan_x);
        // Left: x >= a0 * d = -a0 * z  <=>  x + a0 z >= 0.  Right: -x - a1 z >= 0.
        (Vec3::new(1.0, 0.0, a0).normalize().extend(0.0), Vec3::new(-1.0, 0.0, -a1).normalize().extend(0.0))
    }

    /// Row `y`'s bottom and top planes `(n, w)` without the margin (see [`Self::x_planes`]).
    pub(crate) fn y_planes(&self, y: u32) -> (Vec4, Vec4) {
        if let Some(h) = self.ortho_half {
            let (b0, b1) = (self.ndc_y_edge(y + 1) * h.y, self.ndc_y_edge(y) * h.y);
            return (Vec4::new(0.0, 1.0, 0.0, -b0), Vec4::new(0.0, -1.0, 0.0, b1));
        }
        let tan_y = self.tan_half_fov().y;
        let (b0, b1) = (self.ndc_y_edge(y + 1) * tan_y, self.ndc_y_edge(y) * tan_y);
        (Vec3::new(0.0, 1.0, b0).normalize().extend(0.0), Vec3::new(0.0, -1.0, -b1).normalize().extend(0.0))
    }

    /// Clamps cluster coordinates into the grid.
    fn clamp_coords(&self, x: u32, y: u32, z: u32) -> (u32, u32, u32) {
        (x.min(self.dims.x - 1), y.min(self.dims.y - 1), z.min(self.dims.z - 1))
    }

    /// View-space AABB `(min, max)` of cluster `(x, y, z)` (coordinates clamped into the grid):
    /// the box of its frustum piece's 8 corners, widened by `cluster_margin(z)` on every side.
    pub fn cluster_aabb(&self, x: u32, y: u32, z: u32) -> (Vec3, Vec3) {
        let (x, y, z) = self.clamp_coords(x, y, z);
        let (x0, x1) = self.x_extent(x, z);
        let (y0, y1) = self.y_extent(y, z);
        let (z0, z1) = self.z_extent(z);
        (Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1))
    }

    /// The six planes `(n, w)` of cluster `(x, y, z)` in view space (coordinates clamped), in
    /// the order left, right, bottom, top, near, far; `n` is the unit inward normal and a point
    /// `p` is inside when `dot(n, p) + w >= 0` for all six. Each `w` includes
    /// `cluster_margin(z)`.
    pub fn cluster_planes(&self, x: u32, y: u32, z: u32) -> [Vec4; 6] {
        let (x, y, z) = self.clamp_coords(x, y, z);
        let m = self.cluster_margin(z);
        let (left, right) = self.x_planes(x);
        let (bottom, top) = self.y_planes(y);
        let margin = Vec4::new(0.0, 0.0, 0.0, m);
        [
            left + margin,
            right + margin,
            bottom + margin,
            top + margin,
            // Near: d >= b(z)  <=>  -z - b(z) >= 0.  Far: z + b(z+1) >= 0.
            Vec4::new(0.0, 0.0, -1.0, m - self.slice_boundary(z)),
            Vec4::new(0.0, 0.0, 1.0, m + self.slice_boundary(z + 1)),
        ]
    }
}

/// Range of `a * d` over `a ∈ {a0, a1}`, `d ∈ {d0, d1}` (the corners), widened by `m`.
fn extent(a0: f32, a1: f32, d0: f32, d1: f32, m: f32) -> (f32, f32) {
    let c = [a0 * d0, a0 * d1, a1 * d0, a1 * d1];
    let lo = c.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = c.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    (lo - m, hi + m)
}

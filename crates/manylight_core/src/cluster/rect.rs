//! Each light's screen rectangle of tiles: the GPU build computes it once per light
//! (`light_rect` in `shaders/cluster_build.wgsl`, a twin of [`RectGrid::light_tile_rect`]
//! expression for expression), so that its first two levels can run from the lights' side:
//! a light visits only the coarse tiles, and a coarse-list entry only the tiles, of its
//! rectangle, instead of every (coarse) tile testing every candidate.
//!
//! The rectangle is a **superset** of the tiles whose column accepts the light (the tile
//! level's test, radius × [`TILE_PREFILTER_INFLATION`]), so of the clusters that accept it;
//! a coarse tile `(cx, cy)` with `x0 / span ≤ cx ≤ x1 / span` (and so on) holds every such
//! column of its own. Level 0 keeps a light for a coarse tile in the rectangle that
//! [`super::coarse_tile_accepts`] it, level 1 for a tile in it whose column accepts it, so the
//! tile and cluster lists are the same, light for light (the coarse lists lose only lights no
//! column accepts);
//! `crates/manylight_core/tests/tile_prefilter.rs` checks the superset on random lights.
//!
//! 1. **Reject**: radius `<= 0` or NaN touches nothing (every test says so): no tile.
//! 2. **Give up** on lights the float math below could not bound (a non-finite value or
//!    coordinates beyond [`RECT_MAGNITUDE`]): every tile; the tests decide.
//! 3. **Radius**: `R = r · TPI² · RADIUS_INFLATION + 4m + slack` with `m` the column margin and
//!    `slack = RECT_SLACK · (|c|₁ + r)`, more than any level tests with (the coarse level's
//!    planes use `r · TPI²`, inflated, and its margin twice).
//! 4. **Depth**: no tile when the sphere ends before `near` or starts past `far`.
//! 5. **Slopes** (`x / d`, the tile edges being `ndc · tan`; orthographic: `x` and `ndc · half`):
//!    - the box over `[near, far]`, as the CPU reference's candidates: `[lo / (near or far),
//!      hi / (near or far)]` with `lo, hi = c.x ∓ R` (not for the planes test, which has no box);
//!    - when the sphere lies well in front of the eye (`d > 2R`), and the test has planes, the
//!      two tangents through the eye, intersected with the box: the side planes of a tile pass
//!      only when its edges straddle them. Nearer the eye the formula loses precision, and the
//!      box (or, for the planes test, the whole screen) is kept, unless the sphere misses the
//!      screen's side planes altogether: a tile's left plane at edge slope `e` passes when
//!      `x - e·d + R√(1 + e²) ≥ 0`, convex in `e`, so over the edges in `[-tan, tan]` it is
//!      largest at an end; with the right plane, some tile can pass only if `|x| ≤ |tan·d| +
//!      R√(1 + tan²)` (a light beside the eye, off screen, has none).
//! 6. **Tiles** whose span meets the slope range, padded by [`RECT_PAD`] tiles for rounding.

use glam::{UVec2, Vec4};

use super::cull::RADIUS_INFLATION;
use super::{ClusterGrid, CullTest, TILE_PREFILTER_INFLATION};

/// Relative slack of the rectangle's radius, applied to `|c|₁ + r` (step 3).
pub const RECT_SLACK: f32 = 1e-4;
/// Tiles added on each side of the rectangle for the rounding of its edges (step 6).
pub const RECT_PAD: f32 = 0.125;
/// Largest `|c|₁ + r` the rectangle is computed for; beyond it every tile (step 2). Squares of
/// coordinates this size stay finite in f32.
pub const RECT_MAGNITUDE: f32 = 1e18;

/// What the rectangle needs of a grid, as the GPU reads it (`GpuClusterParams::frustum`):
/// `(tan_x, tan_y, 0, m)` in perspective, `(half_x, half_y, 1, m)` orthographic, `m` being the
/// margin of the grid's deepest slice, which is its columns' margin.
pub fn rect_frustum(grid: &ClusterGrid) -> Vec4 {
    let m = grid.cluster_margin(grid.dims.z - 1);
    match grid.ortho_half {
        Some(h) => Vec4::new(h.x, h.y, 1.0, m),
        None => {
            let t = grid.tan_half_fov();
            Vec4::new(t.x, t.y, 0.0, m)
        }
    }
}

/// What a light's rectangle needs of a grid: its tiles across and down, near and far, and
/// [`rect_frustum`] (as the GPU reads them from `GpuClusterParams`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RectGrid {
    /// Tiles across and down.
    pub tiles: UVec2,
    /// Near and far view distances.
    pub near: f32,
    /// See `near`.
    pub far: f32,
    /// [`rect_frustum`] of the grid.
    pub frustum: Vec4,
}

impl RectGrid {
    /// The rectangle inputs of `grid` (its tiles; slices do not matter).
    pub fn of(grid: &ClusterGrid) -> RectGrid {
        RectGrid { tiles: grid.dims.truncate(), near: grid.near, far: grid.far, frustum: rect_frustum(grid) }
    }

    /// The inclusive tile rectangle `[x0, y0, x1, y1]` of a light (centre `sphere.xyz`, radius
    /// `sphere.w`, view space; module docs); `None` when no tile can accept it.
    pub fn light_tile_rect(&self, sphere: Vec4, test: CullTest) -> Option<[u32; 4]> {
        rect_with(self, sphere, test, [1.0, RECT_PAD])
    }
}

/// [`RectGrid::light_tile_rect`] with the radius `R` scaled by `widen[0]` and a pad of
/// `widen[1]` tiles.
fn rect_with(grid: &RectGrid, sphere: Vec4, test: CullTest, widen: [f32; 2]) -> Option<[u32; 4]> {
    let RectGrid { tiles, near, far, frustum } = *grid;
    let full = Some([0, 0, tiles.x - 1, tiles.y - 1]);
    // Step 1 (the shader: `!(w > 0.0)`).
    if sphere.w.is_nan() || sphere.w <= 0.0 {
        return None;
    }
    // Step 2, NaN and infinities included (the shader: `!(size < RECT_MAGNITUDE)`).
    let c = sphere.truncate();
    let size = c.x.abs() + c.y.abs() + c.z.abs() + sphere.w;
    if size.is_nan() || size >= RECT_MAGNITUDE {
        return full;
    }
    // Step 3.
    let r = sphere.w * (TILE_PREFILTER_INFLATION * TILE_PREFILTER_INFLATION * RADIUS_INFLATION);
    let big = (r + 4.0 * frustum.w + RECT_SLACK * size) * widen[0];
    // Step 4.
    let d = -c.z;
    if d + big < near || d - big > far {
        return None;
    }
    // Step 5: slope ranges in NDC units.
    let (x, y) = if frustum.z > 0.5 {
        (
            [(c.x - big) / frustum.x, (c.x + big) / frustum.x],
            [(c.y - big) / frustum.y, (c.y + big) / frustum.y],
        )
    } else {
        let everything = [f32::NEG_INFINITY, f32::INFINITY];
        let (mut x, mut y) = if test == CullTest::Planes {
            (everything, everything)
        } else {
            (box_slopes(c.x, big, near, far), box_slopes(c.y, big, near, far))
        };
        let den = (d - big) * (d + big);
        if test != CullTest::Aabb && d > 2.0 * big && den > 1e-30 {
            let tx = tangent_slopes(c.x, d, big, den);
            let ty = tangent_slopes(c.y, d, big, den);
            x = [x[0].max(tx[0]), x[1].min(tx[1])];
            y = [y[0].max(ty[0]), y[1].min(ty[1])];
        } else if test != CullTest::Aabb
            && !(within_side_planes(c.x, d, big, frustum.x) && within_side_planes(c.y, d, big, frustum.y))
        {
            return None;
        }
        ([x[0] / frustum.x, x[1] / frustum.x], [y[0] / frustum.y, y[1] / frustum.y])
    };
    // Step 6: tile x spans NDC [-1 + 2k/X, ...]; tile row 0 is at the top.
    let (nx, ny) = (tiles.x as f32, tiles.y as f32);
    let xs = tile_span((x[0] + 1.0) * 0.5 * nx, (x[1] + 1.0) * 0.5 * nx, tiles.x, widen[1])?;
    let ys = tile_span((1.0 - y[1]) * 0.5 * ny, (1.0 - y[0]) * 0.5 * ny, tiles.y, widen[1])?;
    Some([xs[0], ys[0], xs[1], ys[1]])
}

/// Slopes a column's edges must reach for its box over depths `[near, far]` to meet `[a - R,
/// a + R]`: the right edge at least `lo / near` (`lo ≤ 0`) or `lo / far`, the left edge at most
/// `hi / near` (`hi ≥ 0`) or `hi / far`.
fn box_slopes(a: f32, big: f32, near: f32, far: f32) -> [f32; 2] {
    let lo = a - big;
    let hi = a + big;
    [lo / if lo <= 0.0 { near } else { far }, hi / if hi >= 0.0 { near } else { far }]
}

/// Slopes of the two lines through the eye tangent to the circle of radius `big` around `(a,
/// d)`, with `den = (d - big)(d + big) > 0`.
fn tangent_slopes(a: f32, d: f32, big: f32, den: f32) -> [f32; 2] {
    let root = big * (a * a + den).sqrt();
    [(a * d - root) / den, (a * d + root) / den]
}

/// Whether some pair of tile edges in `[-tan, tan]` can have the sphere (coordinate `a` along
/// the axis, depth `d`, radius `big`) within reach of both side planes (module docs, step 5).
fn within_side_planes(a: f32, d: f32, big: f32, tan: f32) -> bool {
    a.abs() <= (tan * d).abs() + big * (1.0 + tan * tan).sqrt()
}

/// Tiles `k ∈ 0..n` whose span `[k, k + 1]` (tile units) meets `[lo, hi]` padded by `pad`
/// tiles; `None` when none does, every tile for NaN.
fn tile_span(lo: f32, hi: f32, n: u32, pad: f32) -> Option<[u32; 2]> {
    let last = (n - 1) as f32;
    let first = (lo - pad).ceil() - 1.0;
    let end = (hi + pad).floor();
    if first > last || end < 0.0 || first > end {
        return None;
    }
    // NaN compares false both ways: the whole axis.
    let a = if first >= 0.0 { first.min(last) } else { 0.0 };
    let b = if end <= last { end.max(0.0) } else { last };
    Some([a as u32, b as u32])
}

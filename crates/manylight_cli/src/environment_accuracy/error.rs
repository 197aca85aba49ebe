//! How far an HDR image of the spheres is from the reference: FLIP of the tone-mapped images
//! and the relative luminance error per sphere, per range of `n.v` and on each sphere's
//! highlights.

use super::spheres::{Hit, ROUGHNESS, ROWS};
use glam::Vec3;
use manylight_core::image_metrics::{FlipStats, flip_compare};
use manylight_core::tonemap::tonemap_to_srgb8;

/// Exposure both images are tone-mapped with (the renderer's default).
pub const EXPOSURE: f32 = 1.0;

/// `n.v` below which a pixel counts as grazing.
pub const GRAZING: f32 = 0.5;

/// `n.v` from which a pixel counts as facing the camera.
pub const FACING: f32 = 0.8;

/// The fraction of each sphere's pixels, the brightest in the reference, that count as its
/// highlights (where the studio lamp or the sun is reflected).
pub const HIGHLIGHT_FRACTION: f64 = 0.05;

/// Luminance of linear Rec. 709 RGB.
pub fn luminance(c: Vec3) -> f64 {
    f64::from(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z)
}

/// Sums for a luminance-weighted relative error: `sum |test - ref| / sum ref` (each pixel's
/// `|test - ref| / ref` weighted by `ref`, so dark pixels, where the ratio is unstable, do not
/// dominate) and its signed twin.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
    abs: f64,
    signed: f64,
    reference: f64,
}

impl Sums {
    fn add(&mut self, test: f64, reference: f64) {
        self.abs += (test - reference).abs();
        self.signed += test - reference;
        self.reference += reference;
    }

    fn merge(self, other: Sums) -> Sums {
        Sums {
            abs: self.abs + other.abs,
            signed: self.signed + other.signed,
            reference: self.reference + other.reference,
        }
    }

    /// The mean relative error (0 over no pixels).
    pub fn relative(&self) -> f64 {
        if self.reference > 0.0 { self.abs / self.reference } else { 0.0 }
    }

    /// The mean signed relative error: above 0 where the test is too bright.
    pub fn bias(&self) -> f64 {
        if self.reference > 0.0 { self.signed / self.reference } else { 0.0 }
    }
}

/// Per-sphere sums, `[row][column]`.
pub type PerSphere = [[Sums; ROUGHNESS.len()]; ROWS.len()];

/// One image measured against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// FLIP of the tone-mapped images over the whole frame, everything but the kept sphere
    /// pixels black in both.
    pub flip: FlipStats,
    /// Every kept pixel of each sphere.
    pub spheres: PerSphere,
    /// Pixels with `n.v <` [`GRAZING`].
    pub grazing: PerSphere,
    /// Pixels with `n.v >=` [`FACING`].
    pub facing: PerSphere,
    /// Each sphere's brightest [`HIGHLIGHT_FRACTION`] of pixels in the reference.
    pub highlights: PerSphere,
}

impl ImageError {
    /// The sums of row `row` (all of its spheres).
    pub fn row(&self, row: usize) -> Sums {
        self.spheres[row].iter().fold(Sums::default(), |a, s| a.merge(*s))
    }

    /// The sums over every sphere.
    pub fn all(&self) -> Sums {
        (0..ROWS.len()).fold(Sums::default(), |a, r| a.merge(self.row(r)))
    }

    /// The sphere with the largest relative error: (row, column, error).
    pub fn worst_sphere(&self) -> (usize, usize, f64) {
        let mut worst = (0, 0, 0.0);
        for (r, row) in self.spheres.iter().enumerate() {
            for (c, s) in row.iter().enumerate() {
                if s.relative() > worst.2 {
                    worst = (r, c, s.relative());
                }
            }
        }
        worst
    }
}

/// The image of `size` with `radiance[i]` at hit `i`'s pixel and black elsewhere, tone mapped.
fn tone_mapped(size: (u32, u32), hits: &[Hit], radiance: &[Vec3]) -> Vec<u8> {
    let mut rgba = vec![0u8; size.0 as usize * size.1 as usize * 4];
    for (hit, &c) in hits.iter().zip(radiance) {
        rgba[hit.pixel * 4..hit.pixel * 4 + 4].copy_from_slice(&tonemap_to_srgb8(c, EXPOSURE));
    }
    for alpha in rgba.iter_mut().skip(3).step_by(4) {
        *alpha = 255;
    }
    rgba
}

/// `test` against `reference`, both the radiance at each of `hits` (in order) in an image of
/// `size`.
pub fn measure(
    size: (u32, u32),
    hits: &[Hit],
    test: &[Vec3],
    reference: &[Vec3],
) -> anyhow::Result<ImageError> {
    let (flip, _) =
        flip_compare(size, &tone_mapped(size, hits, reference), size, &tone_mapped(size, hits, test))?;
    let mut error = ImageError {
        flip,
        spheres: Default::default(),
        grazing: Default::default(),
        facing: Default::default(),
        highlights: Default::default(),
    };
    // Each sphere's highlight threshold: the reference luminance its brightest pixels exceed.
    let mut threshold = [[f64::INFINITY; ROUGHNESS.len()]; ROWS.len()];
    for (r, row) in threshold.iter_mut().enumerate() {
        for (c, t) in row.iter_mut().enumerate() {
            let mut l: Vec<f64> = hits
                .iter()
                .zip(reference)
                .filter(|(h, _)| h.row == r && h.column == c)
                .map(|(_, &v)| luminance(v))
                .collect();
            if l.is_empty() {
                continue;
            }
            l.sort_by(f64::total_cmp);
            let keep = ((l.len() as f64 * HIGHLIGHT_FRACTION).ceil() as usize).clamp(1, l.len());
            *t = l[l.len() - keep];
        }
    }
    for ((hit, &t), &r) in hits.iter().zip(test).zip(reference) {
        let (lt, lr) = (luminance(t), luminance(r));
        let (row, column) = (hit.row, hit.column);
        error.spheres[row][column].add(lt, lr);
        let n_dot_v = hit.normal.dot(hit.view);
        if n_dot_v < GRAZING {
            error.grazing[row][column].add(lt, lr);
        }
        if n_dot_v >= FACING {
            error.facing[row][column].add(lt, lr);
        }
        if lr >= threshold[row][column] {
            error.highlights[row][column].add(lt, lr);
        }
    }
    Ok(error)
}

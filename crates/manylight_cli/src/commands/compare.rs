//! `compare`: FLIP between two PNGs of one size, printed, with the error map written on request.

use anyhow::{Context, Result};
use std::path::Path;

/// Loads `path` as RGBA8, naming it when it cannot be read or decoded.
fn load(path: &Path) -> Result<image::RgbaImage> {
    Ok(image::open(path).with_context(|| format!("cannot read {} as an image", path.display()))?.to_rgba8())
}

/// `compare`: prints FLIP of `test` against `reference` and writes the error map to
/// `error_map` when given.
pub(crate) fn run(reference: &Path, test: &Path, error_map: Option<&Path>) -> Result<()> {
    let (a, b) = (load(reference)?, load(test)?);
    let (stats, map) =
        manylight_core::image_metrics::flip_compare(a.dimensions(), a.as_raw(), b.dimensions(), b.as_raw())
            .with_context(|| format!("cannot compare {} with {}", test.display(), reference.display()))?;
    println!(
        "FLIP of {} against {}: mean {:.4}, p95 {:.4}, p99 {:.4}, max {:.4}",
        test.display(),
        reference.display(),
        stats.mean,
        stats.p95,
        stats.p99,
        stats.max
    );
    if let Some(path) = error_map {
        let (w, h) = a.dimensions();
        let image = image::RgbImage::from_raw(w, h, map).context("the error map has the images' size")?;
        image.save(path).with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote the error map to {}", path.display());
    }
    Ok(())
}

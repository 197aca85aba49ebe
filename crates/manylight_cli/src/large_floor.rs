//! `manylight report --large-floor`: how exactly every pipeline, G-buffer layout and normal
//! codec draws a surface whose vertices lie far from the pixels they cover (docs/reliability.md,
//! "Very large surfaces").
//!
//! For each extent, in order:
//! 1. the floor tessellated into rings (`floor::ring_floor`), drawn by naive forward, is the
//!    reference; it is itself compared with the floor shaded analytically on the CPU (f64);
//! 2. the floor as one quad with corners at ±extent is drawn by every configuration
//!    (`floor::configurations`) and compared with the reference;
//! 3. the same with the floor tilted (`floor::tilt`), against rings tessellated for the tilted
//!    plane (no analytic twin there).
//!
//! Each comparison gives FLIP mean and p99 and the worst 8-bit channel difference; each frame
//! its count of NaN or infinite HDR pixels. One frame per configuration, nothing timed.

mod floor;

use crate::progress::Progress;
use anyhow::{Context, Result};
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::image_metrics::flip_compare;
use manylight_render::{FrameSettings, PipelineKind, RenderSettings};
use manylight_scene::Scene;
use std::fmt::Write as _;

/// Parses one `--floor-extents` value: a finite half-size above zero.
pub fn parse_extent(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{s}` is not a finite extent above 0")),
    }
}

/// Parses `--floor-far`: a far plane beyond the near plane, or `inf` (no far plane).
pub fn parse_far(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > floor::NEAR => Ok(v),
        _ => Err(format!("`{s}` is not a far plane beyond the near plane ({}) or inf", floor::NEAR)),
    }
}

/// One comparison of the table.
struct Row {
    /// `flat` or `tilted`.
    floor: &'static str,
    extent: f64,
    /// What was compared with what.
    name: String,
    flip_mean: f32,
    flip_p99: f32,
    worst: u8,
    /// NaN or infinite HDR pixels of the frame measured (`None`: not counted, or the CPU's).
    nonfinite: Option<u32>,
}

/// Measures the floor at each of `extents` with far plane `far` at `size`, every configuration
/// on `base`'s other settings (cluster options, ambient, exposure), and returns the markdown
/// table with a line of context above it.
pub fn run(extents: &[f64], far: f32, size: UVec2, base: RenderSettings) -> Result<String> {
    let mut renderer = HeadlessRenderer::new()?;
    let adapter = renderer.render_world.gpu().info.name.clone();
    let configs = floor::configurations(base);
    let naive = floor::settings_for(PipelineKind::NaiveForward, base);
    let per_extent = 2 * (configs.len() as u64 + 1);
    let mut progress = Progress::new(per_extent * extents.len() as u64, "frames");
    let mut rows = Vec::new();
    for &extent in extents {
        for (floor, tilted) in [("flat", false), ("tilted", true)] {
            let scene = |rings: bool| match (tilted, rings) {
                (true, _) => floor::tilted_scene(extent, far, rings),
                (false, true) => floor::floor_scene(floor::ring_floor(extent), far),
                (false, false) => floor::floor_scene(floor::quad_floor(extent), far),
            };
            progress.set_message(format!("{floor} {extent:e}: rings, naive forward"));
            let (reference, nonfinite) = render(&mut renderer, &scene(true), size, naive)?;
            progress.step(|| format!("{floor} floor at {extent:e}: the rings"));
            if !tilted {
                let analytic = floor::analytic_floor(extent, f64::from(far), size, &naive);
                let name = "rings (reference) vs analytic".to_string();
                rows.push(compare(floor, extent, name, &analytic, &reference, nonfinite)?);
            }
            for (name, settings) in &configs {
                progress.set_message(format!("{floor} {extent:e}: {name}"));
                let (image, nonfinite) = render(&mut renderer, &scene(false), size, *settings)?;
                let row = compare(floor, extent, format!("quad, {name}"), &reference, &image, nonfinite)?;
                progress
                    .step(|| format!("{floor} floor at {extent:e}, {name}: FLIP mean {:.5}", row.flip_mean));
                rows.push(row);
            }
        }
    }
    progress.finish();
    let context = format!(
        "A floor with corners at ±extent under four point lights, camera 2 units up, {}x{}, \
         far plane {far:e}, {adapter}: the quad in every configuration against the floor as rings \
         drawn by naive forward, the rings against the floor shaded on the CPU (flat only); \
         tilted: the floor turned {} rad about x and {} about z. Worst channel in 8-bit steps.",
        size.x,
        size.y,
        floor::TILT[0],
        floor::TILT[1]
    );
    Ok(markdown(&rows, &context))
}

/// Renders `scene` with `settings` at `size`; returns the image and its count of NaN or
/// infinite HDR pixels.
fn render(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    size: UVec2,
    settings: RenderSettings,
) -> Result<(image::RgbaImage, Option<u32>)> {
    let snapshot = crate::direct::snapshot(scene, &[], 0.0, size, FrameSettings::from(settings), 0);
    let (report, image) = renderer.render(snapshot, true)?;
    let image = image.with_context(|| format!("{}: no image read back", settings.pipeline.name()))?;
    Ok((image, report.nonfinite_pixels))
}

/// `image` against `reference`.
fn compare(
    floor: &'static str,
    extent: f64,
    name: String,
    reference: &image::RgbaImage,
    image: &image::RgbaImage,
    nonfinite: Option<u32>,
) -> Result<Row> {
    let (flip, _) =
        flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
    let worst = floor::worst_channel(reference, image);
    Ok(Row { floor, extent, name, flip_mean: flip.mean, flip_p99: flip.p99, worst, nonfinite })
}

fn markdown(rows: &[Row], context: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{context}\n");
    let _ = writeln!(
        out,
        "| floor | extent | compared | FLIP mean | FLIP p99 | worst channel | non-finite pixels |"
    );
    let _ = writeln!(out, "|---|---:|---|---:|---:|---:|---:|");
    for r in rows {
        let nonfinite = r.nonfinite.map_or("–".to_string(), |n| n.to_string());
        let _ = writeln!(
            out,
            "| {} | {:e} | {} | {:.5} | {:.5} | {} | {nonfinite} |",
            r.floor, r.extent, r.name, r.flip_mean, r.flip_p99, r.worst
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extents_and_far_planes_are_checked() {
        assert_eq!(parse_extent("1e7"), Ok(1e7));
        for bad in ["0", "-3", "inf", "NaN", "ten"] {
            assert!(parse_extent(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_far("inf"), Ok(f32::INFINITY));
        assert_eq!(parse_far("1e8"), Ok(1e8));
        for bad in ["0.1", "0.05", "-1", "NaN", "far"] {
            assert!(parse_far(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_table_has_a_row_per_comparison() {
        let row = |floor, name: &str| Row {
            floor,
            extent: 1e7,
            name: name.into(),
            flip_mean: 0.001,
            flip_p99: 0.01,
            worst: 1,
            nonfinite: Some(0),
        };
        let rows = [row("flat", "rings (reference) vs analytic"), row("tilted", "quad, naive")];
        let table = markdown(&rows, "context");
        assert!(table.starts_with("context\n\n| floor |"), "{table}");
        assert_eq!(table.lines().filter(|l| l.starts_with("| flat") || l.starts_with("| tilted")).count(), 2);
        assert!(table.contains("| tilted | 1e7 | quad, naive | 0.00100 | 0.01000 | 1 | 0 |"), "{table}");
    }
}

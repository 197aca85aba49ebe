//! `manylight report`: what accuracy costs in time. Renders the naive forward reference and
//! every approximation (tiled, clustered, deferred with each G-buffer layout) of the same frame
//! in one run, and prints a markdown table of FLIP error against the reference, frame time and
//! per-pass GPU time.

use crate::direct::snapshot;
use anyhow::Result;
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::image_metrics::flip_compare;
use manylight_render::{FrameReport, FrameSettings, GBufferLayout, PipelineKind};
use manylight_scene::{Scene, light_rig};
use std::fmt::Write as _;
use std::time::Instant;

/// Renders `frames` timed frames (after one warm-up) and returns the median frame time, the
/// last report and the last image.
fn measure(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    lights: usize,
    size: UVec2,
    settings: FrameSettings,
    frames: u32,
) -> Result<(f64, FrameReport, image::RgbaImage)> {
    let rig = light_rig(lights, scene.bounds(), 1);
    let mut times = Vec::new();
    let mut last = None;
    for f in 0..=frames {
        let snap = snapshot(scene, &rig, 0.0, size, settings, f as u64);
        let start = Instant::now();
        let (report, image) = renderer.render(snap, f == frames)?;
        if f > 0 {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        last = Some((report, image));
    }
    times.sort_by(f64::total_cmp);
    let median = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
    let (report, image) = last.ok_or_else(|| anyhow::anyhow!("no frame"))?;
    Ok((median, report, image.ok_or_else(|| anyhow::anyhow!("no image"))?))
}

/// Runs the comparison and returns the markdown table.
pub fn run(scene: &Scene, lights: usize, size: UVec2, frames: u32, base: FrameSettings) -> Result<String> {
    let mut renderer = HeadlessRenderer::new()?;
    let adapter = renderer.render_world.gpu().info.name.clone();
    let naive = FrameSettings { pipeline: PipelineKind::NaiveForward, ..base };
    let (naive_ms, naive_report, reference) = measure(&mut renderer, scene, lights, size, naive, frames)?;
    let configs: Vec<(String, FrameSettings)> = vec![
        ("forward-plus".into(), FrameSettings { pipeline: PipelineKind::ForwardPlus, ..base }),
        ("clustered-forward".into(), FrameSettings { pipeline: PipelineKind::ClusteredForward, ..base }),
        (
            "clustered-deferred, full G-buffer".into(),
            FrameSettings { pipeline: PipelineKind::ClusteredDeferred, gbuffer: GBufferLayout::Full, ..base },
        ),
        (
            "clustered-deferred, compact G-buffer".into(),
            FrameSettings {
                pipeline: PipelineKind::ClusteredDeferred,
                gbuffer: GBufferLayout::Compact,
                ..base
            },
        ),
    ];
    let passes = |r: &FrameReport| {
        r.passes
            .iter()
            .map(|p| match p.gpu_ms {
                Some(ms) if p.gpu_trusted => format!("{} {ms:.1}", p.name),
                Some(ms) => format!("{} {ms:.1}*", p.name),
                None => p.name.clone(),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} lights (+ the scene's own), {}x{}, {adapter}; median of {frames} frames\n",
        lights, size.x, size.y
    );
    let _ = writeln!(
        out,
        "| pipeline | G-buffer bytes/px | FLIP mean | FLIP p99 | frame ms | speed-up | passes (GPU ms; * = untrusted) |"
    );
    let _ = writeln!(out, "|---|---:|---:|---:|---:|---:|---|");
    let _ = writeln!(
        out,
        "| naive forward (reference) | – | 0 | 0 | {naive_ms:.0} | 1.0× | {} |",
        passes(&naive_report)
    );
    for (name, settings) in configs {
        let (ms, report, image) = measure(&mut renderer, scene, lights, size, settings, frames)?;
        let (flip, _) =
            flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
        let bytes = if settings.pipeline == PipelineKind::ClusteredDeferred {
            settings.gbuffer.bytes_per_pixel().to_string()
        } else {
            "–".into()
        };
        let _ = writeln!(
            out,
            "| {name} | {bytes} | {:.5} | {:.5} | {ms:.0} | {:.1}× | {} |",
            flip.mean,
            flip.p99,
            naive_ms / ms,
            passes(&report)
        );
    }
    Ok(out)
}

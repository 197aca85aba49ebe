//! `manylight report`: what accuracy costs in time. Renders the naive forward reference and
//! every approximation (tiled, clustered, deferred with each G-buffer layout) of the same frame
//! in one run, and prints a markdown table of FLIP error against the reference, frame time and
//! per-pass GPU time.

use crate::direct::snapshot;
use anyhow::Result;
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::cluster::CullTest;
use manylight_core::codec::NormalCodec;
use manylight_core::image_metrics::flip_compare;
use manylight_render::{ClusterSettings, FrameReport, FrameSettings, GBufferLayout, PipelineKind};
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

/// Every approximation the report compares with naive forward: the tiled and clustered
/// pipelines, each culling test, a cluster cap, and both deferred pipelines with every G-buffer
/// layout and (for `Packed` and `Compact`) every normal codec the layout can store.
fn configurations(base: FrameSettings) -> Vec<(String, FrameSettings)> {
    let mut configs =
        vec![("forward-plus".to_string(), FrameSettings { pipeline: PipelineKind::ForwardPlus, ..base })];
    for cull in [CullTest::Both, CullTest::Aabb, CullTest::Planes] {
        let clusters = ClusterSettings { cull, ..base.clusters };
        let settings = FrameSettings { pipeline: PipelineKind::ClusteredForward, clusters, ..base };
        configs.push((format!("clustered-forward, cull {}", cull.name()), settings));
    }
    let capped = ClusterSettings { cap: Some(8), ..base.clusters };
    configs.push((
        "clustered-forward, cap 8 lights/cluster".into(),
        FrameSettings { pipeline: PipelineKind::ClusteredForward, clusters: capped, ..base },
    ));
    for pipeline in [PipelineKind::ClusteredDeferred, PipelineKind::LightVolumes] {
        for gbuffer in GBufferLayout::ALL {
            let codecs: Vec<NormalCodec> = if !gbuffer.uses_codec() {
                vec![base.normal_codec]
            } else if pipeline == PipelineKind::ClusteredDeferred {
                NormalCodec::ALL.into_iter().filter(|&c| gbuffer.supports(c)).collect()
            } else {
                vec![NormalCodec::Octa16] // the codecs cost the same in both deferred pipelines
            };
            for normal_codec in codecs {
                let name = if gbuffer.uses_codec() {
                    format!(
                        "{}, {} G-buffer, {} normals",
                        pipeline.name(),
                        gbuffer.name(),
                        normal_codec.name()
                    )
                } else {
                    format!("{}, {} G-buffer", pipeline.name(), gbuffer.name())
                };
                configs.push((name, FrameSettings { pipeline, gbuffer, normal_codec, ..base }));
            }
        }
    }
    configs
}

/// Runs the comparison and returns the markdown table.
pub fn run(scene: &Scene, lights: usize, size: UVec2, frames: u32, base: FrameSettings) -> Result<String> {
    let mut renderer = HeadlessRenderer::new()?;
    let adapter = renderer.render_world.gpu().info.name.clone();
    let naive = FrameSettings { pipeline: PipelineKind::NaiveForward, ..base };
    let (naive_ms, naive_report, reference) = measure(&mut renderer, scene, lights, size, naive, frames)?;
    let configs = configurations(base);
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
        "| pipeline | G-buffer bytes/px | transient texture MiB | FLIP mean | FLIP p99 | dropped light-cluster pairs | frame ms | speed-up | passes (GPU ms; * = untrusted) |"
    );
    let _ = writeln!(out, "|---|---:|---:|---:|---:|---:|---:|---:|---|");
    let _ = writeln!(
        out,
        "| naive forward (reference) | – | {:.1} | 0 | 0 | 0 | {naive_ms:.0} | 1.0× | {} |",
        crate::bench::mib(naive_report.transient_bytes),
        passes(&naive_report)
    );
    for (name, settings) in configs {
        let (ms, report, image) = measure(&mut renderer, scene, lights, size, settings, frames)?;
        let (flip, _) =
            flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
        let bytes = if settings.pipeline.is_deferred() {
            settings.gbuffer.bytes_per_pixel().to_string()
        } else {
            "–".into()
        };
        let dropped = report.clusters.as_ref().map_or(0, |c| c.dropped_pairs);
        let _ = writeln!(
            out,
            "| {name} | {bytes} | {:.1} | {:.5} | {:.5} | {dropped} | {ms:.0} | {:.1}× | {} |",
            crate::bench::mib(report.transient_bytes),
            flip.mean,
            flip.p99,
            naive_ms / ms,
            passes(&report)
        );
    }
    Ok(out)
}

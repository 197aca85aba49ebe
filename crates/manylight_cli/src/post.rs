//! `manylight post`: what bloom and motion blur cost per frame. Renders the same frame without
//! post stages, with each bloom chain, with motion blur (a turning camera, and a still one) and
//! with both, in one run, and prints a markdown table of median frame time, the difference to
//! the frame without post stages, and the post passes' GPU time.

use crate::bench::median;
use crate::direct::{interleaved, snapshot};
use crate::report::Report;
use anyhow::Result;
use glam::{Mat4, UVec2};
use manylight_render::{
    BloomSettings, FrameReport, FrameSettings, FrameSnapshot, MotionBlurSettings, PassTiming,
};
use manylight_scene::{Scene, light_rig};
use std::fmt::Write as _;

/// Camera yaw between the previous and the current frame under motion blur (radians; about
/// 20 px of motion at 1280 px wide).
const TURN: f32 = 0.015;

/// One measured configuration.
struct Config {
    name: &'static str,
    bloom: Option<BloomSettings>,
    motion_blur: Option<MotionBlurSettings>,
    /// The camera turned since the previous frame (only matters with motion blur).
    moving: bool,
}

fn configurations() -> Vec<Config> {
    let mb = Some(MotionBlurSettings::default());
    let c = |name, bloom, motion_blur, moving| Config { name, bloom, motion_blur, moving };
    vec![
        c("no post stages", None, None, false),
        c("bloom, downsampled chain (5 levels, 1/2 … 1/32)", Some(BloomSettings::default()), None, false),
        c(
            "bloom, full-resolution separable blur (1×9 + 9×1 × 5)",
            Some(BloomSettings::full_resolution()),
            None,
            false,
        ),
        c("motion blur (8 samples), turning camera", None, mb, true),
        c("motion blur (8 samples), still camera", None, mb, false),
        c("bloom (downsampled) + motion blur, turning camera", Some(BloomSettings::default()), mb, true),
    ]
}

/// `config` applied to a snapshot: the camera's effects, and last frame's matrix of a camera
/// turned by [`TURN`] when it moves.
fn apply(mut snap: FrameSnapshot, config: &Config) -> FrameSnapshot {
    let size = snap.viewport;
    if let Some(camera) = snap.camera_mut() {
        camera.bloom = config.bloom;
        camera.motion_blur = config.motion_blur;
        let mut previous = *camera;
        if config.moving {
            previous.world_from_view = camera.world_from_view * Mat4::from_rotation_y(TURN);
        }
        camera.prev_clip_from_world = Some(previous.clip_from_world(size));
    }
    snap
}

/// GPU milliseconds of the post passes (bloom, motion blur): their total, and per pass name
/// the sum and the count (the blur passes repeat once per iteration).
fn post_gpu_ms(report: &FrameReport) -> (f64, Vec<(String, f64, u32)>) {
    let mut grouped: Vec<(String, f64, u32)> = Vec::new();
    use manylight_render::passes::{
        BloomBlurPass, BloomBrightPass, BloomCompositePass, BloomUpsamplePass, MotionBlurPass,
    };
    let post = |p: &PassTiming| {
        p.is::<BloomBrightPass>()
            || p.is::<BloomBlurPass>()
            || p.is::<BloomUpsamplePass>()
            || p.is::<BloomCompositePass>()
            || p.is::<MotionBlurPass>()
    };
    for p in report.passes.iter().filter(|p| post(p)) {
        // A pass that recorded nothing (motion blur under a still camera) has no GPU time.
        let ms = p.gpu_ms.unwrap_or(0.0);
        match grouped.iter_mut().find(|(n, _, _)| *n == p.name) {
            Some(g) => {
                g.1 += ms;
                g.2 += 1;
            }
            None => grouped.push((p.name.clone(), ms, 1)),
        }
    }
    (grouped.iter().fold(0.0, |sum, g| sum + g.1), grouped)
}

/// One configuration's medians.
struct PostRow {
    name: &'static str,
    frame_ms: f64,
    post_gpu_ms: f64,
    /// Per post pass: name, median GPU ms (summed over its repeats), repeats per frame.
    passes: Vec<(String, f64, u32)>,
    transient_bytes: u64,
}

/// Runs every configuration on `scene` (called `scene_name` in the output) with `lights` rig
/// lights. Each configuration has its own renderer (so its transient textures stay pooled),
/// and the configurations take turns frame by frame, so a change in machine load hits them
/// alike.
pub fn run(
    scene: &Scene,
    scene_name: &str,
    lights: usize,
    size: UVec2,
    frames: u32,
    base: FrameSettings,
) -> Result<Report> {
    let rig = light_rig(lights, scene.bounds(), 1)?;
    let configs = configurations();
    let names: Vec<String> = configs.iter().map(|c| c.name.to_string()).collect();
    let (adapter, timed) = interleaved(&names, frames, "rounds of every configuration", |i, f| {
        apply(snapshot(scene, &rig, 0.0, size, base, f), &configs[i])
    })?;
    let rows: Vec<PostRow> = configs
        .iter()
        .zip(timed)
        .map(|(config, timed)| {
            let times: Vec<f64> = timed.iter().map(|t| t.ms).collect();
            // Per frame, the post passes grouped by name.
            let passes: Vec<Vec<(String, f64, u32)>> =
                timed.iter().map(|t| post_gpu_ms(&t.report).1).collect();
            let transient_bytes = timed.last().map_or(0, |t| t.report.transient_bytes);
            let post_gpu_ms = median(
                &passes.iter().map(|frame| frame.iter().fold(0.0, |sum, p| sum + p.1)).collect::<Vec<_>>(),
            );
            let per_pass = passes
                .first()
                .map(|first| {
                    first
                        .iter()
                        .map(|(name, _, count)| {
                            let v = median(
                                &passes
                                    .iter()
                                    .filter_map(|frame| frame.iter().find(|p| p.0 == *name).map(|p| p.1))
                                    .collect::<Vec<_>>(),
                            );
                            (name.clone(), v, *count)
                        })
                        .collect()
                })
                .unwrap_or_default();
            PostRow {
                name: config.name,
                frame_ms: median(&times),
                post_gpu_ms,
                passes: per_pass,
                transient_bytes,
            }
        })
        .collect();
    let context = format!(
        "{}×{}, {scene_name}, {} rig lights + {} scene lights, {}, median of {frames} frames after 1 warm-up \
         (configurations interleaved frame by frame), adapter {adapter}",
        size.x,
        size.y,
        lights,
        scene.lights.len(),
        base.pipeline.name()
    );
    Ok(Report { markdown: markdown(&rows, &context)?, csv: csv(&rows, scene_name, size, &adapter)? })
}

fn markdown(rows: &[PostRow], context: &str) -> Result<String> {
    let mut out = String::new();
    writeln!(out, "{context}\n")?;
    writeln!(
        out,
        "| configuration | frame ms | vs none | post passes GPU ms | transient texture MiB | per pass GPU ms |"
    )?;
    writeln!(out, "|---|---:|---:|---:|---:|---|")?;
    let none = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    for r in rows {
        let per_pass = r
            .passes
            .iter()
            .map(
                |(name, v, count)| {
                    if *count > 1 { format!("{name} {v:.2} ({count}×)") } else { format!("{name} {v:.2}") }
                },
            )
            .collect::<Vec<_>>()
            .join(", ");
        writeln!(
            out,
            "| {} | {:.1} | {:+.1} ({:+.0} %) | {:.2} | {:.1} | {} |",
            r.name,
            r.frame_ms,
            r.frame_ms - none,
            (r.frame_ms / none - 1.0) * 100.0,
            r.post_gpu_ms,
            crate::bench::mib(r.transient_bytes),
            if per_pass.is_empty() { "–" } else { &per_pass },
        )?;
    }
    Ok(out)
}

fn csv(rows: &[PostRow], scene: &str, size: UVec2, adapter: &str) -> Result<String> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        for (name, _, _) in &r.passes {
            if !names.contains(&name.as_str()) {
                names.push(name);
            }
        }
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    let columns = ["frame_ms_median", "vs_none_ms", "post_passes_ms", "transient_mib"];
    w.write_record(crate::bench::configuration_header(&columns, &names))?;
    let none = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    for r in rows {
        let mut record = crate::bench::configuration_fields(adapter, scene, size, r.name);
        record.extend([
            format!("{:.3}", r.frame_ms),
            format!("{:.3}", r.frame_ms - none),
            format!("{:.3}", r.post_gpu_ms),
            format!("{:.3}", crate::bench::mib(r.transient_bytes)),
        ]);
        record.extend(
            names.iter().map(|n| {
                r.passes.iter().find(|p| p.0 == *n).map_or(String::new(), |p| format!("{:.3}", p.1))
            }),
        );
        w.write_record(&record)?;
    }
    Ok(String::from_utf8(w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?)?)
}

//! `manylight post`: what bloom and motion blur cost per frame. Renders the same frame without
//! post stages, with each bloom chain, with motion blur (a turning camera, and a still one) and
//! with both, in one run, and prints a markdown table of median frame time, the difference to
//! the frame without post stages, and the post passes' GPU time.

use crate::direct::snapshot;
use anyhow::Result;
use glam::{Mat4, UVec2};
use manylight_app::render_world::HeadlessRenderer;
use manylight_render::{BloomSettings, FrameReport, FrameSettings, FrameSnapshot, MotionBlurSettings};
use manylight_scene::{Scene, light_rig};
use std::fmt::Write as _;
use std::time::Instant;

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
        c("bloom, seed 002 (1×9 + 9×1 × 5, full resolution)", Some(BloomSettings::seed()), None, false),
        c("motion blur (8 samples), turning camera", None, mb, true),
        c("motion blur (8 samples), still camera", None, mb, false),
        c("bloom (downsampled) + motion blur, turning camera", Some(BloomSettings::default()), mb, true),
    ]
}

/// `config` applied to a snapshot: the camera's effects, and last frame's matrix of a camera
/// turned by [`TURN`] when it moves.
fn apply(mut snap: FrameSnapshot, config: &Config) -> FrameSnapshot {
    let size = snap.viewport;
    if let Some(camera) = &mut snap.camera {
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

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// GPU milliseconds of the post passes (bloom, motion blur): their total, and per pass name
/// the sum and the count (the blur passes repeat once per iteration).
fn post_gpu_ms(report: &FrameReport) -> (f64, Vec<(String, f64, u32)>) {
    let mut grouped: Vec<(String, f64, u32)> = Vec::new();
    for p in report.passes.iter().filter(|p| p.name.starts_with("bloom") || p.name == "motion_blur") {
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

/// Runs every configuration on `scene` with `lights` rig lights and returns the table. Each
/// configuration has its own renderer (so its transient textures stay pooled), and the
/// configurations take turns frame by frame, so a change in machine load hits them alike.
pub fn run(scene: &Scene, lights: usize, size: UVec2, frames: u32, base: FrameSettings) -> Result<String> {
    let rig = light_rig(lights, scene.bounds(), 1);
    let configs = configurations();
    let mut renderers = configs.iter().map(|_| HeadlessRenderer::new()).collect::<Result<Vec<_>, _>>()?;
    let adapter = renderers.first().map(|r| r.render_world.gpu().info.name.clone()).unwrap_or_default();
    // Per configuration: frame wall times, and per frame the post passes grouped by name.
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); configs.len()];
    let mut passes: Vec<Vec<Vec<(String, f64, u32)>>> = vec![Vec::new(); configs.len()];
    let mut texture_bytes = vec![0u64; configs.len()];
    for f in 0..=frames {
        for (i, (config, renderer)) in configs.iter().zip(&mut renderers).enumerate() {
            let snap = apply(snapshot(scene, &rig, 0.0, size, base, f as u64), config);
            let start = Instant::now();
            let (report, _) = renderer.render(snap, false)?;
            if f > 0 {
                // Frame 0 warms up (pipelines, textures).
                times[i].push(start.elapsed().as_secs_f64() * 1e3);
                passes[i].push(post_gpu_ms(&report).1);
            }
            texture_bytes[i] = report.transient_bytes;
        }
    }
    let mut out = String::new();
    writeln!(
        out,
        "{}×{}, {} rig lights + {} scene lights, {}, median of {frames} frames after 1 warm-up \
         (configurations interleaved frame by frame), adapter {adapter}\n",
        size.x,
        size.y,
        lights,
        scene.lights.len(),
        base.pipeline.name()
    )?;
    writeln!(
        out,
        "| configuration | frame ms | vs none | post passes GPU ms | transient texture MiB | per pass GPU ms |"
    )?;
    writeln!(out, "|---|---:|---:|---:|---:|---|")?;
    let none = median(times.first().cloned().unwrap_or_default());
    for (((config, times), passes), bytes) in configs.iter().zip(times).zip(passes).zip(texture_bytes) {
        let ms = median(times);
        let total = median(passes.iter().map(|frame| frame.iter().fold(0.0, |sum, p| sum + p.1)).collect());
        let per_pass = passes
            .first()
            .map(|first| {
                first
                    .iter()
                    .map(|(name, _, count)| {
                        let v = median(
                            passes
                                .iter()
                                .filter_map(|frame| frame.iter().find(|p| p.0 == *name).map(|p| p.1))
                                .collect(),
                        );
                        if *count > 1 {
                            format!("{name} {v:.2} ({count}×)")
                        } else {
                            format!("{name} {v:.2}")
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "–".to_string());
        writeln!(
            out,
            "| {} | {ms:.1} | {:+.1} ({:+.0} %) | {total:.2} | {:.1} | {per_pass} |",
            config.name,
            ms - none,
            (ms / none - 1.0) * 100.0,
            crate::bench::mib(bytes),
        )?;
    }
    Ok(out)
}

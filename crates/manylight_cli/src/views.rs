//! `manylight views`: what several cameras cost. The same frame rendered as 1 view, as 2 views
//! side by side and as 4 views in quarters (the same pixels in all three, split among cameras
//! that look in different directions), in one run; each view builds its own clusters, and the
//! lights are uploaded once per frame whatever the number of views.

use crate::bench::median;
use crate::direct::{interleaved, snapshot};
use anyhow::Result;
use glam::{Mat4, UVec2};
use manylight_render::passes::ClusterBuildPass;
use manylight_render::{ExtractedView, FrameReport, FrameSettings, FrameSnapshot, NamedPass, ViewRect};
use manylight_scene::{Scene, light_rig};
use std::fmt::Write as _;

/// The view counts compared.
pub const VIEW_COUNTS: [u32; 3] = [1, 2, 4];

/// `snap`'s camera as `count` views tiling the target: side by side for 2, quarters for 4;
/// view k turned by k × 0.6 rad about the vertical, so each sees other lights.
pub fn split(mut snap: FrameSnapshot, count: u32) -> FrameSnapshot {
    let Some(camera) = snap.camera().copied() else {
        return snap;
    };
    let (cols, rows) = match count {
        1 => (1, 1),
        2 => (2, 1),
        _ => (2, count.div_ceil(2)),
    };
    let cell = UVec2::new(snap.viewport.x / cols, snap.viewport.y / rows).max(UVec2::ONE);
    snap.views = (0..count)
        .map(|k| {
            let mut c = camera;
            c.world_from_view = camera.world_from_view * Mat4::from_rotation_y(k as f32 * 0.6);
            ExtractedView {
                rect: Some(ViewRect { origin: UVec2::new(k % cols, k / cols) * cell, size: cell }),
                order: k as isize,
                ..ExtractedView::main(c)
            }
        })
        .collect();
    snap
}

/// One view count's figures.
struct Row {
    views: u32,
    frame_ms: f64,
    last: FrameReport,
}

/// Runs 1, 2 and 4 views of `scene` (called `scene_name`) with `lights` rig lights; the
/// configurations take turns frame by frame, each on its own renderer.
pub fn run(
    scene: &Scene,
    scene_name: &str,
    lights: usize,
    size: UVec2,
    frames: u32,
    base: FrameSettings,
) -> Result<String> {
    let rig = light_rig(lights, scene.bounds(), 1)?;
    let names: Vec<String> = VIEW_COUNTS.iter().map(|n| format!("{n} view(s)")).collect();
    let (adapter, timed) = interleaved(&names, frames, "rounds of 1, 2 and 4 views", |i, f| {
        split(snapshot(scene, &rig, 0.0, size, base, f), VIEW_COUNTS[i])
    })?;
    let rows: Vec<Row> = VIEW_COUNTS
        .iter()
        .zip(timed)
        .map(|(&views, mut timed)| {
            let frame_ms = median(&timed.iter().map(|t| t.ms).collect::<Vec<_>>());
            let last = timed.pop().map(|t| t.report).unwrap_or_default();
            Row { views, frame_ms, last }
        })
        .collect();
    let context = format!(
        "{}×{} in all, {scene_name}, {} rig lights + {} scene lights, {}, median of {frames} frames after 1 warm-up \
         (view counts interleaved frame by frame), adapter {adapter}",
        size.x,
        size.y,
        lights,
        scene.lights.len(),
        base.pipeline.name()
    );
    markdown(&rows, &context)
}

fn markdown(rows: &[Row], context: &str) -> Result<String> {
    let mut out = String::new();
    writeln!(out, "{context}\n")?;
    writeln!(
        out,
        "| views | frame ms | vs 1 view | passes | cluster builds | light uploads | light KiB uploaded | \
         cluster-list entries (all views) | transient texture MiB |"
    )?;
    writeln!(out, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    let one = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    for r in rows {
        let l = &r.last;
        let builds = l.passes.iter().filter(|p| p.name == ClusterBuildPass::NAME).count();
        let entries: u64 = l.views.iter().filter_map(|v| v.clusters.as_ref()).map(|c| c.total_entries).sum();
        writeln!(
            out,
            "| {} | {:.1} | {:.2}× | {} | {} | {} | {:.1} | {} | {:.1} |",
            r.views,
            r.frame_ms,
            r.frame_ms / one,
            l.passes.len(),
            builds,
            l.light_uploads,
            l.light_upload_bytes as f64 / 1024.0,
            entries,
            crate::bench::mib(l.transient_bytes),
        )?;
    }
    Ok(out)
}

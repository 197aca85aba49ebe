//! Rendering without the app: snapshots built straight from a scene and a light rig, rendered
//! by the app's headless renderer (same render world and graph systems), for benchmarks and
//! measurements that need the renderer's internals (depth buffer, cluster lists).

use anyhow::{Context, Result};
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_app::scene::{extracted_light, scene_snapshot};
use manylight_core::cluster::ClusterAssignment;
use manylight_core::efficiency::{
    CullingEfficiency, culling_efficiency, depth_bounded_lists, depth_masked_lists, exact_pixel_lists,
    pixel_grid, zbinned_lists,
};
use manylight_render::{FrameReport, FrameSettings, FrameSnapshot, PipelineKind};
use manylight_scene::{AnimatedLight, Scene};
use std::sync::Arc;

/// The snapshot of `scene` plus `rig` at animation time `t` (the camera is the scene's first,
/// or one framing it).
pub fn snapshot(
    scene: &Scene,
    rig: &[AnimatedLight],
    t: f32,
    size: UVec2,
    settings: FrameSettings,
    frame_index: u64,
) -> FrameSnapshot {
    let rig_lights = rig.iter().map(|a| extracted_light(&manylight_scene::animated_light_at(a, t)));
    let lights = scene.lights.iter().map(extracted_light).chain(rig_lights).collect();
    scene_snapshot(scene, lights, size, settings, frame_index)
}

/// Makes every light of `snapshot` cast a shadow, with its kind's default biases (what
/// `--shadows on` means for a scene: glTF has no shadow flag).
pub fn cast_every_shadow(snapshot: &mut FrameSnapshot) {
    snapshot.lights.update(|light| *light = manylight_app::scene::with_shadow(light.clone(), true));
    for light in &mut snapshot.directional_lights {
        light.shadow = Some(manylight_render::DirectionalShadow::default());
    }
}

/// What a rendered frame's light lists are measured from, read back from the GPU.
struct FrameLists {
    report: FrameReport,
    projection: manylight_core::Projection,
    grid: manylight_core::cluster::ClusterGrid,
    assignment: manylight_core::cluster::ClusterAssignment,
    spheres: Vec<manylight_core::cluster::ViewSphere>,
    depth: Vec<f32>,
    /// The per-block refined lists, when the frame refined its lists.
    refined: Option<manylight_render::clusters::RefinedLists>,
}

/// Renders `snapshot` and reads back view 0's cluster grid, lists, light spheres and depth.
fn render_and_read_lists(renderer: &mut HeadlessRenderer, snapshot: FrameSnapshot) -> Result<FrameLists> {
    let projection = snapshot.camera().map(|c| c.projection).unwrap_or_default();
    let (report, _) = renderer.render(snapshot, false)?;
    let r = renderer.render_world.renderer();
    let clusters =
        r.view_clusters(0).context("the frame built no clusters (naive pipeline, or no lights)")?;
    let assignment = clusters.read_assignment(&r.gpu)?;
    let refined = clusters.read_refined(&r.gpu)?;
    let (_, _, depth) = r.read_depth()?.context("the frame has no depth buffer")?;
    let (grid, spheres) = (clusters.grid, clusters.read_view_spheres(&r.gpu)?);
    Ok(FrameLists { report, projection, grid, assignment, spheres, depth, refined })
}

/// The culling efficiency of a frame's lists, and of the lists per-cluster depth bounds would
/// make of them (`depth_bounded_lists`: measured, not built).
pub struct Culling {
    /// The lists the frame shades from (its cluster lists; with refined lists, each pixel's
    /// block's list or its cluster's; tiled deferred: cut by its depth masks).
    pub lists: CullingEfficiency,
    /// The same lists cut to each cluster's depth range of pixels.
    pub depth_bounded: CullingEfficiency,
    /// For a frame of one-slice tiles (Forward+, tiled deferred): its tile lists with z-binning
    /// (`zbinned_lists`, [`ZBINS`] bins: measured, not built).
    pub zbinned: Option<CullingEfficiency>,
}

/// Depth bins of the z-binning measurement (`Culling::zbinned`).
pub const ZBINS: u32 = 1024;

/// Renders `snapshot` and measures the culling efficiency of the lists its shading evaluates
/// against its depth buffer, and of its cluster lists cut by per-cluster depth bounds (every
/// 64th covered pixel is also checked against all lights). Tiled deferred shades from its tile
/// lists cut by each tile's depth mask (`depth_masked_lists`, as its shader does); a frame with
/// refined lists from its blocks' lists (read back); every other frame from its cluster lists.
pub fn measure_culling(
    renderer: &mut HeadlessRenderer,
    snapshot: FrameSnapshot,
) -> Result<(FrameReport, Culling)> {
    let test = snapshot.settings.render.clusters.cull;
    let tiled = snapshot.settings.render.pipeline == PipelineKind::TiledDeferred;
    let f = render_and_read_lists(renderer, snapshot)?;
    let lists = if tiled {
        let cells = manylight_render::gpu_types::TILED_DEPTH_CELLS;
        let masked = depth_masked_lists(&f.grid, &f.projection, &f.assignment, &f.spheres, &f.depth, cells);
        culling_efficiency(&f.grid, &f.projection, &masked, &f.spheres, &f.depth, 64)
    } else if let Some(refined) = &f.refined {
        let per_pixel = refined.per_pixel(&f.grid, &f.projection, &f.assignment, &f.depth);
        let pixels = pixel_grid(f.grid.viewport, &f.projection);
        culling_efficiency(&pixels, &f.projection, &per_pixel, &f.spheres, &f.depth, 64)
    } else {
        culling_efficiency(&f.grid, &f.projection, &f.assignment, &f.spheres, &f.depth, 64)
    };
    let bounded = depth_bounded_lists(&f.grid, &f.projection, &f.assignment, &f.spheres, &f.depth, test);
    let depth_bounded = culling_efficiency(&f.grid, &f.projection, &bounded, &f.spheres, &f.depth, 64);
    let zbinned = (f.grid.dims.z == 1).then(|| {
        let binned = zbinned_lists(&f.grid, &f.projection, &f.assignment, &f.spheres, &f.depth, ZBINS);
        culling_efficiency(
            &pixel_grid(f.grid.viewport, &f.projection),
            &f.projection,
            &binned,
            &f.spheres,
            &f.depth,
            64,
        )
    });
    Ok((f.report, Culling { lists, depth_bounded, zbinned }))
}

/// The oracle of `snapshot`'s frame: renders it (so the view has cluster lists and a depth
/// buffer), builds exact per-pixel light lists from the read-back depth and lists
/// (`exact_pixel_lists`), and returns the snapshot that shades from them, with the culling
/// efficiency of those lists (1: only contributing lights). Clustered and tiled deferred become
/// clustered deferred (the deferred oracle: its lighting pass reads the lists); every other pipeline
/// becomes clustered forward (the forward oracle). Callers time only the frame they render from
/// the returned snapshot: building the lists is not the oracle's cost.
pub fn oracle_snapshot(
    renderer: &mut HeadlessRenderer,
    mut snapshot: FrameSnapshot,
) -> Result<(FrameSnapshot, CullingEfficiency)> {
    let render = &mut snapshot.settings.render;
    render.pipeline = match render.pipeline {
        PipelineKind::ClusteredDeferred | PipelineKind::TiledDeferred => PipelineKind::ClusteredDeferred,
        _ => PipelineKind::ClusteredForward,
    };
    snapshot.pixel_light_lists = None;
    if manylight_render::lights::buffered_lights(&snapshot.lights).next().is_none() {
        // No point or spot light, so no clusters: directional lights shade every pixel without
        // a list, and every pixel's exact list is empty.
        let pixels = snapshot.viewport.x as usize * snapshot.viewport.y as usize;
        let empty = ClusterAssignment { ranges: vec![[0, 0]; pixels], ..ClusterAssignment::default() };
        snapshot.pixel_light_lists = Some(Arc::new(empty));
        return Ok((snapshot, CullingEfficiency::default()));
    }
    let f = render_and_read_lists(renderer, snapshot.clone())?;
    let lists = exact_pixel_lists(&f.grid, &f.projection, &f.assignment, &f.spheres, &f.depth);
    // The oracle's own lists measured the same way: 1 by construction.
    let grid = pixel_grid(f.grid.viewport, &f.projection);
    let efficiency = culling_efficiency(&grid, &f.projection, &lists, &f.spheres, &f.depth, 0);
    snapshot.pixel_light_lists = Some(Arc::new(lists));
    Ok((snapshot, efficiency))
}

/// One timed frame of an [`interleaved`] run: its wall-clock milliseconds and its report.
pub struct TimedFrame {
    /// Wall-clock time of the whole frame (upload, record, submit, wait).
    pub ms: f64,
    /// The frame's report.
    pub report: FrameReport,
}

/// Renders the configurations `names` in turns, frame by frame, each on its own renderer (so
/// its transient textures stay pooled), so that a change in machine load hits them alike: one
/// warm-up round (pipelines, textures, cluster buffers), then `frames` timed rounds.
/// `snapshot(i, frame)` gives configuration `i`'s snapshot of round `frame`. Returns the
/// adapter's name and, per configuration, its timed frames.
pub fn interleaved(
    names: &[String],
    frames: u32,
    what: &'static str,
    mut snapshot: impl FnMut(usize, u64) -> FrameSnapshot,
) -> Result<(String, Vec<Vec<TimedFrame>>)> {
    let mut renderers = names.iter().map(|_| HeadlessRenderer::new()).collect::<Result<Vec<_>, _>>()?;
    let adapter = renderers.first().map(|r| r.render_world.gpu().info.name.clone()).unwrap_or_default();
    let mut timed: Vec<Vec<TimedFrame>> = names.iter().map(|_| Vec::new()).collect();
    let mut progress = crate::progress::Progress::new(u64::from(frames) + 1, what);
    for f in 0..=frames {
        for (i, (name, renderer)) in names.iter().zip(&mut renderers).enumerate() {
            progress.set_message(name.clone());
            let snap = snapshot(i, u64::from(f));
            let start = std::time::Instant::now();
            let (report, _) = renderer.render(snap, false)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            if f > 0 {
                timed[i].push(TimedFrame { ms, report });
            }
        }
        progress.step(|| if f == 0 { "warm-up".to_string() } else { format!("frame {f}") });
    }
    progress.finish();
    Ok((adapter, timed))
}

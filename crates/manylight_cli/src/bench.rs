//! `manylight bench`: pipelines × light counts at one size, each frame rendered synchronously
//! and timed end to end (prepare, record, submit, wait), written as CSV.

use crate::direct::{measure_culling, oracle_snapshot, snapshot};
use crate::progress::Progress;
use crate::shadow_error::{measure_shadows, occluders};
use anyhow::{Context, Result};
use glam::UVec2;
use manylight_app::cli::ShadowChoice;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::shadow_oracle::OccluderSet;
use manylight_render::passes::{
    ClusterBuildPass, ClusterDepthPass, ClusteredForwardPass, DeferredLightingPass, DepthPrepass,
    ForwardPass, GBufferPass, LightRefinePass, LightVolumesPass, ShadowMapsPass, TiledDeferredPass,
    TonemapPass,
};
use manylight_render::{FrameReport, FrameSettings, GBufferLayout, NamedPass, PipelineKind, RenderSettings};
use manylight_scene::{
    AnimatedLight, SHELL_LIGHT_RANGE, SHELL_RADIUS, Scene, light_rig, sphere_shell_lights,
};
use std::fmt::Write as _;
use std::time::Instant;

/// One benchmark configuration's measurements.
pub struct Row {
    pipeline: PipelineKind,
    gbuffer: Option<GBufferLayout>,
    lights: usize,
    frame_ms: Vec<f64>,
    last: FrameReport,
    culling: Option<f64>,
    /// The culling ratio the same lists would have with per-cluster depth bounds.
    depth_bounded: Option<f64>,
    /// The culling ratio the same tile lists would have with z-binning (one-slice grids).
    zbinned: Option<f64>,
    /// An oracle's row: the same frames shaded from exact per-pixel lists, by clustered forward
    /// (the forward oracle) or clustered deferred (the deferred oracle, per G-buffer layout).
    oracle: bool,
    /// Every light casts a shadow.
    shadows: ShadowChoice,
    /// The last frame's shadows against exact visibility (`--shadow-oracle`).
    shadow_accuracy: Option<ShadowFigures>,
}

/// What `--shadow-oracle` adds to a row.
#[derive(Clone, Copy, Debug)]
struct ShadowFigures {
    visibility_error: f64,
    flip_vs_reference: f32,
    light_error: f64,
    flicker: f64,
}

impl Row {
    /// The oracle a row's shading is measured against: the forward oracle for the forward
    /// pipelines, the deferred one of the same G-buffer layout for the deferred pipelines.
    fn oracle_of<'a>(&self, rows: &'a [Row]) -> Option<&'a Row> {
        rows.iter().find(|o| {
            o.oracle
                && o.lights == self.lights
                && o.shadows == self.shadows
                && o.pipeline.is_deferred() == self.pipeline.is_deferred()
                && o.gbuffer == self.gbuffer
        })
    }
}

/// Passes that shade lights (a pipeline's lighting cost): forward, clustered forward, deferred
/// lighting, tiled deferred and light volumes.
pub const SHADING_PASSES: [&str; 5] = [
    ForwardPass::NAME,
    ClusteredForwardPass::NAME,
    DeferredLightingPass::NAME,
    TiledDeferredPass::NAME,
    LightVolumesPass::NAME,
];

/// GPU milliseconds of `report`'s shading passes ([`SHADING_PASSES`]); `None` without timings.
pub fn shading_ms(report: &FrameReport) -> Option<f64> {
    let times: Vec<f64> = report
        .passes
        .iter()
        .filter(|p| SHADING_PASSES.contains(&p.name.as_str()))
        .filter_map(|p| p.gpu_ms)
        .collect();
    (!times.is_empty()).then(|| times.iter().sum())
}

/// The leading columns of a CSV with one row per configuration (`report`, `report --shadows`,
/// `post`), then `columns`, then one `{pass}_gpu_ms` column per pass of `passes`.
pub(crate) fn configuration_header(columns: &[&str], passes: &[String]) -> Vec<String> {
    ["adapter", "scene", "width", "height", "configuration"]
        .iter()
        .chain(columns)
        .map(|c| c.to_string())
        .chain(passes.iter().map(|p| format!("{p}_gpu_ms")))
        .collect()
}

/// The leading fields of a row of [`configuration_header`]'s CSV.
pub(crate) fn configuration_fields(
    adapter: &str,
    scene: &str,
    size: UVec2,
    configuration: &str,
) -> Vec<String> {
    vec![
        adapter.to_string(),
        scene.to_string(),
        size.x.to_string(),
        size.y.to_string(),
        configuration.to_string(),
    ]
}

/// The median of `v` (the upper one of an even count; NaN when empty).
pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() { f64::NAN } else { s[s.len() / 2] }
}

/// GPU milliseconds of `r`'s pass of type `P`, or an empty field.
fn pass_ms<P: NamedPass>(r: &FrameReport) -> String {
    r.pass_gpu_ms::<P>().map_or(String::new(), |ms| format!("{ms:.3}"))
}

/// What to sweep.
pub struct Sweep {
    /// Pipelines.
    pub pipelines: Vec<PipelineKind>,
    /// Rig light counts.
    pub lights: Vec<usize>,
    /// Image size.
    pub size: UVec2,
    /// Frames not measured.
    pub warmup: u32,
    /// Frames measured.
    pub frames: u32,
    /// Naive forward is skipped above this many lights (it costs seconds per frame on a CPU).
    pub naive_max_lights: usize,
    /// Also measure the culling efficiency of the tiled/clustered pipelines.
    pub culling_efficiency: bool,
    /// Also render each light count's frames with exact per-pixel light lists (the oracle) and
    /// give every row its shading time against the oracle's.
    pub oracle: bool,
    /// The scene is the sphere-shell preset: light it with its lattice of static lights (as
    /// `manylight render` and the stress example do) instead of the animated rig.
    pub shell_lattice: bool,
    /// G-buffer layouts swept for the deferred pipeline.
    pub gbuffers: Vec<GBufferLayout>,
    /// Shadow settings swept: no light casts, or every light casts into maps or with rays.
    pub shadows: Vec<ShadowChoice>,
    /// Also measure each pipeline row's last frame against exact visibility (visibility error
    /// and FLIP against the shadow reference).
    pub shadow_oracle: bool,
    /// Settings other than the pipeline.
    pub settings: FrameSettings,
}

/// Runs the sweep on `scene` (called `scene_name` in the CSV) and returns the CSV text.
pub fn run(scene: &Scene, scene_name: &str, sweep: &Sweep) -> Result<String> {
    let mut renderer = HeadlessRenderer::new()?;
    let adapter = renderer.render_world.gpu().info.name.clone();
    let shadow_settings: Vec<ShadowChoice> =
        if sweep.shadows.is_empty() { vec![ShadowChoice::Off] } else { sweep.shadows.clone() };
    let configs = configurations(sweep, &shadow_settings);
    let oracles = oracle_configurations(sweep, &shadow_settings);
    let occluders = sweep.shadow_oracle.then(|| occluders(scene));
    let mut progress = Progress::new((configs.len() + oracles.len()) as u64, "configurations");
    let mut rows = Vec::new();
    for config in configs.into_iter().chain(oracles) {
        let label = config.label();
        progress.set_message(label.clone());
        let row = measure_config(&mut renderer, scene, sweep, config, occluders.as_ref())?;
        let median_ms = median(&row.frame_ms);
        progress.step(|| format!("{label}: {median_ms:.1} ms"));
        rows.push(row);
    }
    progress.finish();
    warn_unlike_oracle_frames(&rows);
    Ok(csv(&rows, scene_name, sweep.size, &adapter))
}

/// One configuration of the sweep: a row of the CSV.
#[derive(Clone, Copy, Debug)]
struct Config {
    pipeline: PipelineKind,
    /// The G-buffer layout of a deferred pipeline.
    gbuffer: Option<GBufferLayout>,
    lights: usize,
    /// Every light casts a shadow, into maps or with rays, or none does.
    shadows: ShadowChoice,
    /// An oracle's run (see [`Row::oracle`]).
    oracle: bool,
}

impl Config {
    /// What the progress line calls the configuration.
    fn label(&self) -> String {
        let lights = self.lights;
        let label = match (self.oracle, self.gbuffer) {
            (true, Some(g)) => format!("deferred oracle ({} G-buffer), {lights} lights", g.name()),
            (true, None) => format!("forward oracle, {lights} lights"),
            (false, Some(g)) => format!("{} ({} G-buffer), {lights} lights", self.pipeline.name(), g.name()),
            (false, None) => format!("{}, {lights} lights", self.pipeline.name()),
        };
        if self.shadows.casts() { format!("{label}, shadows {}", self.shadows.name()) } else { label }
    }
}

/// The sweep's pipeline configurations, by light count, pipeline, G-buffer layout (deferred
/// pipelines) and shadow setting (of `shadows`); naive forward only up to
/// `sweep.naive_max_lights` lights.
fn configurations(sweep: &Sweep, shadows: &[ShadowChoice]) -> Vec<Config> {
    sweep
        .lights
        .iter()
        .flat_map(|&lights| {
            sweep.pipelines.iter().flat_map(move |&pipeline| {
                let layouts: Vec<Option<GBufferLayout>> = if pipeline.is_deferred() {
                    sweep.gbuffers.iter().copied().map(Some).collect()
                } else {
                    vec![None]
                };
                layouts.into_iter().flat_map(move |gbuffer| {
                    shadows.iter().map(move |&shadows| Config {
                        pipeline,
                        gbuffer,
                        lights,
                        shadows,
                        oracle: false,
                    })
                })
            })
        })
        .filter(|c| c.pipeline != PipelineKind::NaiveForward || c.lights <= sweep.naive_max_lights)
        .collect()
}

/// The oracles of `--oracle` (none without it): one forward oracle per light count, and a
/// deferred one per G-buffer layout when the sweep has deferred pipelines, each with every
/// shadow setting of `shadows`.
fn oracle_configurations(sweep: &Sweep, shadows: &[ShadowChoice]) -> Vec<Config> {
    if !sweep.oracle {
        return Vec::new();
    }
    let deferred = sweep.pipelines.iter().any(|p| p.is_deferred());
    let kinds: Vec<(PipelineKind, Option<GBufferLayout>)> =
        std::iter::once((PipelineKind::ClusteredForward, None))
            .chain(
                sweep
                    .gbuffers
                    .iter()
                    .filter(|_| deferred)
                    .map(|&g| (PipelineKind::ClusteredDeferred, Some(g))),
            )
            .collect();
    sweep
        .lights
        .iter()
        .filter(|&&n| n > 0)
        .flat_map(|&n| kinds.iter().map(move |&(p, g)| (p, g, n)))
        .flat_map(|(pipeline, gbuffer, lights)| {
            shadows.iter().map(move |&shadows| Config { pipeline, gbuffer, lights, shadows, oracle: true })
        })
        .collect()
}

/// Renders and measures one configuration: its timed frames, its culling ratios (an oracle's
/// lists', or with `--culling-efficiency` a pipeline's) and, with `occluders`, its last frame's
/// shadows against exact visibility.
fn measure_config(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    sweep: &Sweep,
    config: Config,
    occluders: Option<&OccluderSet>,
) -> Result<Row> {
    let Config { pipeline, gbuffer, lights, shadows, oracle } = config;
    let (lit, rig) = lights_of(scene, sweep.shell_lattice, lights)?;
    let mut settings = FrameSettings {
        render: RenderSettings {
            pipeline,
            gbuffer: gbuffer.unwrap_or(sweep.settings.gbuffer),
            ..sweep.settings.render
        },
        ..sweep.settings
    };
    settings.render.shadows.method = shadows.method();
    let (frame_ms, last, oracle_culling) =
        timed_frames(renderer, &lit, &rig, sweep, settings, oracle, shadows.casts())?;
    let (culling, depth_bounded, zbinned) = if oracle {
        (oracle_culling, None, None)
    } else if sweep.culling_efficiency && pipeline.uses_clusters() && lights > 0 {
        let snap = snapshot(&lit, &rig, 0.0, sweep.size, settings, 0);
        let c = measure_culling(renderer, snap)?.1;
        (Some(c.lists.ratio()), Some(c.depth_bounded.ratio()), c.zbinned.map(|z| z.ratio()))
    } else {
        (None, None, None)
    };
    let shadow_accuracy = match occluders {
        Some(occluders) if !oracle => {
            let t = (sweep.warmup + sweep.frames).saturating_sub(1);
            let mut snap = snapshot(&lit, &rig, t as f32 / 60.0, sweep.size, settings, u64::from(t));
            if shadows.casts() {
                crate::direct::cast_every_shadow(&mut snap);
            }
            let a = measure_shadows(renderer, snap, occluders)?;
            Some(ShadowFigures {
                visibility_error: a.visibility_error,
                flip_vs_reference: a.flip.mean,
                light_error: a.light_error,
                flicker: a.flicker,
            })
        }
        _ => None,
    };
    Ok(Row {
        pipeline,
        gbuffer,
        lights,
        frame_ms,
        last,
        culling,
        depth_bounded,
        zbinned,
        oracle,
        shadows,
        shadow_accuracy,
    })
}

/// How far a pass of the same work may take longer or shorter in one frame than in another
/// before their timings are not comparable.
const LIKE_FRAMES_TOLERANCE: f64 = 1.25;

/// The tone map does the same work in an oracle's frame as in the pipelines' frames of the same
/// size: where its time differs by more than [`LIKE_FRAMES_TOLERANCE`], the oracle's frames were
/// not timed in the same state of the GPU (seen on an H200: every pass of the oracle's frames up
/// to 5.7 times slower), and its `shading_vs_oracle` says nothing. Warns of each such oracle;
/// `render --oracle` interleaves the two frame by frame instead.
fn warn_unlike_oracle_frames(rows: &[Row]) {
    let tonemap = |r: &Row| r.last.pass_gpu_ms::<TonemapPass>();
    for o in rows.iter().filter(|r| r.oracle) {
        let theirs: Vec<f64> =
            rows.iter().filter(|r| !r.oracle && r.lights == o.lights).filter_map(tonemap).collect();
        let theirs = median(&theirs);
        if let Some(ours) = tonemap(o)
            && let Some(ratio) = unlike(ours, theirs)
        {
            tracing::warn!(
                "the {} oracle at {} lights: its tone map took {ratio:.2} times the pipelines' \
                 ({ours:.3} ms against {theirs:.3} ms), so its frames were not timed like theirs \
                 and shading_vs_oracle is not comparable at this light count; `manylight render \
                 --oracle` times the two frame by frame",
                if o.pipeline.is_deferred() { "deferred" } else { "forward" },
                o.lights,
            );
        }
    }
}

/// `a / b` where it lies outside [`LIKE_FRAMES_TOLERANCE`] either way.
fn unlike(a: f64, b: f64) -> Option<f64> {
    let ratio = a / b;
    (b > 0.0 && !(1.0 / LIKE_FRAMES_TOLERANCE..=LIKE_FRAMES_TOLERANCE).contains(&ratio)).then_some(ratio)
}

/// The scene lit by `count` lights: the sphere-shell preset (`shell_lattice`) gets its lattice of
/// static lights, every other scene `count` animated rig lights over its own.
fn lights_of(scene: &Scene, shell_lattice: bool, count: usize) -> Result<(Scene, Vec<AnimatedLight>)> {
    if shell_lattice {
        let lights = sphere_shell_lights(count, SHELL_RADIUS, SHELL_LIGHT_RANGE, 1)?;
        Ok((Scene { lights, ..scene.clone() }, Vec::new()))
    } else {
        Ok((scene.clone(), light_rig(count, scene.bounds(), 1)?))
    }
}

/// Renders `sweep.warmup + sweep.frames` frames of `rig` animated at 60 frames a second with
/// `settings`; returns the timed frames' wall milliseconds and the last report. With `oracle`,
/// each frame is shaded from exact per-pixel lists built (not timed) from a render of that same
/// frame, and the lists' culling ratio comes back too. With `shadows` every light casts.
fn timed_frames(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    rig: &[AnimatedLight],
    sweep: &Sweep,
    settings: FrameSettings,
    oracle: bool,
    shadows: bool,
) -> Result<(Vec<f64>, FrameReport, Option<f64>)> {
    let mut frame_ms = Vec::new();
    let mut last = None;
    let mut culling = None;
    for f in 0..sweep.warmup + sweep.frames {
        let mut snap = snapshot(scene, rig, f as f32 / 60.0, sweep.size, settings, f as u64);
        if shadows {
            crate::direct::cast_every_shadow(&mut snap);
        }
        if oracle {
            let (lists, efficiency) = oracle_snapshot(renderer, snap)?;
            (snap, culling) = (lists, Some(efficiency.ratio()));
        }
        let start = Instant::now();
        let (report, _) = renderer.render(snap, false)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if f >= sweep.warmup {
            frame_ms.push(ms);
        }
        last = Some(report);
    }
    Ok((frame_ms, last.context("no frame")?, culling))
}

/// Every pass name of `reports` in an order that keeps each frame's order (a pass first seen
/// goes right after the pass before it in its frame, so the tone map stays last); a pass that
/// runs several times in a frame, like a blur iteration, is named once.
pub fn pass_names<'a>(reports: impl Iterator<Item = &'a FrameReport>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in reports {
        let mut next = 0;
        for p in &r.passes {
            match names.iter().position(|n| *n == p.name) {
                Some(i) => next = i + 1,
                None => {
                    names.insert(next, p.name.clone());
                    next += 1;
                }
            }
        }
    }
    names
}

/// GPU milliseconds of each of `names` in `report` (summed over repeats; empty where the pass
/// did not run or has no time), as CSV fields.
pub fn pass_times(report: &FrameReport, names: &[String]) -> Vec<String> {
    names
        .iter()
        .map(|name| {
            let times: Vec<f64> =
                report.passes.iter().filter(|p| p.name == *name).filter_map(|p| p.gpu_ms).collect();
            if times.is_empty() { String::new() } else { format!("{:.3}", times.iter().sum::<f64>()) }
        })
        .collect()
}

/// Bytes in MiB.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn csv(rows: &[Row], scene: &str, size: UVec2, adapter: &str) -> String {
    // Quoted fields: a `"` inside is doubled.
    let (adapter, scene) = (adapter.replace('"', "\"\""), scene.replace('"', "\"\""));
    let mut out = String::from(
        "adapter,scene,pipeline,gbuffer,gbuffer_bytes_per_pixel,lights,width,height,frames,frame_ms_median,\
         frame_ms_mean,depth_prepass_gpu_ms,cluster_build_gpu_ms,cluster_build_gpu_trusted,\
         forward_gpu_ms,clustered_forward_gpu_ms,gbuffer_gpu_ms,deferred_lighting_gpu_ms,light_volumes_gpu_ms,tonemap_gpu_ms,clusters,non_empty_clusters,list_entries,\
         max_per_cluster,mean_per_non_empty,dropped_pairs,culling_ratio,transient_mib,cluster_buffer_mib,\
         list_capacity,tile_entries,tile_capacity,fallback_clusters,shading_ms,shading_vs_oracle,\
         coarse_tiles,coarse_entries,depth_bounded_ratio,cluster_depth_gpu_ms,light_refine_gpu_ms,\
         zbinned_ratio,shadows,shadow_maps_rendered,shadow_maps_cached,shadow_maps_stale,shadow_atlas_bytes,shadow_gpu_ms,\
         visibility_error,flip_vs_shadow_reference,light_error,flicker,frame_ms_min,frame_ms_max,cpu_frame_ms,cpu_upload_ms,\
         cpu_prepare_ms,cpu_record_ms,cpu_submit_ms,upload_bytes\n",
    );
    for r in rows {
        let fields = [
            r.configuration_fields(size),
            r.pass_fields(),
            r.cluster_fields(),
            r.shading_fields(rows),
            r.refinement_fields(),
            r.shadow_fields(),
            r.cpu_fields(),
        ]
        .concat();
        let _ = writeln!(out, "\"{adapter}\",\"{scene}\",{}", fields.join(","));
    }
    out
}

/// `x` with three decimals; empty when `None`.
fn opt3(x: Option<f64>) -> String {
    x.map_or(String::new(), |x| format!("{x:.3}"))
}

/// The row's fields of [`csv`], in groups of neighbouring columns.
impl Row {
    /// `pipeline` to `frames`: what was rendered.
    fn configuration_fields(&self, size: UVec2) -> Vec<String> {
        let pipeline = match (self.oracle, self.pipeline.is_deferred()) {
            (true, false) => "oracle-forward",
            (true, true) => "oracle-deferred",
            _ => self.pipeline.name(),
        };
        vec![
            pipeline.to_string(),
            self.gbuffer.map_or("", |g| g.name()).to_string(),
            self.gbuffer.map_or(String::new(), |g| g.bytes_per_pixel().to_string()),
            self.lights.to_string(),
            size.x.to_string(),
            size.y.to_string(),
            self.frame_ms.len().to_string(),
        ]
    }

    /// `frame_ms_median` to `tonemap_gpu_ms`: the frame times and the main passes' GPU times.
    fn pass_fields(&self) -> Vec<String> {
        let r = &self.last;
        let trusted = r
            .passes
            .iter()
            .find(|p| p.name == ClusterBuildPass::NAME)
            .map_or(String::new(), |p| p.gpu_trusted.to_string());
        let mean = self.frame_ms.iter().sum::<f64>() / self.frame_ms.len().max(1) as f64;
        vec![
            format!("{:.3}", median(&self.frame_ms)),
            format!("{mean:.3}"),
            pass_ms::<DepthPrepass>(r),
            pass_ms::<ClusterBuildPass>(r),
            trusted,
            pass_ms::<ForwardPass>(r),
            pass_ms::<ClusteredForwardPass>(r),
            pass_ms::<GBufferPass>(r),
            pass_ms::<DeferredLightingPass>(r),
            pass_ms::<LightVolumesPass>(r),
            pass_ms::<TonemapPass>(r),
        ]
    }

    /// `clusters` to `fallback_clusters`: the cluster lists, the culling ratio and the memory.
    fn cluster_fields(&self) -> Vec<String> {
        let c = self.last.clusters.as_ref();
        vec![
            c.map_or(String::new(), |c| c.clusters.to_string()),
            c.map_or(String::new(), |c| c.non_empty.to_string()),
            c.map_or(String::new(), |c| c.total_entries.to_string()),
            c.map_or(String::new(), |c| c.max_per_cluster.to_string()),
            c.map_or(String::new(), |c| format!("{:.2}", c.mean_per_non_empty)),
            c.map_or(String::new(), |c| c.dropped_pairs.to_string()),
            opt3(self.culling),
            format!("{:.2}", mib(self.last.transient_bytes)),
            c.map_or(String::new(), |c| format!("{:.2}", mib(c.buffer_bytes))),
            c.map_or(String::new(), |c| c.index_capacity.to_string()),
            c.map_or(String::new(), |c| c.tile_entries.to_string()),
            c.map_or(String::new(), |c| c.tile_index_capacity.to_string()),
            c.map_or(String::new(), |c| c.fallback_clusters.to_string()),
        ]
    }

    /// `shading_ms` and `shading_vs_oracle` (against the row's oracle among `rows`).
    fn shading_fields(&self, rows: &[Row]) -> Vec<String> {
        let shading = shading_ms(&self.last);
        let oracle = self.oracle_of(rows).and_then(|o| shading_ms(&o.last));
        let vs_oracle = shading.zip(oracle).filter(|&(_, o)| o > 0.0).map(|(s, o)| s / o);
        vec![opt3(shading), opt3(vs_oracle)]
    }

    /// `coarse_tiles` to `zbinned_ratio`: the coarse level, depth bounds, refined lists and
    /// z-binning.
    fn refinement_fields(&self) -> Vec<String> {
        let c = self.last.clusters.as_ref();
        vec![
            c.map_or(String::new(), |c| c.coarse_span.to_string()),
            c.map_or(String::new(), |c| c.coarse_entries.to_string()),
            opt3(self.depth_bounded),
            pass_ms::<ClusterDepthPass>(&self.last),
            pass_ms::<LightRefinePass>(&self.last),
            opt3(self.zbinned),
        ]
    }

    /// `shadows` to `flicker`: the shadow maps and their accuracy.
    fn shadow_fields(&self) -> Vec<String> {
        let s = self.last.shadows;
        let a = self.shadow_accuracy;
        vec![
            self.shadows.name().to_string(),
            s.map_or(0, |s| s.maps_rendered).to_string(),
            s.map_or(0, |s| s.maps_cached).to_string(),
            s.map_or(0, |s| s.maps_stale).to_string(),
            s.map_or(0, |s| s.atlas_bytes).to_string(),
            pass_ms::<ShadowMapsPass>(&self.last),
            a.map_or(String::new(), |a| format!("{:.5}", a.visibility_error)),
            a.map_or(String::new(), |a| format!("{:.5}", a.flip_vs_reference)),
            a.map_or(String::new(), |a| format!("{:.6}", a.light_error)),
            a.map_or(String::new(), |a| format!("{:.6}", a.flicker)),
        ]
    }

    /// `frame_ms_min` to `upload_bytes`: the frame time's range and the CPU phases.
    fn cpu_fields(&self) -> Vec<String> {
        let cpu = &self.last.cpu;
        vec![
            format!("{:.3}", self.frame_ms.iter().copied().fold(f64::INFINITY, f64::min)),
            format!("{:.3}", self.frame_ms.iter().copied().fold(0.0, f64::max)),
            format!("{:.3}", self.last.frame_cpu_ms),
            format!("{:.3}", cpu.upload_ms),
            format!("{:.3}", cpu.prepare_ms),
            format!("{:.3}", cpu.record_ms),
            format!("{:.3}", cpu.submit_ms),
            cpu.upload_bytes.to_string(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::unlike;

    #[test]
    fn frames_are_unlike_only_past_the_tolerance() {
        assert_eq!(unlike(0.131, 0.131), None);
        assert_eq!(unlike(0.150, 0.131), None);
        assert_eq!(unlike(0.110, 0.131), None);
        assert!(unlike(0.752, 0.131).is_some_and(|r| (r - 5.74).abs() < 0.01));
        assert!(unlike(0.05, 0.131).is_some_and(|r| r < 0.5));
        assert_eq!(unlike(0.1, 0.0), None);
    }
}

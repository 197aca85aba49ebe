//! `manylight report`: what accuracy costs in time. Renders the naive forward reference and
//! every approximation (tiled, clustered, deferred with each G-buffer layout) of the same frame
//! in one run, and prints a markdown table of FLIP error against the reference, frame time and
//! per-pass GPU time.

use crate::bench::shading_ms;
use crate::direct::{oracle_snapshot, snapshot};
use crate::progress::Progress;
use anyhow::Result;
use glam::UVec2;
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::attenuation::RANGELESS_LIGHT_CUTOFF;
use manylight_core::cluster::CullTest;
use manylight_core::codec::NormalCodec;
use manylight_core::image_metrics::flip_compare;
use manylight_render::{
    ClusterSettings, FrameReport, FrameSettings, FrameSnapshot, GBufferLayout, PipelineKind, RenderSettings,
};
use manylight_scene::{AnimatedLight, Scene, light_rig};
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
    let rig = light_rig(lights, scene.bounds(), 1)?;
    measure_rig(renderer, scene, &rig, size, settings, frames)
}

/// [`measure`] with the rig given.
fn measure_rig(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    rig: &[AnimatedLight],
    size: UVec2,
    settings: FrameSettings,
    frames: u32,
) -> Result<(f64, FrameReport, image::RgbaImage)> {
    measure_snapshots(renderer, frames, |f| snapshot(scene, rig, 0.0, size, settings, f))
}

/// Renders `frames` timed frames of `snapshot(frame)` after one warm-up and returns the median
/// frame time, the last report and the last image.
fn measure_snapshots(
    renderer: &mut HeadlessRenderer,
    frames: u32,
    snapshot: impl Fn(u64) -> FrameSnapshot,
) -> Result<(f64, FrameReport, image::RgbaImage)> {
    let mut times = Vec::new();
    let mut last = None;
    for f in 0..=frames {
        let snap = snapshot(u64::from(f));
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
    let mut configs = vec![(
        "forward-plus".to_string(),
        FrameSettings {
            render: RenderSettings { pipeline: PipelineKind::ForwardPlus, ..base.render },
            ..base
        },
    )];
    for cull in [CullTest::Both, CullTest::Aabb, CullTest::Planes] {
        let clusters = ClusterSettings { cull, ..base.clusters };
        let settings = FrameSettings {
            render: RenderSettings { pipeline: PipelineKind::ClusteredForward, clusters, ..base.render },
            ..base
        };
        configs.push((format!("clustered-forward, cull {}", cull.name()), settings));
    }
    let capped = ClusterSettings { cap: Some(8), ..base.clusters };
    configs.push((
        "clustered-forward, cap 8 lights/cluster".into(),
        FrameSettings {
            render: RenderSettings {
                pipeline: PipelineKind::ClusteredForward,
                clusters: capped,
                ..base.render
            },
            ..base
        },
    ));
    for pipeline in [PipelineKind::ClusteredDeferred, PipelineKind::TiledDeferred, PipelineKind::LightVolumes]
    {
        for gbuffer in GBufferLayout::ALL {
            let codecs: Vec<NormalCodec> = if !gbuffer.uses_codec() {
                vec![base.normal_codec]
            } else if pipeline == PipelineKind::ClusteredDeferred {
                NormalCodec::ALL.into_iter().filter(|&c| gbuffer.supports(c)).collect()
            } else {
                vec![NormalCodec::Octa16] // the codecs cost the same in every deferred pipeline
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
                configs.push((
                    name,
                    FrameSettings {
                        render: RenderSettings { pipeline, gbuffer, normal_codec, ..base.render },
                        ..base
                    },
                ));
            }
        }
    }
    configs
}

/// One configuration's result.
struct ReportRow {
    name: String,
    settings: Option<FrameSettings>,
    frame_ms: f64,
    report: FrameReport,
    flip_mean: f64,
    flip_p99: f64,
}

/// What a measuring command prints: a markdown table for the terminal and the same figures as
/// CSV (for `--plot`), one row per configuration.
pub struct Report {
    /// The markdown table with a line of context above it.
    pub markdown: String,
    /// The CSV text.
    pub csv: String,
}

/// Runs the comparison on `scene` (called `scene_name` in the output).
pub fn run(
    scene: &Scene,
    scene_name: &str,
    lights: usize,
    size: UVec2,
    frames: u32,
    base: FrameSettings,
) -> Result<Report> {
    let mut renderer = HeadlessRenderer::new()?;
    let adapter = renderer.render_world.gpu().info.name.clone();
    let configs = configurations(base);
    let mut progress = Progress::new(configs.len() as u64 + 3, "configurations");
    progress.set_message("naive forward (reference)");
    let naive = FrameSettings {
        render: RenderSettings { pipeline: PipelineKind::NaiveForward, ..base.render },
        ..base
    };
    let (naive_ms, naive_report, reference) = measure(&mut renderer, scene, lights, size, naive, frames)?;
    progress.step(|| format!("naive forward (reference): {naive_ms:.0} ms"));
    let mut rows = vec![ReportRow {
        name: "naive forward (reference)".into(),
        settings: None,
        frame_ms: naive_ms,
        report: naive_report,
        flip_mean: 0.0,
        flip_p99: 0.0,
    }];
    // The oracles: the same frame shaded from exact per-pixel lists (built from a clustered
    // frame's depth before the timed frames), by clustered forward and by clustered deferred
    // with the base G-buffer layout.
    let rig = light_rig(lights, scene.bounds(), 1)?;
    for (name, pipeline) in
        [(FORWARD_ORACLE, PipelineKind::ClusteredForward), (DEFERRED_ORACLE, PipelineKind::ClusteredDeferred)]
    {
        progress.set_message(name.to_string());
        let settings = FrameSettings { render: RenderSettings { pipeline, ..base.render }, ..base };
        let (oracle, _) = oracle_snapshot(&mut renderer, snapshot(scene, &rig, 0.0, size, settings, 0))?;
        let (ms, report, image) =
            measure_snapshots(&mut renderer, frames, |f| FrameSnapshot { frame_index: f, ..oracle.clone() })?;
        let (flip, _) =
            flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
        progress.step(|| format!("{name}: {ms:.0} ms, FLIP mean {:.5}", flip.mean));
        rows.push(ReportRow {
            name: name.to_string(),
            settings: Some(settings),
            frame_ms: ms,
            report,
            flip_mean: f64::from(flip.mean),
            flip_p99: f64::from(flip.p99),
        });
    }
    for (name, settings) in configs {
        progress.set_message(name.clone());
        let (ms, report, image) = measure(&mut renderer, scene, lights, size, settings, frames)?;
        let (flip, _) =
            flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
        progress.step(|| format!("{name}: {ms:.0} ms, FLIP mean {:.5}", flip.mean));
        rows.push(ReportRow {
            name,
            settings: Some(settings),
            frame_ms: ms,
            report,
            flip_mean: f64::from(flip.mean),
            flip_p99: f64::from(flip.p99),
        });
    }
    progress.finish();
    let context = format!(
        "{lights} lights (+ the scene's own), {}x{}, {scene_name}, {adapter}; median of {frames} frames",
        size.x, size.y
    );
    let mut markdown = markdown(&rows, &context);
    markdown.push('\n');
    markdown.push_str(&rangeless_lights(&mut renderer, scene, lights, size, frames, base)?);
    Ok(Report { markdown, csv: csv(&rows, scene_name, size, &adapter)? })
}

/// Cut-off thresholds the "lights without a range" table compares, as fractions of a light's
/// intensity (the loader's is [`RANGELESS_LIGHT_CUTOFF`]).
pub const CUTOFFS: [f32; 5] = [0.1, 0.03, 0.01, RANGELESS_LIGHT_CUTOFF, 0.001];

/// The range standing in for "unbounded": the falloff's window `(1 - (d/r)^4)^2` stays within
/// 1e-7 of 1 for every distance under 50 (the scenes' size), so the sum equals the unbounded
/// inverse-square sum to f32 precision.
pub const UNBOUNDED_RANGE: f32 = 1.0e4;

/// What cutting lights without a range costs: the rig's lights as if they came without one,
/// cut off at each of [`CUTOFFS`] (range `radius_for_intensity(intensity, cutoff)`) and
/// shaded by clustered forward, against the unbounded sum (every light reaching every pixel,
/// naive forward). A markdown table of FLIP error and frame time.
pub fn rangeless_lights(
    renderer: &mut HeadlessRenderer,
    scene: &Scene,
    lights: usize,
    size: UVec2,
    frames: u32,
    base: FrameSettings,
) -> Result<String> {
    let rig = light_rig(lights, scene.bounds(), 1)?;
    let with_range = |range: &dyn Fn(&AnimatedLight) -> f32| -> Vec<AnimatedLight> {
        rig.iter().map(|l| AnimatedLight { radius: range(l), ..*l }).collect()
    };
    let with = |pipeline| FrameSettings { render: RenderSettings { pipeline, ..base.render }, ..base };
    let mut progress = Progress::new(CUTOFFS.len() as u64 + 2, "cut-offs");
    progress.set_message("unbounded, naive forward (reference)");
    let unbounded = with_range(&|_| UNBOUNDED_RANGE);
    let (naive_ms, _, reference) =
        measure_rig(renderer, scene, &unbounded, size, with(PipelineKind::NaiveForward), frames)?;
    progress.step(|| format!("unbounded, naive forward: {naive_ms:.0} ms"));
    let mut out = format!(
        "Lights without a range: the {lights} rig lights cut off where they fall to a fraction of \
         their intensity, clustered forward, against their unbounded sum (naive forward, \
         {naive_ms:.0} ms); the loader cuts at {RANGELESS_LIGHT_CUTOFF}.\n\n"
    );
    out.push_str("| cut off at | mean range | FLIP mean | FLIP p99 | frame ms | vs unbounded naive |\n");
    out.push_str("|---|---:|---:|---:|---:|---:|\n");
    let clustered = with(PipelineKind::ClusteredForward);
    let mut rows: Vec<(String, Vec<AnimatedLight>)> = CUTOFFS
        .iter()
        .map(|&c| {
            let lit =
                with_range(&|l| manylight_core::radius_for_intensity(l.intensity * l.color.max_element(), c));
            (format!("{c}"), lit)
        })
        .collect();
    rows.push(("unbounded".into(), unbounded));
    for (name, lit) in rows {
        progress.set_message(format!("cut off at {name}"));
        let (ms, _, image) = measure_rig(renderer, scene, &lit, size, clustered, frames)?;
        let (flip, _) =
            flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
        let mean_range = lit.iter().map(|l| f64::from(l.radius)).sum::<f64>() / lit.len().max(1) as f64;
        let _ = writeln!(
            out,
            "| {name} | {mean_range:.1} | {:.5} | {:.5} | {ms:.0} | {:.2}× |",
            flip.mean,
            flip.p99,
            naive_ms / ms
        );
        progress.step(|| format!("cut off at {name}: {ms:.0} ms, FLIP mean {:.5}", flip.mean));
    }
    progress.finish();
    Ok(out)
}

fn passes(r: &FrameReport) -> String {
    r.passes
        .iter()
        .map(|p| match p.gpu_ms {
            Some(ms) if p.gpu_trusted => format!("{} {ms:.1}", p.name),
            Some(ms) => format!("{} {ms:.1}*", p.name),
            None => p.name.clone(),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Name of the report's row shaded by clustered forward from exact per-pixel lists.
const FORWARD_ORACLE: &str = "oracle, forward (exact per-pixel lists)";
/// Name of the report's row shaded by clustered deferred from exact per-pixel lists.
const DEFERRED_ORACLE: &str = "oracle, deferred (exact per-pixel lists)";

/// `row`'s shading GPU time (`shading_ms`) over its oracle's: the deferred oracle's (base
/// G-buffer layout) for the deferred pipelines, the forward oracle's for the others.
fn shading_vs_oracle(rows: &[ReportRow], row: &ReportRow) -> Option<f64> {
    let deferred = row.settings.is_some_and(|s| s.pipeline.is_deferred());
    let name = if deferred { DEFERRED_ORACLE } else { FORWARD_ORACLE };
    let oracle = rows.iter().find(|r| r.name == name).and_then(|r| shading_ms(&r.report))?;
    shading_ms(&row.report).filter(|_| oracle > 0.0).map(|s| s / oracle)
}

fn markdown(rows: &[ReportRow], context: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{context}\n");
    let _ = writeln!(
        out,
        "| pipeline | G-buffer bytes/px | transient texture MiB | FLIP mean | FLIP p99 | dropped light-cluster pairs | frame ms | speed-up | shading vs oracle | passes (GPU ms; * = untrusted) |"
    );
    let _ = writeln!(out, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    let naive_ms = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    for r in rows {
        let bytes = match r.settings {
            Some(s) if s.pipeline.is_deferred() => s.gbuffer.bytes_per_pixel().to_string(),
            _ => "–".into(),
        };
        let dropped = r.report.clusters.as_ref().map_or(0, |c| c.dropped_pairs);
        let (mean, p99) = if r.settings.is_none() {
            ("0".to_string(), "0".to_string())
        } else {
            (format!("{:.5}", r.flip_mean), format!("{:.5}", r.flip_p99))
        };
        let vs_oracle = shading_vs_oracle(rows, r).map_or("–".to_string(), |x| format!("{x:.2}×"));
        let _ = writeln!(
            out,
            "| {} | {bytes} | {:.1} | {mean} | {p99} | {dropped} | {:.0} | {:.1}× | {vs_oracle} | {} |",
            r.name,
            crate::bench::mib(r.report.transient_bytes),
            r.frame_ms,
            naive_ms / r.frame_ms,
            passes(&r.report)
        );
    }
    out
}

fn csv(rows: &[ReportRow], scene: &str, size: UVec2, adapter: &str) -> Result<String> {
    let pass_names = crate::bench::pass_names(rows.iter().map(|r| &r.report));
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = crate::bench::configuration_header(
        &[
            "pipeline",
            "gbuffer",
            "gbuffer_bytes_per_pixel",
            "normal_codec",
            "flip_mean",
            "flip_p99",
            "dropped_pairs",
            "frame_ms_median",
            "speedup",
            "shading_ms",
            "shading_vs_oracle",
            "transient_mib",
            "cluster_buffer_mib",
            "untrusted_passes",
        ],
        &pass_names,
    );
    w.write_record(&header)?;
    let naive_ms = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    for r in rows {
        let deferred = r.settings.filter(|s| s.pipeline.is_deferred());
        let mut record = crate::bench::configuration_fields(adapter, scene, size, &r.name);
        record.extend([
            r.report.pipeline.name().to_string(),
            deferred.map_or(String::new(), |s| s.gbuffer.name().to_string()),
            deferred.map_or(String::new(), |s| s.gbuffer.bytes_per_pixel().to_string()),
            deferred
                .filter(|s| s.gbuffer.uses_codec())
                .map_or(String::new(), |s| s.normal_codec.name().to_string()),
            format!("{:.6}", r.flip_mean),
            format!("{:.6}", r.flip_p99),
            r.report.clusters.as_ref().map_or(0, |c| c.dropped_pairs).to_string(),
            format!("{:.3}", r.frame_ms),
            format!("{:.3}", naive_ms / r.frame_ms),
            shading_ms(&r.report).map_or(String::new(), |x| format!("{x:.3}")),
            shading_vs_oracle(rows, r).map_or(String::new(), |x| format!("{x:.3}")),
            format!("{:.3}", crate::bench::mib(r.report.transient_bytes)),
            r.report
                .clusters
                .as_ref()
                .map_or(String::new(), |c| format!("{:.3}", crate::bench::mib(c.buffer_bytes))),
            r.report
                .passes
                .iter()
                .filter(|p| p.gpu_ms.is_some() && !p.gpu_trusted)
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(";"),
        ]);
        record.extend(crate::bench::pass_times(&r.report, &pass_names));
        w.write_record(&record)?;
    }
    Ok(String::from_utf8(w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?)?)
}

/// One setting of `report --shadows`.
struct ShadowConfiguration {
    name: String,
    settings: FrameSettings,
    /// The rig stands still (every frame at time 0): what caching keeps; otherwise it moves at
    /// 60 frames a second and every map changes every frame.
    still: bool,
}

/// The shadow settings `report --shadows` compares: none, then the atlas sizes and resolution
/// policies and redraw budgets (at the default atlas) and shadow rays with moving lights, then
/// caching and rays with still lights; every light of the scene and the rig casting.
fn shadow_configurations(base: FrameSettings) -> Vec<ShadowConfiguration> {
    let with = |name: &str, still: bool, f: &dyn Fn(&mut manylight_render::ShadowSettings)| {
        let mut settings = base;
        f(&mut settings.render.shadows);
        ShadowConfiguration { name: name.to_string(), settings, still }
    };
    vec![
        with("shadows off", false, &|s| s.enabled = false),
        with("atlas 2048", false, &|s| s.atlas_size = 2048),
        with("atlas 4096, at most 256 maps redrawn (default)", false, &|_| {}),
        with("atlas 8192", false, &|s| s.atlas_size = 8192),
        with("faces ×0.5", false, &|s| s.resolution_scale = 0.5),
        with("faces ×2", false, &|s| s.resolution_scale = 2.0),
        with("faces at most 128", false, &|s| s.max_face_size = 128),
        with("Gaussian filter (3×3)", false, &|s| {
            s.filter = manylight_render::ShadowFilteringMethod::Gaussian
        }),
        with("every changed map redrawn", false, &|s| s.max_redrawn_maps = None),
        with("at most 64 maps redrawn", false, &|s| s.max_redrawn_maps = Some(64)),
        with("rays (exact)", false, &|s| s.method = manylight_render::ShadowMethod::Rays),
        with("still lights, shadows off", true, &|s| s.enabled = false),
        with("still lights, maps cached (default)", true, &|_| {}),
        with("still lights, no caching", true, &|s| {
            s.cache_maps = false;
            s.max_redrawn_maps = None;
        }),
        with("still lights, rays (exact)", true, &|s| s.method = manylight_render::ShadowMethod::Rays),
    ]
}

/// One shadow setting's result.
struct ShadowRow {
    name: String,
    /// Shadows are off: the rows after it are timed against it (× off).
    off: bool,
    frame_ms: f64,
    report: FrameReport,
    accuracy: crate::shadow_error::ShadowAccuracy,
}

/// What shadows cost and how far each setting is from exact visibility: for each of
/// [`shadow_configurations`], the median frame time of `frames` timed frames and the last
/// frame's visibility error and FLIP against the shadow reference
/// (`crate::shadow_error::measure_shadows`), `lights` rig lights all casting, clustered forward,
/// each setting on a renderer of its own.
pub fn shadows(
    scene: &Scene,
    scene_name: &str,
    lights: usize,
    size: UVec2,
    frames: u32,
    base: FrameSettings,
) -> Result<Report> {
    let mut adapter = String::new();
    let rig = light_rig(lights, scene.bounds(), 1)?;
    let occluders = crate::shadow_error::occluders(scene);
    let base = FrameSettings {
        render: RenderSettings { pipeline: PipelineKind::ClusteredForward, ..base.render },
        ..base
    };
    let configs = shadow_configurations(base);
    let mut progress = Progress::new(configs.len() as u64, "shadow settings");
    let mut rows = Vec::new();
    for ShadowConfiguration { name, settings, still } in configs {
        progress.set_message(name.clone());
        // A renderer each: the atlas never shrinks, so a setting after a larger one would draw
        // into (and clear) the larger atlas.
        let mut renderer = HeadlessRenderer::new()?;
        adapter = renderer.render_world.gpu().info.name.clone();
        let casting = |f: u64| {
            let time = if still { 0.0 } else { f as f32 / 60.0 };
            let mut snap = snapshot(scene, &rig, time, size, settings, f);
            crate::direct::cast_every_shadow(&mut snap);
            snap
        };
        let (frame_ms, report, _) = measure_snapshots(&mut renderer, frames, casting)?;
        // The frame after the timed ones, as caching and the budget leave it.
        let accuracy =
            crate::shadow_error::measure_shadows(&mut renderer, casting(u64::from(frames) + 1), &occluders)?;
        progress
            .step(|| format!("{name}: {frame_ms:.0} ms, visibility error {:.4}", accuracy.visibility_error));
        rows.push(ShadowRow { name, off: !settings.render.shadows.enabled, frame_ms, report, accuracy });
    }
    progress.finish();
    let context = format!(
        "{scene_name}, {lights} rig lights (and the scene's own) all casting, {}x{}, clustered forward, \
         {adapter}; hardware 2×2 filter unless said; lights moving at 60 frames a second unless still \
         (× off: against the first row of the same motion); the last frame's figures",
        size.x, size.y
    );
    Ok(Report {
        markdown: shadow_markdown(&rows, &context),
        csv: shadow_csv(&rows, scene_name, size, &adapter)?,
    })
}

fn shadow_markdown(rows: &[ShadowRow], context: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{context}\n");
    let _ = writeln!(
        out,
        "| setting | frame ms | × off | shadow pass ms | atlas MiB | maps drawn / cached / stale | smaller than asked / none | visibility error | false shadow | light leak | FLIP vs shadow reference | light error | flicker |"
    );
    let _ = writeln!(out, "|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|");
    let mut off_ms = f64::NAN;
    for r in rows {
        if r.off {
            off_ms = r.frame_ms;
        }
        let s = r.report.shadows.unwrap_or_default();
        let pass = r.report.pass_gpu_ms::<manylight_render::passes::ShadowMapsPass>();
        let a = &r.accuracy;
        let _ = writeln!(
            out,
            "| {} | {:.0} | {:.2}× | {} | {:.0} | {} / {} / {} | {} / {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.5} | {:.5} |",
            r.name,
            r.frame_ms,
            r.frame_ms / off_ms,
            pass.map_or("–".to_string(), |ms| format!("{ms:.0}")),
            crate::bench::mib(s.atlas_bytes),
            s.maps_rendered,
            s.maps_cached,
            s.maps_stale,
            s.downgraded_lights,
            s.dropped_lights,
            a.visibility_error,
            a.false_shadow,
            a.light_leak,
            a.flip.mean,
            a.light_error,
            a.flicker
        );
    }
    out
}

/// The shadow rows as CSV: `flip_mean` is FLIP against the shadow reference, so `plot` draws
/// the accuracy-against-time figure of the settings.
fn shadow_csv(rows: &[ShadowRow], scene: &str, size: UVec2, adapter: &str) -> Result<String> {
    let pass_names = crate::bench::pass_names(rows.iter().map(|r| &r.report));
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = crate::bench::configuration_header(
        &[
            "frame_ms_median",
            "flip_mean",
            "flip_p99",
            "visibility_error",
            "false_shadow",
            "light_leak",
            "light_error",
            "flicker",
            "shadow_maps_rendered",
            "shadow_maps_cached",
            "shadow_maps_stale",
            "shadow_atlas_bytes",
            "downgraded_lights",
            "dropped_lights",
            "transient_mib",
        ],
        &pass_names,
    );
    w.write_record(&header)?;
    for r in rows {
        let s = r.report.shadows.unwrap_or_default();
        let a = &r.accuracy;
        let mut record = crate::bench::configuration_fields(adapter, scene, size, &r.name);
        record.extend([
            format!("{:.3}", r.frame_ms),
            format!("{:.6}", a.flip.mean),
            format!("{:.6}", a.flip.p99),
            format!("{:.6}", a.visibility_error),
            format!("{:.6}", a.false_shadow),
            format!("{:.6}", a.light_leak),
            format!("{:.6}", a.light_error),
            format!("{:.6}", a.flicker),
            s.maps_rendered.to_string(),
            s.maps_cached.to_string(),
            s.maps_stale.to_string(),
            s.atlas_bytes.to_string(),
            s.downgraded_lights.to_string(),
            s.dropped_lights.to_string(),
            format!("{:.2}", crate::bench::mib(r.report.transient_bytes)),
        ]);
        record.extend(crate::bench::pass_times(&r.report, &pass_names));
        w.write_record(&record)?;
    }
    Ok(String::from_utf8(w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?)?)
}

//! What `render` measures of its last frame besides drawing it: the culling efficiency of
//! its light lists (`--culling-efficiency`), its shading time against the oracle's
//! (`--oracle`), its shadows against exact visibility (`--shadow-oracle`), and the
//! `--stats-json` document that carries them.

use crate::args::RenderArgs;
use crate::{bench, direct, shadow_error};
use anyhow::{Context, Result};
use manylight_app::FrameStats;
use manylight_render::PipelineKind;
use manylight_scene::Scene;

/// The measured frame of `--culling-efficiency`, `--oracle` and `--shadow-oracle` (`None`
/// without them): the last frame's animation time with `rig_lights` rig lights, rendered
/// straight from the scene (no app).
pub(super) fn measured_snapshot(
    args: &RenderArgs,
    scene: &Scene,
    rig_lights: usize,
    shadows: manylight_render::ShadowSettings,
) -> Result<Option<manylight_render::FrameSnapshot>> {
    if !(args.culling_efficiency || args.oracle || args.shadow_oracle) {
        return Ok(None);
    }
    let rig = manylight_scene::light_rig(rig_lights, scene.bounds(), args.seed)?;
    let t = args.frames.max(1).saturating_sub(1) as f32 / 60.0;
    let settings = manylight_render::FrameSettings {
        render: manylight_render::RenderSettings {
            pipeline: args.pipeline,
            shading: args.shading,
            clusters: args.clusters.settings(&args.scene),
            gbuffer: args.clusters.gbuffer,
            normal_codec: args.clusters.normal_codec,
            shadows,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut snapshot = direct::snapshot(scene, &rig, t, args.size, settings, 0);
    if args.shadows.casts() {
        direct::cast_every_shadow(&mut snapshot);
    }
    Ok(Some(snapshot))
}

/// Measures the culling efficiency of `snapshot`'s lists, and of the lists depth bounds and
/// z-binning would make (measured, not built), prints them and returns the lists'.
pub(super) fn measure_culling_efficiency(
    snapshot: manylight_render::FrameSnapshot,
) -> Result<manylight_core::efficiency::CullingEfficiency> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let (_, culling) = direct::measure_culling(&mut renderer, snapshot)?;
    let eff = culling.lists;
    println!(
        "culling efficiency: {} light-pixel pairs evaluated, {} contributing: {:.3}x \
         ({} sampled pixels, {} contributing pairs missing from the lists)",
        eff.evaluated_pairs,
        eff.contributing_pairs,
        eff.ratio(),
        eff.sampled_pixels,
        eff.missed_pairs
    );
    let bounded = culling.depth_bounded;
    println!(
        "with per-cluster depth bounds (measured on these lists, not built): {} pairs \
         evaluated: {:.3}x ({} contributing pairs missing)",
        bounded.evaluated_pairs,
        bounded.ratio(),
        bounded.missed_pairs
    );
    if let Some(z) = culling.zbinned {
        println!(
            "with z-binning of the tile lists ({} bins; measured, not built): {} pairs \
             evaluated: {:.3}x ({} contributing pairs missing)",
            direct::ZBINS,
            z.evaluated_pairs,
            z.ratio(),
            z.missed_pairs
        );
    }
    Ok(eff)
}

/// Times `snapshot`'s shading passes against the oracle's (the same frame shaded from exact
/// per-pixel lists): 3 frames of each, interleaved after a warm-up, medians. Prints and returns
/// (pipeline ms, oracle ms).
pub(super) fn measure_oracle(
    snapshot: manylight_render::FrameSnapshot,
    pipeline: PipelineKind,
) -> Result<(f64, f64)> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let (oracle, _) = direct::oracle_snapshot(&mut renderer, snapshot.clone())?;
    let names = [pipeline.name().to_string(), "oracle".to_string()];
    let snapshots = [snapshot, oracle];
    let (_, timed) = direct::interleaved(&names, 3, "frames", |i, _| snapshots[i].clone())?;
    let shading = |frames: &[direct::TimedFrame], what: &str| -> Result<f64> {
        let ms = frames.iter().map(|f| bench::shading_ms(&f.report)).collect::<Option<Vec<f64>>>();
        Ok(bench::median(&ms.with_context(|| format!("no GPU timings for {what}'s shading"))?))
    };
    let (ours, floor) = (shading(&timed[0], pipeline.name())?, shading(&timed[1], "the oracle")?);
    println!(
        "oracle: {} shades in {ours:.1} ms GPU, the oracle (exact per-pixel lists) in {floor:.1} ms: {:.2}x the floor (medians of 3)",
        pipeline.name(),
        ours / floor
    );
    Ok((ours, floor))
}

/// Measures `snapshot`'s shadows against exact visibility through `scene`'s triangles and
/// prints the result.
pub(super) fn measure_shadow_accuracy(
    scene: &Scene,
    snapshot: manylight_render::FrameSnapshot,
) -> Result<shadow_error::ShadowAccuracy> {
    let mut renderer = manylight_app::render_world::HeadlessRenderer::new()?;
    let occluders = shadow_error::occluders(scene);
    let a = shadow_error::measure_shadows(&mut renderer, snapshot, &occluders)?;
    println!(
        "shadow oracle: visibility error {:.4} (false shadow {:.4}, light leak {:.4}) over {} \
         contributing light-pixel pairs ({} blocked, {} tested on the wrong side); FLIP against \
         the shadow reference: mean {:.4}, p99 {:.4}; light error {:.5} (HDR luminance against \
         the shadow reference, of the unshadowed light); flicker {:.5} (the next still frame's \
         change); the oracle cast {} rays in {:.0} ms",
        a.visibility_error,
        a.false_shadow,
        a.light_leak,
        a.contributing_pairs,
        a.blocked_pairs,
        a.wrong_pairs,
        a.flip.mean,
        a.flip.p99,
        a.light_error,
        a.flicker,
        a.rays,
        a.ray_cast_ms
    );
    if !scene.directional_lights.is_empty() {
        println!(
            "shadow oracle: the {} directional light(s) are not measured (the reference keeps their cascades)",
            scene.directional_lights.len()
        );
    }
    Ok(a)
}

/// `--stats-json`'s document: the last frame's statistics ([`stats_json`]) and the
/// measurements `render` made of it.
pub(super) fn render_stats_json(
    stats: &FrameStats,
    oracle: Option<(f64, f64)>,
    shadow_accuracy: Option<&shadow_error::ShadowAccuracy>,
    culling: Option<manylight_core::efficiency::CullingEfficiency>,
) -> serde_json::Value {
    let mut json = stats_json(stats);
    if let Some((ours, floor)) = oracle {
        json["oracle"] = serde_json::json!({
            "shading_ms": ours,
            "oracle_shading_ms": floor,
            "shading_vs_oracle": ours / floor,
        });
    }
    if let Some(a) = shadow_accuracy {
        json["shadow_oracle"] = serde_json::json!({
            "contributing_pairs": a.contributing_pairs,
            "blocked_pairs": a.blocked_pairs,
            "wrong_pairs": a.wrong_pairs,
            "visibility_error": a.visibility_error,
            "false_shadow": a.false_shadow,
            "light_leak": a.light_leak,
            "flip_vs_shadow_reference": a.flip.mean,
            "flip_vs_shadow_reference_p99": a.flip.p99,
            "light_error": a.light_error,
            "flicker": a.flicker,
            "rays": a.rays,
            "ray_cast_ms": a.ray_cast_ms,
        });
    }
    if let Some(e) = culling {
        json["culling_efficiency"] = serde_json::json!({
            "pixels": e.pixels,
            "evaluated_pairs": e.evaluated_pairs,
            "contributing_pairs": e.contributing_pairs,
            "ratio": e.ratio(),
            "sampled_pixels": e.sampled_pixels,
            "missed_pairs": e.missed_pairs,
        });
    }
    json
}

/// The last frame's statistics as JSON.
fn stats_json(stats: &FrameStats) -> serde_json::Value {
    // Plain data with string keys: it serialises to a value whatever it holds.
    serde_json::to_value(stats.document()).unwrap_or(serde_json::Value::Null)
}

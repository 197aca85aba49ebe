//! A floor whose corners lie at ±10⁷ under point lights, drawn as one quad (two triangles
//! whose vertices lie up to 10⁷ units from pixels two units from the camera), in every
//! pipeline, G-buffer layout and normal codec, against the same plane tessellated into rings
//! that grow geometrically with the distance from the camera's foot point (the reference: no
//! triangle's vertices lie much farther from the camera than the pixels it covers), which is
//! itself checked against the floor shaded analytically on the CPU. The figures before and after
//! shading `surface_point` are in docs/reliability.md (very large surfaces); `manylight report
//! --large-floor` measures them at any extent, flat and tilted.

mod support;
// The floor, its references and the configurations, shared with `manylight report
// --large-floor` (which measures what these tests hold to a tolerance, at any extent).
#[allow(dead_code)]
#[path = "../crates/manylight_cli/src/large_floor/floor.rs"]
mod floor;

use floor::{
    NEAR, analytic_floor, configurations, floor_scene, quad_floor, ring_floor, settings_for, worst_channel,
};
use manylight::app::RenderSettings;
use manylight::prelude::*;
use support::{STRICT, Tolerance, assert_similar, gpu, render_scene as render};

const SIZE: UVec2 = UVec2::new(256, 144);

/// The tolerance of a configuration against naive forward on ordinary scenes
/// (`tests/deferred.rs`, `tests/image.rs`).
fn tolerance(settings: &RenderSettings) -> Tolerance {
    let deferred = settings.pipeline.is_deferred();
    match (deferred, settings.gbuffer, settings.normal_codec) {
        (true, GBufferLayout::Compact, _) => support::COMPACT,
        (true, GBufferLayout::Packed, NormalCodec::Xyz) => Tolerance { mean: 0.005, p99: 0.08 },
        _ => STRICT,
    }
}

/// Half-size of the floor: its corners lie 10⁷ units from pixels two units from the camera.
const HUGE: f64 = 1e7;
/// Far plane beyond the whole floor (no far-plane clipping).
const FAR: f32 = 1e8;

/// The reference is right: the ring floor drawn by naive forward equals the analytic floor to
/// one 8-bit step (the rounding of the f16 HDR target and of the output).
#[test]
fn ring_floor_matches_the_analytic_floor() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward, RenderSettings::default());
    let rings = render(floor_scene(ring_floor(HUGE), FAR), SIZE, 0, naive);
    let analytic = analytic_floor(HUGE, f64::from(FAR), SIZE, &naive);
    let worst = worst_channel(&analytic, &rings.image);
    let s = support::flip(&analytic, &rings.image);
    eprintln!("rings vs analytic: FLIP mean {:.5}, p99 {:.5}, worst channel {worst}", s.mean, s.p99);
    assert!(worst <= 2, "ring floor vs analytic floor: worst channel {worst}/255");
}

/// Every pipeline, layout and codec draws the one-quad floor like the ring floor, within the
/// tolerance it is held to on ordinary scenes, with no NaN or infinite pixel (`render`).
/// Before each pass shaded `surface_point`, naive forward measured FLIP mean 0.134 here and
/// the Compact layout 0.218.
#[test]
fn huge_floor_matches_the_tessellated_reference_in_every_pipeline() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward, RenderSettings::default());
    let reference = render(floor_scene(ring_floor(HUGE), FAR), SIZE, 0, naive);
    for (name, settings) in configurations(RenderSettings::default()) {
        let frame = render(floor_scene(quad_floor(HUGE), FAR), SIZE, 0, settings);
        let passes = frame.stats.last.as_ref().expect("report").pass_names();
        if settings.pipeline == PipelineKind::LightVolumes {
            assert!(passes.contains(&"light_volumes"), "{name}: {passes:?}");
        } else if settings.pipeline == PipelineKind::ClusteredDeferred {
            assert!(passes.contains(&"deferred_lighting"), "{name}: {passes:?}");
        } else if settings.pipeline == PipelineKind::TiledDeferred {
            assert!(passes.contains(&"tiled_deferred"), "{name}: {passes:?}");
        }
        let s = assert_similar(
            &format!("huge_floor_{name}"),
            &reference.image,
            &frame.image,
            tolerance(&settings),
        );
        let worst = worst_channel(&reference.image, &frame.image);
        eprintln!("huge floor {name}: FLIP mean {:.5}, p99 {:.5}, worst channel {worst}", s.mean, s.p99);
    }
}

/// Without a far plane nothing is clipped however far the floor reaches (it runs to the
/// horizon at 10⁷, where a finite stand-in of near × 10⁴ would have cut it at 1 000): the ring
/// floor matches the analytic floor with `t ≤ ∞`, and every pipeline, layout and codec draws
/// the one-quad floor like it. The lights reach 16 units, so the cluster grid ends there and
/// the floor beyond lies in its last slice.
#[test]
fn an_infinite_projection_clips_nothing_in_every_pipeline() {
    let _gpu = gpu();
    let naive = settings_for(PipelineKind::NaiveForward, RenderSettings::default());
    let reference = render(floor_scene(ring_floor(HUGE), f32::INFINITY), SIZE, 0, naive);
    let analytic = analytic_floor(HUGE, f64::INFINITY, SIZE, &naive);
    // The frame shows floor beyond 1 000 units: a far plane there would change pixels.
    let clipped = analytic_floor(HUGE, f64::from(NEAR) * 1e4, SIZE, &naive);
    assert!(worst_channel(&analytic, &clipped) > 2, "the view shows no floor beyond 1 000 units");
    let worst = worst_channel(&analytic, &reference.image);
    assert!(worst <= 2, "infinite ring floor vs analytic floor: worst channel {worst}/255");
    for (name, settings) in configurations(RenderSettings::default()) {
        let frame = render(floor_scene(quad_floor(HUGE), f32::INFINITY), SIZE, 0, settings);
        let report = frame.stats.last.as_ref().expect("report");
        assert_eq!(report.sanitized_cameras, 0, "{name}: an infinite projection is kept as it is");
        let s = assert_similar(
            &format!("infinite_floor_{name}"),
            &reference.image,
            &frame.image,
            tolerance(&settings),
        );
        eprintln!("infinite floor {name}: FLIP mean {:.5}, p99 {:.5}", s.mean, s.p99);
    }
}

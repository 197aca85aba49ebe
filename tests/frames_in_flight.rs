//! Frames in flight: 100 frames of the pipelined plugin with 1 024 animated lights, headless
//! without capture and in a window (on its own Xvfb server when no display is set), after a
//! few warm-up frames: no blocking GPU wait, no buffer and no bind group created, and the
//! statistics of frame k reported by frame k + N + 1 (N frames in flight).
//!
//! winit allows one event loop per process; this file has one window test.

mod support;

use manylight::app::window::WindowConfig;
use manylight::app::{FrameStats, FrameTotals, HeadlessCapture};
use manylight::prelude::*;
use manylight::render::FrameReport;
use std::sync::{Arc, Mutex};

const LIGHTS: usize = 1024;
const FRAMES: u64 = 100;
/// Frames after which nothing may be created or waited for (pipelines, meshes, lists and
/// textures are created in the first ones).
const WARMUP: u64 = 10;
const FRAMES_IN_FLIGHT: u32 = 2;

/// What the checking system saw.
#[derive(Default)]
struct Seen {
    reports: Vec<FrameReport>,
    /// (frame submitted, latest frame reported, the totals so far) after each update.
    lags: Vec<(u64, u64, FrameTotals)>,
    updates: u64,
}

fn setup(app: &mut App, seen: Arc<Mutex<Seen>>, exit_after: Option<u64>) {
    app.add_systems(Startup, |mut commands: Commands| {
        let scene = manylight::scene::default_scene();
        spawn_scene(&mut commands, &scene, true, 4.0 / 3.0);
        spawn_light_rig(&mut commands, LIGHTS, scene.bounds(), 7).expect("the rig's lights fit");
    })
    .insert_resource(RenderSettings { pipeline: PipelineKind::ClusteredForward, ..default() })
    .add_systems(Last, move |stats: Res<FrameStats>, mut exit: MessageWriter<AppExit>| {
        let mut seen = seen.lock().unwrap_or_else(|e| e.into_inner());
        seen.updates += 1;
        if let Some(last) = &stats.last
            && seen.reports.last().is_none_or(|r| r.frame_index != last.frame_index)
        {
            seen.reports.push(last.clone());
        }
        let reported = stats.last.as_ref().map_or(0, |r| r.frame_index);
        seen.lags.push((stats.submitted, reported, stats.totals));
        if exit_after.is_some_and(|n| seen.updates >= n) {
            exit.write(AppExit::Success);
        }
    });
}

/// Checks what a run saw: `max_lag` is the most frames a report may arrive after its frame
/// was submitted.
fn check(seen: &Seen, max_lag: u64, what: &str) {
    // Several reports can arrive in one update; the last of each is checked one by one, and
    // every one through the totals below.
    assert!(seen.reports.len() as u64 >= (FRAMES - WARMUP) / 2, "{what}: {} reports", seen.reports.len());
    // The counters count: the first frames create the meshes' buffers and the bind groups.
    let totals = seen.lags.last().map(|l| l.2).unwrap_or_default();
    assert!(
        totals.buffers_created > 0 && totals.bind_groups_created > 0,
        "{what}: nothing counted: {totals:?}"
    );
    for r in seen.reports.iter().filter(|r| r.frame_index > WARMUP) {
        let at = format!("{what}, frame {}", r.frame_index);
        assert!(!r.passes.is_empty(), "{at}: no passes");
        assert_eq!(r.blocking_waits, 0, "{at}: blocking GPU waits");
        assert_eq!(r.buffers_created, 0, "{at}: buffers created");
        assert_eq!(r.bind_groups_created, 0, "{at}: bind groups created");
        assert_eq!(r.frames_in_flight_limit, FRAMES_IN_FLIGHT, "{at}");
        assert!(
            r.frames_in_flight >= 1 && r.frames_in_flight <= FRAMES_IN_FLIGHT,
            "{at}: {}",
            r.frames_in_flight
        );
        // The figures read back without waiting are there: the cluster counters.
        let clusters = r.clusters.as_ref().unwrap_or_else(|| panic!("{at}: no cluster statistics"));
        assert!(
            clusters.total_entries > 0
                && clusters.total_entries <= clusters.index_capacity
                && clusters.fallback_clusters == 0,
            "{at}: {clusters:?}"
        );
        assert_eq!(r.nonfinite_pixels, Some(0), "{at}");
        assert!(r.light_count as usize >= LIGHTS, "{at}: {} lights", r.light_count);
    }
    for &(submitted, reported, _) in seen.lags.iter().filter(|(s, _, _)| *s > WARMUP) {
        assert!(
            submitted - reported <= max_lag,
            "{what}: frame {submitted} submitted, the latest report is frame {reported} (at most {max_lag} frames late)"
        );
    }
    // Every frame after the warm-up: once the reports are past it, the totals stay flat.
    let steady: Vec<(u64, FrameTotals)> =
        seen.lags.iter().filter(|(_, reported, _)| *reported >= WARMUP).map(|l| (l.1, l.2)).collect();
    let (Some(&(first_frame, first)), Some(&(last_frame, last))) = (steady.first(), steady.last()) else {
        panic!("{what}: no report after the warm-up");
    };
    // Every frame between the first and the last report seen was reported (reports may arrive
    // several at once, so the count is compared with the frames between, not with FRAMES).
    assert!(
        last.frames - first.frames >= last_frame - first_frame,
        "{what}: frames {first_frame}..{last_frame}, {first:?} → {last:?}"
    );
    let (first, last) = (&first, &last);
    let flat = |t: &FrameTotals| (t.blocking_waits, t.buffers_created, t.bind_groups_created);
    assert_eq!(
        flat(first),
        flat(last),
        "{what}: waits, buffers or bind groups after the warm-up: {first:?} → {last:?}"
    );
}

#[test]
fn headless_frames_in_flight_never_wait_or_allocate() {
    let _gpu = support::gpu();
    for pipelined in [false, true] {
        let seen = Arc::new(Mutex::new(Seen::default()));
        let mut app = App::new();
        app.add_plugins(
            ManyLightPlugin::headless(UVec2::new(128, 96))
                .with_pipelined(pipelined)
                .with_frames_in_flight(FRAMES_IN_FLIGHT),
        )
        .insert_resource(HeadlessCapture { enabled: false, image: None });
        setup(&mut app, seen.clone(), None);
        manylight::app::headless::finish_plugins(&mut app);
        for _ in 0..FRAMES {
            app.update();
            assert_eq!(app.world().resource::<manylight::app::RenderFailure>().0, None);
        }
        manylight::app::headless::finish_frames(&mut app);
        let seen = seen.lock().unwrap_or_else(|e| e.into_inner());
        // A frame's report comes back by the time its slot is reused, N frames later: frame
        // k is reported by frame k + N + 1 at the latest (`FrameStats::submitted` counts the
        // frames the renderer submitted; pipelined, the main world is a frame ahead of it).
        let max_lag = u64::from(FRAMES_IN_FLIGHT) + 1;
        check(&seen, max_lag, if pipelined { "headless pipelined" } else { "headless synchronous" });
        // Every frame was reported once the frames in flight were flushed.
        let stats = app.world().resource::<FrameStats>();
        assert_eq!(stats.frames_rendered, FRAMES, "frames reported");
        assert_eq!(stats.last.as_ref().map(|r| r.frame_index), Some(stats.submitted));
    }
}

#[test]
fn window_frames_in_flight_never_wait_or_allocate() {
    let Some(_xvfb) = support::window_display() else {
        return;
    };
    let _gpu = support::gpu();
    let seen = Arc::new(Mutex::new(Seen::default()));
    let mut app = App::new();
    app.add_plugins(
        ManyLightPlugin::window(WindowConfig {
            width: 160,
            height: 120,
            vsync: false,
            any_thread: true,
            overlay: true,
            ..default()
        })
        .with_frames_in_flight(FRAMES_IN_FLIGHT),
    );
    setup(&mut app, seen.clone(), Some(FRAMES));
    let exit = app.run();
    assert!(exit.is_success(), "the window app failed: {exit:?}");
    let seen = seen.lock().unwrap_or_else(|e| e.into_inner());
    check(&seen, u64::from(FRAMES_IN_FLIGHT) + 1, "window");
    // The overlay pass is timed through the same read-back slots.
    let last = seen.reports.last().expect("reports");
    assert!(last.passes.iter().any(|p| p.name == "egui_overlay"), "{:?}", last.pass_names());
}

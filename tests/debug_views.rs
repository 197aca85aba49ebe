//! Every debug view renders something non-trivial on the default scene (stored references,
//! FLIP), replaces tone mapping, and follows the `DebugView` resource when a system changes it.

mod support;

use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::app::{DebugView, FrameStats};
use manylight::prelude::*;
use support::{STRICT, assert_matches_reference, gpu};

const SIZE: UVec2 = UVec2::new(128, 72);

fn render(debug: DebugView, settings: RenderSettings) -> HeadlessFrame {
    let scene = default_scene();
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let bounds = scene.bounds();
    render_headless(SIZE, 1, move |app| {
        app.insert_resource(settings).insert_resource(debug).add_systems(
            Startup,
            move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, aspect);
                spawn_light_rig(&mut commands, 64, bounds, 1);
            },
        );
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"))
}

#[test]
fn every_debug_view_renders_its_data() {
    let _gpu = gpu();
    for mode in DebugViewMode::ALL.into_iter().filter(|&m| m != DebugViewMode::None) {
        let mut settings =
            RenderSettings { pipeline: PipelineKind::ClusteredForward, ..RenderSettings::default() };
        if mode == DebugViewMode::Overflow {
            // A small cap, so some clusters overflow (red) and others do not (green).
            settings.clusters.cap = Some(8);
        }
        let frame = render(DebugView::new(mode), settings);
        let names = frame.stats.pass_names();
        assert_eq!(names.last().map(String::as_str), Some("debug_view"), "{mode:?}: {names:?}");
        assert!(!names.iter().any(|n| n == "tonemap" || n == "clustered_forward"), "{mode:?}: {names:?}");
        let mut colors: Vec<[u8; 4]> = frame.image.pixels().map(|p| p.0).collect();
        colors.sort_unstable();
        colors.dedup();
        // At least the background and two different surfaces / clusters.
        if colors.len() < 3 {
            let _ = frame.image.save(support::output_dir().join(format!("debug_{}.actual.png", mode.name())));
        }
        assert!(colors.len() >= 3, "{mode:?} shows {} colours", colors.len());
        if mode == DebugViewMode::Overflow {
            let red = frame.image.pixels().filter(|p| p[0] > 200 && p[1] < 100).count();
            let green = frame.image.pixels().filter(|p| p[1] > p[0] && p[1] > 30).count();
            assert!(red > 0 && green > 0, "overflow: {red} red and {green} green pixels");
            let c = frame.stats.last.as_ref().and_then(|r| r.clusters.clone()).expect("cluster report");
            assert!(c.clusters_overflowed > 0, "{c:?}");
        }
        assert_matches_reference(&format!("debug_{}", mode.name().replace('-', "_")), &frame.image, STRICT);
    }
}

#[test]
fn a_system_toggles_the_debug_view_at_run_time() {
    let _gpu = gpu();
    let modes = [DebugViewMode::Depth, DebugViewMode::None, DebugViewMode::Albedo, DebugViewMode::LightCount];
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(64, 48)))
        .add_systems(Startup, |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, 64.0 / 48.0);
        })
        .add_systems(Update, move |clock: Res<FrameClock>, mut debug: ResMut<DebugView>| {
            debug.mode = modes[(clock.frame as usize - 1) % modes.len()];
        });
    for mode in modes {
        app.update();
        let names = app.world().resource::<FrameStats>().pass_names();
        let last = if mode == DebugViewMode::None { "tonemap" } else { "debug_view" };
        assert_eq!(names.last().map(String::as_str), Some(last), "{mode:?}: {names:?}");
    }
}

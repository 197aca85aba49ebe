//! The shadow measures that need only a technique's images, as a user gets them from the
//! `manylight` binary: `render --shadow-oracle` reports the light error (HDR luminance the
//! shadows get wrong against exact visibility, over the unshadowed light) and the flicker (the
//! next frame of a still scene against this one), for shadow maps and shadow rays
//! (`bench --shadow-oracle`'s columns are checked in `cli.rs`). Runs on a real device (lavapipe
//! in CI), one command at a time.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn manylight(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_manylight")).args(args).output().expect("the binary runs")
}

/// `render --shadow-oracle`'s `shadow_oracle` figures of the default hall with 8 rig lights at
/// 128×96, every light casting (`shadows` on or rays) or none; the text it printed.
fn measured(dir: &Path, shadows: &str) -> (serde_json::Value, String) {
    let json = dir.join(format!("shadow_measures_{shadows}.json"));
    let out = manylight(&[
        "render",
        "--lights",
        "8",
        "--size",
        "128x96",
        "--shadows",
        shadows,
        "--shadow-oracle",
        "--out",
        dir.join(format!("shadow_measures_{shadows}.png")).to_str().expect("utf-8"),
        "--stats-json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("valid");
    (stats["shadow_oracle"].clone(), String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The light error of the shadow maps is a small part of the light exact shadows remove, the
/// shadow rays' is none of it, and with still lights neither flickers.
///
/// Bounds, from the values on lavapipe (128×96): without shadows the light error is the share
/// of the light the blocked pairs carry, 0.049; the maps leave 0.0028 of it (visibility error
/// 1.2 %). A map-sized error (acne, leaks at contacts) stays under 0.02 and under a quarter of
/// what no shadows get wrong; shadows that test most blocked pairs lit (a stale or missing
/// map) reach the unshadowed figure. Both frames of the flicker are deterministic renders of
/// the same scene: lavapipe gives exactly 0; 10⁻⁴ leaves room for a device whose light lists
/// come out in another order (sums rounded differently), far below a visible change.
#[test]
fn render_reports_the_light_error_and_flicker_of_maps_and_rays() {
    let dir = root().join("target/cli-tests");
    std::fs::create_dir_all(&dir).expect("mkdir");

    let (off, _) = measured(&dir, "off");
    let (on, text) = measured(&dir, "on");
    assert!(text.contains("light error") && text.contains("flicker"), "{text}");
    let figure = |a: &serde_json::Value, name: &str| -> f64 {
        a[name].as_f64().unwrap_or_else(|| panic!("no finite `{name}` in {a}"))
    };
    let (unshadowed_error, maps_error) = (figure(&off, "light_error"), figure(&on, "light_error"));
    assert!(
        (0.01..1.0).contains(&unshadowed_error),
        "without shadows the light error is the blocked light's share: {unshadowed_error}"
    );
    assert!(maps_error.is_finite() && maps_error >= 0.0, "{maps_error}");
    assert!(maps_error < 0.02, "shadow maps' light error {maps_error}");
    assert!(
        maps_error < 0.25 * unshadowed_error,
        "shadow maps' light error {maps_error} against {unshadowed_error} without shadows"
    );
    // Rays test every reached pair exactly: what is left is rounding at the shadows' edges.
    let (rays, _) = measured(&dir, "rays");
    assert_eq!(figure(&rays, "visibility_error"), 0.0, "{rays}");
    assert!(figure(&rays, "light_error") < 1e-3, "{rays}");
    for (a, shadows) in [(&off, "off"), (&on, "on"), (&rays, "rays")] {
        let flicker = figure(a, "flicker");
        assert!((0.0..1e-4).contains(&flicker), "shadows {shadows}: flicker {flicker}");
    }
}

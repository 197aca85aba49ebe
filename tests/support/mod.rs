//! Shared helpers of the GPU integration tests: one GPU test at a time (lavapipe is slow and
//! single-queue), a hard failure when no adapter exists, and FLIP image comparison against
//! stored references.
#![allow(dead_code)]

use image::RgbaImage;
use manylight::math::image_metrics::{FlipStats, flip_compare};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, OnceLock};

/// Serialises GPU tests within a test binary and checks once that an adapter exists.
pub fn gpu() -> MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    static CHECKED: OnceLock<Result<String, String>> = OnceLock::new();
    let guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let adapter = CHECKED.get_or_init(|| {
        manylight::render::GpuContext::headless().map(|g| g.info.name.clone()).map_err(|e| e.to_string())
    });
    match adapter {
        Ok(_) => guard,
        // A GPU test never skips: without an adapter it fails with what to install.
        Err(e) => panic!("GPU test needs an adapter: {e}"),
    }
}

/// Tolerances of an image comparison.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Largest allowed mean FLIP error.
    pub mean: f32,
    /// Largest allowed 99th-percentile FLIP error.
    pub p99: f32,
}

/// The tolerance of pipelines compared with each other and of stored references.
pub const STRICT: Tolerance = Tolerance { mean: 0.005, p99: 0.05 };
/// What the Compact G-buffer's 8-bit albedo is held to against naive forward on lit scenes
/// (docs/accuracy.md: FLIP mean about 0.010 on the default scene).
pub const COMPACT: Tolerance = Tolerance { mean: 0.015, p99: 0.05 };

/// An image of another device against lavapipe's (the web page on Chromium's SwiftShader):
/// the two devices pick texture mip levels and filter differently, most at the edges of the
/// floor's tiles (docs/accuracy.md, "The web page against native").
pub const CROSS_DEVICE: Tolerance = Tolerance { mean: 0.045, p99: 0.2 };

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Where failing comparisons write their images.
pub fn output_dir() -> PathBuf {
    let dir = root().join("target").join("image-tests");
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// Compares two images; on failure writes `<name>.actual.png`, `<name>.expected.png` and
/// `<name>.diff.png` to `target/image-tests/` and panics with the statistics.
pub fn assert_similar(name: &str, expected: &RgbaImage, actual: &RgbaImage, tol: Tolerance) -> FlipStats {
    let result = flip_compare(expected.dimensions(), expected.as_raw(), actual.dimensions(), actual.as_raw());
    let out = output_dir();
    let write_pair = || {
        let _ = actual.save(out.join(format!("{name}.actual.png")));
        let _ = expected.save(out.join(format!("{name}.expected.png")));
    };
    let (stats, diff) = match result {
        Ok(r) => r,
        Err(e) => {
            write_pair();
            panic!("{name}: {e}");
        }
    };
    if stats.mean > tol.mean || stats.p99 > tol.p99 {
        write_pair();
        let (w, h) = actual.dimensions();
        if let Some(img) = image::RgbImage::from_raw(w, h, diff) {
            let _ = img.save(out.join(format!("{name}.diff.png")));
        }
        panic!(
            "{name}: FLIP mean {:.5} (max {}), p99 {:.5} (max {}); images written to {}",
            stats.mean,
            tol.mean,
            stats.p99,
            tol.p99,
            out.display()
        );
    }
    stats
}

/// Compares with the stored reference `tests/reference/<name>.png`. A missing reference fails
/// (the actual image is written to `target/image-tests/` to be reviewed and copied);
/// `MANYLIGHT_UPDATE_REFERENCES=1` rewrites the reference instead.
pub fn assert_matches_reference(name: &str, actual: &RgbaImage, tol: Tolerance) -> FlipStats {
    let path = root().join("tests").join("reference").join(format!("{name}.png"));
    if std::env::var("MANYLIGHT_UPDATE_REFERENCES").is_ok_and(|v| v == "1") {
        actual.save(&path).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        eprintln!("updated reference {}", path.display());
    }
    let expected = match image::open(&path) {
        Ok(img) => img.to_rgba8(),
        Err(e) => {
            let out = output_dir().join(format!("{name}.actual.png"));
            let _ = actual.save(&out);
            panic!(
                "reference {} is missing or unreadable ({e}); the actual image is at {} \
                 (run with MANYLIGHT_UPDATE_REFERENCES=1 to create it)",
                path.display(),
                out.display()
            );
        }
    };
    assert_similar(name, &expected, actual, tol)
}

/// A scene of the repository's `assets/` folder.
pub fn asset(rel: &str) -> PathBuf {
    let p = root().join("assets").join(rel);
    assert!(p.exists(), "test asset {} is missing", p.display());
    p
}

/// FLIP statistics of two images of the same size (panics on a size mismatch).
pub fn flip(a: &RgbaImage, b: &RgbaImage) -> FlipStats {
    flip_compare(a.dimensions(), a.as_raw(), b.dimensions(), b.as_raw()).expect("images of the same size").0
}

/// Renders `scene` (with its camera) at `size` with `lights` rig lights (seed 1) through the
/// headless plugin, one frame.
pub fn try_render_scene(
    scene: manylight::prelude::Scene,
    size: manylight::prelude::UVec2,
    lights: usize,
    settings: manylight::app::RenderSettings,
) -> Result<manylight::app::headless::HeadlessFrame, String> {
    use manylight::prelude::*;
    let aspect = size.x as f32 / size.y as f32;
    let bounds = scene.bounds();
    manylight::app::headless::render_headless(size, 1, move |app| {
        app.insert_resource(settings).add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, aspect);
            spawn_light_rig(&mut commands, lights, bounds, 1).expect("the rig's lights fit");
        });
    })
    .map_err(|e| e.to_string())
}

/// [`try_render_scene`] that panics on failure, and when any pixel of the frame's HDR image
/// was NaN or infinite (the tone map counts them).
pub fn render_scene(
    scene: manylight::prelude::Scene,
    size: manylight::prelude::UVec2,
    lights: usize,
    settings: manylight::app::RenderSettings,
) -> manylight::app::headless::HeadlessFrame {
    let frame =
        try_render_scene(scene, size, lights, settings).unwrap_or_else(|e| panic!("render failed: {e}"));
    assert_finite(&frame);
    frame
}

/// Panics unless the frame's tone map ran and counted no NaN or infinite HDR pixel.
pub fn assert_finite(frame: &manylight::app::headless::HeadlessFrame) {
    let report = frame.stats.last.as_ref().expect("a frame report");
    assert_eq!(
        report.nonfinite_pixels,
        Some(0),
        "{} pipeline: pixels with a NaN or infinite HDR colour",
        report.pipeline.name()
    );
}

/// A display for a window test: the one set, or a new Xvfb server (kept alive by the returned
/// guard, and named in `DISPLAY`). `None` when there is neither: the caller skips, loudly,
/// except under `CI=true`, where this panics.
///
/// Call it before anything starts a thread that reads the environment (the event loop, the
/// renderer): it sets `DISPLAY`.
pub fn window_display() -> Option<Option<manylight::app::window::xvfb::Xvfb>> {
    let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
    if manylight::app::window::xvfb::has_display() {
        return Some(None);
    }
    match manylight::app::window::xvfb::Xvfb::start() {
        Ok(x) => {
            // SAFETY: the caller runs this before any other thread of its test binary reads the
            // environment (window tests have one test per binary that opens a window).
            unsafe { std::env::set_var("DISPLAY", format!(":{}", x.display)) };
            Some(Some(x))
        }
        Err(e) if ci => panic!("CI=true but no display and {e}: install Xvfb (package xvfb)"),
        Err(e) => {
            eprintln!("\n\n*** SKIPPING the window test: no DISPLAY and {e}. Install Xvfb to run it. ***\n");
            None
        }
    }
}

/// Every pipeline but naive forward, then clustered deferred with the Packed and Compact
/// G-buffers, each named `{prefix}_{pipeline}[_{layout}]`, with the settings `base` gives for
/// a pipeline: what an image test compares with naive forward.
pub fn pipelines_besides_naive(
    prefix: &str,
    base: impl Fn(manylight::app::prelude::PipelineKind) -> manylight::app::RenderSettings,
) -> Vec<(String, manylight::app::RenderSettings)> {
    use manylight::app::prelude::{GBufferLayout, PipelineKind};
    let mut out: Vec<(String, manylight::app::RenderSettings)> = PipelineKind::ALL
        .into_iter()
        .filter(|p| *p != PipelineKind::NaiveForward)
        .map(|p| (format!("{prefix}_{}", p.name()), base(p)))
        .collect();
    for layout in [GBufferLayout::Packed, GBufferLayout::Compact] {
        let deferred = base(PipelineKind::ClusteredDeferred);
        out.push((
            format!("{prefix}_clustered_deferred_{}", layout.name()),
            manylight::app::RenderSettings { gbuffer: layout, ..deferred },
        ));
    }
    out
}

//! Loads measured for peak heap growth, one at a time: the test binaries that assert what a
//! load costs (`budgets`, `tangents`) share these. The including file declares
//! `counting_alloc` as its global allocator. A load's wall time is printed, never asserted:
//! [`LOAD_TIMEOUT`] only turns a hang into a failure.
#![allow(dead_code)]

use super::counting_alloc;
use manylight_scene::{LoadOptions, Scene, SceneError, load_gltf};
use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

/// Tests run one at a time (each holds this for its whole body), so a peak measured during a
/// load belongs to that load alone.
static SERIAL: Mutex<()> = Mutex::new(());

/// Takes [`SERIAL`] for the rest of the test.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// One mebibyte.
pub const MIB: usize = 1 << 20;

/// Longest a single load may take before the test fails instead of hanging.
pub const LOAD_TIMEOUT: Duration = Duration::from_secs(60);

/// What a load returned and cost.
pub struct Outcome {
    /// The scene or the error.
    pub result: Result<Scene, SceneError>,
    /// Peak heap growth during the load (the returned scene included).
    pub peak: usize,
}

impl Outcome {
    /// The error, which must be an `OverBudget` for `option` naming `path`.
    pub fn over_budget(self, path: &Path, option: &str) -> String {
        let message = match self.result {
            Ok(s) => {
                panic!("{} loaded ({} instances) but must be refused", path.display(), s.instances.len())
            }
            Err(e) => {
                assert!(matches!(&e, SceneError::OverBudget { option: o, .. } if *o == option), "{e}");
                e.to_string()
            }
        };
        assert!(message.contains(&path.display().to_string()), "does not name the file: {message}");
        assert!(message.contains(&format!("(LoadOptions::{option})")), "{message}");
        message
    }

    /// The scene, which must have loaded.
    pub fn scene(self) -> Scene {
        self.result.unwrap_or_else(|e| panic!("{e}"))
    }
}

/// Loads `path` on a worker thread, measuring its peak heap growth (its time is printed).
pub fn load(path: &Path, options: LoadOptions) -> Outcome {
    counting_alloc::set_cap(4 << 30);
    let owned = path.to_owned();
    let (result, peak, elapsed) = counting_alloc::measure(LOAD_TIMEOUT, move || load_gltf(&owned, &options))
        .unwrap_or_else(|| panic!("loading {} took over {LOAD_TIMEOUT:?}", path.display()));
    eprintln!("{}: peak {:.1} MiB, {elapsed:?}", path.display(), peak as f64 / MIB as f64);
    Outcome { result, peak }
}

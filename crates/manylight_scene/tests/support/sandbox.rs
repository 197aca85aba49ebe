//! A fresh temporary folder per test, removed on drop, for glTF files the tests write.

use serde_json::Value;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh temporary folder, removed on drop.
pub struct Sandbox(PathBuf);

impl Sandbox {
    /// An empty folder named after the process, a counter and `name`.
    pub fn new(name: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("manylight_tests_{}_{n}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create sandbox");
        Self(dir)
    }

    /// The path of `name` in the folder (not created).
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// Writes `bytes` as `name` and returns its path.
    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.path(name);
        std::fs::write(&path, bytes).expect("write");
        path
    }

    /// Writes `root` as JSON to `name` and returns its path.
    pub fn write_json(&self, name: &str, root: &Value) -> PathBuf {
        self.write(name, serde_json::to_string(root).expect("serialize").as_bytes())
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

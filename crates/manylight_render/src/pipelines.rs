//! Pipelines created on first use and kept for the life of the renderer.

use std::any::{Any, TypeId};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A cache of pipeline objects keyed by their Rust type and a variant key (e.g. the target
/// format), so a pass creates its pipeline once, not every frame.
#[derive(Default)]
pub struct PipelineCache {
    map: Mutex<HashMap<(TypeId, u64), Arc<dyn Any + Send + Sync>>>,
}

impl PipelineCache {
    /// The cached `T` for `variant`, created by `create` on first use.
    pub fn get_or_create<T: Any + Send + Sync, E>(
        &self,
        variant: u64,
        create: impl FnOnce() -> Result<T, E>,
    ) -> Result<Arc<T>, E> {
        let key = (TypeId::of::<T>(), variant);
        if let Some(found) = self.map.lock().ok().and_then(|m| m.get(&key).cloned())
            && let Ok(t) = found.downcast::<T>()
        {
            return Ok(t);
        }
        let created = Arc::new(create()?);
        if let Ok(mut m) = self.map.lock() {
            m.insert(key, created.clone());
        }
        Ok(created)
    }

    /// Number of pipelines created.
    pub fn len(&self) -> usize {
        self.map.lock().map(|m| m.len()).unwrap_or(0)
    }

    /// True when no pipeline was created yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A stable number for a texture format, for use as a cache variant key.
pub fn format_key(format: wgpu::TextureFormat) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    format.hash(&mut h);
    h.finish()
}

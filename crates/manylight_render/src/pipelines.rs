//! Pipelines created on first use and kept for the life of the renderer, keyed by typed
//! descriptors.
//!
//! A pass describes the pipeline it needs with a key type of its own that holds every choice
//! the pipeline depends on (a target format, a G-buffer layout and normal codec, a sample
//! count), compared field by field: two different descriptors can never share a pipeline, as
//! hashed variant numbers could. The key type names the pipeline objects it creates
//! ([`PipelineKey::Pipeline`]).

use std::any::{Any, TypeId};
use std::collections::HashMap;
use std::fmt::Debug;
use std::hash::Hash;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A typed pipeline descriptor: everything a pipeline depends on.
pub trait PipelineKey: Clone + Eq + Hash + Debug + Send + Sync + 'static {
    /// The pipeline objects (pipelines and their bind group layouts) this key creates.
    type Pipeline: Send + Sync + 'static;
}

/// The pipelines of one key type.
struct Family<K: PipelineKey>(HashMap<K, Arc<K::Pipeline>>);

/// A cache of pipeline objects by their descriptors, so a pass creates its pipeline once, not
/// every frame.
#[derive(Default)]
pub struct PipelineCache {
    /// One map per key type (the type only finds the map; the key is the descriptor).
    families: Mutex<HashMap<TypeId, Box<dyn Any + Send + Sync>>>,
    created: AtomicUsize,
}

impl PipelineCache {
    /// The pipeline for `key`, created by `create` on first use.
    pub fn get_or_create<K: PipelineKey, E>(
        &self,
        key: K,
        create: impl FnOnce(&K) -> Result<K::Pipeline, E>,
    ) -> Result<Arc<K::Pipeline>, E> {
        let found = self.with_family::<K, _>(|family| family.0.get(&key).cloned());
        if let Some(pipeline) = found.flatten() {
            return Ok(pipeline);
        }
        let created = Arc::new(create(&key)?);
        self.with_family::<K, _>(|family| family.0.insert(key, created.clone()));
        self.created.fetch_add(1, Ordering::Relaxed);
        Ok(created)
    }

    fn with_family<K: PipelineKey, R>(&self, f: impl FnOnce(&mut Family<K>) -> R) -> Option<R> {
        let mut families = self.families.lock().unwrap_or_else(|e| e.into_inner());
        let entry =
            families.entry(TypeId::of::<K>()).or_insert_with(|| Box::new(Family::<K>(HashMap::new())));
        entry.downcast_mut::<Family<K>>().map(f)
    }

    /// Number of pipelines created.
    pub fn len(&self) -> usize {
        self.created.load(Ordering::Relaxed)
    }

    /// True when no pipeline was created yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    struct A(u32);
    impl PipelineKey for A {
        type Pipeline = String;
    }
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    struct B(u32);
    impl PipelineKey for B {
        type Pipeline = u64;
    }

    #[test]
    fn descriptors_are_compared_whole_and_by_type() {
        let cache = PipelineCache::default();
        let first = cache.get_or_create(A(1), |k| Ok::<_, ()>(format!("a{}", k.0))).unwrap();
        let again = cache.get_or_create(A(1), |_| Err(())).unwrap();
        assert!(Arc::ptr_eq(&first, &again), "the same descriptor is created once");
        assert_eq!(*cache.get_or_create(A(2), |k| Ok::<_, ()>(format!("a{}", k.0))).unwrap(), "a2");
        // Another key type with equal fields is another pipeline.
        assert_eq!(*cache.get_or_create(B(1), |k| Ok::<_, ()>(u64::from(k.0) + 10)).unwrap(), 11);
        assert_eq!(cache.len(), 3);
        // A failed creation caches nothing.
        assert!(cache.get_or_create(B(7), |_| Err::<u64, _>("no")).is_err());
        assert_eq!(cache.len(), 3);
    }
}

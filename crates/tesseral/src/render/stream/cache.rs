//! A cache of decoded pieces (chunk indexes, colour blocks) under a byte budget,
//! least recently used first out, shared by the rendering threads.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use rustc_hash::FxHashMap;

/// Decoded values by key, at most `budget` bytes of them kept (a value in use by a
/// thread stays alive until that thread drops it, even once evicted).
pub(super) struct Cache<V> {
    budget: u64,
    inner: Mutex<Inner<V>>,
    /// How many values were decoded (misses).
    pub(super) loads: AtomicU64,
}

struct Inner<V> {
    map: FxHashMap<u64, (Arc<V>, u64, u64)>,
    used: u64,
    clock: u64,
}

impl<V> Cache<V> {
    pub(super) fn new(budget: u64) -> Self {
        Self {
            budget,
            inner: Mutex::new(Inner {
                map: FxHashMap::default(),
                used: 0,
                clock: 0,
            }),
            loads: AtomicU64::new(0),
        }
    }

    /// The value at `key`, decoded by `load` (which returns it and its size in
    /// bytes) when it is not kept. Two threads may decode one value at once; the
    /// first kept wins.
    pub(super) fn get<E>(
        &self,
        key: u64,
        load: impl FnOnce() -> Result<(V, u64), E>,
    ) -> Result<Arc<V>, E> {
        {
            let mut g = self.inner.lock().unwrap_or_else(PoisonError::into_inner);
            g.clock += 1;
            let now = g.clock;
            if let Some(e) = g.map.get_mut(&key) {
                e.2 = now;
                return Ok(Arc::clone(&e.0));
            }
        }
        let (value, bytes) = load()?;
        self.loads.fetch_add(1, Ordering::Relaxed);
        let value = Arc::new(value);
        let mut g = self.inner.lock().unwrap_or_else(PoisonError::into_inner);
        g.clock += 1;
        let now = g.clock;
        if let Some(e) = g.map.get_mut(&key) {
            e.2 = now;
            return Ok(Arc::clone(&e.0));
        }
        g.map.insert(key, (Arc::clone(&value), bytes, now));
        g.used += bytes;
        while g.used > self.budget && g.map.len() > 1 {
            let oldest = g
                .map
                .iter()
                .filter(|(&k, _)| k != key)
                .min_by_key(|(_, e)| e.2)
                .map(|(&k, _)| k);
            let Some(k) = oldest else { break };
            if let Some((_, b, _)) = g.map.remove(&k) {
                g.used -= b;
            }
        }
        Ok(value)
    }

    /// The bytes kept now.
    pub(super) fn used(&self) -> u64 {
        self.inner
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .used
    }
}

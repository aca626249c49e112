//! A cache of decoded pieces (chunk indexes, colour blocks) under a byte budget,
//! least recently used first out, shared by the rendering threads.
//!
//! The budget covers what the threads hold too. A thread holds at most two values
//! outside the cache: the one its reader is in (it may have been evicted since)
//! and the one it is decoding (not yet kept). With `holders` such values at most
//! (twice the threads), the cache keeps no more than the budget less `holders`
//! times the largest value seen, so that kept and held values together stay
//! within the budget:
//!
//! kept + held ≤ (budget − holders × largest) + holders × largest = budget,
//!
//! as long as the budget is at least `holders` × the largest value plus one value;
//! below that the cache keeps the last value only, and the bound is one value
//! plus `holders` values. A value's size counts what decoding it holds at once
//! (see `StreamedTree`).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use rustc_hash::FxHashMap;

/// Decoded values by key, at most `budget` bytes of them kept (a value in use by a
/// thread stays alive until that thread drops it, even once evicted).
pub(super) struct Cache<V> {
    budget: u64,
    /// How many values the threads may hold outside the cache.
    holders: u64,
    inner: Mutex<Inner<V>>,
    /// How many values were decoded (misses).
    pub(super) loads: AtomicU64,
}

struct Inner<V> {
    map: FxHashMap<u64, (Arc<V>, u64, u64)>,
    used: u64,
    clock: u64,
    /// The largest value seen, in bytes.
    largest: u64,
}

impl<V> Cache<V> {
    /// A cache of at most `budget` bytes, kept and held together, for `holders`
    /// values held outside it at once (see the module's notes).
    pub(super) fn new(budget: u64, holders: u64) -> Self {
        Self {
            budget,
            holders,
            inner: Mutex::new(Inner {
                map: FxHashMap::default(),
                used: 0,
                clock: 0,
                largest: 0,
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
        g.largest = g.largest.max(bytes);
        let keep = self
            .budget
            .saturating_sub(self.holders.saturating_mul(g.largest));
        while g.used > keep && g.map.len() > 1 {
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

    /// The largest value seen, in bytes.
    #[cfg(test)]
    pub(super) fn largest(&self) -> u64 {
        self.inner
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .largest
    }

    /// The bytes kept now.
    pub(super) fn used(&self) -> u64 {
        self.inner
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .used
    }
}

#[cfg(test)]
mod tests {
    use super::Cache;

    /// Kept bytes stay within the budget less the holders' share of the largest
    /// value, against a model of what should be kept (the most recent values that
    /// fit).
    #[test]
    fn the_cache_leaves_room_for_the_values_threads_hold() {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        for holders in [0u64, 1, 4] {
            let budget = 1000;
            let c: Cache<u64> = Cache::new(budget, holders);
            let mut largest = 0;
            for i in 0..500 {
                let key = next() % 40;
                let size = 1 + next() % 60;
                let got = c.get(key, || Ok::<_, ()>((key, size))).unwrap();
                assert_eq!(*got, key);
                largest = c.largest().max(largest);
                let keep = budget.saturating_sub(holders * largest);
                let len = c.inner.lock().unwrap().map.len();
                assert!(
                    c.used() <= keep || len == 1,
                    "step {i}: {} > {keep}",
                    c.used()
                );
                assert!(c.used() + holders * largest <= budget || len == 1);
            }
        }
    }
}

//! A cache of decoded pieces (chunk indexes, colour blocks) under a byte budget,
//! least recently used first out, shared by the rendering threads.
//!
//! A value has two sizes: what it keeps once decoded (`kept`), and what decoding
//! it held at once (`peak`, at least `kept`: a chunk's leaves and its growing
//! node vector, of which the index keeps the nodes). The cache counts what it
//! keeps at the kept sizes.
//!
//! The budget covers what the threads hold too. A thread holds at most `holders`
//! / threads values outside the cache: the ones its readers are in (they may have
//! been evicted since) and the one it is decoding (not yet kept), each at most the
//! largest peak seen. With `holders` such values at most, the cache keeps no more
//! than the budget less `holders` times the largest peak, so that kept and held
//! values together stay within the budget:
//!
//! kept + held ≤ (budget − holders × largest peak) + holders × largest peak = budget,
//!
//! as long as the budget is at least `holders` × the largest peak plus one value;
//! below that the cache keeps the last value only, and the bound is one value
//! plus `holders` values.

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
    /// The largest peak seen, in bytes.
    largest: u64,
}

/// What a value costs: the bytes it keeps once decoded, and the bytes decoding it
/// held at once (at least as many).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Cost {
    pub(super) kept: u64,
    pub(super) peak: u64,
}

impl Cost {
    /// A value that keeps all that decoding it held.
    pub(super) fn flat(bytes: u64) -> Self {
        Self {
            kept: bytes,
            peak: bytes,
        }
    }
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

    /// The value at `key`, decoded by `load` (which returns it and its [`Cost`])
    /// when it is not kept. Two threads may decode one value at once; the
    /// first kept wins.
    pub(super) fn get<E>(
        &self,
        key: u64,
        load: impl FnOnce() -> Result<(V, Cost), E>,
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
        let (value, cost) = load()?;
        debug_assert!(cost.kept <= cost.peak, "{cost:?}");
        self.loads.fetch_add(1, Ordering::Relaxed);
        let value = Arc::new(value);
        let mut g = self.inner.lock().unwrap_or_else(PoisonError::into_inner);
        g.clock += 1;
        let now = g.clock;
        if let Some(e) = g.map.get_mut(&key) {
            e.2 = now;
            return Ok(Arc::clone(&e.0));
        }
        g.map.insert(key, (Arc::clone(&value), cost.kept, now));
        g.used += cost.kept;
        g.largest = g.largest.max(cost.peak);
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

    /// The largest peak seen, in bytes.
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
    use super::{Cache, Cost};

    /// Kept bytes stay within the budget less the holders' share of the largest
    /// peak, and the kept values are the most recent ones that fit (against a model:
    /// a list of keys by last use), for values whose peak is above what they keep.
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
            // The model: (key, kept) from least to most recently used.
            let mut model: Vec<(u64, u64)> = Vec::new();
            let mut largest = 0;
            for i in 0..500 {
                let key = next() % 40;
                // A key's sizes are its own (as a chunk's are).
                let kept = 1 + key % 30;
                let peak = kept + key % 7 * 5;
                let got = c
                    .get(key, || Ok::<_, ()>((key, Cost { kept, peak })))
                    .unwrap();
                assert_eq!(*got, key);
                if let Some(at) = model.iter().position(|&(k, _)| k == key) {
                    let e = model.remove(at);
                    model.push(e);
                } else {
                    model.push((key, kept));
                    largest = largest.max(peak);
                    let keep = budget.saturating_sub(holders * largest);
                    while model.iter().map(|e| e.1).sum::<u64>() > keep && model.len() > 1 {
                        model.remove(0);
                    }
                }
                assert_eq!(c.largest(), largest);
                let mut kept_keys: Vec<u64> = c.inner.lock().unwrap().map.keys().copied().collect();
                kept_keys.sort_unstable();
                let mut want: Vec<u64> = model.iter().map(|e| e.0).collect();
                want.sort_unstable();
                assert_eq!(kept_keys, want, "step {i}");
                assert_eq!(c.used(), model.iter().map(|e| e.1).sum::<u64>());
                let keep = budget.saturating_sub(holders * largest);
                assert!(
                    c.used() <= keep || model.len() == 1,
                    "step {i}: {} > {keep}",
                    c.used()
                );
            }
        }
    }
}

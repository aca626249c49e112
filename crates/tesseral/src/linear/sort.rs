//! Least-significant-digit radix sort of 64-bit keys (voxel codes, packed leaves).
//!
//! Passes of 8 bits run only up to the highest key bit in use, and a pass whose
//! digit is the same for every key is skipped, so sorting the codes of a depth-8
//! tree takes at most three passes.

use super::Leaf;

/// Below this many keys the standard library's sort is faster.
const RADIX_MIN_LEN: usize = 256;

/// Sorts `keys` in place, ascending.
///
/// # Runtime
/// O(n · b / 8) for keys of at most b significant bits.
pub(crate) fn sort_u64(keys: &mut Vec<u64>) {
    sort_by_u64(keys, |&k| k);
}

/// Sorts `items` by a 64-bit key, stably: items of one key keep their order (so that
/// pairs sort as `(key, position)` would).
///
/// # Runtime
/// O(n · b / 8) for keys of at most b significant bits, and one copy of `items`.
pub(crate) fn sort_by_u64<T: Copy>(items: &mut Vec<T>, key: impl Fn(&T) -> u64) {
    if items.len() < RADIX_MIN_LEN {
        items.sort_by_key(&key);
        return;
    }
    let all = items.iter().fold(0u64, |acc, t| acc | key(t));
    let bits = 64 - all.leading_zeros();
    let mut buf = items.clone();
    let mut shift = 0;
    while shift < bits {
        let digit = |t: &T| ((key(t) >> shift) & 0xff) as usize;
        let mut count = [0usize; 256];
        for t in items.iter() {
            count[digit(t)] += 1;
        }
        if count.contains(&items.len()) {
            shift += 8;
            continue;
        }
        let mut sum = 0;
        for c in &mut count {
            let n = *c;
            *c = sum;
            sum += n;
        }
        for t in items.iter() {
            let d = digit(t);
            buf[count[d]] = *t;
            count[d] += 1;
        }
        std::mem::swap(items, &mut buf);
        shift += 8;
    }
}

/// Sorts leaves into tesseral order (packed leaves sort as their codes do).
pub(crate) fn sort_leaves(leaves: &mut Vec<Leaf>) {
    let mut keys: Vec<u64> = leaves.iter().map(|l| l.packed()).collect();
    sort_u64(&mut keys);
    leaves.clear();
    leaves.extend(keys.into_iter().map(Leaf::from_packed));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radix_sort_matches_std_sort() {
        for (seed, n, mask) in [
            (1u64, 10_000, u64::MAX),
            (7, 5000, 0xffff_ff00),
            (3, 300, 0x3f),
        ] {
            let mut s = seed;
            let mut v: Vec<u64> = (0..n)
                .map(|_| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    s & mask
                })
                .collect();
            let mut want = v.clone();
            want.sort_unstable();
            sort_u64(&mut v);
            assert_eq!(v, want, "seed {seed}");
        }
    }

    /// Items of one key keep their order: pairs of a few keys and their positions
    /// sort by key alone as they sort whole.
    #[test]
    fn sorting_by_a_key_is_stable() {
        for (n, mask) in [
            (10_000usize, 0x0f0f_u64),
            (3000, u64::MAX << 56 | 3),
            (100, 7),
        ] {
            let mut s = n as u64;
            let mut v: Vec<(u64, usize)> = (0..n)
                .map(|i| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    (s & mask, i)
                })
                .collect();
            let mut want = v.clone();
            want.sort_unstable();
            sort_by_u64(&mut v, |p| p.0);
            assert_eq!(v, want, "{n} items");
        }
    }
}

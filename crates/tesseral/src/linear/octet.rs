//! Eight neighbouring voxels at once: the 2 × 2 × 2 box at a lattice point, as the
//! boundary mesher asks of every vertex (`mesh::boundary`). One binary search, then
//! a galloping search forward from the last leaf for each further code in order:
//! the eight codes are mostly near each other in tesseral order, so the leaves they
//! land in are mostly the same or next to each other.

use super::{Leaf, LinearOctree};
use crate::Voxel;

impl LinearOctree {
    /// Which voxels of the box `lo ..= lo + 1` are black: bit `o` for voxel
    /// `lo + (o & 1, o >> 1 & 1, o >> 2 & 1)` (voxels outside the space are white),
    /// as eight calls of [`contains`](Self::contains) would say.
    ///
    /// # Runtime
    /// O(log n) for the first voxel, O(log d) for each further one, d the leaves
    /// between it and the one before.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(2, [0, 0, 0], [[1, 1, 1], [2, 1, 1]]).unwrap();
    /// assert_eq!(t.octet([1, 1, 1]), 0b11);
    /// assert_eq!(t.octet([0, 0, 0]), 0b1000_0000);
    /// ```
    #[must_use]
    pub fn octet(&self, lo: Voxel) -> u8 {
        self.octet_near(lo, &mut 0)
    }

    /// [`octet`](Self::octet), its search started from leaf `near` (a leaf found
    /// for a box nearby, as the mesher's points come sorted), and `near` left at
    /// the leaf of this box's first voxel in tesseral order, for the next box.
    ///
    /// # Runtime
    /// O(log d) for the first voxel, d the leaves between it and `near`; as
    /// [`octet`](Self::octet) for the others.
    pub(crate) fn octet_near(&self, lo: Voxel, near: &mut usize) -> u8 {
        let mut codes = [(u64::MAX, 0u8); 8];
        let mut n = 0;
        for o in 0..8u8 {
            let v = [0, 1, 2].map(|a| lo[a].wrapping_add(i64::from(o >> a & 1)));
            // `lo + 1` past i64 wraps below the space: outside, white.
            if (0..3).all(|a| v[a] >= lo[a]) {
                if let Some(c) = self.code_of(v) {
                    codes[n] = (c, o);
                    n += 1;
                }
            }
        }
        let codes = &mut codes[..n];
        codes.sort_unstable();
        let leaves = self.leaves();
        let mut bits = 0u8;
        // The leaf that held (or preceded) the last code looked up.
        let mut at = *near;
        for (k, &(c, o)) in codes.iter().enumerate() {
            let i = first_above(leaves, c, at);
            if i > 0 && leaves[i - 1].contains_code(c) {
                bits |= 1 << o;
            }
            at = i.saturating_sub(1);
            if k == 0 {
                *near = at;
            }
        }
        bits
    }
}

/// The first of `leaves` (sorted by code) whose code is above `c`, as
/// `partition_point` gives it, found by galloping from index `near` (either way):
/// O(log d) for d leaves between `near` and the answer.
pub(crate) fn first_above(leaves: &[Leaf], c: u64, near: usize) -> usize {
    gallop(leaves, near, |l| l.code() <= c)
}

/// The first index of `items` where `at_or_below` turns false (it must be true,
/// then false, along the items), as `partition_point` gives it, galloping from
/// index `near` either way: O(log d) calls for d items between `near` and the
/// answer.
pub(crate) fn gallop<T>(items: &[T], near: usize, at_or_below: impl Fn(&T) -> bool) -> usize {
    let n = items.len();
    if n == 0 {
        return 0;
    }
    let near = near.min(n - 1);
    let mut step = 1;
    if at_or_below(&items[near]) {
        // `lo` is at or below: widen until an item above, or the end.
        let mut lo = near;
        while lo + step < n && at_or_below(&items[lo + step]) {
            lo += step;
            step *= 2;
        }
        let hi = (lo + step).min(n);
        lo + 1 + items[lo + 1..hi].partition_point(at_or_below)
    } else {
        // `hi` is above: widen down until an item at or below, or the start.
        let mut hi = near;
        while hi >= step && !at_or_below(&items[hi - step]) {
            hi -= step;
            step *= 2;
        }
        let lo = hi.saturating_sub(step);
        lo + items[lo..hi].partition_point(at_or_below)
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};

    use super::*;

    /// Against eight calls of `contains`, on seeded random trees and boxes that
    /// reach past the space on every side.
    #[test]
    fn octet_agrees_with_contains() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x0c7e);
        for round in 0..200 {
            let depth = rng.random_range(0..=5u8);
            let side = 1i64 << depth;
            let origin = [0, 1, 2].map(|_| rng.random_range(-8..8i64));
            let n = rng.random_range(0..=(side * side * side) as usize);
            let voxels: Vec<Voxel> = (0..n)
                .map(|_| [0, 1, 2].map(|a| origin[a] + rng.random_range(0..side)))
                .collect();
            let t = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
            t.assert_valid();
            for _ in 0..50 {
                let lo = [0, 1, 2].map(|a| origin[a] + rng.random_range(-2..=side));
                let mut want = 0u8;
                for o in 0..8u8 {
                    let v = [0, 1, 2].map(|a| lo[a] + i64::from(o >> a & 1));
                    if t.contains(v) {
                        want |= 1 << o;
                    }
                }
                assert_eq!(t.octet(lo), want, "round {round}, lo {lo:?}");
                let mut near = rng.random_range(0..=t.leaves().len() + 1);
                assert_eq!(
                    t.octet_near(lo, &mut near),
                    want,
                    "round {round}, lo {lo:?}"
                );
            }
        }
        // first_above from every start, against partition_point.
        for _ in 0..200 {
            let depth = rng.random_range(0..=4u8);
            let side = 1i64 << depth;
            let voxels: Vec<Voxel> = (0..rng.random_range(0..40))
                .map(|_| [0, 1, 2].map(|_| rng.random_range(0..side)))
                .collect();
            let t = LinearOctree::from_voxels(depth, [0, 0, 0], voxels).unwrap();
            let leaves = t.leaves();
            let end = 1u64 << (3 * u32::from(depth));
            for c in (0..end).step_by(rng.random_range(1..4)) {
                let want = leaves.partition_point(|l| l.code() <= c);
                for near in 0..=leaves.len() + 1 {
                    assert_eq!(first_above(leaves, c, near), want, "c {c} near {near}");
                }
            }
        }
        // At the top of i64: the box's far voxels wrap, and are white.
        let t = LinearOctree::from_voxels(0, [i64::MAX; 3], [[i64::MAX; 3]]).unwrap();
        assert_eq!(t.octet([i64::MAX; 3]), 1);
    }
}

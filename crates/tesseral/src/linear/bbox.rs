//! The bounding box of a linear octree's black voxels, by six pruned descents.

use super::{Leaf, LinearOctree};
use crate::Voxel;

impl LinearOctree {
    /// The inclusive bounding box `(min, max)` of the black voxels, or `None` when empty.
    ///
    /// # Runtime
    /// Six pruned descents (one per face): cells that cannot beat the best face
    /// found so far are skipped, so a compact solid costs O(depth · log n); at
    /// worst O(n log n).
    #[must_use]
    pub fn bbox(&self) -> Option<(Voxel, Voxel)> {
        if self.is_empty() {
            return None;
        }
        let mut lo = [0i64; 3];
        let mut hi = [0i64; 3];
        for a in 0..3 {
            let mut best = u64::MAX;
            extreme(self.leaves(), 0, self.depth, [0; 3], a, false, &mut best);
            lo[a] = self.origin[a] + best as i64;
            let mut best = u64::MAX;
            extreme(self.leaves(), 0, self.depth, [0; 3], a, true, &mut best);
            // For the maximum the search minimises a reversed coordinate.
            hi[a] = self.origin[a] + (REVERSED_TOP - best) as i64;
        }
        Some((lo, hi))
    }
}

/// The least coordinate on `axis` of a black voxel in the cell `(code, k)` whose
/// lowest voxel is `min` (relative), over `leaves` (all inside the cell or one
/// covering it); with `reversed`, of the coordinate counted from the top of the
/// space. Lowers `best`; skips cells that cannot beat it.
fn extreme(
    leaves: &[Leaf],
    code: u64,
    k: u8,
    min: [u64; 3],
    axis: usize,
    reversed: bool,
    best: &mut u64,
) {
    if leaves.is_empty() {
        return;
    }
    // The cell's own extreme on the axis, in the search's direction.
    let cell_near = cell_near(min, k, axis, reversed);
    if cell_near >= *best {
        return;
    }
    if leaves.len() == 1 && leaves[0].size_log2() >= k {
        *best = cell_near;
        return;
    }
    let half = 1u64 << (k - 1);
    let child = 1u64 << (3 * u32::from(k - 1));
    let mut parts: [&[Leaf]; 8] = [&[]; 8];
    let mut rest = leaves;
    for (d, part) in parts.iter_mut().enumerate() {
        let end = code + (d as u64 + 1) * child;
        let n = rest.partition_point(|l| l.packed() < end << 1);
        *part = &rest[..n];
        rest = &rest[n..];
    }
    // Visit the near half on the axis first: it is the likelier to hold the best.
    let near_bit = usize::from(reversed);
    for side in [near_bit, 1 - near_bit] {
        for (d, part) in parts.iter().enumerate() {
            if (d >> axis) & 1 != side {
                continue;
            }
            let m = [
                min[0] + (d as u64 & 1) * half,
                min[1] + ((d as u64 >> 1) & 1) * half,
                min[2] + ((d as u64 >> 2) & 1) * half,
            ];
            extreme(
                part,
                code + d as u64 * child,
                k - 1,
                m,
                axis,
                reversed,
                best,
            );
        }
    }
}

/// Reversed coordinates count down from here, so that one minimising search finds
/// both faces: the highest coordinate `c` is the least `REVERSED_TOP - c`.
const REVERSED_TOP: u64 = u64::MAX >> 1;

/// The best coordinate any voxel of the cell could give the search: the cell's
/// lowest on `axis`, or (reversed) its highest, reversed.
#[inline]
fn cell_near(min: [u64; 3], k: u8, axis: usize, reversed: bool) -> u64 {
    if reversed {
        REVERSED_TOP - (min[axis] + (1u64 << k) - 1)
    } else {
        min[axis]
    }
}

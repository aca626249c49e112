//! Box queries on a linear octree: is an inclusive box of voxels all white, all
//! black or mixed? The top-down builders of `affine` classify preimage boxes with it.

use super::LinearOctree;
use crate::Voxel;

/// What an inclusive box of voxels holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxState {
    /// No black voxel.
    Empty,
    /// Every voxel black.
    Full,
    /// Some of each.
    Mixed,
}

impl LinearOctree {
    /// Whether the inclusive box `[lo, hi]` of voxels is all white, all black or
    /// mixed; voxels outside the space are white. O(log n + boundary nodes), with an
    /// early exit at the first mixed evidence.
    ///
    /// ```
    /// use tesseral::linear::{BoxState, LinearOctree};
    /// let t = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 0, 0]]).unwrap();
    /// assert_eq!(t.box_state([0, 0, 0], [1, 0, 0]), BoxState::Full);
    /// assert_eq!(t.box_state([0, 0, 0], [2, 0, 0]), BoxState::Mixed);
    /// assert_eq!(t.box_state([2, 2, 2], [9, 9, 9]), BoxState::Empty);
    /// ```
    #[must_use]
    pub fn box_state(&self, lo: Voxel, hi: Voxel) -> BoxState {
        if (0..3).any(|a| lo[a] > hi[a]) {
            return BoxState::Empty;
        }
        let o = self.origin();
        let side = 1i128 << self.depth();
        let outside = (0..3).any(|a| {
            i128::from(lo[a]) < i128::from(o[a]) || i128::from(hi[a]) >= i128::from(o[a]) + side
        });
        let inside_any = (0..3).all(|a| {
            i128::from(hi[a]) >= i128::from(o[a]) && i128::from(lo[a]) < i128::from(o[a]) + side
        });
        if !inside_any {
            return BoxState::Empty;
        }
        let rel_lo: [u64; 3] = std::array::from_fn(|a| (lo[a].max(o[a]) - o[a]) as u64);
        let rel_hi: [u64; 3] = std::array::from_fn(|a| {
            (i128::from(hi[a]).min(i128::from(o[a]) + side - 1) - i128::from(o[a])) as u64
        });
        let mut seen = Seen {
            black: false,
            white: outside,
        };
        // Start at the smallest aligned node holding the box: two binary searches
        // instead of a walk from the root.
        let s = (0..3)
            .map(|a| 64 - (rel_lo[a] ^ rel_hi[a]).leading_zeros())
            .max()
            .unwrap_or(0) as u8;
        let node_min = rel_lo.map(|c| c >> s << s);
        let node_code =
            crate::code::encode(node_min[0] as u32, node_min[1] as u32, node_min[2] as u32);
        let leaves = self.leaves();
        let first = leaves.partition_point(|l| l.code() <= node_code);
        if first > 0
            && leaves[first - 1].contains_code(node_code)
            && leaves[first - 1].size_log2() >= s
        {
            seen.black = true;
        } else {
            let start = leaves.partition_point(|l| l.code() < node_code);
            let end = start
                + leaves[start..]
                    .partition_point(|l| l.code() < node_code + (1u64 << (3 * u32::from(s))));
            visit(
                &leaves[start..end],
                node_code,
                s,
                node_min,
                (rel_lo, rel_hi),
                &mut seen,
            );
        }
        match (seen.black, seen.white) {
            (false, _) => BoxState::Empty,
            (true, false) => BoxState::Full,
            (true, true) => BoxState::Mixed,
        }
    }
}

struct Seen {
    black: bool,
    white: bool,
}

/// Visits the node of `size_log2` at relative corner `min` with first code `code`,
/// whose leaves are `leaves`, where it meets the box.
fn visit(
    leaves: &[super::Leaf],
    code: u64,
    size_log2: u8,
    min: [u64; 3],
    (lo, hi): ([u64; 3], [u64; 3]),
    seen: &mut Seen,
) {
    if seen.black && seen.white {
        return;
    }
    let side = 1u64 << size_log2;
    if (0..3).any(|a| min[a] > hi[a] || min[a] + side - 1 < lo[a]) {
        return;
    }
    match leaves.first() {
        None => {
            seen.white = true;
            return;
        }
        Some(l) if l.size_log2() >= size_log2 => {
            seen.black = true;
            return;
        }
        _ => {}
    }
    let child = size_log2 - 1;
    let cells = 1u64 << (3 * u32::from(child));
    let half = side / 2;
    for d in 0..8u64 {
        let cmin = [0, 1, 2].map(|a| min[a] + ((d >> a) & 1) * half);
        if (0..3).any(|a| cmin[a] > hi[a] || cmin[a] + half - 1 < lo[a]) {
            continue;
        }
        let start = code + d * cells;
        let from = leaves.partition_point(|l| l.code() < start);
        let to = from + leaves[from..].partition_point(|l| l.code() < start + cells);
        visit(&leaves[from..to], start, child, cmin, (lo, hi), seen);
        if seen.black && seen.white {
            return;
        }
    }
}

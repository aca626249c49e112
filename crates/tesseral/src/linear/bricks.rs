//! A dense view of a linear octree in bricks of 8 × 8 × 8 voxels, for the point and
//! box queries of the top-down builders in `affine`: a voxel is one array index and
//! at most one bit away, where the tree needs a binary search over its leaves.
//!
//! The bricks tile the tree's bounding box on the tree's own grid of 8 (its origin
//! plus multiples of 8), so a leaf of side 8 or more covers whole bricks, which are
//! marked full; only the bricks that smaller leaves touch hold a bitmap (512 bits:
//! word `z`, bit `8y + x`). Voxels outside the view are white.

use super::LinearOctree;
use crate::Voxel;

/// A brick with no black voxel: the index of the bitmap of zeros.
const EMPTY: u32 = 0;
/// A brick whose 512 voxels are black: the index of the bitmap of ones.
const FULL: u32 = 1;
/// One bit in each byte: `x` spans a byte, so a row mask times this repeats it over
/// the rows `y`.
const ROWS: u64 = 0x0101_0101_0101_0101;

/// The bricks of one tree (see the module notes).
#[derive(Debug)]
pub(super) struct BrickView {
    /// The world voxel at the lowest corner of brick (0, 0, 0).
    base: Voxel,
    /// Bricks per axis.
    dims: [usize; 3],
    /// Voxels per axis (`8 · dims`), for the bounds check.
    extent: [u64; 3],
    /// Per brick, x fastest: its bitmap's index in `bits`.
    states: Vec<u32>,
    /// The bitmaps: zeros (`EMPTY`), ones (`FULL`), then one per brick that is
    /// neither, so a voxel is looked up without a branch on the brick's kind.
    bits: Vec<[u64; 8]>,
}

/// The bits of an 8 × 8 slice that lie in `[x0, x1] × [y0, y1]` (inclusive, 0..8).
#[inline]
fn slice_mask(x: (u64, u64), y: (u64, u64)) -> u64 {
    let row = ((1u64 << (x.1 - x.0 + 1)) - 1) << x.0;
    let rows = (ROWS >> (8 * (7 - (y.1 - y.0)))) << (8 * y.0);
    row * rows
}

impl BrickView {
    /// The view of `tree`, or `None` when it is empty or would need more than
    /// `max_bricks` bricks.
    pub(super) fn new(tree: &LinearOctree, max_bricks: usize) -> Option<Self> {
        let (lo, hi) = tree.bbox()?;
        let o = tree.origin();
        // Offsets from the origin fit: the tree's space lies inside i64.
        let first: [u64; 3] = std::array::from_fn(|a| (lo[a] - o[a]) as u64 >> 3);
        let dims: [usize; 3] =
            std::array::from_fn(|a| (((hi[a] - o[a]) as u64 >> 3) - first[a] + 1) as usize);
        let count = dims[0].checked_mul(dims[1])?.checked_mul(dims[2])?;
        if count > max_bricks {
            return None;
        }
        let mut view = Self {
            base: std::array::from_fn(|a| o[a] + (first[a] << 3) as i64),
            dims,
            extent: dims.map(|d| (d as u64) << 3),
            states: vec![EMPTY; count],
            bits: vec![[0; 8], [u64::MAX; 8]],
        };
        for leaf in tree.leaves() {
            let c = crate::code::decode(leaf.code());
            // Relative to the view's base, in voxels.
            let rel: [usize; 3] =
                std::array::from_fn(|a| (u64::from(c[a]) - (first[a] << 3)) as usize);
            let k = leaf.size_log2();
            if k >= 3 {
                let n = 1usize << (k - 3);
                let b = rel.map(|r| r >> 3);
                for z in b[2]..b[2] + n {
                    for y in b[1]..b[1] + n {
                        let row = view.index([b[0], y, z]);
                        view.states[row..row + n].fill(FULL);
                    }
                }
            } else {
                let i = view.index(rel.map(|r| r >> 3));
                if view.states[i] == EMPTY {
                    view.states[i] = view.bits.len() as u32;
                    view.bits.push([0; 8]);
                }
                let s = 1u64 << k;
                let l = rel.map(|r| (r & 7) as u64);
                let m = slice_mask((l[0], l[0] + s - 1), (l[1], l[1] + s - 1));
                let words = &mut view.bits[view.states[i] as usize];
                for w in &mut words[l[2] as usize..(l[2] + s) as usize] {
                    *w |= m;
                }
            }
        }
        // A canonical tree has no brick filled by small leaves; any other is
        // marked full all the same.
        for s in &mut view.states {
            if *s > FULL && view.bits[*s as usize] == [u64::MAX; 8] {
                *s = FULL;
            }
        }
        Some(view)
    }

    #[inline]
    fn index(&self, b: [usize; 3]) -> usize {
        (b[2] * self.dims[1] + b[1]) * self.dims[0] + b[0]
    }

    /// The offsets of `v` from the base when it lies in the view.
    #[inline]
    fn rel(&self, v: Voxel) -> Option<[u64; 3]> {
        // A voxel below the base wraps to a huge offset, which the check rejects.
        let r: [u64; 3] = std::array::from_fn(|a| v[a].wrapping_sub(self.base[a]) as u64);
        (r[0] < self.extent[0] && r[1] < self.extent[1] && r[2] < self.extent[2]).then_some(r)
    }

    /// Whether voxel `v` is black.
    #[inline]
    pub(super) fn contains(&self, v: Voxel) -> bool {
        let Some(r) = self.rel(v) else {
            return false;
        };
        let i = self.index(r.map(|c| (c >> 3) as usize));
        let words = &self.bits[self.states[i] as usize];
        words[(r[2] & 7) as usize] >> ((r[1] & 7) * 8 + (r[0] & 7)) & 1 == 1
    }

    /// How many bricks the inclusive box `[lo, hi]` (assumed non-empty) meets, at
    /// most; the cost of [`BrickView::box_state`].
    #[inline]
    pub(super) fn bricks_in(lo: Voxel, hi: Voxel) -> u128 {
        (0..3)
            .map(|a| ((i128::from(hi[a]) - i128::from(lo[a])).max(0) as u128 >> 3) + 2)
            .fold(1, u128::saturating_mul)
    }

    /// [`LinearOctree::box_state`] of the viewed tree, by the bricks the box meets,
    /// with an early exit at the first mixed evidence.
    pub(super) fn box_state(&self, lo: Voxel, hi: Voxel) -> super::BoxState {
        use super::BoxState;
        if (0..3).any(|a| lo[a] > hi[a]) {
            return BoxState::Empty;
        }
        // Clamp to the view; anything cut off is white.
        let mut white = false;
        let mut rlo = [0u64; 3];
        let mut rhi = [0u64; 3];
        for a in 0..3 {
            let l = i128::from(lo[a]) - i128::from(self.base[a]);
            let h = i128::from(hi[a]) - i128::from(self.base[a]);
            let ext = i128::from(self.extent[a]);
            if h < 0 || l >= ext {
                return BoxState::Empty;
            }
            white |= l < 0 || h >= ext;
            rlo[a] = l.max(0) as u64;
            rhi[a] = h.min(ext - 1) as u64;
        }
        let mut black = false;
        let (blo, bhi) = (rlo.map(|c| c >> 3), rhi.map(|c| c >> 3));
        // The part of brick coordinate `b` on axis `a` that the box covers (0..8).
        let part = |a: usize, b: u64| {
            (
                if b == blo[a] { rlo[a] & 7 } else { 0 },
                if b == bhi[a] { rhi[a] & 7 } else { 7 },
            )
        };
        for bz in blo[2]..=bhi[2] {
            let z = part(2, bz);
            for by in blo[1]..=bhi[1] {
                let y = part(1, by);
                let row = self.index([0, by as usize, bz as usize]);
                for bx in blo[0]..=bhi[0] {
                    match self.states[row + bx as usize] {
                        EMPTY => white = true,
                        FULL => black = true,
                        s => {
                            let m = slice_mask(part(0, bx), y);
                            for &w in &self.bits[s as usize][z.0 as usize..=z.1 as usize] {
                                black |= w & m != 0;
                                white |= w & m != m;
                            }
                        }
                    }
                    if black && white {
                        return BoxState::Mixed;
                    }
                }
            }
        }
        match (black, white) {
            (false, _) => BoxState::Empty,
            (true, false) => BoxState::Full,
            (true, true) => BoxState::Mixed,
        }
    }
}

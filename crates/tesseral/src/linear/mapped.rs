//! The top-down builder behind [`LinearOctree::affine`] and
//! [`LinearOctree::scale_axes`]: the image of a tree under a map given by its inverse
//! on voxel centres.
//!
//! An output cell of side `2^k ≥ 8` is classified by the box of input voxels holding
//! the preimages of its centres: all black makes it black, all white makes it white,
//! and only the rest is split. A cell of side 4 is classified the same way when the
//! view answers cheaply, and otherwise decided voxel by voxel: each row of
//! four centres is mapped back with the row's constant terms computed once, and each
//! preimage looked up in a dense view of the input in 8³ bricks ([`BrickView`]), so
//! the 64 answers come out as one word in tesseral order. Box queries go to the same
//! view while the box meets few bricks, and to [`LinearOctree::box_state`] otherwise
//! (or always, for an input too sparse for the view).

use rayon::prelude::*;

use super::bricks::BrickView;
use super::{push_merging, BoxState, Leaf, LinearOctree};
use crate::Voxel;

/// A map from output voxels back to input voxels.
pub(super) trait Sampling: Sync {
    /// The input voxel holding the preimage of output voxel `w`'s centre.
    fn preimage(&self, w: Voxel) -> Voxel;
    /// An inclusive box of input voxels holding the preimages of the centres of the
    /// output cell `[min, max]`.
    fn preimage_box(&self, min: Voxel, max: Voxel) -> (Voxel, Voxel);
    /// [`Sampling::preimage`] of the row `w + (x, 0, 0)` for `x` in `0..out.len()`;
    /// an implementation may share work between the row's voxels but must give the
    /// same answers.
    fn preimage_row(&self, w: Voxel, out: &mut [Voxel]) {
        for (x, o) in out.iter_mut().enumerate() {
            *o = self.preimage([w[0] + x as i64, w[1], w[2]]);
        }
    }
}

/// The most bricks a dense view may have; past it the tree answers every query.
pub(super) const MAX_VIEW_BRICKS: usize = 1 << 22;

/// Box queries meeting at most this many bricks go to the view.
const VIEW_QUERY_MAX_BRICKS: u128 = 4096;

/// Below this cell size (log2) the recursion stays on one thread.
const PARALLEL_MIN_SIZE_LOG2: u8 = 6;

/// Cells of this size (log2) or less are decided voxel by voxel.
const LEAF_CELL_LOG2: u8 = 2;

/// The tesseral code of `(x, y, z)` for coordinates below 4.
const MORTON4: [u8; 64] = {
    let mut t = [0u8; 64];
    let mut i = 0;
    while i < 64 {
        let (x, y, z) = (i & 3, (i >> 2) & 3, i >> 4);
        t[i] = (spread2(x) | (spread2(y) << 1) | (spread2(z) << 2)) as u8;
        i += 1;
    }
    t
};

/// The two low bits of `c` three places apart.
const fn spread2(c: usize) -> usize {
    (c & 1) | ((c & 2) << 2)
}

struct Mapper<'a, S> {
    input: &'a LinearOctree,
    view: Option<BrickView>,
    map: &'a S,
    /// The output space's origin.
    origin: Voxel,
}

/// The leaves (sorted, merged) of the image of `input` under `map` in the space of
/// side `2^depth` from `origin`; the input gets a dense view when it needs at most
/// `max_view_bricks` bricks.
pub(super) fn build_mapped<S: Sampling>(
    input: &LinearOctree,
    map: &S,
    depth: u8,
    origin: Voxel,
    max_view_bricks: usize,
) -> Vec<Leaf> {
    // The view only pays when the input has leaves to search among: a few bricks
    // per leaf at most.
    let budget = max_view_bricks.min(input.leaf_count().saturating_mul(64).saturating_add(4096));
    let mapper = Mapper {
        input,
        view: BrickView::new(input, budget),
        map,
        origin,
    };
    let mut out = Vec::new();
    mapper.build(0, depth, &mut out);
    out
}

impl<S: Sampling> Mapper<'_, S> {
    fn black(&self, p: Voxel) -> bool {
        match &self.view {
            Some(v) => v.contains(p),
            None => self.input.contains(p),
        }
    }

    fn box_state(&self, lo: Voxel, hi: Voxel) -> BoxState {
        match &self.view {
            Some(v) if BrickView::bricks_in(lo, hi) <= VIEW_QUERY_MAX_BRICKS => v.box_state(lo, hi),
            _ => self.input.box_state(lo, hi),
        }
    }

    fn build(&self, code: u64, k: u8, out: &mut Vec<Leaf>) {
        let c = crate::code::decode(code);
        let min: Voxel = std::array::from_fn(|a| self.origin[a] + i64::from(c[a]));
        if k < LEAF_CELL_LOG2 || (k == LEAF_CELL_LOG2 && self.view.is_none()) {
            self.leaf_cell(code, min, k, out);
            return;
        }
        let max = min.map(|c| c + (1i64 << k) - 1);
        let (lo, hi) = self.map.preimage_box(min, max);
        if k == LEAF_CELL_LOG2 {
            // Decided by the view when its preimage box is, else voxel by voxel.
            match self.box_state(lo, hi) {
                BoxState::Empty => {}
                BoxState::Full => out.push(Leaf::new(code, k)),
                BoxState::Mixed => self.leaf_cell(code, min, k, out),
            }
            return;
        }
        match self.box_state(lo, hi) {
            BoxState::Empty => {}
            BoxState::Full => out.push(Leaf::new(code, k)),
            BoxState::Mixed => {
                let cells = 1u64 << (3 * u32::from(k - 1));
                if k >= PARALLEL_MIN_SIZE_LOG2 {
                    let parts: Vec<Vec<Leaf>> = (0..8u64)
                        .into_par_iter()
                        .map(|d| {
                            let mut part = Vec::new();
                            self.build(code + d * cells, k - 1, &mut part);
                            part
                        })
                        .collect();
                    for part in &parts {
                        out.extend_from_slice(part);
                    }
                } else {
                    for d in 0..8 {
                        self.build(code + d * cells, k - 1, out);
                    }
                }
                if let Some(last) = out.pop() {
                    push_merging(out, last);
                }
            }
        }
    }

    /// Decides the cell of side `2^k ≤ 4` at `min` voxel by voxel and pushes its
    /// leaves (unmerged with what precedes it: the caller merges).
    fn leaf_cell(&self, code: u64, min: Voxel, k: u8, out: &mut Vec<Leaf>) {
        let s = 1usize << k;
        let mut bits = 0u64;
        let mut row = [[0i64; 3]; 4];
        for z in 0..s {
            for y in 0..s {
                self.map.preimage_row(
                    [min[0], min[1] + y as i64, min[2] + z as i64],
                    &mut row[..s],
                );
                for (x, p) in row[..s].iter().enumerate() {
                    bits |= u64::from(self.black(*p)) << MORTON4[x | y << 2 | z << 4];
                }
            }
        }
        let all = if k == 2 {
            u64::MAX
        } else {
            (1u64 << (s * s * s)) - 1
        };
        if bits == all {
            out.push(Leaf::new(code, k));
            return;
        }
        // Blocks of side 2 (eight bits each), then single voxels.
        for d in 0..(s * s * s).div_ceil(8) {
            let byte = (bits >> (8 * d)) as u8;
            let at = code + 8 * d as u64;
            if byte == 0xff && k >= 1 {
                out.push(Leaf::new(at, 1));
            } else {
                let mut b = byte;
                while b != 0 {
                    out.push(Leaf::new(at + u64::from(b.trailing_zeros()), 0));
                    b &= b - 1;
                }
            }
        }
    }
}

//! The top-down octree builder of a compiled solid: cells classified by interval
//! tests (balls round cells), the bottom 4³ cells by masks of point samples, in
//! parallel over subtrees, under a leaf budget checked as the leaves are made.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use super::compile::{Csg, Known, Op};
use super::prim::Prim;
use super::DEFAULT_MAX_LEAVES;
use super::{CsgError, Shape};
use crate::linear::{push_merging, CellClass, Classifier, Leaf, LinearOctree};
use crate::Voxel;

impl Csg {
    /// Builds the linear octree of the solid in the space of `2^depth` voxels per axis
    /// from `origin`, with [`DEFAULT_MAX_LEAVES`].
    ///
    /// # Runtime
    /// Proportional to the cells the surface may cross (about 8 × the partial cells),
    /// times the primitives still undecided in each; parallel over subtrees (rayon).
    ///
    /// # Errors
    /// [`CsgError::Octree`] when `depth` is too large; [`CsgError::TooManyLeaves`].
    pub fn build(&self, depth: u8, origin: Voxel) -> Result<LinearOctree, CsgError> {
        self.build_limited(depth, origin, DEFAULT_MAX_LEAVES)
    }

    /// As [`Csg::build`], stopping with [`CsgError::TooManyLeaves`] once more than
    /// `max_leaves` leaves have been produced.
    ///
    /// # Errors
    /// As [`Csg::build`].
    pub fn build_limited(
        &self,
        depth: u8,
        origin: Voxel,
        max_leaves: usize,
    ) -> Result<LinearOctree, CsgError> {
        LinearOctree::empty(depth, origin)?;
        let budget = Budget {
            used: AtomicUsize::new(0),
            max: max_leaves,
            stop: AtomicBool::new(false),
        };
        let chunks = if depth >= PARALLEL_MIN_SIZE_LOG2 {
            self.build_par(0, origin, depth, Known::default(), &budget)
        } else {
            let mut v = Vec::new();
            self.build_cell(0, origin, depth, Known::default(), &mut v);
            vec![v]
        };
        let n: usize = chunks.iter().map(Vec::len).sum();
        if budget.stop.load(Ordering::Relaxed) || n > max_leaves {
            return Err(CsgError::TooManyLeaves { limit: max_leaves });
        }
        let mut out = Vec::with_capacity(n);
        for c in chunks {
            out.extend_from_slice(&c);
        }
        // The builder emits leaves sorted and canonical (merging as it goes), so they are
        // taken as they are; the tests check `assert_valid` on every build.
        Ok(LinearOctree::from_parts(depth, origin, out).with_bricks())
    }

    /// The parallel levels: the leaves come back as a list of sorted chunks, so that
    /// big subtrees are never copied on the way up.
    fn build_par(
        &self,
        code: u64,
        min: Voxel,
        k: u8,
        known: Known,
        budget: &Budget,
    ) -> Vec<Vec<Leaf>> {
        if budget.stop.load(Ordering::Relaxed) {
            return Vec::new();
        }
        let (c, r) = cell_ball(min, k);
        let mut learn = known;
        match self.eval(self.root, c, r, known, &mut learn) {
            CellClass::Outside => Vec::new(),
            CellClass::Inside => vec![vec![Leaf::new(code, k)]],
            CellClass::Partial => {
                let parts: Vec<Vec<Vec<Leaf>>> = (0..8u64)
                    .into_par_iter()
                    .map(|d| {
                        let (cc, cm) = child_of(code, min, k, d);
                        if k > PARALLEL_MIN_SIZE_LOG2 {
                            self.build_par(cc, cm, k - 1, learn, budget)
                        } else {
                            let mut part = Vec::with_capacity(256);
                            self.build_cell(cc, cm, k - 1, learn, &mut part);
                            let n = part.len();
                            if budget.used.fetch_add(n, Ordering::Relaxed) + n > budget.max {
                                budget.stop.store(true, Ordering::Relaxed);
                            }
                            vec![part]
                        }
                    })
                    .collect();
                // Eight full children merge into this cell; nothing else can merge.
                let full = parts.iter().all(|p| {
                    let mut leaves = p.iter().flatten();
                    matches!((leaves.next(), leaves.next()), (Some(l), None) if l.size_log2() == k - 1)
                });
                if full {
                    return vec![vec![Leaf::new(code, k)]];
                }
                parts
                    .into_iter()
                    .flatten()
                    .filter(|c| !c.is_empty())
                    .collect()
            }
        }
    }

    /// Classifies the cell `(min, k)` with nothing known from its ancestors.
    pub(crate) fn classify_cell(&self, min: Voxel, k: u8) -> CellClass {
        let (c, r) = cell_ball(min, k);
        let known = Known::default();
        let mut learn = known;
        self.eval(self.root, c, r, known, &mut learn)
    }

    /// Appends the leaves of the cell `(code, min, k)`, built on this thread.
    pub(crate) fn build_subtree(&self, code: u64, min: Voxel, k: u8, out: &mut Vec<Leaf>) {
        self.build_cell(code, min, k, Known::default(), out);
    }

    /// The sequential levels: leaves are appended to `out`, merged as they come.
    fn build_cell(&self, code: u64, min: Voxel, k: u8, known: Known, out: &mut Vec<Leaf>) {
        let (c, r) = cell_ball(min, k);
        let mut learn = known;
        match self.eval(self.root, c, r, known, &mut learn) {
            CellClass::Outside => {}
            CellClass::Inside => out.push(Leaf::new(code, k)),
            CellClass::Partial if k == 0 => out.push(Leaf::new(code, 0)),
            CellClass::Partial if k == 2 => {
                // 64 voxels: evaluate them all at once, as bit masks in tesseral order.
                let mask = self.eval_mask(self.root, min, learn);
                emit_mask(code, mask, out);
            }
            CellClass::Partial => {
                for d in 0..8 {
                    let (cc, cm) = child_of(code, min, k, d);
                    self.build_cell(cc, cm, k - 1, learn, out);
                }
                if let Some(last) = out.pop() {
                    push_merging(out, last);
                }
            }
        }
    }
}

/// The code and lowest voxel of child `d` of the cell `(code, min, k)`.
#[inline]
fn child_of(code: u64, min: Voxel, k: u8, d: u64) -> (u64, Voxel) {
    let half = 1i64 << (k - 1);
    (
        code + d * (1u64 << (3 * u32::from(k - 1))),
        [
            min[0] + half * (d & 1) as i64,
            min[1] + half * ((d >> 1) & 1) as i64,
            min[2] + half * ((d >> 2) & 1) as i64,
        ],
    )
}

/// The offsets of the 64 voxels of a 4x4x4 cell, in tesseral order.
const OFFSETS_4: [[f64; 3]; 64] = {
    let mut t = [[0.0; 3]; 64];
    let mut b = 0;
    while b < 64 {
        t[b] = [
            ((b & 1) | ((b >> 3) & 1) << 1) as f64,
            (((b >> 1) & 1) | ((b >> 4) & 1) << 1) as f64,
            (((b >> 2) & 1) | ((b >> 5) & 1) << 1) as f64,
        ];
        b += 1;
    }
    t
};

/// Pushes the leaves of a 4x4x4 cell whose black voxels are the set bits of `mask`
/// (bit i = the voxel at tesseral offset i), merging full octets.
fn emit_mask(code: u64, mask: u64, out: &mut Vec<Leaf>) {
    if mask == u64::MAX {
        out.push(Leaf::new(code, 2));
        return;
    }
    for j in 0..8u64 {
        let byte = (mask >> (8 * j)) & 0xff;
        if byte == 0xff {
            out.push(Leaf::new(code + 8 * j, 1));
        } else {
            let mut b = byte;
            while b != 0 {
                let i = u64::from(b.trailing_zeros());
                out.push(Leaf::new(code + 8 * j + i, 0));
                b &= b - 1;
            }
        }
    }
}

impl Prim {
    /// The 64 voxels of the 4x4x4 cell at `min`, as a bit mask in tesseral order.
    fn mask4(&self, min: Voxel) -> u64 {
        let l0 = self.local([
            min[0] as f64 + 0.5,
            min[1] as f64 + 0.5,
            min[2] as f64 + 0.5,
        ]);
        let m = &self.inv;
        let cols = [
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ];
        #[inline(always)]
        fn each(l0: [f64; 3], cols: &[[f64; 3]; 3], test: impl Fn([f64; 3]) -> bool) -> u64 {
            let mut mask = 0u64;
            for (b, o) in OFFSETS_4.iter().enumerate() {
                let p = [
                    l0[0] + o[0] * cols[0][0] + o[1] * cols[1][0] + o[2] * cols[2][0],
                    l0[1] + o[0] * cols[0][1] + o[1] * cols[1][1] + o[2] * cols[2][1],
                    l0[2] + o[0] * cols[0][2] + o[1] * cols[1][2] + o[2] * cols[2][2],
                ];
                mask |= u64::from(test(p)) << b;
            }
            mask
        }
        // One loop per shape, so that each is compiled on its own.
        match &self.shape {
            Shape::Sphere { r } => {
                let r2 = r * r;
                each(l0, &cols, |p| p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= r2)
            }
            Shape::Box { half } => each(l0, &cols, |p| {
                p[0].abs() <= half[0] && p[1].abs() <= half[1] && p[2].abs() <= half[2]
            }),
            shape => each(l0, &cols, |p| shape.contains(p)),
        }
    }
}

impl Csg {
    /// The 64 voxels of the 4x4x4 cell at `min` as a bit mask in tesseral order.
    fn eval_mask(&self, n: u32, min: Voxel, known: Known) -> u64 {
        let node = &self.nodes[n as usize];
        let kids = &self.kids[node.first as usize..(node.first + node.len) as usize];
        match node.op {
            Op::Prim(i) => {
                if i < 64 {
                    let bit = 1u64 << i;
                    if known.inside & bit != 0 {
                        return u64::MAX;
                    }
                    if known.outside & bit != 0 {
                        return 0;
                    }
                }
                self.prims[i as usize].mask4(min)
            }
            Op::Union if self.index[n as usize].is_some() => {
                // The voxel centres of the cell span [min + 0.5, min + 3.5].
                let lo = min.map(|v| v as f64 + 0.5);
                let query = (lo, lo.map(|v| v + 3.0));
                let mut acc = 0;
                if let Some(ix) = &self.index[n as usize] {
                    let _ = ix.for_each_meeting(&query, |k| {
                        acc |= self.eval_mask(k, min, known);
                        if acc == u64::MAX {
                            ControlFlow::Break(())
                        } else {
                            ControlFlow::Continue(())
                        }
                    });
                }
                acc
            }
            Op::Union => {
                let mut acc = 0;
                for &k in kids {
                    acc |= self.eval_mask(k, min, known);
                    if acc == u64::MAX {
                        break;
                    }
                }
                acc
            }
            Op::Inter | Op::Diff => {
                let mut acc = u64::MAX;
                for (j, &k) in kids.iter().enumerate() {
                    let m = self.eval_mask(k, min, known);
                    acc &= if node.op == Op::Diff && j > 0 { !m } else { m };
                    if acc == 0 {
                        break;
                    }
                }
                acc
            }
            Op::Not => !self.eval_mask(kids[0], min, known),
        }
    }
}

struct Budget {
    used: AtomicUsize,
    max: usize,
    stop: AtomicBool,
}

/// Below this cell size (log2) the build runs on one thread.
const PARALLEL_MIN_SIZE_LOG2: u8 = 5;

/// The ball holding the voxel centres of the cell `[min, min + 2^k)`: its centre and
/// radius (0 for a single voxel).
#[inline]
fn cell_ball(min: Voxel, k: u8) -> ([f64; 3], f64) {
    let half = f64::from(1u32 << k) / 2.0;
    let c = [
        min[0] as f64 + half,
        min[1] as f64 + half,
        min[2] as f64 + half,
    ];
    let r = if k == 0 {
        0.0
    } else {
        (half - 0.5) * 3f64.sqrt()
    };
    (c, r)
}

impl Classifier for Csg {
    /// Classifies the cell by the bounding-sphere test of every primitive (no pruning
    /// across cells; [`Csg::build`] adds that).
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        let (c, r) = cell_ball(min, size_log2);
        self.eval(self.root, c, r, Known::default(), &mut Known::default())
    }
}

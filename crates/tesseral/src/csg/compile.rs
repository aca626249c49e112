//! A solid compiled for evaluation, its conservative cell classifier and its top-down
//! octree builder.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use super::index::{Bounds, BoxIndex};
use super::{Colour, CsgError, Shape, Solid, Transform};
use crate::linear::{push_merging, CellClass, Classifier, Leaf, LinearOctree};
use crate::Voxel;

/// The default cap on the leaves of a build (about 400 MB of leaves): a hostile scene
/// stops with [`CsgError::TooManyLeaves`] rather than exhausting memory.
pub const DEFAULT_MAX_LEAVES: usize = 50_000_000;

/// A primitive with its world-to-local map `local = inv · (p − at)`, where
/// `inv = Rᵀ / s`; world distances are `s` times local ones.
#[derive(Debug, Clone)]
struct Prim {
    shape: Shape,
    inv: [[f64; 3]; 3],
    at: [f64; 3],
    scale: f64,
    world: Transform,
}

impl Prim {
    #[inline]
    fn local(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [p[0] - self.at[0], p[1] - self.at[1], p[2] - self.at[2]];
        let m = &self.inv;
        [
            m[0][0] * d[0] + m[0][1] * d[1] + m[0][2] * d[2],
            m[1][0] * d[0] + m[1][1] * d[1] + m[1][2] * d[2],
            m[2][0] * d[0] + m[2][1] * d[1] + m[2][2] * d[2],
        ]
    }

    /// The class of the ball of radius `r` around `c` (`r == 0`: the point `c`).
    #[inline]
    fn class(&self, c: [f64; 3], r: f64) -> CellClass {
        let l = self.local(c);
        if r == 0.0 {
            return if self.shape.contains(l) {
                CellClass::Inside
            } else {
                CellClass::Outside
            };
        }
        let b = self.scale * self.shape.bound(l);
        // The margin absorbs rounding: the bound is decided well clear of the surface.
        let m = r + 1e-6 + 1e-9 * r;
        if b > m {
            CellClass::Outside
        } else if b < -m {
            CellClass::Inside
        } else {
            CellClass::Partial
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Prim(u32),
    Union,
    Inter,
    Diff,
    Not,
}

#[derive(Debug, Clone)]
struct Node {
    op: Op,
    first: u32,
    len: u32,
    colour: Option<Colour>,
}

/// Per-cell knowledge passed from a cell to its children: which of the first 64
/// primitives are already known to be wholly inside or outside the cell (and so are of
/// every sub-cell).
#[derive(Debug, Clone, Copy, Default)]
struct Known {
    inside: u64,
    outside: u64,
}

/// A compiled solid: primitives with their world-to-local maps and the tree of set
/// operations over them. It is a [`Classifier`], and builds octrees with
/// [`Csg::build`], which also prunes primitives already decided for a cell.
///
/// ```
/// use tesseral::csg::{Shape, Solid};
/// let csg = Solid::shape(Shape::sphere(10.0)).at([16.0, 16.0, 16.0]).compile().unwrap();
/// let tree = csg.build(5, [0, 0, 0]).unwrap();
/// assert_eq!(tree.contains([16, 16, 16]), csg.contains([16.5, 16.5, 16.5]));
/// ```
#[derive(Debug, Clone)]
pub struct Csg {
    prims: Vec<Prim>,
    nodes: Vec<Node>,
    kids: Vec<u32>,
    root: u32,
    /// Per node: for a union of at least [`INDEX_MIN_PARTS`] parts, the index of
    /// their boxes.
    index: Vec<Option<BoxIndex>>,
}

/// Unions of at least this many parts get a [`BoxIndex`]; below it a scan is as fast.
const INDEX_MIN_PARTS: u32 = 16;

impl Csg {
    pub(crate) fn compile(solid: &Solid) -> Result<Self, CsgError> {
        let mut c = Csg {
            prims: Vec::new(),
            nodes: Vec::new(),
            kids: Vec::new(),
            root: 0,
            index: Vec::new(),
        };
        c.root = c.add(solid, &Transform::IDENTITY, None, 0)?;
        c.index = (0..c.nodes.len() as u32)
            .map(|n| {
                let node = &c.nodes[n as usize];
                (node.op == Op::Union && node.len >= INDEX_MIN_PARTS).then(|| {
                    let parts: Vec<(u32, Option<Bounds>)> =
                        c.kids_of(n).iter().map(|&k| (k, c.node_bbox(k))).collect();
                    BoxIndex::new(&parts)
                })
            })
            .collect();
        Ok(c)
    }

    fn kids_of(&self, n: u32) -> &[u32] {
        let node = &self.nodes[n as usize];
        &self.kids[node.first as usize..(node.first + node.len) as usize]
    }

    fn add(
        &mut self,
        solid: &Solid,
        t: &Transform,
        colour: Option<Colour>,
        nesting: usize,
    ) -> Result<u32, CsgError> {
        if nesting > 256 {
            return Err(CsgError::Invalid("solids nest more than 256 deep".into()));
        }
        let (op, children): (Op, &[Solid]) = match solid {
            Solid::Primitive(shape) => {
                shape.validate().map_err(CsgError::Invalid)?;
                let r = t.rot;
                let s = t.scale;
                let inv = [
                    [r[0][0] / s, r[1][0] / s, r[2][0] / s],
                    [r[0][1] / s, r[1][1] / s, r[2][1] / s],
                    [r[0][2] / s, r[1][2] / s, r[2][2] / s],
                ];
                self.prims.push(Prim {
                    shape: shape.clone(),
                    inv,
                    at: t.at,
                    scale: s,
                    world: *t,
                });
                let i = self.prims.len() as u32 - 1;
                return Ok(self.push_node(Op::Prim(i), &[], colour));
            }
            Solid::Transformed(inner, u) => {
                let finite =
                    u.at.iter()
                        .chain(u.rot.iter().flatten())
                        .all(|v| v.is_finite());
                if !(finite && u.scale.is_finite() && u.scale > 0.0) {
                    return Err(CsgError::Invalid(
                        "a transform must be finite, with a positive scale".into(),
                    ));
                }
                return self.add(inner, &t.then_inner(u), colour, nesting + 1);
            }
            Solid::Coloured(inner, c) => return self.add(inner, t, Some(*c), nesting + 1),
            Solid::Union(v) => (Op::Union, v),
            Solid::Intersection(v) => (Op::Inter, v),
            Solid::Difference(v) => {
                if v.is_empty() {
                    return Err(CsgError::Invalid("a difference needs a first solid".into()));
                }
                (Op::Diff, v)
            }
            Solid::Not(inner) => (Op::Not, std::slice::from_ref(&**inner)),
        };
        let mut ids = Vec::with_capacity(children.len());
        for child in children {
            ids.push(self.add(child, t, None, nesting + 1)?);
        }
        Ok(self.push_node(op, &ids, colour))
    }

    fn push_node(&mut self, op: Op, kids: &[u32], colour: Option<Colour>) -> u32 {
        let first = self.kids.len() as u32;
        self.kids.extend_from_slice(kids);
        self.nodes.push(Node {
            op,
            first,
            len: kids.len() as u32,
            colour,
        });
        self.nodes.len() as u32 - 1
    }

    /// The number of primitives.
    #[must_use]
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// Whether the point `p` lies in the solid: the exact predicate the octree
    /// reproduces at voxel centres.
    ///
    /// # Runtime
    /// O(primitives).
    #[must_use]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.eval(self.root, p, 0.0, Known::default(), &mut Known::default()) == CellClass::Inside
    }

    /// Classifies the ball of radius `r` around `c`, using and extending `known`.
    fn eval(&self, n: u32, c: [f64; 3], r: f64, known: Known, learn: &mut Known) -> CellClass {
        let node = &self.nodes[n as usize];
        let kids = &self.kids[node.first as usize..(node.first + node.len) as usize];
        match node.op {
            Op::Prim(i) => {
                if i < 64 {
                    let bit = 1u64 << i;
                    if known.inside & bit != 0 {
                        return CellClass::Inside;
                    }
                    if known.outside & bit != 0 {
                        return CellClass::Outside;
                    }
                    let class = self.prims[i as usize].class(c, r);
                    match class {
                        CellClass::Inside => learn.inside |= bit,
                        CellClass::Outside => learn.outside |= bit,
                        CellClass::Partial => {}
                    }
                    class
                } else {
                    self.prims[i as usize].class(c, r)
                }
            }
            Op::Union if self.index[n as usize].is_some() => {
                // Only the parts whose boxes meet the ball can hold its points.
                let query = (c.map(|v| v - r), c.map(|v| v + r));
                let mut all_out = true;
                let found = self.index[n as usize]
                    .as_ref()
                    .map(|ix| {
                        ix.for_each_meeting(&query, |k| match self.eval(k, c, r, known, learn) {
                            CellClass::Inside => ControlFlow::Break(()),
                            CellClass::Partial => {
                                all_out = false;
                                ControlFlow::Continue(())
                            }
                            CellClass::Outside => ControlFlow::Continue(()),
                        })
                    })
                    .is_some_and(|f| f.is_break());
                if found {
                    CellClass::Inside
                } else if all_out {
                    CellClass::Outside
                } else {
                    CellClass::Partial
                }
            }
            Op::Union => {
                let mut all_out = true;
                for &k in kids {
                    match self.eval(k, c, r, known, learn) {
                        CellClass::Inside => return CellClass::Inside,
                        CellClass::Partial => all_out = false,
                        CellClass::Outside => {}
                    }
                }
                if all_out {
                    CellClass::Outside
                } else {
                    CellClass::Partial
                }
            }
            Op::Inter | Op::Diff => {
                let mut all_in = true;
                for (j, &k) in kids.iter().enumerate() {
                    let mut class = self.eval(k, c, r, known, learn);
                    if node.op == Op::Diff && j > 0 {
                        class = flip(class);
                    }
                    match class {
                        CellClass::Outside => return CellClass::Outside,
                        CellClass::Partial => all_in = false,
                        CellClass::Inside => {}
                    }
                }
                if all_in {
                    CellClass::Inside
                } else {
                    CellClass::Partial
                }
            }
            Op::Not => flip(self.eval(kids[0], c, r, known, learn)),
        }
    }

    /// The colour of the solid at `p`: the colour named by the innermost coloured
    /// node on the path to a primitive containing `p` (for a union, the last part that
    /// contains `p`; for an intersection or difference, the first part).
    /// `None` when no node on that path has a colour.
    #[must_use]
    pub fn colour_at(&self, p: [f64; 3]) -> Option<Colour> {
        let mut n = self.root;
        let mut colour = None;
        loop {
            let node = &self.nodes[n as usize];
            colour = node.colour.or(colour);
            let kids = &self.kids[node.first as usize..(node.first + node.len) as usize];
            match node.op {
                Op::Prim(_) | Op::Not => return colour,
                Op::Union => {
                    let hit = kids.iter().rev().find(|&&k| {
                        self.eval(k, p, 0.0, Known::default(), &mut Known::default())
                            == CellClass::Inside
                    });
                    match hit {
                        Some(&k) => n = k,
                        None => return colour,
                    }
                }
                Op::Inter | Op::Diff => match kids.first() {
                    Some(&k) => n = k,
                    None => return colour,
                },
            }
        }
    }

    /// An outward normal estimate at `p` (the gradient of the distance bound of the
    /// primitive whose surface is nearest), for smooth shading. `None` far from every
    /// surface.
    #[must_use]
    pub fn normal_at(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        let (mut best, mut which) = (f64::INFINITY, None);
        for (i, pr) in self.prims.iter().enumerate() {
            let d = (pr.scale * pr.shape.bound(pr.local(p))).abs();
            if d < best {
                best = d;
                which = Some(i);
            }
        }
        let pr = &self.prims[which?];
        let h = 0.25;
        let f = |q: [f64; 3]| pr.shape.bound(pr.local(q));
        let mut g = [0.0; 3];
        for a in 0..3 {
            let (mut hi, mut lo) = (p, p);
            hi[a] += h;
            lo[a] -= h;
            g[a] = f(hi) - f(lo);
        }
        let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        if l.is_nan() || l <= 1e-12 {
            return None;
        }
        // A primitive that is subtracted or negated has its normal flipped.
        let sign = if self.prim_is_negated(which? as u32) {
            -1.0
        } else {
            1.0
        };
        Some([sign * g[0] / l, sign * g[1] / l, sign * g[2] / l])
    }

    fn prim_is_negated(&self, prim: u32) -> bool {
        fn walk(c: &Csg, n: u32, prim: u32, neg: bool) -> Option<bool> {
            let node = &c.nodes[n as usize];
            let kids = &c.kids[node.first as usize..(node.first + node.len) as usize];
            match node.op {
                Op::Prim(i) => (i == prim).then_some(neg),
                Op::Not => walk(c, kids[0], prim, !neg),
                Op::Diff => kids
                    .iter()
                    .enumerate()
                    .find_map(|(j, &k)| walk(c, k, prim, neg ^ (j > 0))),
                Op::Union | Op::Inter => kids.iter().find_map(|&k| walk(c, k, prim, neg)),
            }
        }
        walk(self, self.root, prim, false).unwrap_or(false)
    }

    /// An axis-aligned box `(min, max)` holding the solid, or `None` when it is
    /// unbounded (a negation or a half-space not cut down by an intersection).
    #[must_use]
    pub fn bbox(&self) -> Option<([f64; 3], [f64; 3])> {
        self.node_bbox(self.root)
    }

    fn node_bbox(&self, n: u32) -> Option<([f64; 3], [f64; 3])> {
        let node = &self.nodes[n as usize];
        let kids = &self.kids[node.first as usize..(node.first + node.len) as usize];
        match node.op {
            Op::Prim(i) => {
                let p = &self.prims[i as usize];
                let h = p.shape.local_half_extent()?;
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for corner in 0..8 {
                    let q = [
                        if corner & 1 == 0 { -h[0] } else { h[0] },
                        if corner & 2 == 0 { -h[1] } else { h[1] },
                        if corner & 4 == 0 { -h[2] } else { h[2] },
                    ];
                    let w = p.world.apply(q);
                    for a in 0..3 {
                        lo[a] = lo[a].min(w[a]);
                        hi[a] = hi[a].max(w[a]);
                    }
                }
                Some((lo, hi))
            }
            Op::Union => {
                let mut acc: Option<([f64; 3], [f64; 3])> = None;
                for &k in kids {
                    let b = self.node_bbox(k)?;
                    acc = Some(match acc {
                        None => b,
                        Some(a) => (
                            std::array::from_fn(|i| a.0[i].min(b.0[i])),
                            std::array::from_fn(|i| a.1[i].max(b.1[i])),
                        ),
                    });
                }
                // The empty union: an empty box.
                Some(acc.unwrap_or(([0.0; 3], [0.0; 3])))
            }
            Op::Inter => {
                let mut acc: Option<([f64; 3], [f64; 3])> = None;
                for &k in kids {
                    if let Some(b) = self.node_bbox(k) {
                        acc = Some(match acc {
                            None => b,
                            Some(a) => (
                                std::array::from_fn(|i| a.0[i].max(b.0[i])),
                                std::array::from_fn(|i| a.1[i].min(b.1[i])),
                            ),
                        });
                    }
                }
                acc
            }
            Op::Diff => self.node_bbox(kids[0]),
            Op::Not => None,
        }
    }

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
        Ok(LinearOctree::from_parts(depth, origin, out))
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

#[inline]
fn flip(c: CellClass) -> CellClass {
    match c {
        CellClass::Inside => CellClass::Outside,
        CellClass::Outside => CellClass::Inside,
        CellClass::Partial => CellClass::Partial,
    }
}

impl Classifier for Csg {
    /// Classifies the cell by the bounding-sphere test of every primitive (no pruning
    /// across cells; [`Csg::build`] adds that).
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        let (c, r) = cell_ball(min, size_log2);
        self.eval(self.root, c, r, Known::default(), &mut Known::default())
    }
}

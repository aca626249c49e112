//! A solid compiled for evaluation: primitives with their maps, the node list of
//! the expression, the conservative cell test (`eval`) and point queries (inside,
//! colour, normal, bounds). The primitives are in `prim.rs`, the builder in
//! `build.rs`.

use std::ops::ControlFlow;

use super::index::{Bounds, BoxIndex};
use super::prim::Prim;
use super::{Colour, CsgError, Solid, Transform};
use crate::linear::CellClass;

/// The default cap on the leaves of a build (about 400 MB of leaves): a hostile scene
/// stops with [`CsgError::TooManyLeaves`] rather than exhausting memory.
pub const DEFAULT_MAX_LEAVES: usize = 50_000_000;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    Prim(u32),
    Union,
    Inter,
    Diff,
    Not,
}

#[derive(Debug, Clone)]
pub(super) struct Node {
    pub(super) op: Op,
    pub(super) first: u32,
    pub(super) len: u32,
    pub(super) colour: Option<Colour>,
}

/// Per-cell knowledge passed from a cell to its children: which of the first 64
/// primitives are already known to be wholly inside or outside the cell (and so are of
/// every sub-cell).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Known {
    pub(super) inside: u64,
    pub(super) outside: u64,
}

/// A compiled solid: primitives with their world-to-local maps and the tree of set
/// operations over them. It is a [`Classifier`](crate::linear::Classifier), and builds octrees with
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
    pub(super) prims: Vec<Prim>,
    pub(super) nodes: Vec<Node>,
    pub(super) kids: Vec<u32>,
    pub(super) root: u32,
    /// Per node: for a union of at least [`INDEX_MIN_PARTS`] parts, the index of
    /// their boxes.
    pub(super) index: Vec<Option<BoxIndex>>,
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

    pub(super) fn kids_of(&self, n: u32) -> &[u32] {
        let node = &self.nodes[n as usize];
        &self.kids[node.first as usize..(node.first + node.len) as usize]
    }

    pub(super) fn add(
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

    pub(super) fn push_node(&mut self, op: Op, kids: &[u32], colour: Option<Colour>) -> u32 {
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
    pub(super) fn eval(
        &self,
        n: u32,
        c: [f64; 3],
        r: f64,
        known: Known,
        learn: &mut Known,
    ) -> CellClass {
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

    pub(super) fn prim_is_negated(&self, prim: u32) -> bool {
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

    pub(super) fn node_bbox(&self, n: u32) -> Option<([f64; 3], [f64; 3])> {
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
}

#[inline]
pub(super) fn flip(c: CellClass) -> CellClass {
    match c {
        CellClass::Inside => CellClass::Outside,
        CellClass::Outside => CellClass::Inside,
        CellClass::Partial => CellClass::Partial,
    }
}

//! Interference and clearance of two octrees by one parallel traversal of both trees
//! (Ahuja & Nash §5: "detecting interference between two objects is easy if octree
//! representations of the objects are given, since it requires a single parallel
//! traversal of the two trees"). The moved tree is never built: each tree's cells are
//! placed in the world on the fly (a rotation by multiples of 90° and an integer
//! offset), so cells of the two trees need not be aligned with each other.

use std::ops::ControlFlow;

use serde::Serialize;

use super::orient::Rotation;
use super::traverse::Node;
use super::view::{shift_mask, Traversable};
use crate::linear::{Leaf, LinearOctree};
use crate::Voxel;

/// Where a tree is put in the world: a voxel `v` of the tree lands on
/// `rotation.apply_voxel(v) + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Placement {
    /// Applied first, about the lattice point (0, 0, 0) of the tree's coordinates.
    pub rotation: Rotation,
    /// Added after the rotation.
    pub offset: Voxel,
}

impl Placement {
    /// A pure translation by `offset`.
    #[must_use]
    pub fn at(offset: Voxel) -> Placement {
        Placement {
            rotation: Rotation::IDENTITY,
            offset,
        }
    }

    /// Where voxel `v` of the tree lands.
    #[must_use]
    pub fn apply_voxel(&self, v: Voxel) -> Voxel {
        let r = self.rotation.apply_voxel(v);
        [
            r[0] + self.offset[0],
            r[1] + self.offset[1],
            r[2] + self.offset[2],
        ]
    }

    /// The world box `w` seen in the placed tree's own coordinates (the inverse map).
    #[inline]
    pub(crate) fn unplace_box(&self, w: &IBox) -> IBox {
        let lo = [0, 1, 2].map(|a| w.lo[a] - i128::from(self.offset[a]));
        let hi = [0, 1, 2].map(|a| w.hi[a] - i128::from(self.offset[a]));
        if self.rotation.is_identity() {
            return IBox { lo, hi };
        }
        let (lo, hi) = self.rotation.inverse().apply_box(lo, hi);
        IBox { lo, hi }
    }

    /// The half-open box `b` (in the tree's coordinates) placed in the world.
    #[inline]
    pub(crate) fn place_box(&self, b: &IBox) -> IBox {
        if self.rotation.is_identity() {
            return IBox {
                lo: [0, 1, 2].map(|a| b.lo[a] + i128::from(self.offset[a])),
                hi: [0, 1, 2].map(|a| b.hi[a] + i128::from(self.offset[a])),
            };
        }
        let (lo, hi) = self.rotation.apply_box(b.lo, b.hi);
        IBox {
            lo: [0, 1, 2].map(|a| lo[a] + i128::from(self.offset[a])),
            hi: [0, 1, 2].map(|a| hi[a] + i128::from(self.offset[a])),
        }
    }
}

/// A tree with its placement in the world: a [`LinearOctree`] or a prepared
/// [`BoxTree`](super::BoxTree).
#[derive(Debug)]
pub struct Placed<'t, T: Traversable + ?Sized = LinearOctree> {
    /// The tree, in its own coordinates.
    pub tree: &'t T,
    /// Where it is put.
    pub place: Placement,
}

impl<T: Traversable + ?Sized> Clone for Placed<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Traversable + ?Sized> Copy for Placed<'_, T> {}

impl<'t, T: Traversable + ?Sized> Placed<'t, T> {
    /// `tree` where it stands (identity placement).
    #[must_use]
    pub fn fixed(tree: &'t T) -> Self {
        Placed {
            tree,
            place: Placement::default(),
        }
    }

    /// `tree` placed by `place`.
    #[must_use]
    pub fn new(tree: &'t T, place: Placement) -> Self {
        Placed { tree, place }
    }

    #[inline]
    pub(crate) fn world_box(&self, n: &T::Node) -> IBox {
        self.place.place_box(&self.tree.node_box(n))
    }
}

/// A box of voxels `min..=max` per axis (both inclusive), in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Aabb {
    /// The lowest voxel.
    pub min: Voxel,
    /// The highest voxel (inclusive).
    pub max: Voxel,
}

impl Aabb {
    /// The number of voxels in the box.
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        (0..3)
            .map(|a| (self.max[a] - self.min[a] + 1) as u64)
            .product()
    }
}

/// A half-open integer box `[lo, hi)` per axis (internal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[doc(hidden)]
pub struct IBox {
    pub lo: Wide,
    pub hi: Wide,
}

/// A point of a box in 128-bit coordinates: a box of `i64` voxels ends one past
/// `i64::MAX`, and the gap between boxes at opposite ends of `i64` is 2^64.
#[doc(hidden)]
pub type Wide = [i128; 3];

/// `v` widened to [`Wide`].
#[doc(hidden)]
#[inline]
#[must_use]
pub fn wide(v: Voxel) -> Wide {
    v.map(i128::from)
}

/// `v` clamped into `i64`: for coordinates known to lie in a tree's space.
#[doc(hidden)]
#[inline]
#[must_use]
pub fn narrow(v: i128) -> i64 {
    v.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
}

impl IBox {
    /// The cube of side `side` from `min`.
    #[inline]
    #[must_use]
    pub fn cube(min: Voxel, side: i64) -> IBox {
        let lo = wide(min);
        IBox {
            lo,
            hi: lo.map(|c| c + i128::from(side)),
        }
    }

    #[inline]
    pub fn overlaps(&self, o: &IBox) -> bool {
        (0..3).all(|a| self.lo[a] < o.hi[a] && o.lo[a] < self.hi[a])
    }

    #[inline]
    pub fn inside(&self, o: &IBox) -> bool {
        (0..3).all(|a| o.lo[a] <= self.lo[a] && self.hi[a] <= o.hi[a])
    }

    #[inline]
    pub fn intersection(&self, o: &IBox) -> IBox {
        let mut r = *self;
        for a in 0..3 {
            r.lo[a] = r.lo[a].max(o.lo[a]);
            r.hi[a] = r.hi[a].min(o.hi[a]);
        }
        r
    }

    #[inline]
    pub fn volume(&self) -> u64 {
        (0..3)
            .map(|a| u64::try_from((self.hi[a] - self.lo[a]).max(0)).unwrap_or(u64::MAX))
            .fold(1u64, u64::saturating_mul)
    }

    /// The squared Euclidean gap between the two closed boxes, exactly: each axis's
    /// gap is below 2^64, so the sum of three squares needs a little over 128 bits.
    #[inline]
    pub fn gap2(&self, o: &IBox) -> Gap2 {
        let mut d = Gap2::default();
        for a in 0..3 {
            let g = (o.lo[a] - self.hi[a]).max(self.lo[a] - o.hi[a]).max(0) as u128;
            d = d.plus(g * g);
        }
        d
    }

    /// The box's voxels; only for boxes inside a tree's space, which fits `i64`.
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo.map(narrow),
            max: self.hi.map(|c| narrow(c - 1)),
        }
    }
}

/// A squared distance between boxes: `carry · 2^128 + low`, ordered as the number.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Gap2 {
    carry: u8,
    low: u128,
}

impl Gap2 {
    /// The largest value, above every real gap.
    pub const MAX: Gap2 = Gap2 {
        carry: u8::MAX,
        low: u128::MAX,
    };

    #[inline]
    fn plus(self, x: u128) -> Gap2 {
        let (low, over) = self.low.overflowing_add(x);
        Gap2 {
            carry: self.carry + u8::from(over),
            low,
        }
    }

    /// The value, saturated at `u128::MAX` (reached only by gaps beyond 1.8·10^19).
    #[must_use]
    pub fn saturated(self) -> u128 {
        if self.carry > 0 {
            u128::MAX
        } else {
            self.low
        }
    }

    /// The square root of the value, as `f64`.
    #[must_use]
    pub fn sqrt(self) -> f64 {
        (f64::from(self.carry) * 2f64.powi(128) + self.low as f64).sqrt()
    }
}

/// The answer of [`interference`].
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Interference {
    /// Whether the two solids share a voxel.
    pub intersects: bool,
    /// The number of voxels they share.
    pub overlap_voxels: u64,
    /// When asked for: disjoint boxes whose union is exactly the shared voxels, one per
    /// pair of overlapping blocks.
    pub contacts: Vec<Aabb>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Any,
    Volume,
    Contacts,
}

struct Overlap<'t, A: Traversable + ?Sized, B: Traversable + ?Sized> {
    a: Placed<'t, A>,
    b: Placed<'t, B>,
    mode: Mode,
    /// Whether 4³ masks may be compared (no rotation, no contact boxes wanted).
    masks: bool,
    out: Interference,
}

/// Pushes the placed boxes of every black cell under `n`.
fn push_leaves<T: Traversable + ?Sized>(p: Placed<'_, T>, n: T::Node, out: &mut Vec<Aabb>) {
    if p.tree.is_black(&n) {
        out.push(p.world_box(&n).aabb());
        return;
    }
    let mut kids = [n; 8];
    let k = p.tree.node_children(&n, &mut kids);
    for &c in &kids[..k] {
        push_leaves(p, c, out);
    }
}

impl<A: Traversable + ?Sized, B: Traversable + ?Sized> Overlap<'_, A, B> {
    /// All of a node's voxels overlap the other tree's black cell.
    fn covered(&mut self, voxels: u64, leaves: impl FnOnce(&mut Vec<Aabb>)) -> ControlFlow<()> {
        self.out.intersects = true;
        match self.mode {
            Mode::Any => return ControlFlow::Break(()),
            Mode::Volume => self.out.overlap_voxels += voxels,
            Mode::Contacts => {
                self.out.overlap_voxels += voxels;
                leaves(&mut self.out.contacts);
            }
        }
        ControlFlow::Continue(())
    }

    /// Visits a pair of nodes whose placed boxes `ba` and `bb` overlap.
    fn visit(&mut self, na: A::Node, ba: IBox, nb: B::Node, bb: IBox) -> ControlFlow<()> {
        if self.masks {
            if let (Some((ca, ma)), Some((cb, mb))) =
                (self.a.tree.small_mask(&na), self.b.tree.small_mask(&nb))
            {
                // Both nodes fit 4³ cells: compare them as bit masks at once.
                let d = [0, 1, 2]
                    .map(|i| cb[i] + self.b.place.offset[i] - ca[i] - self.a.place.offset[i]);
                if d.iter().any(|c| c.abs() >= 4) {
                    return ControlFlow::Continue(());
                }
                let m = ma & shift_mask(mb, d);
                if m != 0 {
                    self.out.intersects = true;
                    if self.mode == Mode::Any {
                        return ControlFlow::Break(());
                    }
                    self.out.overlap_voxels += u64::from(m.count_ones());
                }
                return ControlFlow::Continue(());
            }
        }
        let fa = self.a.tree.is_black(&na);
        let fb = self.b.tree.is_black(&nb);
        if fa && fb {
            self.out.intersects = true;
            if self.mode == Mode::Any {
                return ControlFlow::Break(());
            }
            let i = ba.intersection(&bb);
            self.out.overlap_voxels += i.volume();
            if self.mode == Mode::Contacts {
                self.out.contacts.push(i.aabb());
            }
            return ControlFlow::Continue(());
        }
        if fa && bb.inside(&ba) {
            let (b, v) = (self.b, self.b.tree.node_voxels(&nb));
            return self.covered(v, |out| push_leaves(b, nb, out));
        }
        if fb && ba.inside(&bb) {
            let (a, v) = (self.a, self.a.tree.node_voxels(&na));
            return self.covered(v, |out| push_leaves(a, na, out));
        }
        // Split the larger node; its children are filtered against the other box
        // seen in its own coordinates, so only the survivors are placed.
        if !fa && (fb || self.a.tree.node_size(&na) >= self.b.tree.node_size(&nb)) {
            let mut kids = [na; 8];
            let q = self.a.place.unplace_box(&bb);
            let n = self.a.tree.children_meeting(&na, &q, &mut kids);
            for &c in &kids[..n] {
                let bc = self.a.world_box(&c);
                self.visit(c, bc, nb, bb)?;
            }
        } else {
            let mut kids = [nb; 8];
            let q = self.b.place.unplace_box(&ba);
            let n = self.b.tree.children_meeting(&nb, &q, &mut kids);
            for &c in &kids[..n] {
                let bc = self.b.world_box(&c);
                self.visit(na, ba, c, bc)?;
            }
        }
        ControlFlow::Continue(())
    }
}

fn run_overlap<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    b: Placed<'_, B>,
    mode: Mode,
) -> Interference {
    let mut o = Overlap {
        a,
        b,
        mode,
        masks: mode != Mode::Contacts
            && a.place.rotation.is_identity()
            && b.place.rotation.is_identity(),
        out: Interference::default(),
    };
    if let (Some(ra), Some(rb)) = (a.tree.root_node(), b.tree.root_node()) {
        let (ba, bb) = (a.world_box(&ra), b.world_box(&rb));
        if ba.overlaps(&bb) {
            let _ = o.visit(ra, ba, rb, bb);
        }
    }
    o.out
}

/// Whether `a` (where it stands) and `b` placed by `place` share a voxel.
///
/// One parallel traversal of both trees that stops at the first overlapping pair of
/// black blocks; the moved tree is never built.
///
/// # Runtime
/// Proportional to the number of pairs of cells whose boxes overlap, at most
/// O(n_a + n_b) pairs per depth for blocky solids; O(1) when the bounding cells are
/// disjoint.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{intersects, Placement};
/// let cube = LinearOctree::from_voxels(2, [0, 0, 0], (0..64).map(|i| [i % 4, i / 4 % 4, i / 16])).unwrap();
/// assert!(intersects(&cube, &cube, Placement::at([3, 3, 3])));
/// assert!(!intersects(&cube, &cube, Placement::at([4, 0, 0])));
/// ```
#[must_use]
pub fn intersects<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: &A,
    b: &B,
    place: Placement,
) -> bool {
    intersects_placed(Placed::fixed(a), Placed::new(b, place))
}

/// [`intersects`] with both trees placed.
#[must_use]
pub fn intersects_placed<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    b: Placed<'_, B>,
) -> bool {
    run_overlap(a, b, Mode::Any).intersects
}

/// Whether `a` and `b` placed by `place` overlap, by how many voxels, and, when
/// `contacts` is true, the boxes where they overlap.
///
/// # Runtime
/// Proportional to the number of pairs of cells whose boxes overlap (one parallel
/// traversal), plus the size of the output.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{interference, Placement};
/// let cube = LinearOctree::from_voxels(2, [0, 0, 0], (0..64).map(|i| [i % 4, i / 4 % 4, i / 16])).unwrap();
/// let hit = interference(&cube, &cube, Placement::at([3, 2, 0]), true);
/// assert_eq!(hit.overlap_voxels, 1 * 2 * 4);
/// assert_eq!(hit.contacts.iter().map(|b| b.voxel_count()).sum::<u64>(), 8);
/// ```
#[must_use]
pub fn interference<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: &A,
    b: &B,
    place: Placement,
    contacts: bool,
) -> Interference {
    interference_placed(Placed::fixed(a), Placed::new(b, place), contacts)
}

/// [`interference`] with both trees placed.
#[must_use]
pub fn interference_placed<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    b: Placed<'_, B>,
    contacts: bool,
) -> Interference {
    let mode = if contacts {
        Mode::Contacts
    } else {
        Mode::Volume
    };
    run_overlap(a, b, mode)
}

/// The clearance between `a` and `b` placed by `place`: the least Euclidean distance
/// between the two solids, each a union of closed unit cubes, in voxels. It is 0
/// when they touch (share a face, edge or corner) or overlap, and `None` when either
/// is empty.
///
/// Branch and bound over the same parallel traversal: a pair of cells is skipped when
/// the gap between their boxes is no less than the best distance found, and children
/// are visited nearest first.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{clearance, Placement};
/// let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
/// // gaps of 3 along x and 2 along y between the closed unit cubes
/// assert_eq!(clearance(&dot, &dot, Placement::at([4, 3, 0])), Some(13f64.sqrt()));
/// assert_eq!(clearance(&dot, &dot, Placement::at([1, 0, 0])), Some(0.0));
/// ```
#[must_use]
pub fn clearance<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: &A,
    b: &B,
    place: Placement,
) -> Option<f64> {
    clearance_gap2(Placed::fixed(a), Placed::new(b, place)).map(Gap2::sqrt)
}

/// The squared clearance of two placed trees, exactly, or `None` when either is empty.
#[must_use]
pub fn clearance_squared<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    b: Placed<'_, B>,
) -> Option<u128> {
    clearance_gap2(a, b).map(Gap2::saturated)
}

/// The squared clearance, exactly, past `u128` (trees at opposite ends of `i64`).
fn clearance_gap2<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    b: Placed<'_, B>,
) -> Option<Gap2> {
    let ra = a.tree.root_node()?;
    let rb = b.tree.root_node()?;
    let mut c = Clearance {
        a,
        b,
        best: Gap2::MAX,
    };
    c.visit(ra, rb);
    Some(c.best)
}

struct Clearance<'t, A: Traversable + ?Sized, B: Traversable + ?Sized> {
    a: Placed<'t, A>,
    b: Placed<'t, B>,
    best: Gap2,
}

impl<A: Traversable + ?Sized, B: Traversable + ?Sized> Clearance<'_, A, B> {
    fn visit(&mut self, na: A::Node, nb: B::Node) {
        let ba = self.a.world_box(&na);
        let bb = self.b.world_box(&nb);
        let d = ba.gap2(&bb);
        if d >= self.best {
            return;
        }
        let fa = self.a.tree.is_black(&na);
        let fb = self.b.tree.is_black(&nb);
        if fa && fb {
            self.best = d;
            return;
        }
        let mut order = [(Gap2::default(), 0usize); 8];
        if !fa && (fb || self.a.tree.node_size(&na) >= self.b.tree.node_size(&nb)) {
            let mut kids = [na; 8];
            let n = self.a.tree.node_children(&na, &mut kids);
            for i in 0..n {
                order[i] = (self.a.world_box(&kids[i]).gap2(&bb), i);
            }
            order[..n].sort_unstable();
            for &(d, i) in &order[..n] {
                if d >= self.best {
                    break;
                }
                self.visit(kids[i], nb);
            }
        } else {
            let mut kids = [nb; 8];
            let n = self.b.tree.node_children(&nb, &mut kids);
            for i in 0..n {
                order[i] = (ba.gap2(&self.b.world_box(&kids[i])), i);
            }
            order[..n].sort_unstable();
            for &(d, i) in &order[..n] {
                if d >= self.best {
                    break;
                }
                self.visit(na, kids[i]);
            }
        }
    }
}

/// [`clearance`] with `b` at a real-valued offset (after its rotation): the least
/// Euclidean distance between the closed unit cubes of the two solids, or `None`
/// when either is empty. Used to measure the clearance along smoothed paths, whose
/// points need not be lattice points.
#[must_use]
pub fn clearance_at(
    a: &LinearOctree,
    b: &LinearOctree,
    rotation: Rotation,
    offset: [f64; 3],
) -> Option<f64> {
    let ra = Node::tight_root(a)?;
    let rb = Node::tight_root(b)?;
    let mut c = ClearanceF {
        a: a.leaves(),
        b: b.leaves(),
        rotation,
        offset,
        best: f64::INFINITY,
    };
    c.visit(ra, rb);
    Some(c.best.sqrt())
}

struct ClearanceF<'t> {
    a: &'t [Leaf],
    b: &'t [Leaf],
    rotation: Rotation,
    offset: [f64; 3],
    best: f64,
}

impl ClearanceF<'_> {
    fn a_box(n: &Node) -> ([f64; 3], [f64; 3]) {
        let lo = n.min.map(|c| c as f64);
        let s = n.side() as f64;
        (lo, [lo[0] + s, lo[1] + s, lo[2] + s])
    }

    fn b_box(&self, n: &Node) -> ([f64; 3], [f64; 3]) {
        let r = self.rotation.apply_cube(n.min, n.side());
        let lo = [0, 1, 2].map(|a| r[a] as f64 + self.offset[a]);
        let s = n.side() as f64;
        (lo, [lo[0] + s, lo[1] + s, lo[2] + s])
    }

    fn gap2(x: &([f64; 3], [f64; 3]), y: &([f64; 3], [f64; 3])) -> f64 {
        (0..3)
            .map(|a| {
                let g = (y.0[a] - x.1[a]).max(x.0[a] - y.1[a]).max(0.0);
                g * g
            })
            .sum()
    }

    fn visit(&mut self, na: Node, nb: Node) {
        let ba = Self::a_box(&na);
        let bb = self.b_box(&nb);
        let d = Self::gap2(&ba, &bb);
        if d >= self.best {
            return;
        }
        let fa = na.is_full(self.a);
        let fb = nb.is_full(self.b);
        if fa && fb {
            self.best = d;
            return;
        }
        let mut kids = [na; 8];
        let mut order = [(0f64, 0usize); 8];
        let split_a = !fa && (fb || na.k >= nb.k);
        let n = if split_a {
            na.children(self.a, &mut kids)
        } else {
            nb.children(self.b, &mut kids)
        };
        for i in 0..n {
            order[i].0 = if split_a {
                Self::gap2(&Self::a_box(&kids[i]), &bb)
            } else {
                Self::gap2(&ba, &self.b_box(&kids[i]))
            };
            order[i].1 = i;
        }
        order[..n].sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        for &(d, i) in &order[..n] {
            if d >= self.best {
                break;
            }
            if split_a {
                self.visit(kids[i], nb);
            } else {
                self.visit(na, kids[i]);
            }
        }
    }
}

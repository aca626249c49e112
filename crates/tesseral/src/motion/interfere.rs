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

    #[inline]
    pub(crate) fn cell(&self, min: Voxel, side: i64) -> IBox {
        let r = self.rotation.apply_cube(min, side);
        let lo = [
            r[0] + self.offset[0],
            r[1] + self.offset[1],
            r[2] + self.offset[2],
        ];
        IBox {
            lo,
            hi: [lo[0] + side, lo[1] + side, lo[2] + side],
        }
    }
}

/// A tree with its placement in the world.
#[derive(Debug, Clone, Copy)]
pub struct Placed<'t> {
    /// The tree, in its own coordinates.
    pub tree: &'t LinearOctree,
    /// Where it is put.
    pub place: Placement,
}

impl<'t> Placed<'t> {
    /// `tree` where it stands (identity placement).
    #[must_use]
    pub fn fixed(tree: &'t LinearOctree) -> Self {
        Placed {
            tree,
            place: Placement::default(),
        }
    }

    /// `tree` placed by `place`.
    #[must_use]
    pub fn new(tree: &'t LinearOctree, place: Placement) -> Self {
        Placed { tree, place }
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
pub(crate) struct IBox {
    pub lo: Voxel,
    pub hi: Voxel,
}

impl IBox {
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
            .map(|a| (self.hi[a] - self.lo[a]).max(0) as u64)
            .product()
    }

    /// The squared Euclidean gap between the two closed boxes.
    #[inline]
    pub fn gap2(&self, o: &IBox) -> u128 {
        let mut d = 0u128;
        for a in 0..3 {
            let g = (o.lo[a] - self.hi[a]).max(self.lo[a] - o.hi[a]).max(0);
            d += (g as u128) * (g as u128);
        }
        d
    }

    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo,
            max: [self.hi[0] - 1, self.hi[1] - 1, self.hi[2] - 1],
        }
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

struct Overlap<'t> {
    a: &'t [Leaf],
    b: &'t [Leaf],
    pa: Placement,
    pb: Placement,
    mode: Mode,
    out: Interference,
}

impl Overlap<'_> {
    /// Every leaf of the `leaves` run of `n`, placed, lies inside the black box of the
    /// other tree: all of them overlap.
    fn covered(&mut self, leaves: &[Leaf], place: Placement, n: Node) -> ControlFlow<()> {
        self.out.intersects = true;
        match self.mode {
            Mode::Any => return ControlFlow::Break(()),
            Mode::Volume => self.out.overlap_voxels += n.voxel_count(leaves),
            Mode::Contacts => {
                self.out.overlap_voxels += n.voxel_count(leaves);
                // The run's leaves, placed: walk them as blocks relative to the cell.
                for l in &leaves[n.lo..n.hi] {
                    let rel = crate::code::decode(l.code() - n.code);
                    let min = [
                        n.min[0] + i64::from(rel[0]),
                        n.min[1] + i64::from(rel[1]),
                        n.min[2] + i64::from(rel[2]),
                    ];
                    let b = place.cell(min, 1 << l.size_log2());
                    self.out.contacts.push(b.aabb());
                }
            }
        }
        ControlFlow::Continue(())
    }

    fn visit(&mut self, na: Node, nb: Node) -> ControlFlow<()> {
        let ba = self.pa.cell(na.min, na.side());
        let bb = self.pb.cell(nb.min, nb.side());
        if !ba.overlaps(&bb) {
            return ControlFlow::Continue(());
        }
        let fa = na.is_full(self.a);
        let fb = nb.is_full(self.b);
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
            return self.covered(self.b, self.pb, nb);
        }
        if fb && ba.inside(&bb) {
            return self.covered(self.a, self.pa, na);
        }
        let mut kids = [na; 8];
        if !fa && (fb || na.k >= nb.k) {
            let n = na.children(self.a, &mut kids);
            for &c in &kids[..n] {
                self.visit(c, nb)?;
            }
        } else {
            let n = nb.children(self.b, &mut kids);
            for &c in &kids[..n] {
                self.visit(na, c)?;
            }
        }
        ControlFlow::Continue(())
    }
}

fn run_overlap(a: Placed<'_>, b: Placed<'_>, mode: Mode) -> Interference {
    let mut o = Overlap {
        a: a.tree.leaves(),
        b: b.tree.leaves(),
        pa: a.place,
        pb: b.place,
        mode,
        out: Interference::default(),
    };
    if let (Some(ra), Some(rb)) = (Node::tight_root(a.tree), Node::tight_root(b.tree)) {
        let _ = o.visit(ra, rb);
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
pub fn intersects(a: &LinearOctree, b: &LinearOctree, place: Placement) -> bool {
    intersects_placed(Placed::fixed(a), Placed::new(b, place))
}

/// [`intersects`] with both trees placed.
#[must_use]
pub fn intersects_placed(a: Placed<'_>, b: Placed<'_>) -> bool {
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
pub fn interference(
    a: &LinearOctree,
    b: &LinearOctree,
    place: Placement,
    contacts: bool,
) -> Interference {
    interference_placed(Placed::fixed(a), Placed::new(b, place), contacts)
}

/// [`interference`] with both trees placed.
#[must_use]
pub fn interference_placed(a: Placed<'_>, b: Placed<'_>, contacts: bool) -> Interference {
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
pub fn clearance(a: &LinearOctree, b: &LinearOctree, place: Placement) -> Option<f64> {
    clearance_squared(Placed::fixed(a), Placed::new(b, place)).map(|d| (d as f64).sqrt())
}

/// The squared clearance of two placed trees, exactly, or `None` when either is empty.
#[must_use]
pub fn clearance_squared(a: Placed<'_>, b: Placed<'_>) -> Option<u128> {
    let ra = Node::tight_root(a.tree)?;
    let rb = Node::tight_root(b.tree)?;
    let mut c = Clearance {
        a: a.tree.leaves(),
        b: b.tree.leaves(),
        pa: a.place,
        pb: b.place,
        best: u128::MAX,
    };
    c.visit(ra, rb);
    Some(c.best)
}

struct Clearance<'t> {
    a: &'t [Leaf],
    b: &'t [Leaf],
    pa: Placement,
    pb: Placement,
    best: u128,
}

impl Clearance<'_> {
    fn visit(&mut self, na: Node, nb: Node) {
        let ba = self.pa.cell(na.min, na.side());
        let bb = self.pb.cell(nb.min, nb.side());
        let d = ba.gap2(&bb);
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
        let mut order = [(0u128, 0usize); 8];
        if !fa && (fb || na.k >= nb.k) {
            let n = na.children(self.a, &mut kids);
            for i in 0..n {
                order[i] = (self.pa.cell(kids[i].min, kids[i].side()).gap2(&bb), i);
            }
            order[..n].sort_unstable();
            for &(d, i) in &order[..n] {
                if d >= self.best {
                    break;
                }
                self.visit(kids[i], nb);
            }
        } else {
            let n = nb.children(self.b, &mut kids);
            for i in 0..n {
                order[i] = (ba.gap2(&self.pb.cell(kids[i].min, kids[i].side())), i);
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

//! Clearance: the least distance between two placed trees, by branch and bound, at
//! a lattice offset or a real-valued one.

use super::{Gap2, Placed, Placement};
use crate::linear::{Leaf, LinearOctree};
use crate::motion::orient::Rotation;
use crate::motion::traverse::Node;
use crate::motion::view::Traversable;

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

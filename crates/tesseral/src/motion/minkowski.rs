//! Configuration-space obstacles (Ahuja & Nash §5, after Lozano-Pérez & Wesley): the
//! object placed at offset `p` hits the environment exactly when `p` lies in
//! `env ⊕ (−object)`. [`minkowski_sum`] computes it on octrees: a cell of the result is
//! classified by a parallel traversal of the two trees (a pair of blocks sums to a
//! box), and the top-down builder splits only the cells on the obstacles' boundary.
//! Also the cube maps of whole trees (`rotated`, `reflected`).

use std::ops::ControlFlow;

use super::interfere::IBox;
use super::orient::Rotation;
use super::traverse::Node;
use crate::code;
use crate::linear::{CellClass, Classifier, Leaf, LinearOctree, OctreeError};
use crate::Voxel;

/// Maps every block of `tree` by the cube map of `rotation` (which may be the point
/// reflection) and then shifts it by `shift`. The result is a tree of the same
/// depth with as many leaves.
pub(crate) fn map_tree(tree: &LinearOctree, rotation: Rotation, shift: Voxel) -> LinearOctree {
    let side = tree.side() as i64;
    let o = rotation.apply_cube(tree.origin(), side);
    let origin = [o[0] + shift[0], o[1] + shift[1], o[2] + shift[2]];
    let mut leaves: Vec<Leaf> = tree
        .blocks()
        .map(|b| {
            let m = rotation.apply_cube(b.min, b.size());
            let rel = [0, 1, 2].map(|a| (m[a] + shift[a] - origin[a]) as u32);
            Leaf::new(code::encode(rel[0], rel[1], rel[2]), b.size_log2)
        })
        .collect();
    leaves.sort_unstable();
    LinearOctree::from_sorted_leaves(tree.depth(), origin, leaves)
        .expect("same depth as a valid tree")
}

/// The solid rotated: voxel `v` goes to `rotation.apply_voxel(v)`.
///
/// # Runtime
/// O(n log n) for n leaves.
#[must_use]
pub fn rotated(tree: &LinearOctree, rotation: Rotation) -> LinearOctree {
    map_tree(tree, rotation, [0; 3])
}

/// The point reflection of a set of lattice points: `v` goes to `−v`.
#[must_use]
pub fn reflected(tree: &LinearOctree) -> LinearOctree {
    map_tree(tree, Rotation::REFLECTION, [1, 1, 1])
}

/// Classifies cells of `a ⊕ b` by a parallel traversal of both trees.
struct MinkowskiClassifier<'t> {
    a: &'t LinearOctree,
    b: &'t LinearOctree,
    ra: Option<Node>,
    rb: Option<Node>,
}

struct MinkowskiQuery<'t> {
    a: &'t [Leaf],
    b: &'t [Leaf],
    p: IBox,
    partial: bool,
}

impl MinkowskiQuery<'_> {
    fn visit(&mut self, na: Node, nb: Node) -> ControlFlow<()> {
        // Points a + b with a in [a.lo, a.hi) and b in [b.lo, b.hi): [a.lo + b.lo, a.hi + b.hi - 1).
        let s = IBox {
            lo: [0, 1, 2].map(|i| i128::from(na.min[i]) + i128::from(nb.min[i])),
            hi: [0, 1, 2].map(|i| {
                i128::from(na.min[i])
                    + i128::from(nb.min[i])
                    + i128::from(na.side())
                    + i128::from(nb.side())
                    - 1
            }),
        };
        if !s.overlaps(&self.p) {
            return ControlFlow::Continue(());
        }
        // Once the cell is known to be partly covered, only a pair whose sum covers
        // the whole cell can change the answer, and no descendant of a pair that
        // does not cover it covers it.
        let covers = self.p.inside(&s);
        if self.partial && !covers {
            return ControlFlow::Continue(());
        }
        let fa = na.is_full(self.a);
        let fb = nb.is_full(self.b);
        if fa && fb {
            if covers {
                return ControlFlow::Break(());
            }
            self.partial = true;
            return ControlFlow::Continue(());
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

impl Classifier for MinkowskiClassifier<'_> {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        let (Some(ra), Some(rb)) = (self.ra, self.rb) else {
            return CellClass::Outside;
        };
        let side = 1i64 << size_log2;
        let mut q = MinkowskiQuery {
            a: self.a.leaves(),
            b: self.b.leaves(),
            p: IBox::cube(min, side),
            partial: false,
        };
        match q.visit(ra, rb) {
            ControlFlow::Break(()) => CellClass::Inside,
            ControlFlow::Continue(()) if q.partial => CellClass::Partial,
            ControlFlow::Continue(()) => CellClass::Outside,
        }
    }
}

/// The Minkowski sum `a ⊕ b = {x + y : x ∈ a, y ∈ b}` of two sets of lattice points
/// (voxel indices), as an octree whose space spans both: origin `a.origin +
/// b.origin`, depth one more than the deeper tree.
///
/// Built top down: a cell is outside when no pair of blocks sums to a box meeting
/// it, inside when one pair's box covers it, and split otherwise.
///
/// # Runtime
/// Proportional to the number of cells on the boundary of the sum, times the pairs
/// of cells of `a` and `b` whose sum meets each.
///
/// # Errors
/// [`OctreeError::DepthTooLarge`] when the sum would be deeper than [`MAX_DEPTH`](crate::linear::MAX_DEPTH).
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::minkowski_sum;
/// let bar = LinearOctree::from_voxels(2, [0, 0, 0], (0..4).map(|x| [x, 0, 0])).unwrap();
/// let post = LinearOctree::from_voxels(2, [0, 0, 0], (0..3).map(|z| [0, 0, z])).unwrap();
/// let plate = minkowski_sum(&bar, &post).unwrap();
/// assert_eq!(plate.voxel_count(), 4 * 3);
/// assert!(plate.contains([3, 0, 2]) && !plate.contains([0, 1, 0]));
/// ```
pub fn minkowski_sum(a: &LinearOctree, b: &LinearOctree) -> Result<LinearOctree, OctreeError> {
    let depth = a.depth().max(b.depth()) + 1;
    let origin = [0, 1, 2].map(|i| a.origin()[i] + b.origin()[i]);
    minkowski_in(a, b, depth, origin)
}

pub(crate) fn minkowski_in(
    a: &LinearOctree,
    b: &LinearOctree,
    depth: u8,
    origin: Voxel,
) -> Result<LinearOctree, OctreeError> {
    let c = MinkowskiClassifier {
        a,
        b,
        ra: Node::tight_root(a),
        rb: Node::tight_root(b),
    };
    LinearOctree::from_classifier(depth, origin, &c)
}

/// The configuration-space obstacles of `object` (turned by `rotation`) among
/// `environment`: the offsets `p` at which the placed object shares a voxel with the
/// environment, `environment ⊕ −rotation(object)`.
///
/// # Errors
/// [`OctreeError::DepthTooLarge`] when the result would be deeper than [`MAX_DEPTH`](crate::linear::MAX_DEPTH).
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{config_obstacles, intersects, Placement, Rotation};
/// let env = LinearOctree::from_voxels(3, [0, 0, 0], [[4, 4, 4], [5, 4, 4]]).unwrap();
/// let obj = LinearOctree::from_voxels(1, [0, 0, 0], [[0, 0, 0], [1, 0, 0]]).unwrap();
/// let c = config_obstacles(&env, &obj, Rotation::IDENTITY).unwrap();
/// assert_eq!(c.voxel_count(), 3); // offsets x = 3, 4, 5 at (y, z) = (4, 4)
/// assert_eq!(c.contains([3, 4, 4]), intersects(&env, &obj, Placement::at([3, 4, 4])));
/// ```
pub fn config_obstacles(
    environment: &LinearOctree,
    object: &LinearOctree,
    rotation: Rotation,
) -> Result<LinearOctree, OctreeError> {
    let neg = map_tree(object, Rotation::REFLECTION.compose(rotation), [1, 1, 1]);
    minkowski_sum(environment, &neg)
}

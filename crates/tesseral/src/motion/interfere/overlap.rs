//! Interference: whether, and how much, two placed trees overlap.

use std::ops::ControlFlow;

use serde::Serialize;

use super::{Aabb, IBox, Placed, Placement};
use crate::motion::view::{shift_mask, Traversable};

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

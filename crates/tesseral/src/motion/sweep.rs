//! Continuous (swept) collision for linear motion: the exact first time at which two
//! solids begin to overlap while one moves along a straight line relative to the
//! other. Sampling poses (as FCL does) lets a fast object tunnel through a thin wall;
//! here the time is computed, as a fraction, from the blocks' slabs.

use std::cmp::Ordering;
use std::fmt;

use serde::Serialize;

use super::interfere::{Aabb, IBox, Placed};
use super::view::Traversable;
use crate::Voxel;

/// An exact non-negative rational number `num / den`, in lowest terms, `den > 0`.
///
/// ```
/// use tesseral::motion::Fraction;
/// let t = Fraction::new(6, 8);
/// assert_eq!((t.num(), t.den()), (3, 4));
/// assert!(Fraction::new(1, 3) < Fraction::new(1, 2));
/// assert_eq!(t.to_f64(), 0.75);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Fraction {
    num: i64,
    den: i64,
}

impl Fraction {
    /// Zero.
    pub const ZERO: Fraction = Fraction { num: 0, den: 1 };
    /// One.
    pub const ONE: Fraction = Fraction { num: 1, den: 1 };

    /// `num / den` reduced to lowest terms.
    ///
    /// # Panics
    /// When `den == 0`.
    #[must_use]
    pub fn new(num: i64, den: i64) -> Fraction {
        assert!(den != 0, "zero denominator");
        let (mut n, mut d) = if den < 0 { (-num, -den) } else { (num, den) };
        let g = gcd(n.unsigned_abs(), d.unsigned_abs()).max(1) as i64;
        n /= g;
        d /= g;
        Fraction { num: n, den: d }
    }

    /// The numerator.
    #[must_use]
    pub fn num(self) -> i64 {
        self.num
    }

    /// The denominator (positive).
    #[must_use]
    pub fn den(self) -> i64 {
        self.den
    }

    /// The nearest `f64`.
    #[must_use]
    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Ord for Fraction {
    fn cmp(&self, o: &Self) -> Ordering {
        (i128::from(self.num) * i128::from(o.den)).cmp(&(i128::from(o.num) * i128::from(self.den)))
    }
}

impl PartialOrd for Fraction {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl fmt::Display for Fraction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// The first contact found by [`first_contact`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SweptContact {
    /// The fraction of the move, in `[0, 1)`, at which the solids begin to overlap
    /// (they touch at that instant and overlap just after). 0 when they overlap at
    /// the start.
    pub time: Fraction,
    /// A block of the first solid that is hit, in world coordinates.
    pub a_block: Aabb,
    /// The block of the second solid that hits it, where it stands at the start.
    pub b_block: Aabb,
}

/// The open interval of times `(lo, hi)` during which box `b`, moving by `v` per unit
/// time, overlaps the interior of box `a`; `None` bounds are infinite. Returns `None`
/// when they never overlap.
#[allow(clippy::type_complexity)]
fn slab_interval(a: &IBox, b: &IBox, v: Voxel) -> Option<(Option<Fraction>, Option<Fraction>)> {
    let mut lo: Option<Fraction> = None;
    let mut hi: Option<Fraction> = None;
    for (ax, &s) in v.iter().enumerate() {
        // Overlap on this axis: b.lo + t v < a.hi and a.lo < b.hi + t v.
        // Clamped to ±i64::MAX: |p| beyond it exceeds |s|, a time past the motion's end.
        let fit = |x: i128| x.clamp(-i128::from(i64::MAX), i128::from(i64::MAX)) as i64;
        let (p, q) = (fit(a.hi[ax] - b.lo[ax]), fit(a.lo[ax] - b.hi[ax])); // t v < p, t v > q
        let (l, h) = match s.cmp(&0) {
            Ordering::Equal => {
                if q < 0 && 0 < p {
                    continue;
                }
                return None;
            }
            Ordering::Greater => (Fraction::new(q, s), Fraction::new(p, s)),
            Ordering::Less => (Fraction::new(p, s), Fraction::new(q, s)),
        };
        lo = Some(lo.map_or(l, |x| x.max(l)));
        hi = Some(hi.map_or(h, |x| x.min(h)));
    }
    Some((lo, hi))
}

/// The first time in `[0, 1)` at which the boxes overlap, if any.
fn first_time(a: &IBox, b: &IBox, v: Voxel) -> Option<Fraction> {
    let (lo, hi) = slab_interval(a, b, v)?;
    let start = lo.map_or(Fraction::ZERO, |l| l.max(Fraction::ZERO));
    let end = hi.map_or(Fraction::ONE, |h| h.min(Fraction::ONE));
    // Overlap holds on the open interval (lo, hi); it meets [0, 1) past `start`
    // exactly when start < end (and start < 1).
    (start < end && start < Fraction::ONE && hi.is_none_or(|h| h > start)).then_some(start)
}

/// The exact first time at which `a` and `b` overlap while each moves in a straight
/// line from its placement at time 0 to the same placement shifted by its
/// displacement at time 1 (`a_move`, `b_move`, in voxels). Rotations stay fixed.
/// Returns `None` when they never overlap during `[0, 1)`.
///
/// Overlap means sharing interior, as in [`super::intersects`]: solids sliding along
/// each other's faces do not collide. Branch and bound over one parallel traversal:
/// a pair of cells is skipped when their boxes cannot meet before the best time found.
///
/// # Runtime
/// Proportional to the pairs of cells whose swept boxes overlap, as
/// [`super::interference`] is to pairs of overlapping cells.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{first_contact, Fraction, Placed};
/// // A one-voxel wall at x = 10 and a 2x2x2 cube flying from x = 0 to x = 20 in one step:
/// let wall = LinearOctree::from_voxels(5, [0, 0, 0], (0..4).flat_map(|y| (0..4).map(move |z| [10, y, z]))).unwrap();
/// let cube = LinearOctree::from_voxels(1, [0, 0, 0], (0..8).map(|i| [i & 1, i >> 1 & 1, i >> 2])).unwrap();
/// let hit = first_contact(Placed::fixed(&wall), [0; 3], Placed::fixed(&cube), [20, 0, 0]).unwrap();
/// assert_eq!(hit.time, Fraction::new(8, 20)); // its front face x = 2 reaches x = 10
/// ```
#[must_use]
pub fn first_contact<A: Traversable + ?Sized, B: Traversable + ?Sized>(
    a: Placed<'_, A>,
    a_move: Voxel,
    b: Placed<'_, B>,
    b_move: Voxel,
) -> Option<SweptContact> {
    let ra = a.tree.root_node()?;
    let rb = b.tree.root_node()?;
    let mut s = Sweep {
        a,
        b,
        v: [
            b_move[0] - a_move[0],
            b_move[1] - a_move[1],
            b_move[2] - a_move[2],
        ],
        best: None,
    };
    s.visit(ra, rb);
    s.best
}

struct Sweep<'t, A: Traversable + ?Sized, B: Traversable + ?Sized> {
    a: Placed<'t, A>,
    b: Placed<'t, B>,
    v: Voxel,
    best: Option<SweptContact>,
}

impl<A: Traversable + ?Sized, B: Traversable + ?Sized> Sweep<'_, A, B> {
    fn improves(&self, t: Fraction) -> bool {
        self.best.is_none_or(|b| t < b.time)
    }

    fn visit(&mut self, na: A::Node, nb: B::Node) {
        let ba = self.a.world_box(&na);
        let bb = self.b.world_box(&nb);
        let Some(t) = first_time(&ba, &bb, self.v) else {
            return;
        };
        if !self.improves(t) {
            return;
        }
        let fa = self.a.tree.is_black(&na);
        let fb = self.b.tree.is_black(&nb);
        if fa && fb {
            self.best = Some(SweptContact {
                time: t,
                a_block: ba.aabb(),
                b_block: bb.aabb(),
            });
            return;
        }
        let mut order: [(Fraction, usize); 8] = [(Fraction::ZERO, 0); 8];
        let mut m = 0;
        let split_a = !fa && (fb || self.a.tree.node_size(&na) >= self.b.tree.node_size(&nb));
        if split_a {
            let mut kids = [na; 8];
            let n = self.a.tree.node_children(&na, &mut kids);
            for (i, kid) in kids[..n].iter().enumerate() {
                if let Some(t) = first_time(&self.a.world_box(kid), &bb, self.v) {
                    order[m] = (t, i);
                    m += 1;
                }
            }
            order[..m].sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.cmp(&y.1)));
            for &(t, i) in &order[..m] {
                if !self.improves(t) {
                    break;
                }
                self.visit(kids[i], nb);
            }
        } else {
            let mut kids = [nb; 8];
            let n = self.b.tree.node_children(&nb, &mut kids);
            for (i, kid) in kids[..n].iter().enumerate() {
                if let Some(t) = first_time(&ba, &self.b.world_box(kid), self.v) {
                    order[m] = (t, i);
                    m += 1;
                }
            }
            order[..m].sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.cmp(&y.1)));
            for &(t, i) in &order[..m] {
                if !self.improves(t) {
                    break;
                }
                self.visit(na, kids[i]);
            }
        }
    }
}

/// The first contact time of two voxel sets by brute force over every pair of voxels
/// (for tests: obviously right, quadratic).
#[cfg(test)]
pub(crate) fn first_contact_brute(a: &[Voxel], b: &[Voxel], v: Voxel) -> Option<Fraction> {
    let unit = |p: Voxel| IBox::cube(p, 1);
    a.iter()
        .flat_map(|&p| {
            b.iter()
                .filter_map(move |&q| first_time(&unit(p), &unit(q), v))
        })
        .min()
}

//! The set operations on the bricked form: one merge of the two sorted entry
//! lists, as the leaf-list kernels of `merge.rs` do, with the bottom three levels
//! combined word by word.
//!
//! Overlapping entries are equal bricks, or nested with the outer one a leaf of side
//! 8 or more (a brick contains nothing smaller: entries start on multiples of 512).
//! Each step of a kernel:
//! - **two bricks** at one code combine their masks (`|`, `&`, `& !`, `^`); a mask
//!   that comes out empty is dropped, one that comes out full (union, symmetric
//!   difference) becomes a leaf of side 8 and may complete its parent;
//! - **a run** of entries of one operand that ends before the other's current entry
//!   (or lies inside one leaf of it) is found by galloping and copied or skipped,
//!   with its masks, as two slices;
//! - **a leaf holding entries of the other operand** is kept, dropped, or cut around
//!   them (the gaps greedily as maximal blocks, all of side 8 or more), a brick
//!   inside it leaving its complement.
//!
//! The results are canonical for the reasons the leaf kernels' are, each checked
//! against a `HashSet` model in `tests.rs`.

use super::super::merge::{emit_gap, ending_by, inside, push_m, span2};
use super::super::{push_merging, Leaf, SetOp};
use super::{bricks_in, is_brick, Bricked, Mask, BRICK_CODES, FULL};

/// The code span `[start, end)` of an entry.
#[inline(always)]
fn span(item: Leaf) -> (u64, u64) {
    if is_brick(item) {
        let s = item.packed() >> 1;
        (s, s + BRICK_CODES)
    } else {
        span2(item)
    }
}

#[inline(always)]
fn combine(a: &Mask, b: &Mask, f: impl Fn(u64, u64) -> u64) -> Mask {
    std::array::from_fn(|w| f(a[w], b[w]))
}

/// One operand being read: its entries and masks, and how far each is read.
struct Cursor<'a> {
    items: &'a [Leaf],
    masks: &'a [Mask],
    i: usize,
    m: usize,
}

impl<'a> Cursor<'a> {
    fn new(t: &'a Bricked) -> Self {
        Self {
            items: &t.items,
            masks: &t.masks,
            i: 0,
            m: 0,
        }
    }

    #[inline(always)]
    fn live(&self) -> bool {
        self.i < self.items.len()
    }

    #[inline(always)]
    fn item(&self) -> Leaf {
        self.items[self.i]
    }

    /// Takes the next `n` entries, returning them and their masks.
    #[inline(always)]
    fn take(&mut self, n: usize) -> (&'a [Leaf], &'a [Mask]) {
        let items = &self.items[self.i..self.i + n];
        let c = bricks_in(items);
        let masks = &self.masks[self.m..self.m + c];
        self.i += n;
        self.m += c;
        (items, masks)
    }

    /// Takes the current entry, a brick.
    #[inline(always)]
    fn take_brick(&mut self) -> &'a Mask {
        let m = &self.masks[self.m];
        self.i += 1;
        self.m += 1;
        m
    }

    /// Takes the current entry, a leaf.
    #[inline(always)]
    fn take_leaf(&mut self) -> Leaf {
        self.i += 1;
        self.items[self.i - 1]
    }

    /// The number of entries from the current one that end by code `at` (a
    /// multiple of 512).
    #[inline(always)]
    fn ending_by(&self, at: u64) -> usize {
        ending_by(&self.items[self.i..], at)
    }

    /// The number of entries from the current one inside the leaf ending at `end`.
    #[inline(always)]
    fn inside(&self, end: u64) -> usize {
        inside(&self.items[self.i..], end)
    }

    /// Everything not yet read.
    fn rest(&mut self) -> (&'a [Leaf], &'a [Mask]) {
        self.take(self.items.len() - self.i)
    }
}

impl Bricked {
    #[inline(always)]
    fn push_brick(&mut self, code_item: Leaf, m: Mask) {
        self.items.push(code_item);
        self.masks.push(m);
    }

    /// Pushes the combined mask of the brick at `item`: dropped when empty, a leaf
    /// of side 8 (merged with its siblings) when full.
    #[inline(always)]
    fn push_combined(&mut self, item: Leaf, m: Mask) {
        if m == FULL {
            push_merging(&mut self.items, Leaf::new(item.packed() >> 1, 3));
        } else if m != [0; 8] {
            self.push_brick(item, m);
        }
    }

    /// Appends entries of one canonical operand, merging at their front only (as
    /// `merge::push_run`: a run never completes a parent by itself).
    #[inline]
    fn push_run(&mut self, (items, masks): (&[Leaf], &[Mask])) {
        let mut foreign_end = self.items.len();
        let mut k = 0;
        while k < items.len() && self.items.len() - foreign_end < 7 {
            let before = self.items.len();
            push_m(&mut self.items, items[k]);
            if self.items.len() <= before {
                foreign_end = self.items.len();
            }
            k += 1;
        }
        self.items.extend_from_slice(&items[k..]);
        self.masks.extend_from_slice(masks);
    }

    /// Appends entries with no merging (intersection, difference).
    #[inline]
    fn push_plain(&mut self, (items, masks): (&[Leaf], &[Mask])) {
        self.items.extend_from_slice(items);
        self.masks.extend_from_slice(masks);
    }

    /// Appends the leaf `[start, end)` cut around `holes` (entries inside it): each
    /// gap as maximal blocks, each brick hole leaving its complement.
    fn push_cut(&mut self, (start, end): (u64, u64), (holes, masks): (&[Leaf], &[Mask]), merge: bool) {
        let mut pos = start;
        let mut masks = masks.iter();
        for &h in holes {
            let (s, e) = span(h);
            emit_gap(&mut self.items, pos, s, merge);
            if is_brick(h) {
                let m = masks.next().expect("one mask per brick");
                self.push_brick(h, m.map(|w| !w));
            }
            pos = e;
        }
        emit_gap(&mut self.items, pos, end, merge);
    }
}

/// The set operation `op` of two bricked forms of one space.
pub(crate) fn set_op(a: &Bricked, b: &Bricked, op: SetOp) -> Bricked {
    // Union and intersection keep at most every input entry and mask; a difference
    // may cut more and grows. The unused tail is given back.
    let mut out = Bricked {
        items: Vec::with_capacity(a.items.len() + b.items.len() + 8),
        masks: Vec::with_capacity(a.masks.len() + b.masks.len()),
    };
    let (x, y) = (Cursor::new(a), Cursor::new(b));
    match op {
        SetOp::Union => union(x, y, &mut out),
        SetOp::Intersection => intersection(x, y, &mut out),
        SetOp::Difference => difference(x, y, &mut out),
        SetOp::SymmetricDifference => symmetric_difference(x, y, &mut out),
    }
    out.items.shrink_to_fit();
    out.masks.shrink_to_fit();
    out
}

/// Whether entry `x` is a leaf holding entry `y` (an overlapping pair is nested).
#[inline(always)]
fn holds(x: Leaf, (xs, xe): (u64, u64), (ys, ye): (u64, u64)) -> bool {
    !is_brick(x) && xs <= ys && ye <= xe
}

fn union(mut a: Cursor<'_>, mut b: Cursor<'_>, out: &mut Bricked) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            let m = combine(a.take_brick(), b.take_brick(), |p, q| p | q);
            out.push_combined(x, m);
            continue;
        }
        let (sx, sy) = (span(x), span(y));
        if sx.1 <= sy.0 {
            let run = a.take(a.ending_by(sy.0));
            out.push_run(run);
        } else if sy.1 <= sx.0 {
            let run = b.take(b.ending_by(sx.0));
            out.push_run(run);
        } else if holds(x, sx, sy) {
            push_m(&mut out.items, a.take_leaf());
            b.take(b.inside(sx.1));
        } else {
            push_m(&mut out.items, b.take_leaf());
            a.take(a.inside(sy.1));
        }
    }
    out.push_run(a.rest());
    out.push_run(b.rest());
}

fn intersection(mut a: Cursor<'_>, mut b: Cursor<'_>, out: &mut Bricked) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            // Never full: both masks are mixed.
            let m = combine(a.take_brick(), b.take_brick(), |p, q| p & q);
            if m != [0; 8] {
                out.push_brick(x, m);
            }
            continue;
        }
        let (sx, sy) = (span(x), span(y));
        if sx.1 <= sy.0 {
            a.take(a.ending_by(sy.0));
        } else if sy.1 <= sx.0 {
            b.take(b.ending_by(sx.0));
        } else if holds(x, sx, sy) {
            a.take_leaf();
            let inner = b.take(b.inside(sx.1));
            out.push_plain(inner);
        } else {
            b.take_leaf();
            let inner = a.take(a.inside(sy.1));
            out.push_plain(inner);
        }
    }
}

fn difference(mut a: Cursor<'_>, mut b: Cursor<'_>, out: &mut Bricked) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            // Never full: the first mask is mixed.
            let m = combine(a.take_brick(), b.take_brick(), |p, q| p & !q);
            if m != [0; 8] {
                out.push_brick(x, m);
            }
            continue;
        }
        let (sx, sy) = (span(x), span(y));
        if sx.1 <= sy.0 {
            let run = a.take(a.ending_by(sy.0));
            out.push_plain(run);
        } else if sy.1 <= sx.0 {
            b.take(b.ending_by(sx.0));
        } else if holds(x, sx, sy) {
            // A full parent of the result lies in one leaf of `a`, in one gap: no
            // merging needed.
            a.take_leaf();
            let holes = b.take(b.inside(sx.1));
            out.push_cut(sx, holes, false);
        } else {
            b.take_leaf();
            a.take(a.inside(sy.1));
        }
    }
    out.push_plain(a.rest());
}

fn symmetric_difference(mut a: Cursor<'_>, mut b: Cursor<'_>, out: &mut Bricked) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            let m = combine(a.take_brick(), b.take_brick(), |p, q| p ^ q);
            out.push_combined(x, m);
            continue;
        }
        let (sx, sy) = (span(x), span(y));
        if sx.1 <= sy.0 {
            let run = a.take(a.ending_by(sy.0));
            out.push_run(run);
        } else if sy.1 <= sx.0 {
            let run = b.take(b.ending_by(sx.0));
            out.push_run(run);
        } else if holds(x, sx, sy) {
            a.take_leaf();
            let holes = b.take(b.inside(sx.1));
            out.push_cut(sx, holes, true);
        } else {
            b.take_leaf();
            let holes = a.take(a.inside(sy.1));
            out.push_cut(sy, holes, true);
        }
    }
    out.push_run(a.rest());
    out.push_run(b.rest());
}

//! The set operations on one level of the bricked form: one merge of the two sorted
//! entry lists, as the leaf-list kernels of `merge.rs` do, generic over the payload
//! of a mixed cell (a brick's mask, or a chunk's own entries).
//!
//! Overlapping entries are equal mixed cells, or nested with the outer one a leaf
//! (a mixed cell contains no entry of its level: entries start on multiples of the
//! cell's codes). Each step of a kernel:
//! - **two mixed cells** at one code combine their payloads ([`Payload::combine`]:
//!   masks word by word, chunks by these kernels one level down); a result that
//!   comes out empty is dropped, one that comes out full (union, symmetric
//!   difference) becomes a leaf of the cell's side and may complete its parent;
//! - **a run** of entries of one operand that ends before the other's current entry
//!   (or lies inside one leaf of it) is found by galloping and copied or skipped,
//!   with its payloads, as two slices (a chunk is shared, not copied);
//! - **a leaf holding entries of the other operand** is kept, dropped, or cut around
//!   them (the gaps greedily as maximal blocks, all of the cell's side or more), a
//!   mixed cell inside it leaving its complement.
//!
//! The results are canonical for the reasons the leaf kernels' are, each checked
//! against a `HashSet` model in `tests.rs`.

use super::super::merge::{emit_gap, ending_by, inside, push_m, span2};
use super::super::{push_merging, Leaf, SetOp};
use super::{bricks_in, is_brick, Level};

/// What combining two mixed cells gives.
pub(crate) enum Combined<P> {
    /// No voxel.
    Empty,
    /// Every voxel of the cell.
    Full,
    /// Some: the payload.
    Mixed(P),
}

/// The contents of a mixed cell of side `2^LOG2`.
pub(crate) trait Payload: Clone {
    /// The cell's side, log2.
    const LOG2: u8;
    /// The cell's codes, `8^LOG2`.
    const CODES: u64 = 1 << (3 * Self::LOG2 as u32);
    /// `op` of two payloads of the cell at `code`.
    fn combine(op: SetOp, code: u64, a: &Self, b: &Self) -> Combined<Self>;
    /// The complement within the cell at `code` (mixed, as the payload is).
    fn complement(&self, code: u64) -> Self;
}

/// The code span `[start, end)` of an entry.
#[inline(always)]
fn span<P: Payload>(item: Leaf) -> (u64, u64) {
    if is_brick(item) {
        let s = item.packed() >> 1;
        (s, s + P::CODES)
    } else {
        span2(item)
    }
}

/// One operand being read: its entries and payloads, and how far each is read.
struct Cursor<'a, P> {
    items: &'a [Leaf],
    payloads: &'a [P],
    i: usize,
    m: usize,
}

impl<'a, P: Payload> Cursor<'a, P> {
    fn new(t: &'a Level<P>) -> Self {
        Self {
            items: &t.items,
            payloads: &t.payloads,
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

    /// Takes the next `n` entries, returning them and their payloads.
    #[inline(always)]
    fn take(&mut self, n: usize) -> (&'a [Leaf], &'a [P]) {
        let items = &self.items[self.i..self.i + n];
        let c = bricks_in(items);
        let payloads = &self.payloads[self.m..self.m + c];
        self.i += n;
        self.m += c;
        (items, payloads)
    }

    /// Takes the current entry, a mixed cell.
    #[inline(always)]
    fn take_mixed(&mut self) -> &'a P {
        let m = &self.payloads[self.m];
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
    /// multiple of the cell's codes).
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
    fn rest(&mut self) -> (&'a [Leaf], &'a [P]) {
        self.take(self.items.len() - self.i)
    }
}

impl<P: Payload> Level<P> {
    #[inline(always)]
    fn push_mixed(&mut self, item: Leaf, m: P) {
        self.items.push(item);
        self.payloads.push(m);
    }

    /// Pushes a combined cell: dropped when empty, a leaf (merged with its
    /// siblings) when full.
    #[inline(always)]
    fn push_combined(&mut self, item: Leaf, c: Combined<P>) {
        match c {
            Combined::Empty => {}
            Combined::Full => {
                push_merging(&mut self.items, Leaf::new(item.packed() >> 1, P::LOG2));
            }
            Combined::Mixed(m) => self.push_mixed(item, m),
        }
    }

    /// Appends entries of one canonical operand, merging at their front only (as
    /// `merge::push_run`: a run never completes a parent by itself).
    #[inline]
    fn push_run(&mut self, (items, payloads): (&[Leaf], &[P])) {
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
        self.payloads.extend_from_slice(payloads);
    }

    /// Appends entries with no merging (intersection, difference).
    #[inline]
    fn push_plain(&mut self, (items, payloads): (&[Leaf], &[P])) {
        self.items.extend_from_slice(items);
        self.payloads.extend_from_slice(payloads);
    }

    /// Appends the leaf `[start, end)` cut around `holes` (entries inside it): each
    /// gap as maximal blocks, each mixed hole leaving its complement.
    fn push_cut(
        &mut self,
        (start, end): (u64, u64),
        (holes, payloads): (&[Leaf], &[P]),
        merge: bool,
    ) {
        let mut pos = start;
        let mut payloads = payloads.iter();
        for &h in holes {
            let (s, e) = span::<P>(h);
            emit_gap(&mut self.items, pos, s, merge);
            if is_brick(h) {
                let m = payloads.next().expect("one payload per mixed cell");
                self.push_mixed(h, m.complement(s));
            }
            pos = e;
        }
        emit_gap(&mut self.items, pos, end, merge);
    }
}

/// The set operation `op` of two levels of one space (or of one chunk cell).
pub(crate) fn level_op<P: Payload>(a: &Level<P>, b: &Level<P>, op: SetOp) -> Level<P> {
    // Union and intersection keep at most every input entry and payload; a
    // difference may cut more and grows. The unused tail is given back.
    let mut out = Level {
        items: Vec::with_capacity(a.items.len() + b.items.len() + 8),
        payloads: Vec::with_capacity(a.payloads.len() + b.payloads.len()),
    };
    let (x, y) = (Cursor::new(a), Cursor::new(b));
    match op {
        SetOp::Union => union(x, y, &mut out),
        SetOp::Intersection => intersection(x, y, &mut out),
        SetOp::Difference => difference(x, y, &mut out),
        SetOp::SymmetricDifference => symmetric_difference(x, y, &mut out),
    }
    out.items.shrink_to_fit();
    out.payloads.shrink_to_fit();
    out
}

/// Whether entry `x` is a leaf holding entry `y` (an overlapping pair is nested).
#[inline(always)]
fn holds(x: Leaf, (xs, xe): (u64, u64), (ys, ye): (u64, u64)) -> bool {
    !is_brick(x) && xs <= ys && ye <= xe
}

fn union<P: Payload>(mut a: Cursor<'_, P>, mut b: Cursor<'_, P>, out: &mut Level<P>) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            let c = P::combine(
                SetOp::Union,
                x.packed() >> 1,
                a.take_mixed(),
                b.take_mixed(),
            );
            out.push_combined(x, c);
            continue;
        }
        let (sx, sy) = (span::<P>(x), span::<P>(y));
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

fn intersection<P: Payload>(mut a: Cursor<'_, P>, mut b: Cursor<'_, P>, out: &mut Level<P>) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            // Never full: both cells are mixed.
            let c = P::combine(
                SetOp::Intersection,
                x.packed() >> 1,
                a.take_mixed(),
                b.take_mixed(),
            );
            out.push_combined(x, c);
            continue;
        }
        let (sx, sy) = (span::<P>(x), span::<P>(y));
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

fn difference<P: Payload>(mut a: Cursor<'_, P>, mut b: Cursor<'_, P>, out: &mut Level<P>) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            // Never full: the first cell is mixed.
            let c = P::combine(
                SetOp::Difference,
                x.packed() >> 1,
                a.take_mixed(),
                b.take_mixed(),
            );
            out.push_combined(x, c);
            continue;
        }
        let (sx, sy) = (span::<P>(x), span::<P>(y));
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

fn symmetric_difference<P: Payload>(
    mut a: Cursor<'_, P>,
    mut b: Cursor<'_, P>,
    out: &mut Level<P>,
) {
    while a.live() && b.live() {
        let (x, y) = (a.item(), b.item());
        if x == y && is_brick(x) {
            let c = P::combine(
                SetOp::SymmetricDifference,
                x.packed() >> 1,
                a.take_mixed(),
                b.take_mixed(),
            );
            out.push_combined(x, c);
            continue;
        }
        let (sx, sy) = (span::<P>(x), span::<P>(y));
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

//! The merge kernels of the set operations: two canonical leaf lists in, the
//! canonical leaf list of the result out (appended to `out`).
//!
//! Each kernel keeps one invariant at the top of its loop: everything already read
//! from either list ends at or before the start of both current leaves. Three things
//! make them fast on real solids (issue 17), each checked against a `HashSet` model
//! in `tests_merge.rs`:
//! - **Two single voxels** (packed forms both even) are compared as plain integers:
//!   the smaller is disjoint from all that is left of the other list, and equal ones
//!   are the same voxel, so the step needs no spans.
//! - **Runs.** A stretch of leaves of one list that all end before the other list's
//!   current leaf (or that all lie inside one leaf of the other list) is found by
//!   galloping (exponential then binary search) and copied or skipped in one go.
//! - **Merging only where it can happen.** In a union, a run copied from one
//!   canonical list can complete a parent only together with leaves pushed before
//!   it; once seven of its own leaves follow the last such leaf, the rest of the run
//!   is copied as a slice.

use super::{push_merging, Leaf};

/// The code span `[start, end)` of a leaf, read straight off the packed form:
/// `m = p ^ (p + 1)` is the size marker plus the zero bit above it.
#[inline(always)]
pub(super) fn span2(leaf: Leaf) -> (u64, u64) {
    let p = leaf.packed();
    let m = p ^ (p.wrapping_add(1));
    let start = (p & !m) >> 1;
    (start, start + (m >> 1) + 1)
}

/// Pushes a leaf that follows every leaf in `out`, merging siblings only when the
/// leaf is the last child (label 7) of its parent: the only time a merge can occur.
#[inline(always)]
pub(super) fn push_m(out: &mut Vec<Leaf>, leaf: Leaf) {
    let p = leaf.packed();
    if p.checked_shr(p.trailing_ones() + 1).unwrap_or(0) & 7 == 7 {
        push_merging(out, leaf);
    } else {
        out.push(leaf);
    }
}

/// Appends a run of leaves of one canonical list, merging at its front only: the
/// run's own leaves never complete a parent among themselves, so once seven of them
/// follow the last leaf that came from elsewhere (or was made by a merge), the rest
/// is copied as a slice.
#[inline]
fn push_run(out: &mut Vec<Leaf>, run: &[Leaf]) {
    let mut foreign_end = out.len();
    let mut k = 0;
    while k < run.len() && out.len() - foreign_end < 7 {
        let before = out.len();
        push_m(out, run[k]);
        if out.len() <= before {
            // A merge: the new block holds leaves from before the run.
            foreign_end = out.len();
        }
        k += 1;
    }
    out.extend_from_slice(&run[k..]);
}

/// The number of leaves at the front of `s` for which `keep` holds, `keep` being
/// true on a prefix: exponential search, then binary search in the last step.
#[inline]
fn gallop(s: &[Leaf], keep: impl Fn(Leaf) -> bool) -> usize {
    let mut lo = 0; // keep(s[..lo]) all hold
    let mut step = 1;
    loop {
        let probe = lo + step;
        if probe > s.len() || !keep(s[probe - 1]) {
            let hi = probe.min(s.len());
            // The answer lies in lo..=hi; s[lo..hi - 1]... searched by partition.
            return lo + s[lo..hi].partition_point(|&l| keep(l));
        }
        lo = probe;
        step *= 2;
    }
}

/// How many leaves at the front of `s` end at or before code `at`.
#[inline]
pub(super) fn ending_by(s: &[Leaf], at: u64) -> usize {
    gallop(s, |l| span2(l).1 <= at)
}

/// How many leaves at the front of `s` start before code `end`, when each of them
/// either lies inside the block ending at `end` or starts at or after it. Such a
/// leaf of side `2^k` from `s` has `packed >> 1 = s + (8^k - 1) / 2`, below `end`
/// exactly when it lies inside.
#[inline]
pub(super) fn inside(s: &[Leaf], end: u64) -> usize {
    gallop(s, |l| l.packed() >> 1 < end)
}

/// Union of two canonical leaf lists.
pub(super) fn union(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (pa, pb) = (a[i].packed(), b[j].packed());
        if (pa | pb) & 1 == 0 {
            push_m(out, Leaf::from_packed(pa.min(pb)));
            i += usize::from(pa <= pb);
            j += usize::from(pb <= pa);
            continue;
        }
        let ((xs, xe), (ys, ye)) = (span2(a[i]), span2(b[j]));
        if xe <= ys {
            let n = ending_by(&a[i..], ys);
            push_run(out, &a[i..i + n]);
            i += n;
        } else if ye <= xs {
            let n = ending_by(&b[j..], xs);
            push_run(out, &b[j..j + n]);
            j += n;
        } else if xs <= ys && ye <= xe {
            // b's leaves inside a's: skipped.
            push_m(out, a[i]);
            i += 1;
            j += inside(&b[j..], xe);
        } else {
            push_m(out, b[j]);
            j += 1;
            i += inside(&a[i..], ye);
        }
    }
    push_run(out, &a[i..]);
    push_run(out, &b[j..]);
}

/// Intersection: of two overlapping (hence nested) leaves the smaller is kept.
/// No merge can occur: a full parent in both operands is inside a leaf of each.
pub(super) fn intersection(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (pa, pb) = (a[i].packed(), b[j].packed());
        if (pa | pb) & 1 == 0 {
            if pa == pb {
                out.push(a[i]);
            }
            i += usize::from(pa <= pb);
            j += usize::from(pb <= pa);
            continue;
        }
        let ((xs, xe), (ys, ye)) = (span2(a[i]), span2(b[j]));
        if xe <= ys {
            i += ending_by(&a[i..], ys);
        } else if ye <= xs {
            j += ending_by(&b[j..], xs);
        } else if xs <= ys && ye <= xe {
            let n = inside(&b[j..], xe);
            out.extend_from_slice(&b[j..j + n]);
            j += n;
            i += 1;
        } else {
            let n = inside(&a[i..], ye);
            out.extend_from_slice(&a[i..i + n]);
            i += n;
            j += 1;
        }
    }
}

/// Difference: a leaf of `a` is kept whole, dropped, or cut around the leaves of
/// `b` inside it (the gaps are emitted greedily as maximal blocks, which is
/// canonical: a full parent of the result lies in one leaf of `a`, in one gap).
pub(super) fn difference(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (pa, pb) = (a[i].packed(), b[j].packed());
        if (pa | pb) & 1 == 0 {
            if pa < pb {
                out.push(a[i]);
            }
            i += usize::from(pa <= pb);
            j += usize::from(pb <= pa);
            continue;
        }
        let ((xs, xe), (ys, ye)) = (span2(a[i]), span2(b[j]));
        if xe <= ys {
            let n = ending_by(&a[i..], ys);
            out.extend_from_slice(&a[i..i + n]);
            i += n;
        } else if ye <= xs {
            j += ending_by(&b[j..], xs);
        } else if ys <= xs && xe <= ye {
            // a's leaves inside b's: dropped.
            i += inside(&a[i..], ye);
            j += 1;
        } else {
            // b's leaves inside a's: cut a's leaf around them.
            let n = inside(&b[j..], xe);
            let mut pos = xs;
            for &y in &b[j..j + n] {
                let (ys, ye) = span2(y);
                emit_gap(out, pos, ys, false);
                pos = ye;
            }
            emit_gap(out, pos, xe, false);
            j += n;
            i += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
}

/// Symmetric difference: disjoint leaves pass, a nested pair leaves the larger cut
/// around every leaf of the other operand inside it; siblings may merge.
pub(super) fn symmetric_difference(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let ((xs, xe), (ys, ye)) = (span2(a[i]), span2(b[j]));
        if xe <= ys {
            let n = ending_by(&a[i..], ys);
            push_run(out, &a[i..i + n]);
            i += n;
        } else if ye <= xs {
            let n = ending_by(&b[j..], xs);
            push_run(out, &b[j..j + n]);
            j += n;
        } else {
            // Nested: cut the larger around the leaves of the other inside it.
            let (big_start, big_end, small) = if xs <= ys && ye <= xe {
                i += 1;
                let n = inside(&b[j..], xe);
                j += n;
                (xs, xe, &b[j - n..j])
            } else {
                j += 1;
                let n = inside(&a[i..], ye);
                i += n;
                (ys, ye, &a[i - n..i])
            };
            let mut pos = big_start;
            for &l in small {
                let (s, e) = span2(l);
                emit_gap(out, pos, s, true);
                pos = e;
            }
            emit_gap(out, pos, big_end, true);
        }
    }
    push_run(out, &a[i..]);
    push_run(out, &b[j..]);
}

/// Appends the maximal blocks of the code interval `[s, e)`, greedily (the largest
/// block aligned at each start that fits), merging as it goes when asked.
#[inline]
pub(super) fn emit_gap(out: &mut Vec<Leaf>, mut s: u64, e: u64, merge: bool) {
    while s < e {
        let align = s.trailing_zeros().min(63) / 3;
        let fit = (63 - (e - s).leading_zeros()) / 3;
        let k = align.min(fit);
        let leaf = Leaf::new(s, k as u8);
        if merge {
            push_m(out, leaf);
        } else {
            out.push(leaf);
        }
        s += 1u64 << (3 * k);
    }
}

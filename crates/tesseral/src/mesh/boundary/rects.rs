//! Step 2: boundary squares merged greedily into rectangles.

use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::squares::Square;

/// A rectangle of boundary in plane `x_a = c`, facing +a when `pos`, spanning
/// `[u0, u1] × [v0, v1]` in the axes `(a+1) % 3`, `(a+2) % 3`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rect {
    pub(super) a: usize,
    pub(super) pos: bool,
    pub(super) c: i64,
    pub(super) u0: i64,
    pub(super) u1: i64,
    pub(super) v0: i64,
    pub(super) v1: i64,
}

/// The rectangles of the boundary squares (in runs, as [`super::squares`] gives
/// them): each square cut into unit squares, or with `merge` the squares merged
/// greedily into rows and rows stacked.
pub(super) fn rectangles(squares: &[Vec<Square>], merge: bool) -> Vec<Rect> {
    let squares = || squares.iter().flatten();
    if !merge {
        let mut out = Vec::new();
        for q in squares() {
            for du in 0..q.s {
                for dv in 0..q.s {
                    out.push(Rect {
                        a: q.a,
                        pos: q.pos,
                        c: q.c,
                        u0: q.u + du,
                        u1: q.u + du + 1,
                        v0: q.v + dv,
                        v1: q.v + dv + 1,
                    });
                }
            }
        }
        return out;
    }
    // Rows: (axis, orientation, plane, v, u0, u1).
    let mut rows: Vec<(usize, bool, i64, i64, i64, i64)> = Vec::new();
    for q in squares() {
        for v in q.v..q.v + q.s {
            rows.push((q.a, q.pos, q.c, v, q.u, q.u + q.s));
        }
    }
    // Equal rows are the same value: the order is the same as a stable sort's.
    rows.par_sort_unstable();
    // Join touching runs in each row.
    let mut runs: Vec<(usize, bool, i64, i64, i64, i64)> = Vec::with_capacity(rows.len());
    for r in rows {
        if let Some(last) = runs.last_mut() {
            if (last.0, last.1, last.2, last.3) == (r.0, r.1, r.2, r.3) && last.5 == r.4 {
                last.5 = r.5;
                continue;
            }
        }
        runs.push(r);
    }
    // Stack identical runs of consecutive rows.
    // (axis, orientation, plane, u0, u1) -> (first row, last row)
    type RunKey = (usize, bool, i64, i64, i64);
    let mut open: FxHashMap<RunKey, (i64, i64)> = FxHashMap::default();
    let mut out = Vec::new();
    let emit = |key: RunKey, span: (i64, i64), out: &mut Vec<Rect>| {
        out.push(Rect {
            a: key.0,
            pos: key.1,
            c: key.2,
            u0: key.3,
            u1: key.4,
            v0: span.0,
            v1: span.1 + 1,
        });
    };
    for (a, pos, c, v, u0, u1) in runs {
        let key = (a, pos, c, u0, u1);
        match open.get_mut(&key) {
            Some(span) if span.1 == v - 1 => span.1 = v,
            Some(span) => {
                let old = *span;
                *span = (v, v);
                emit(key, old, &mut out);
            }
            None => {
                open.insert(key, (v, v));
            }
        }
    }
    let mut rest: Vec<_> = open.into_iter().collect();
    rest.sort_unstable_by_key(|e| e.0);
    for (key, span) in rest {
        emit(key, span, &mut out);
    }
    out
}

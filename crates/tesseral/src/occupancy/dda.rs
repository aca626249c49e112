//! The 3-D DDA of Amanatides & Woo on cell keys, as OctoMap's `computeRayKeys`: a
//! ray's set-up, the reference walk, and the jump out of a block (the fast walk is
//! [`Scratch::miss_walk`](super::ray::Scratch::miss_walk)).

/// The state of one ray's walk (Amanatides & Woo) after its first cell.
pub(crate) struct Dda {
    /// ±1 or 0 per axis.
    pub step: [i64; 3],
    /// The ray parameter at the next border along each axis.
    pub t_max: [f64; 3],
    /// The ray parameter between borders along each axis.
    pub t_delta: [f64; 3],
    /// Steps left along each axis before the end cell's plane.
    pub left_axis: [i64; 3],
    /// Steps left in all before the end cell.
    pub left: i64,
}

impl Dda {
    /// The walk from `origin` (in cell `key_origin`) to `end` (in `key_end`), or
    /// `None` when both lie in one cell: [`RayOrigin::dda`] for one ray.
    ///
    /// The steps left along an axis are never negative (the key of the end lies on
    /// the side `step` goes). The walk reaches the end cell when no step is left, and
    /// stops early when it would step past the end cell's plane along an axis, which
    /// only float rounding can cause. (OctoMap stops once the border distance exceeds
    /// the length, which can drop the last cell before an end point lying exactly on
    /// a face; the count on keys cannot.)
    #[cfg(test)]
    pub fn new(
        origin: [f64; 3],
        end: [f64; 3],
        key_origin: [i64; 3],
        key_end: [i64; 3],
        res: f64,
    ) -> Option<Self> {
        RayOrigin::new(origin, key_origin, res).dda_to(end, key_end)
    }
}

/// What the rays of a scan share: the origin, its cell, and the distance from the
/// origin to its cell's border on each side of each axis (OctoMap: centre ± res/2;
/// OctoMap adds the half cell rounded to `f32`, which moves the border by up to
/// 1e-9 of a cell; we keep it exact), so that a ray's set-up is its divisions alone.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RayOrigin {
    origin: [f64; 3],
    key: [i64; 3],
    res: f64,
    /// Border minus origin per axis, stepping down (`[0]`) and up (`[1]`).
    to_border: [[f64; 2]; 3],
}

impl RayOrigin {
    /// The shared set-up of rays from `origin`, in cell `key`, at resolution `res`.
    pub fn new(origin: [f64; 3], key: [i64; 3], res: f64) -> Self {
        let to_border = [0, 1, 2].map(|i| {
            [-1.0, 1.0].map(|s: f64| (key[i] as f64 + 0.5) * res + s * res * 0.5 - origin[i])
        });
        Self {
            origin,
            key,
            res,
            to_border,
        }
    }

    /// The walk to `end`, in cell `key_end` ([`dda`](Self::dda) with the offset
    /// and length computed here).
    #[inline(always)]
    pub fn dda_to(&self, end: [f64; 3], key_end: [i64; 3]) -> Option<Dda> {
        let o = self.origin;
        let d = [end[0] - o[0], end[1] - o[1], end[2] - o[2]];
        self.dda(d, (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), key_end)
    }

    /// The walk along `d` (end minus origin) of length `length` (`|d|`, summed
    /// x, y, z), ending in cell `key_end`, or `None` when that is the origin's
    /// cell. The divisions do not depend on each other or on a branch, so that
    /// they overlap.
    #[inline(always)]
    pub fn dda(&self, d: [f64; 3], length: f64, key_end: [i64; 3]) -> Option<Dda> {
        if key_end == self.key {
            return None;
        }
        let dir = d.map(|c| c / length);
        // +1, −1, or 0 (also for NaN, from a length that underflowed).
        let step = dir.map(|c| i64::from(c > 0.0) - i64::from(c < 0.0));
        let t = [0, 1, 2].map(|i| self.to_border[i][usize::from(dir[i] > 0.0)] / dir[i]);
        let td = dir.map(|c| self.res / c.abs());
        let t_max = [0, 1, 2].map(|i| if step[i] != 0 { t[i] } else { f64::MAX });
        let t_delta = [0, 1, 2].map(|i| if step[i] != 0 { td[i] } else { f64::MAX });
        let left_axis = [0, 1, 2].map(|i| (key_end[i] - self.key[i]) * step[i]);
        Some(Dda {
            step,
            t_max,
            t_delta,
            left_axis,
            left: left_axis[0] + left_axis[1] + left_axis[2],
        })
    }
}

/// One ray's walk: the cells OctoMap's `computeRayKeys(origin, end)` returns.
///
/// Nothing when both ends lie in one cell; otherwise the origin's cell, then each
/// cell entered, stopping before the end's cell (or once the walk has passed it
/// along an axis, which only float rounding can cause). Ties between axes go as
/// in OctoMap (x before z, y before z, y before x only when strictly smaller).
/// This is the reference form; [`Scratch::miss_walk`](super::ray::Scratch::miss_walk)
/// is the fast one.
#[cfg(test)]
pub(crate) fn walk(
    origin: [f64; 3],
    end: [f64; 3],
    key_origin: [i64; 3],
    key_end: [i64; 3],
    res: f64,
    visit: impl FnMut([i64; 3]),
) {
    if let Some(w) = Dda::new(origin, end, key_origin, key_end, res) {
        walk_from(w, key_origin, visit);
    }
}

/// The cells of the walk `w` from cell `key_origin`: [`walk`] after its set-up.
#[cfg(test)]
pub(crate) fn walk_from(mut w: Dda, key_origin: [i64; 3], mut visit: impl FnMut([i64; 3])) {
    visit(key_origin);
    let mut key = key_origin;
    loop {
        let dim = if w.t_max[0] < w.t_max[1] {
            if w.t_max[0] < w.t_max[2] {
                0
            } else {
                2
            }
        } else if w.t_max[1] < w.t_max[2] {
            1
        } else {
            2
        };
        if w.left_axis[dim] == 0 {
            return;
        }
        w.left_axis[dim] -= 1;
        w.left -= 1;
        if w.left == 0 {
            return;
        }
        key[dim] += w.step[dim];
        w.t_max[dim] += w.t_delta[dim];
        visit(key);
    }
}

/// Where a walk leaves its block: the axis it leaves along, the steps it takes along
/// each axis up to and including the step out, and the ray parameters then, exactly
/// as `walk`'s steps would leave them (`walk`, the reference form, is built for
/// tests only).
///
/// The walk is a merge of three sequences of border parameters, one per axis, each
/// summed step by step as the walk sums them (`t`, `t + d`, `t + d + d`, ...), in the
/// order (parameter, then z before y before x on ties). The step out of the block
/// along axis `i` comes `w_i` borders on (8 − x or x + 1); the first of these in the
/// merge order is the exit, and the steps along another axis are its borders that
/// precede the exit. At most 8 sums per axis, whatever the path inside.
#[inline]
pub(crate) fn exit_block(
    t: [f64; 3],
    d: [f64; 3],
    step: [i64; 3],
    c: [i64; 3],
) -> (usize, [i64; 3], [f64; 3]) {
    let mut w = [0i64; 3];
    let mut e = [f64::MAX; 3];
    for i in 0..3 {
        if step[i] != 0 {
            w[i] = steps_to_face(c[i], step[i]);
            e[i] = face(t[i], d[i], c[i], step[i]);
        }
    }
    let a = if e[0] < e[1] {
        if e[0] < e[2] {
            0
        } else {
            2
        }
    } else if e[1] < e[2] {
        1
    } else {
        2
    };
    let mut n = [0i64; 3];
    let mut out = t;
    for j in 0..3 {
        if j == a {
            n[j] = w[j];
            out[j] = e[j] + d[j];
        } else if step[j] != 0 {
            while n[j] + 1 < w[j] && (out[j] < e[a] || (out[j] == e[a] && j > a)) {
                out[j] += d[j];
                n[j] += 1;
            }
        }
    }
    (a, n, out)
}

/// The borders a walk at block-local coordinate `c` crosses along an axis, stepping
/// `s` (±1), up to and including its block's face (8 − c or c + 1).
#[inline(always)]
pub(crate) fn steps_to_face(c: i64, s: i64) -> i64 {
    if s > 0 {
        8 - c
    } else {
        c + 1
    }
}

/// The parameter of the block face ahead along an axis, from `t`, the parameter of
/// the next border, `d` apart, summed border by border as the walk sums them; the
/// largest float when the axis is not stepped (`s` 0).
#[inline(always)]
pub(crate) fn face(t: f64, d: f64, c: i64, s: i64) -> f64 {
    if s == 0 {
        return f64::MAX;
    }
    let mut v = t;
    for _ in 1..steps_to_face(c, s) {
        v += d;
    }
    v
}

/// Blocks crossed by [`exit_block`] so far (tests check that the jump is taken).
#[cfg(test)]
pub(crate) static JUMPS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Blocks crossed in runs of full blocks, face to face, so far (tests check that
/// runs are taken).
#[cfg(test)]
pub(crate) static RUN_JUMPS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

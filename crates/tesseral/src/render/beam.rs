//! Beams: a lower bound on where a bundle of rays first meets the solid.

use super::index::{RayTree, Root};
use super::nodes::{child_min, Kid, NodeId, Nodes, Trace};

impl RayTree {
    /// A lower bound on where a bundle of rays first meets the solid (ESVO-style beam
    /// optimization, Laine & Karras 2010). `near(min, max)` returns, for a box, `None`
    /// when no ray of the bundle can enter it, else a lower bound on the ray parameter
    /// of its points. Nodes of side `2^stop_log2` or less count as solid, so the search
    /// stays coarse. Returns infinity when no ray of the bundle meets a black block.
    ///
    /// # Runtime
    /// O(nodes whose boxes the bundle meets, down to the stop size).
    #[must_use]
    pub fn beam_start(
        &self,
        stop_log2: u8,
        near: &impl Fn([f64; 3], [f64; 3]) -> Option<f64>,
    ) -> f64 {
        beam_start(self, stop_log2, near)
    }
}

/// [`RayTree::beam_start`] for any tree.
pub(crate) fn beam_start<T: Trace + ?Sized>(
    t: &T,
    stop_log2: u8,
    near: &impl Fn([f64; 3], [f64; 3]) -> Option<f64>,
) -> f64 {
    let (depth, origin) = t.space();
    let side = f64::from(1u32 << depth);
    let lo = origin.map(|v| v as f64);
    let hi = lo.map(|v| v + side);
    match t.root() {
        (Root::White, _) => f64::INFINITY,
        (Root::Black, _) => near(lo, hi).unwrap_or(f64::INFINITY),
        (Root::Gray, root) => {
            if near(lo, hi).is_none() {
                return f64::INFINITY;
            }
            let mut best = f64::INFINITY;
            let mut beam = Beam {
                cur: t.cursor(),
                stop: stop_log2,
                near,
                best: &mut best,
            };
            beam.rec(root, origin, depth, 0);
            best
        }
    }
}

struct Beam<'a, N, F> {
    cur: N,
    stop: u8,
    near: &'a F,
    best: &'a mut f64,
}

impl<N: Nodes, F: Fn([f64; 3], [f64; 3]) -> Option<f64>> Beam<'_, N, F> {
    fn rec(&mut self, n: NodeId, min: [i64; 3], k: u8, path: u64) {
        let half = 1i64 << (k - 1);
        let mut kids: [(f64, u8, [i64; 3]); 8] = [(0.0, 0, [0; 3]); 8];
        let mut count = 0;
        for label in 0..8u8 {
            if !self.cur.maybe(n, label) {
                continue;
            }
            let cmin = child_min(min, half, label);
            let lo = cmin.map(|v| v as f64);
            let hi = lo.map(|v| v + half as f64);
            if let Some(t) = (self.near)(lo, hi) {
                // Insertion by t: nearer children first prune the rest sooner.
                let mut i = count;
                while i > 0 && kids[i - 1].0 > t {
                    kids[i] = kids[i - 1];
                    i -= 1;
                }
                kids[i] = (t, label, cmin);
                count += 1;
            }
        }
        for &(t, label, cmin) in &kids[..count] {
            if t >= *self.best {
                break;
            }
            let cpath = (path << 3) | u64::from(label);
            match self.cur.kid(n, label, cpath, k - 1) {
                Kid::White => {}
                Kid::Black => *self.best = t,
                Kid::Gray(_) if k - 1 <= self.stop => *self.best = t,
                Kid::Gray(c) => self.rec(c, cmin, k - 1, cpath),
            }
        }
    }
}

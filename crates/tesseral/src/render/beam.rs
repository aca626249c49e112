//! Beams: a lower bound on where a bundle of rays first meets the solid.

use super::index::{RayTree, Root};
use super::trace::rank;

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
        let side = f64::from(1u32 << self.depth);
        let lo = self.origin.map(|v| v as f64);
        let hi = lo.map(|v| v + side);
        match self.root {
            Root::White => f64::INFINITY,
            Root::Black => near(lo, hi).unwrap_or(f64::INFINITY),
            Root::Gray => {
                if near(lo, hi).is_none() {
                    return f64::INFINITY;
                }
                let mut best = f64::INFINITY;
                self.beam_rec(
                    self.root_node,
                    self.origin,
                    self.depth,
                    stop_log2,
                    near,
                    &mut best,
                );
                best
            }
        }
    }

    fn beam_rec(
        &self,
        n: u32,
        min: [i64; 3],
        k: u8,
        stop: u8,
        near: &impl Fn([f64; 3], [f64; 3]) -> Option<f64>,
        best: &mut f64,
    ) {
        let node = self.nodes[n as usize];
        let half = 1i64 << (k - 1);
        let mut kids: [(f64, u8, [i64; 3]); 8] = [(0.0, 0, [0; 3]); 8];
        let mut count = 0;
        for label in 0..8u8 {
            let bit = 1u8 << label;
            if (node.black | node.gray) & bit == 0 {
                continue;
            }
            let cmin = [
                min[0] + half * i64::from(label & 1),
                min[1] + half * i64::from((label >> 1) & 1),
                min[2] + half * i64::from((label >> 2) & 1),
            ];
            let lo = cmin.map(|v| v as f64);
            let hi = lo.map(|v| v + half as f64);
            if let Some(t) = near(lo, hi) {
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
            if t >= *best {
                break;
            }
            let bit = 1u8 << label;
            if node.black & bit != 0 || k - 1 <= stop {
                *best = t;
            } else {
                let j = rank(node.gray, bit);
                self.beam_rec(node.first + j, cmin, k - 1, stop, near, best);
            }
        }
    }
}

//! A primitive as the compiled solid holds it: its shape and world-to-local map,
//! and its conservative class of a cell's voxel centres.

use super::{Shape, Transform};
use crate::linear::CellClass;

/// A primitive with its world-to-local map `local = inv · (p − at)`, where
/// `inv = Rᵀ / s`; world distances are `s` times local ones.
#[derive(Debug, Clone)]
pub(super) struct Prim {
    pub(super) shape: Shape,
    pub(super) inv: [[f64; 3]; 3],
    pub(super) at: [f64; 3],
    pub(super) scale: f64,
    pub(super) world: Transform,
}

impl Prim {
    /// A box's class of a cell's centres by their bounding box rather than their
    /// ball: the centres' box (half-side `r/√3` in world units), mapped to the box's
    /// frame, bounded by a local box of half-sides `Σⱼ |inv[i][j]| · r/√3`. Exact
    /// for a box not rotated off the axes, where the ball cannot decide a cell whose
    /// face lies on the box's (every cell along a box that fills its space); `None`
    /// when undecided.
    #[inline]
    fn box_class(&self, l: [f64; 3], r: f64, half: [f64; 3]) -> Option<CellClass> {
        let e = r / 3f64.sqrt();
        let margin = (1e-6 + 1e-9 * r) / self.scale;
        let mut inside = true;
        for (i, row) in self.inv.iter().enumerate() {
            let ext = e * (row[0].abs() + row[1].abs() + row[2].abs());
            let d = l[i].abs();
            if d - ext > half[i] + margin {
                return Some(CellClass::Outside);
            }
            inside &= d + ext < half[i] - margin;
        }
        inside.then_some(CellClass::Inside)
    }

    #[inline]
    pub(super) fn local(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [p[0] - self.at[0], p[1] - self.at[1], p[2] - self.at[2]];
        let m = &self.inv;
        [
            m[0][0] * d[0] + m[0][1] * d[1] + m[0][2] * d[2],
            m[1][0] * d[0] + m[1][1] * d[1] + m[1][2] * d[2],
            m[2][0] * d[0] + m[2][1] * d[1] + m[2][2] * d[2],
        ]
    }

    /// The class of the voxel centres of a cell, given as their ball (`cell_ball`:
    /// radius `r` around `c`; `r == 0`: the point `c`).
    #[inline]
    pub(super) fn class(&self, c: [f64; 3], r: f64) -> CellClass {
        let l = self.local(c);
        if r == 0.0 {
            return if self.shape.contains(l) {
                CellClass::Inside
            } else {
                CellClass::Outside
            };
        }
        if let Shape::Box { half } = self.shape {
            if let Some(class) = self.box_class(l, r, half) {
                return class;
            }
        }
        // The margin absorbs rounding: the bound is decided well clear of the surface.
        let m = r + 1e-6 + 1e-9 * r;
        let b = self.scale * self.shape.bound(l);
        if b > m {
            CellClass::Outside
        } else if b < -m {
            CellClass::Inside
        } else {
            CellClass::Partial
        }
    }
}

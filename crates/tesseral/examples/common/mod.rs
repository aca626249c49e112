//! Solids shared by the examples (included with `mod common;`).

use tesseral::linear::{CellClass, LinearOctree};

/// The solid sphere of radius `r` about the lattice origin (voxel centres inside),
/// as the OpenVDB harnesses build it: in doubled coordinates the centre of
/// voxel x is 2x + 1, inside when |2c|² ≤ 4r².
pub fn sphere(r: i64) -> LinearOctree {
    let classify = move |min: [i64; 3], k: u8| {
        let s = 1i64 << k;
        let (mut near, mut far) = (0i64, 0i64);
        for &m in &min {
            let (lo, hi) = (2 * m + 1, 2 * (m + s) - 1);
            let n = if lo > 0 {
                lo
            } else if hi < 0 {
                hi
            } else {
                0
            };
            let f = lo.abs().max(hi.abs());
            near += n * n;
            far += f * f;
        }
        if far <= 4 * r * r {
            CellClass::Inside
        } else if near > 4 * r * r {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    };
    let depth = (64 - (2 * r + 2).leading_zeros()) as u8;
    let half = 1i64 << (depth - 1);
    LinearOctree::from_classifier(depth, [-half; 3], &classify).expect("sphere")
}

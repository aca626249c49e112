//! What the examples share (included with `mod common;`): the OpenVDB harnesses'
//! sphere, and the process's CPU time.
#![allow(dead_code)] // each example uses part of it

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

/// The process's CPU time in seconds (all its threads). The machine may be shared,
/// so wall time would count other processes' turns on the core; since it sums every
/// thread, no work done off the calling thread is missed.
pub fn process_cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

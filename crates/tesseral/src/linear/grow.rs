//! Growing a space by root expansion (Libes §3): the old root becomes one of the
//! eight children of a new root of twice the side, so every old block keeps its
//! alignment in the new lattice.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use super::{OctreeError, MAX_DEPTH};
use crate::Voxel;

/// The smallest space grown from `(depth, origin)` by root expansion that holds the
/// inclusive box `[lo, hi]`. At each step, an axis on which the box pokes out below
/// the space grows downwards (the old root becomes the upper child on that axis);
/// every other axis grows upwards.
///
/// # Errors
/// [`OctreeError::DepthTooLarge`] past [`MAX_DEPTH`]; [`OctreeError::Overflow`]
/// when the origin leaves the `i64` range.
pub(crate) fn grown_space(
    depth: u8,
    origin: Voxel,
    lo: Voxel,
    hi: Voxel,
) -> Result<(u8, Voxel), OctreeError> {
    let (mut d, mut o) = (depth, origin);
    loop {
        let side = 1i128 << d;
        let fits = (0..3).all(|a| {
            i128::from(o[a]) <= i128::from(lo[a]) && i128::from(hi[a]) < i128::from(o[a]) + side
        });
        if fits {
            return Ok((d, o));
        }
        if d >= MAX_DEPTH {
            return Err(OctreeError::DepthTooLarge(d.saturating_add(1)));
        }
        for a in 0..3 {
            if lo[a] < o[a] {
                o[a] = i64::try_from(i128::from(o[a]) - side).map_err(|_| OctreeError::Overflow)?;
            }
        }
        d += 1;
    }
}

/// The child label that the old root takes in each root expansion from
/// `(depth, origin)` to the grown `(new_depth, new_origin)`, outermost first.
#[allow(dead_code)]
pub(crate) fn expansion_labels(
    depth: u8,
    origin: Voxel,
    new_depth: u8,
    new_origin: Voxel,
) -> Vec<u8> {
    // Replay grown_space's choices: at step d -> d+1 the old cell's lowest corner
    // relative to the new one is 0 or 2^d on each axis.
    let mut labels = Vec::new();
    let rel: [i128; 3] = std::array::from_fn(|a| i128::from(origin[a]) - i128::from(new_origin[a]));
    for d in depth..new_depth {
        let mut label = 0;
        for (a, r) in rel.iter().enumerate() {
            if (r >> d) & 1 == 1 {
                label |= 1 << a;
            }
        }
        labels.push(label);
    }
    labels.reverse();
    labels
}

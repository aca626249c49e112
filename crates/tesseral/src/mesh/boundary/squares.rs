//! Step 1: the boundary squares, found top-down against the tree.

use rayon::prelude::*;

use crate::code;
use crate::linear::{first_above, LinearOctree};
use crate::Voxel;

#[derive(Clone, Copy)]
pub(super) struct Square {
    pub(super) a: usize,
    pub(super) pos: bool,
    pub(super) c: i64,
    pub(super) u: i64,
    pub(super) v: i64,
    pub(super) s: i64,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Region {
    Full,
    Empty,
    Mixed,
}

/// Classifies the cube of side `2^k` at `min` (aligned in the tree's space, or wholly
/// outside it) against the tree, searching from leaf `near` (the block whose face
/// it is across: its neighbours are mostly near it in code order).
fn classify_cube(tree: &LinearOctree, min: Voxel, k: u8, near: usize) -> Region {
    let side = tree.side() as i64;
    let o = tree.origin();
    let mut rel = [0u32; 3];
    for a in 0..3 {
        let r = min[a] - o[a];
        if r < 0 || r >= side {
            return Region::Empty;
        }
        rel[a] = r as u32;
    }
    let c = code::encode(rel[0], rel[1], rel[2]);
    let len = 1u64 << (3 * u32::from(k));
    let leaves = tree.leaves();
    let i = first_above(leaves, c, near);
    if i > 0 && leaves[i - 1].end() > c {
        return if leaves[i - 1].size_log2() >= k {
            Region::Full
        } else {
            Region::Mixed
        };
    }
    if i < leaves.len() && leaves[i].code() < c + len {
        Region::Mixed
    } else {
        Region::Empty
    }
}

/// Leaves per parallel task of [`boundary_squares`].
const LEAVES_PER_TASK: usize = 1 << 12;

/// The boundary squares of every black block's six faces, block by block in
/// tesseral order, in runs of [`LEAVES_PER_TASK`] blocks searched in parallel (not
/// joined: a copy of them all would double their memory).
pub(super) fn boundary_squares(tree: &LinearOctree) -> Vec<Vec<Square>> {
    let leaves = tree.leaves();
    (0..leaves.len().div_ceil(LEAVES_PER_TASK))
        .into_par_iter()
        .map(|k| {
            let mut out = Vec::new();
            let from = k * LEAVES_PER_TASK;
            let to = leaves.len().min(from + LEAVES_PER_TASK);
            for (near, leaf) in leaves[from..to].iter().enumerate() {
                let (near, min, k) = (from + near, tree.voxel_of(leaf.code()), leaf.size_log2());
                let s = 1i64 << k;
                for a in 0..3 {
                    for pos in [false, true] {
                        let mut n = min;
                        n[a] += if pos { s } else { -s };
                        let plane = if pos { min[a] + s } else { min[a] };
                        descend(tree, (n, k), near, (a, pos, plane), &mut out);
                    }
                }
            }
            out
        })
        .collect()
}

/// The boundary squares of the face (axis `a`, side `pos`, at `plane`) across which
/// lies `cube` (its lowest voxel, its side's log2), searched from leaf `near`.
fn descend(
    tree: &LinearOctree,
    (cube, k): (Voxel, u8),
    near: usize,
    (a, pos, plane): (usize, bool, i64),
    out: &mut Vec<Square>,
) {
    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
    match classify_cube(tree, cube, k, near) {
        Region::Full => {}
        Region::Empty => out.push(Square {
            a,
            pos,
            c: plane,
            u: cube[u],
            v: cube[v],
            s: 1 << k,
        }),
        Region::Mixed => {
            let h = 1i64 << (k - 1);
            for du in 0..2 {
                for dv in 0..2 {
                    let mut m = cube;
                    m[u] += du * h;
                    m[v] += dv * h;
                    if !pos {
                        m[a] += h;
                    }
                    descend(tree, (m, k - 1), near, (a, pos, plane), out);
                }
            }
        }
    }
}

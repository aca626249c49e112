//! Step 3's lattice points, without hashing: every point on a rectangle's sides,
//! in the order the polygons walk them, gets the number of its distinct point (the
//! points sorted by a packed key, in parallel), and each distinct point's colouring
//! and vertex groups are worked out once, in parallel.

use rayon::prelude::*;

use super::groups::{group_table, is_pinch_edge, joined_by_black};
use super::rects::Rect;
use super::vertices::point;
use crate::linear::LinearOctree;
use crate::Voxel;

/// A lattice point's coordinates relative to the tree's origin (0 to the side,
/// so `bits` = depth + 1 bits each), packed so that keys sort as the points do.
trait Key: Copy + Ord + Send + Sync {
    fn pack(rel: [u64; 3], bits: u32) -> Self;
    fn unpack(self, bits: u32) -> [u64; 3];
}

impl Key for u64 {
    fn pack(rel: [u64; 3], bits: u32) -> Self {
        rel[0] << (2 * bits) | rel[1] << bits | rel[2]
    }
    fn unpack(self, bits: u32) -> [u64; 3] {
        let mask = (1u64 << bits) - 1;
        [self >> (2 * bits), self >> bits & mask, self & mask]
    }
}

impl Key for u128 {
    fn pack(rel: [u64; 3], bits: u32) -> Self {
        u128::from(rel[0]) << (2 * bits) | u128::from(rel[1]) << bits | u128::from(rel[2])
    }
    fn unpack(self, bits: u32) -> [u64; 3] {
        let mask = (1u128 << bits) - 1;
        [self >> (2 * bits), self >> bits & mask, self & mask].map(|c| c as u64)
    }
}

/// The points on the sides of `r` in the order its polygon walks them, counter-
/// clockwise seen from +a: corner 0 `(u0, v0)` and the points inside the side to
/// corner 1 `(u1, v0)`, then corner 1 and the side to corner 2 `(u1, v1)`, corner 2
/// and the side to corner 3 `(u0, v1)`, corner 3 and the side back. Corners are at
/// [`corners`]; 2 (w + h) points in all.
pub(super) fn perimeter(r: &Rect) -> impl Iterator<Item = Voxel> + '_ {
    let along_v0 = (r.u0..r.u1).map(move |u| (u, r.v0));
    let along_u1 = (r.v0..r.v1).map(move |v| (r.u1, v));
    let along_v1 = (r.u0 + 1..=r.u1).rev().map(move |u| (u, r.v1));
    let along_u0 = (r.v0 + 1..=r.v1).rev().map(move |v| (r.u0, v));
    along_v0
        .chain(along_u1)
        .chain(along_v1)
        .chain(along_u0)
        .map(move |(u, v)| point(r, u, v))
}

/// The four corners of `r` in [`perimeter`] order, each with where it comes there.
pub(super) fn corners(r: &Rect) -> [(usize, Voxel); 4] {
    let (w, h) = ((r.u1 - r.u0) as usize, (r.v1 - r.v0) as usize);
    [
        (0, point(r, r.u0, r.v0)),
        (w, point(r, r.u1, r.v0)),
        (w + h, point(r, r.u1, r.v1)),
        (2 * w + h, point(r, r.u0, r.v1)),
    ]
}

/// The rectangles' points, numbered by distinct point, and what is known of each.
pub(super) struct Lattice {
    /// Per point on the rectangles' sides, rectangle by rectangle in
    /// [`perimeter`] order: the number of its distinct point.
    pub(super) point: Vec<u32>,
    /// Per rectangle, where its points start in `point`.
    pub(super) starts: Vec<usize>,
    /// Per distinct point: which of its eight voxels are black
    /// ([`LinearOctree::octet`] of the point − 1).
    pub(super) config: Vec<u8>,
    /// Per distinct point: the group of each of its 12 faces (−1: not boundary).
    pub(super) groups: Vec<[i8; 12]>,
}

impl Lattice {
    /// The lattice of the rectangles `rects` of `tree`'s boundary.
    pub(super) fn new(tree: &LinearOctree, rects: &[Rect]) -> Self {
        let bits = u32::from(tree.depth()) + 1;
        if 3 * bits <= 64 {
            Self::with_keys::<u64>(tree, rects, bits)
        } else {
            Self::with_keys::<u128>(tree, rects, bits)
        }
    }

    fn with_keys<K: Key>(tree: &LinearOctree, rects: &[Rect], bits: u32) -> Self {
        let o = tree.origin();
        let mut starts = Vec::with_capacity(rects.len() + 1);
        let mut total = 0usize;
        for r in rects {
            starts.push(total);
            total += 2 * ((r.u1 - r.u0) + (r.v1 - r.v0)) as usize;
        }
        // Every point with where it comes, sorted: runs of one point.
        let mut tagged: Vec<(K, usize)> = rects
            .par_iter()
            .zip(starts.par_iter())
            .flat_map_iter(|(r, &at)| {
                perimeter(r).enumerate().map(move |(j, p)| {
                    let rel = [0, 1, 2].map(|a| (p[a] - o[a]) as u64);
                    (K::pack(rel, bits), at + j)
                })
            })
            .collect();
        starts.push(total);
        tagged.par_sort_unstable();
        let mut point = vec![0u32; total];
        let mut keys: Vec<K> = Vec::new();
        for &(k, at) in &tagged {
            if keys.last() != Some(&k) {
                keys.push(k);
            }
            // Fewer than 2^32 distinct points: the mesh numbers its vertices in u32.
            point[at] = (keys.len() - 1) as u32;
        }
        drop(tagged);
        // Each run of points starts its searches where the last point's ended:
        // sorted, the points follow one another, and so do their leaves.
        let (config, groups) = keys
            .par_iter()
            .map_init(
                || 0usize,
                |near, k| {
                    let rel = k.unpack(bits);
                    let p = [0, 1, 2].map(|a| o[a] + rel[a] as i64);
                    let config = tree.octet_near(p.map(|c| c - 1), near);
                    (config, groups_at(tree, p, config, *near))
                },
            )
            .unzip();
        Self {
            point,
            starts,
            config,
            groups,
        }
    }
}

/// The vertex groups of the 12 faces at `p`, whose colouring is `config`. An edge
/// with four boundary faces pairs them by black voxel, unless that pinches the
/// edge at both of its ends, in which case it pairs them by white voxel (which then
/// cannot pinch at either end), so that no two triangles' edges share both
/// vertices twice.
/// `near`: a leaf near `p`'s, where the searches start.
fn groups_at(tree: &LinearOctree, p: Voxel, config: u8, mut near: usize) -> [i8; 12] {
    let cfg = usize::from(config);
    let mut mask = 0usize;
    for e in 0..3 {
        for s in 0..2 {
            if is_pinch_edge(cfg, e, s) && joined_by_black(cfg, e, s) {
                let mut q = p;
                q[e] += if s == 1 { 1 } else { -1 };
                let qcfg = usize::from(tree.octet_near(q.map(|c| c - 1), &mut near));
                if joined_by_black(qcfg, e, 1 - s) {
                    mask |= 1 << (2 * e + s);
                }
            }
        }
    }
    group_table()[cfg][mask]
}

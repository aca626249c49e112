//! Moving a linear octree into another space (depth and origin), for formats whose
//! grid is fixed (OctoMap's 2^16 keys centred at 32768) or fitted to the data.

use crate::code;
use crate::linear::{Leaf, LinearOctree, OctreeError};
use crate::Voxel;

/// The same black voxels in the space of side `2^depth` whose lowest corner is
/// `origin`.
///
/// # Runtime
/// O(n) for n leaves when the tree's space is an aligned cube of the new one (the
/// offset a multiple of the tree's side: every code moves by one constant, order
/// kept); O(n log n) when the offset is a multiple of every block's size (each
/// block then maps to one block); otherwise each block is cut into aligned cubes,
/// O(its surface) each.
///
/// # Errors
/// [`OctreeError::OutOfBounds`] naming a voxel that does not fit the new space;
/// [`OctreeError::DepthTooLarge`].
///
/// ```
/// use tesseral::io::reframe;
/// use tesseral::linear::LinearOctree;
/// let t = LinearOctree::full(1, [0, 0, 0]).unwrap();
/// let moved = reframe(&t, 3, [-1, -1, -1]).unwrap(); // no longer aligned: 8 voxels
/// assert_eq!((moved.voxel_count(), moved.leaf_count()), (8, 8));
/// ```
pub fn reframe(tree: &LinearOctree, depth: u8, origin: Voxel) -> Result<LinearOctree, OctreeError> {
    if depth == tree.depth() && origin == tree.origin() {
        return Ok(tree.clone());
    }
    LinearOctree::empty(depth, origin)?;
    if let Some(base) = sub_cube(tree, depth, origin) {
        let moved = tree
            .leaves()
            .iter()
            .map(|l| Leaf::new(base + l.code(), l.size_log2()));
        return LinearOctree::from_sorted_leaves(depth, origin, moved);
    }
    let side = 1i64 << depth;
    let mut leaves = Vec::with_capacity(tree.leaf_count());
    for b in tree.blocks() {
        let s = b.size();
        let mut rel = [0i64; 3];
        for a in 0..3 {
            let r = b.min[a].checked_sub(origin[a]);
            match r {
                Some(r) if r >= 0 && r.checked_add(s).is_some_and(|e| e <= side) => rel[a] = r,
                _ => {
                    // Name the first voxel of the block that falls outside.
                    let mut v = b.min;
                    if !matches!(r, Some(r) if r >= 0) {
                        v[a] = b.min[a];
                    } else {
                        v[a] = origin[a].saturating_add(side);
                    }
                    return Err(OctreeError::OutOfBounds(v));
                }
            }
        }
        if rel.iter().all(|r| r % s == 0) {
            leaves.push(Leaf::new(
                code::encode(rel[0] as u32, rel[1] as u32, rel[2] as u32),
                b.size_log2,
            ));
        } else {
            cut_box(rel, s, &mut leaves);
        }
    }
    leaves.sort_unstable();
    LinearOctree::from_sorted_leaves(depth, origin, leaves)
}

/// The code of the tree's lowest voxel in the space of side `2^depth` from
/// `origin`, when the tree's space is an aligned cube of that one: its offset a
/// multiple of its side on each axis, inside. Every code of the tree then moves by
/// that much, and a leaf stays a leaf.
fn sub_cube(tree: &LinearOctree, depth: u8, origin: Voxel) -> Option<u64> {
    let side = 1i64 << tree.depth();
    let mut rel = [0u32; 3];
    for (a, r) in rel.iter_mut().enumerate() {
        let d = tree.origin()[a].checked_sub(origin[a])?;
        if d < 0 || d % side != 0 || d.checked_add(side)? > 1i64 << depth {
            return None;
        }
        *r = u32::try_from(d).ok()?;
    }
    Some(code::encode(rel[0], rel[1], rel[2]))
}

/// Cuts the cube `[lo, lo + s)` per axis into maximal aligned cubes.
fn cut_box(lo: [i64; 3], s: i64, out: &mut Vec<Leaf>) {
    // The cube overlaps at most eight aligned cells of size s.
    let k = s.trailing_zeros() as u8;
    let base = lo.map(|l| l & !(s - 1));
    for d in 0..8 {
        let cell = [
            base[0] + (d & 1) * s,
            base[1] + ((d >> 1) & 1) * s,
            base[2] + ((d >> 2) & 1) * s,
        ];
        cut_cell(cell, k, lo, s, out);
    }
}

fn cut_cell(cell: [i64; 3], k: u8, lo: [i64; 3], s: i64, out: &mut Vec<Leaf>) {
    let c = 1i64 << k;
    let mut inside = true;
    for a in 0..3 {
        let (c0, c1, b0, b1) = (cell[a], cell[a] + c, lo[a], lo[a] + s);
        if c1 <= b0 || c0 >= b1 {
            return;
        }
        if c0 < b0 || c1 > b1 {
            inside = false;
        }
    }
    if inside {
        out.push(Leaf::new(
            code::encode(cell[0] as u32, cell[1] as u32, cell[2] as u32),
            k,
        ));
        return;
    }
    let h = c / 2;
    for d in 0..8 {
        let child = [
            cell[0] + (d & 1) * h,
            cell[1] + ((d >> 1) & 1) * h,
            cell[2] + ((d >> 2) & 1) * h,
        ];
        cut_cell(child, k - 1, lo, s, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::collections::HashSet;

    /// A random tree of depth 3 (seeded), its origin, and the generator after it.
    fn random_tree(seed: u64) -> (rand_pcg::Pcg64, Voxel, LinearOctree) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let (origin, voxels) = crate::io::random_voxels(&mut rng, 5, 8, 400);
        let tree = LinearOctree::from_voxels(3, origin, voxels).unwrap();
        (rng, origin, tree)
    }

    #[test]
    fn reframe_keeps_voxels_for_random_offsets() {
        for seed in 0..60u64 {
            let (mut rng, origin, tree) = random_tree(seed);
            let new_origin = [
                origin[0] - rng.random_range(0..8),
                origin[1] - rng.random_range(0..8),
                origin[2] - 4,
            ];
            let moved = reframe(&tree, 4, new_origin).unwrap();
            moved.assert_valid();
            let a: HashSet<Voxel> = tree.voxels().collect();
            let b: HashSet<Voxel> = moved.voxels().collect();
            assert_eq!(a, b, "seed {seed}");
            if !tree.is_empty() {
                assert!(
                    reframe(&tree, 3, [origin[0] + 8, origin[1], origin[2]]).is_err()
                        || a.iter().all(|v| v[0] >= origin[0] + 8)
                );
            }
        }
    }

    #[test]
    fn aligned_sub_cubes_move_by_one_code() {
        for seed in 0..60u64 {
            let (mut rng, origin, tree) = random_tree(seed);
            // Offsets that are multiples of the tree's side: the fast path.
            let new_origin = origin.map(|c| c - 8 * rng.random_range(0..8i64));
            assert!(sub_cube(&tree, 6, new_origin).is_some());
            let moved = reframe(&tree, 6, new_origin).unwrap();
            moved.assert_valid();
            let expected = LinearOctree::from_voxels(6, new_origin, tree.voxels()).unwrap();
            assert_eq!(moved, expected, "seed {seed}");
            // Not a multiple, or not inside: the general path.
            assert!(sub_cube(&tree, 6, new_origin.map(|c| c + 4)).is_none());
            assert!(sub_cube(&tree, 3, origin.map(|c| c - 8)).is_none());
            assert!(sub_cube(&tree, 6, origin.map(|c| c - 64)).is_none());
        }
    }
}

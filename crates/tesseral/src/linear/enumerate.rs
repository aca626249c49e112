//! Every black voxel into a buffer, fast: a leaf's voxels in tesseral order are its
//! lowest voxel plus the decoded codes 0, 1, 2, ..., so a table of the decoded offsets
//! of one 16³ block serves every leaf (larger leaves walk their 16³ sub-blocks in
//! tesseral order). About a copy's speed, against a decode per voxel for
//! [`LinearOctree::voxels`].

use std::sync::OnceLock;

use rayon::prelude::*;

use super::LinearOctree;
use crate::Voxel;

/// log2 of the table's block side.
const TABLE_LOG2: u8 = 4;

/// The offsets of the voxels of a 16³ block in tesseral order.
fn table() -> &'static [[u8; 3]] {
    static TABLE: OnceLock<Vec<[u8; 3]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..1u64 << (3 * u32::from(TABLE_LOG2)))
            .map(|c| crate::code::decode(c).map(|x| x as u8))
            .collect()
    })
}

impl LinearOctree {
    /// Appends every black voxel, in tesseral order (the order of
    /// [`LinearOctree::voxels`]), to `out`, filling runs of leaves in parallel.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(3, [0; 3], [[0, 0, 0], [5, 1, 2]]).unwrap();
    /// let mut v = Vec::new();
    /// t.voxels_into(&mut v);
    /// assert_eq!(v, t.voxels().collect::<Vec<_>>());
    /// ```
    pub fn voxels_into(&self, out: &mut Vec<Voxel>) {
        let n = usize::try_from(self.voxel_count()).unwrap_or(usize::MAX);
        let start = out.len();
        if out.is_empty() {
            // Zeroed memory from the allocator is mapped lazily: no pass over it.
            *out = vec![[0; 3]; n];
        } else {
            out.resize(start + n, [0; 3]);
        }
        let dst = &mut out[start..];
        // Split the leaves into runs of about a million voxels, each filling its own
        // part of the buffer, in parallel.
        let mut runs: Vec<(&[super::Leaf], &mut [Voxel])> = Vec::new();
        let (mut rest, mut leaves) = (dst, self.leaves());
        while !leaves.is_empty() {
            let (mut count, mut i) = (0usize, 0);
            while i < leaves.len() && (count < 1 << 20 || i == 0) {
                count += 1usize << (3 * u32::from(leaves[i].size_log2()));
                i += 1;
            }
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(count);
            runs.push((&leaves[..i], part));
            rest = tail;
            leaves = &leaves[i..];
        }
        runs.into_par_iter()
            .for_each(|(leaves, part)| self.fill(leaves, part));
    }

    /// Writes the voxels of `leaves` into `dst`, which holds exactly as many.
    fn fill(&self, leaves: &[super::Leaf], dst: &mut [Voxel]) {
        let table = table();
        let mut at = 0;
        let mut put = |base: Voxel, offsets: &[[u8; 3]]| {
            for (d, o) in dst[at..at + offsets.len()].iter_mut().zip(offsets) {
                *d = [
                    base[0] + i64::from(o[0]),
                    base[1] + i64::from(o[1]),
                    base[2] + i64::from(o[2]),
                ];
            }
            at += offsets.len();
        };
        for leaf in leaves {
            let min = self.voxel_of(leaf.code());
            let k = leaf.size_log2();
            if k <= TABLE_LOG2 {
                put(min, &table[..1usize << (3 * u32::from(k))]);
            } else {
                for s in 0..1u64 << (3 * u32::from(k - TABLE_LOG2)) {
                    let d = crate::code::decode(s);
                    put(
                        std::array::from_fn(|a| min[a] + (i64::from(d[a]) << TABLE_LOG2)),
                        table,
                    );
                }
            }
        }
    }
}

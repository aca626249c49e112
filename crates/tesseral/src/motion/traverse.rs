//! Cells of a linear octree seen as the nodes of its (implicit) pointer tree, for the
//! parallel traversal of two trees (Ahuja & Nash §5, after Ahuja et al. 1980).
//!
//! A node is a cell of the tree's space together with the run of leaves that lie in
//! it: empty runs are white, a run of one leaf as large as the cell is black, anything
//! else is gray. Splitting a gray node partitions its run by seven binary searches, so
//! no pointer tree is built.

use crate::linear::{Leaf, LinearOctree};
use crate::Voxel;

/// Runs shorter than this are split by a linear scan instead of binary searches.
const LINEAR_SPLIT: usize = 24;

/// A cell with its run of leaves `leaves[lo..hi]`.
#[derive(Debug, Clone, Copy)]
#[doc(hidden)]
pub struct Node {
    /// The code of the cell's lowest voxel, relative to the tree's origin.
    pub code: u64,
    /// The lowest voxel of the cell in the tree's own world coordinates.
    pub min: Voxel,
    /// The side of the cell as a power of two.
    pub k: u8,
    /// First leaf in the cell.
    pub lo: usize,
    /// One past the last leaf in the cell.
    pub hi: usize,
}

impl Node {
    /// The root cell, or `None` for an empty tree.
    pub fn root(tree: &LinearOctree) -> Option<Node> {
        if tree.is_empty() {
            return None;
        }
        Some(Node {
            code: 0,
            min: tree.origin(),
            k: tree.depth(),
            lo: 0,
            hi: tree.leaf_count(),
        })
    }

    /// The smallest cell that holds every leaf: descends from the root while one
    /// child holds the whole run, so traversals start tight.
    pub fn tight_root(tree: &LinearOctree) -> Option<Node> {
        let leaves = tree.leaves();
        let mut n = Self::root(tree)?;
        let mut kids = [n; 8];
        while !n.is_full(leaves) {
            if n.children(leaves, &mut kids) != 1 {
                break;
            }
            n = kids[0];
        }
        Some(n)
    }

    /// Whether the cell is one black leaf.
    #[inline]
    pub fn is_full(&self, leaves: &[Leaf]) -> bool {
        self.hi - self.lo == 1 && leaves[self.lo].size_log2() == self.k
    }

    /// The side in voxels.
    #[inline]
    pub fn side(&self) -> i64 {
        1 << self.k
    }

    /// The number of black voxels in the cell.
    pub fn voxel_count(&self, leaves: &[Leaf]) -> u64 {
        leaves[self.lo..self.hi]
            .iter()
            .map(|l| l.voxel_count())
            .sum()
    }

    /// Writes the non-empty children of a gray cell into `out`, in label order, and
    /// returns how many there are.
    #[inline]
    pub fn children(&self, leaves: &[Leaf], out: &mut [Node; 8]) -> usize {
        debug_assert!(self.k > 0 && !self.is_full(leaves));
        let k = self.k - 1;
        let step = 1u64 << (3 * u32::from(k));
        let half = 1i64 << k;
        let mut n = 0;
        let mut lo = self.lo;
        for d in 0..8u64 {
            let hi = if d == 7 {
                self.hi
            } else {
                // A leaf lies before child d + 1 exactly when its packed value is below
                // the packed start of that child (see `Leaf`'s packing).
                let bound = (self.code + (d + 1) * step) << 1;
                let run = &leaves[lo..self.hi];
                if run.len() < LINEAR_SPLIT {
                    lo + run.iter().take_while(|l| l.packed() < bound).count()
                } else {
                    lo + run.partition_point(|l| l.packed() < bound)
                }
            };
            if hi > lo {
                out[n] = Node {
                    code: self.code + d * step,
                    min: [
                        self.min[0] + (d & 1) as i64 * half,
                        self.min[1] + ((d >> 1) & 1) as i64 * half,
                        self.min[2] + ((d >> 2) & 1) as i64 * half,
                    ],
                    k,
                    lo,
                    hi,
                };
                n += 1;
            }
            lo = hi;
        }
        n
    }
}

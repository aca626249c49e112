//! The pointer-less tree the viewer's shader walks: one `u32` entry per node, the
//! children of a node stored together, breadth first.
//!
//! An entry's low 8 bits are its child mask (bit `d` set when child `d = x + 2y + 4z`
//! holds black voxels) and its high 24 bits its payload:
//!
//! - mask ≠ 0: a grey node; the payload is the index of its first child's entry, and
//!   child `d` sits at `payload + popcount(mask & ((1 << d) − 1))`;
//! - mask = 0: a black leaf; the payload is its colour's index in the palette.
//!
//! White children have no entry. A tree of `L` levels kept has its last level's
//! cells all black leaves; a tree cut short ([`PackedTree::build`] with a budget)
//! turns every grey node of its last level into a black leaf coloured as the first
//! leaf under it (a voxel of the coarse tree is black when any voxel in it is).

use crate::linear::Leaf;

use super::ViewError;

/// The most entries a packed tree (all frames of a page together) can have: a
/// payload has 24 bits.
pub const MAX_ENTRIES: usize = 1 << 24;

/// Where a tree packed for the GPU sits in a shared entry array, and how deep it
/// goes. See the [module docs](self).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PackedTree {
    /// The index of the root's entry (0 unless several trees share the entries).
    pub root: u32,
    /// The depth of the tree packed (its side is `2^depth` voxels).
    pub depth: u8,
    /// The levels kept: `depth` when exact, fewer when cut short, so that a cell of
    /// the last level is `2^(depth − levels)` voxels across.
    pub levels: u8,
    /// Whether the tree has no black voxel (then `entries` holds nothing of it).
    pub empty: bool,
}

impl PackedTree {
    /// Packs `leaves` (sorted by code, disjoint, each with a palette index below
    /// 2^24) of a tree of `depth`, appending the entries to `entries`, whose
    /// length must stay within `max_entries` (and [`MAX_ENTRIES`]): when the whole
    /// tree does not fit, the deepest levels that do not fit are dropped.
    ///
    /// # Errors
    /// [`ViewError::TooLarge`] when not even the root fits.
    ///
    /// # Runtime
    /// O(n · depth) for n leaves.
    pub fn build(
        entries: &mut Vec<u32>,
        depth: u8,
        leaves: &[(Leaf, u32)],
        max_entries: usize,
    ) -> Result<PackedTree, ViewError> {
        let max_entries = max_entries.min(MAX_ENTRIES);
        let root = entries.len();
        if leaves.is_empty() {
            return Ok(PackedTree {
                root: root as u32,
                depth,
                levels: depth,
                empty: true,
            });
        }
        if root + 1 > max_entries {
            return Err(ViewError::TooLarge {
                entries: root + 1,
                limit: max_entries,
            });
        }
        // A node still to expand: its entry, the leaves under it, its size (log2)
        // and the code of its lowest voxel.
        struct Open {
            entry: usize,
            lo: usize,
            hi: usize,
            size_log2: u8,
            code: u64,
        }
        let root_open = Open {
            entry: root,
            lo: 0,
            hi: leaves.len(),
            size_log2: depth,
            code: 0,
        };
        if leaves.len() == 1 && leaves[0].0.size_log2() == depth {
            entries.push(leaves[0].1 << 8);
            return Ok(PackedTree {
                root: root as u32,
                depth,
                levels: depth,
                empty: false,
            });
        }
        entries.push(0);
        let mut level = vec![root_open];
        let mut levels = 0u8;
        while !level.is_empty() {
            // The children of every node of this level, before anything is written.
            let mut children: Vec<(usize, u8, Option<Open>, u32)> = Vec::new();
            for (i, node) in level.iter().enumerate() {
                let s = node.size_log2 - 1;
                let span = 1u64 << (3 * u32::from(s));
                let mut at = node.lo;
                for d in 0..8u8 {
                    let start = node.code + u64::from(d) * span;
                    let end = start + span;
                    let lo = at;
                    while at < node.hi && leaves[at].0.code() < end {
                        at += 1;
                    }
                    if lo == at {
                        continue;
                    }
                    let first = &leaves[lo];
                    if at - lo == 1 && first.0.size_log2() == s {
                        children.push((i, d, None, first.1));
                    } else {
                        let open = Open {
                            entry: 0,
                            lo,
                            hi: at,
                            size_log2: s,
                            code: start,
                        };
                        children.push((i, d, Some(open), first.1));
                    }
                }
            }
            if entries.len() + children.len() > max_entries {
                // Cut short: this level's grey nodes become black leaves.
                if levels == 0 {
                    return Err(ViewError::TooLarge {
                        entries: entries.len() + children.len(),
                        limit: max_entries,
                    });
                }
                for node in &level {
                    entries[node.entry] = leaves[node.lo].1 << 8;
                }
                break;
            }
            levels += 1;
            let mut next = Vec::new();
            let mut i_prev = usize::MAX;
            for (i, d, open, colour) in children {
                if i != i_prev {
                    entries[level[i].entry] = (entries.len() as u32) << 8;
                    i_prev = i;
                }
                entries[level[i].entry] |= 1 << d;
                match open {
                    None => entries.push(colour << 8),
                    Some(mut o) => {
                        o.entry = entries.len();
                        entries.push(0);
                        next.push(o);
                    }
                }
            }
            level = next;
        }
        // Whatever the budget, a finished tree keeps all its levels.
        let levels = if level.is_empty() { depth } else { levels };
        Ok(PackedTree {
            root: root as u32,
            depth,
            levels,
            empty: false,
        })
    }
}

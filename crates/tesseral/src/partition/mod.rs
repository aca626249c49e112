//! Partitions: a linear octree cut by code range into pieces whose concatenation is
//! the whole, the road past one machine's memory.
//!
//! A [`Partition`] is a code range `[lo, hi)` of one space. A [`PartitionedOctree`]
//! is a list of (range, [`LinearOctree`]) pairs whose ranges tile the space in
//! order, each tree holding only leaves inside its range (a leaf across a cut is
//! split into aligned blocks). Set operations run part by part after the operands
//! are re-split to the same ranges, in parallel (rayon); [`PartitionedOctree::concat`]
//! joins the parts, merging blocks across the cuts.
//!
//! On disk a partitioned dataset is a directory of `.tess` parts and a
//! `manifest.json` ([`dataset`]). A scene builds straight into one with bounded
//! memory ([`build_scene_dataset`]), and into a single streamed `.tess` file with
//! [`write_plan_tess`].

use std::ops::Range;

use rayon::prelude::*;

use crate::linear::{push_merging, Leaf, LinearOctree, OctreeError, SetOp};
use crate::Voxel;

mod blocks;
pub mod dataset;
mod merge;
mod models;
mod recut;
mod scan;
mod shuffle;
mod stream;
mod translate;

pub use dataset::{
    is_dataset, open_part, read_dataset, read_dataset_model, read_manifest, read_part,
    write_dataset, write_manifest, write_model_part, write_part, Manifest, ManifestPart, MANIFEST,
};
pub use merge::{stream_concat, stream_set_op, stream_set_op_files, stream_set_op_in};
pub use models::{
    build_scene_range, embedded_ranges, join_models, move_and_split, set_op_models, split_model,
};
pub use recut::{leaf_facts, leaf_ranges, stream_dataset, write_xyz, LeafFacts};
pub use shuffle::{
    balanced_ranges_exact, join_pieces, reach, set_op_part, translated_sample, translated_space,
    union_bbox, SAMPLE_PER_PART,
};
pub use stream::{
    build_scene_dataset, scene_ranges, write_plan_tess, write_plan_tess_coloured, StreamSummary,
};
pub use translate::{stream_translate, stream_translate_in, StreamTranslation, CELL_LEAVES};

/// Errors of partitioned octrees and datasets.
#[derive(Debug, thiserror::Error)]
pub enum PartitionError {
    /// Ranges that do not tile the space in order, or parts of other spaces.
    #[error("partition: {0}")]
    Ranges(String),
    /// An octree error.
    #[error(transparent)]
    Octree(#[from] OctreeError),
    /// A part file could not be read or written.
    #[error(transparent)]
    Format(#[from] crate::io::FormatError),
    /// A bad manifest: the file and what is wrong.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest or part file.
        path: std::path::PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// A code range `[lo, hi)` of one space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Partition {
    /// The first code of the range.
    pub lo: u64,
    /// One past the last code.
    pub hi: u64,
}

impl Partition {
    /// The range as a `Range`.
    #[must_use]
    pub fn range(self) -> Range<u64> {
        self.lo..self.hi
    }
}

/// Checks that `parts` tile `[0, 8^depth)` in order, each non-empty.
fn check_tiling(depth: u8, parts: &[Partition]) -> Result<(), PartitionError> {
    let end = 1u64 << (3 * u32::from(depth));
    let mut at = 0;
    for (i, p) in parts.iter().enumerate() {
        if p.lo != at || p.hi <= p.lo {
            return Err(PartitionError::Ranges(format!(
                "range {i} is [{}, {}) where one starting at {at} was expected",
                p.lo, p.hi
            )));
        }
        at = p.hi;
    }
    if at != end {
        return Err(PartitionError::Ranges(format!(
            "the ranges end at {at}, not at the end of the depth-{depth} space ({end})"
        )));
    }
    Ok(())
}

/// `k` ranges tiling the depth-`depth` space with about equal shares of `weights`
/// (code ranges, each counted once, sorted): the cuts fall between them. Fewer
/// ranges come back when there are fewer weights than `k`.
#[must_use]
pub fn balanced_ranges(depth: u8, k: usize, weights: &[Range<u64>]) -> Vec<Partition> {
    let end = 1u64 << (3 * u32::from(depth));
    let n = weights.len();
    // A cut falls at a weight's start: more parts than weights cannot be cut.
    let k = k.clamp(1, n.max(1));
    let mut cuts = vec![0u64];
    for j in 1..k {
        // In 128 bits: j · n passes 2^64 for a few billion weights.
        let i = (j as u128 * n as u128 / k as u128) as usize;
        if i == 0 || i >= n {
            continue;
        }
        let cut = weights[i].start;
        if cut > *cuts.last().expect("a cut") && cut < end {
            cuts.push(cut);
        }
    }
    cuts.push(end);
    cuts.windows(2)
        .map(|w| Partition { lo: w[0], hi: w[1] })
        .collect()
}

/// `k` ranges with about equal leaf counts of `tree` (sampling its leaves).
#[must_use]
pub fn balanced_ranges_of(tree: &LinearOctree, k: usize) -> Vec<Partition> {
    let w: Vec<Range<u64>> = tree.leaves().iter().map(|l| l.code()..l.end()).collect();
    balanced_ranges(tree.depth(), k, &w)
}

/// A linear octree cut into code ranges (see the module docs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartitionedOctree {
    depth: u8,
    origin: Voxel,
    parts: Vec<(Partition, LinearOctree)>,
}

/// The leaves of `leaves` inside `range`, clipped to it.
fn clip(leaves: &[Leaf], range: &Range<u64>) -> Vec<Leaf> {
    let first = leaves.partition_point(|l| l.end() <= range.start);
    let mut out = Vec::new();
    for &l in &leaves[first..] {
        if l.code() >= range.end {
            break;
        }
        crate::csg::clip_leaf(l, range, &mut out);
    }
    out
}

impl PartitionedOctree {
    /// Cuts `tree` into `ranges` (which must tile its space in order).
    ///
    /// # Errors
    /// [`PartitionError::Ranges`] for ranges that do not tile the space.
    pub fn split(tree: &LinearOctree, ranges: &[Partition]) -> Result<Self, PartitionError> {
        check_tiling(tree.depth(), ranges)?;
        let parts = ranges
            .par_iter()
            .map(|p| {
                let leaves = clip(tree.leaves(), &p.range());
                (
                    *p,
                    LinearOctree::from_parts(tree.depth(), tree.origin(), leaves),
                )
            })
            .collect();
        Ok(Self {
            depth: tree.depth(),
            origin: tree.origin(),
            parts,
        })
    }

    /// Assembles parts: each tree in the same space, its leaves inside its range,
    /// the ranges tiling the space.
    ///
    /// # Errors
    /// [`PartitionError::Ranges`] naming the part at fault.
    pub fn from_parts(
        depth: u8,
        origin: Voxel,
        parts: Vec<(Partition, LinearOctree)>,
    ) -> Result<Self, PartitionError> {
        LinearOctree::empty(depth, origin)?;
        let ranges: Vec<Partition> = parts.iter().map(|(p, _)| *p).collect();
        check_tiling(depth, &ranges)?;
        for (i, (p, t)) in parts.iter().enumerate() {
            if t.depth() != depth || t.origin() != origin {
                return Err(PartitionError::Ranges(format!(
                    "part {i} is in another space (depth {}, origin {:?})",
                    t.depth(),
                    t.origin()
                )));
            }
            if t.leaves().first().is_some_and(|l| l.code() < p.lo)
                || t.leaves().last().is_some_and(|l| l.end() > p.hi)
            {
                return Err(PartitionError::Ranges(format!(
                    "part {i} has leaves outside its range [{}, {})",
                    p.lo, p.hi
                )));
            }
        }
        Ok(Self {
            depth,
            origin,
            parts,
        })
    }

    /// The depth of the space.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The lowest voxel of the space.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The parts, in order.
    #[must_use]
    pub fn parts(&self) -> &[(Partition, LinearOctree)] {
        &self.parts
    }

    /// The ranges, in order.
    #[must_use]
    pub fn ranges(&self) -> Vec<Partition> {
        self.parts.iter().map(|(p, _)| *p).collect()
    }

    /// The whole tree: the parts joined, blocks merged across the cuts.
    #[must_use]
    pub fn concat(&self) -> LinearOctree {
        let n: usize = self.parts.iter().map(|(_, t)| t.leaf_count()).sum();
        let mut leaves = Vec::with_capacity(n);
        for (_, t) in &self.parts {
            for &l in t.leaves() {
                push_merging(&mut leaves, l);
            }
        }
        LinearOctree::from_parts(self.depth, self.origin, leaves)
    }

    /// The same tree cut into other ranges, part by part (each new part gathers the
    /// leaves of the old parts that meet its range).
    ///
    /// # Errors
    /// [`PartitionError::Ranges`] for ranges that do not tile the space.
    pub fn resplit(&self, ranges: &[Partition]) -> Result<Self, PartitionError> {
        check_tiling(self.depth, ranges)?;
        let parts = ranges
            .par_iter()
            .map(|p| {
                let r = p.range();
                let mut leaves = Vec::new();
                for (q, t) in &self.parts {
                    if q.hi > r.start && q.lo < r.end {
                        leaves.extend(clip(t.leaves(), &r));
                    }
                }
                (
                    *p,
                    LinearOctree::from_parts(self.depth, self.origin, leaves),
                )
            })
            .collect();
        Ok(Self {
            depth: self.depth,
            origin: self.origin,
            parts,
        })
    }

    /// A set operation part by part: `other` is re-split to these ranges first.
    ///
    /// # Errors
    /// [`PartitionError::Ranges`] when the spaces differ.
    pub fn set_op(&self, other: &Self, op: SetOp) -> Result<Self, PartitionError> {
        if (self.depth, self.origin) != (other.depth, other.origin) {
            return Err(PartitionError::Ranges(format!(
                "the operands are in different spaces (depth {} origin {:?}, depth {} origin {:?})",
                self.depth, self.origin, other.depth, other.origin
            )));
        }
        let other = if other.ranges() == self.ranges() {
            other.clone()
        } else {
            other.resplit(&self.ranges())?
        };
        let parts = self
            .parts
            .par_iter()
            .zip(other.parts.par_iter())
            .map(|((p, a), (_, b))| Ok((*p, set_op_part(a, b, op)?)))
            .collect::<Result<_, PartitionError>>()?;
        Ok(Self {
            depth: self.depth,
            origin: self.origin,
            parts,
        })
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_models;
#[cfg(test)]
mod tests_shuffle;

#[cfg(test)]
mod tests_parts;
#[cfg(test)]
mod tests_recut;
#[cfg(test)]
mod tests_translate;

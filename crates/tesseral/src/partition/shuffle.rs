//! The pieces of partitioned work that a distributed engine schedules one by one
//! (the Python package's `tesseral.dask` calls them in its tasks): a set operation
//! of two parts, the union of the pieces that land in one range, and a translation
//! as a shuffle between ranges: each source part is moved into the result's space
//! and cut by the target ranges; the pieces of each target range are joined.
//!
//! [`PartitionedOctree::translate`] runs the same steps in one process; it is what
//! the distributed version is tested against.

use std::ops::Range;

use rayon::prelude::*;

use super::{balanced_ranges, Partition, PartitionError, PartitionedOctree};
use crate::linear::{grow, push_merging, Leaf, LinearOctree, OctreeError, SetOp};
use crate::Voxel;

/// The set operation of two parts of one space cut to the same range: the result
/// lies in that range and is canonical.
///
/// # Errors
/// [`PartitionError::Ranges`] when the parts are in different spaces.
pub fn set_op_part(
    a: &LinearOctree,
    b: &LinearOctree,
    op: SetOp,
) -> Result<LinearOctree, PartitionError> {
    same_space(a, b)?;
    // The merge of two clipped parts need not come out canonical (eight siblings
    // from the two operands); one pass merges them.
    let r = a.set_op_same_space(b, op);
    let mut leaves = Vec::with_capacity(r.leaf_count());
    for &l in r.leaves() {
        push_merging(&mut leaves, l);
    }
    Ok(LinearOctree::from_parts(a.depth(), a.origin(), leaves))
}

fn same_space(a: &LinearOctree, b: &LinearOctree) -> Result<(), PartitionError> {
    if (a.depth(), a.origin()) != (b.depth(), b.origin()) {
        return Err(PartitionError::Ranges(format!(
            "the operands are in different spaces (depth {} origin {:?}, depth {} origin {:?})",
            a.depth(),
            a.origin(),
            b.depth(),
            b.origin()
        )));
    }
    Ok(())
}

/// The union of pieces of one space (the pieces that a shuffle sends to one range);
/// an empty tree of `(depth, origin)` when there are none. Disjoint pieces (those
/// of a shuffle) are joined in one pass, a k-way merge taking runs of one piece at
/// a time; overlapping ones by pairwise unions.
///
/// # Runtime
/// O(n + r log k) for n leaves in all, k pieces and r runs, when disjoint.
///
/// # Errors
/// [`PartitionError::Ranges`] when a piece is in another space.
pub fn join_pieces(
    depth: u8,
    origin: Voxel,
    pieces: Vec<LinearOctree>,
) -> Result<LinearOctree, PartitionError> {
    let empty = LinearOctree::empty(depth, origin)?;
    for p in &pieces {
        same_space(&empty, p)?;
    }
    if let Some(leaves) = merge_disjoint(&pieces) {
        return Ok(LinearOctree::from_parts(depth, origin, leaves));
    }
    let mut level = pieces;
    while level.len() > 1 {
        level = level
            .par_chunks(2)
            .map(|w| match w {
                [a, b] => set_op_part(a, b, SetOp::Union),
                [a] => Ok(a.clone()),
                _ => unreachable!("chunks of two"),
            })
            .collect::<Result<_, _>>()?;
    }
    Ok(level.pop().unwrap_or(empty))
}

/// The leaves of sorted, pairwise disjoint pieces merged into one canonical list (a
/// k-way merge on a heap), or `None` at the first overlap.
fn merge_disjoint(pieces: &[LinearOctree]) -> Option<Vec<Leaf>> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let n: usize = pieces.iter().map(LinearOctree::leaf_count).sum();
    let mut heap: BinaryHeap<Reverse<(Leaf, usize, usize)>> = pieces
        .iter()
        .enumerate()
        .filter_map(|(p, t)| t.leaves().first().map(|&l| Reverse((l, p, 0))))
        .collect();
    let mut out: Vec<Leaf> = Vec::with_capacity(n);
    let mut end = 0u64;
    while let Some(Reverse((l, p, i))) = heap.pop() {
        if !out.is_empty() && l.code() < end {
            return None;
        }
        end = l.end();
        push_merging(&mut out, l);
        // Take the rest of this piece while it stays below every other head.
        let leaves = pieces[p].leaves();
        let mut j = i + 1;
        let bound = heap.peek().map(|Reverse((h, _, _))| h.code());
        while j < leaves.len() && bound.is_none_or(|b| leaves[j].code() < b) {
            if leaves[j].code() < end {
                return None;
            }
            end = leaves[j].end();
            push_merging(&mut out, leaves[j]);
            j += 1;
        }
        if j < leaves.len() {
            heap.push(Reverse((leaves[j], p, j)));
        }
    }
    Some(out)
}

/// The space that [`LinearOctree::translate`] gives a tree of space
/// `(depth, origin)` whose black voxels have the bounding box `bbox`, moved by `by`:
/// the same space when the moved box fits, else the space grown by root expansion.
///
/// # Errors
/// As [`LinearOctree::translate`].
pub fn translated_space(
    depth: u8,
    origin: Voxel,
    bbox: Option<(Voxel, Voxel)>,
    by: [i64; 3],
) -> Result<(u8, Voxel), OctreeError> {
    LinearOctree::empty(depth, origin)?;
    let Some((lo, hi)) = bbox else {
        return Ok((depth, origin));
    };
    let add = |v: Voxel| -> Result<Voxel, OctreeError> {
        let mut out = [0i64; 3];
        for a in 0..3 {
            out[a] = v[a].checked_add(by[a]).ok_or(OctreeError::Overflow)?;
        }
        Ok(out)
    };
    grow::grown_space(depth, origin, add(lo)?, add(hi)?)
}

/// The bounding box of the union of boxes (`None` for none).
#[must_use]
pub fn union_bbox(
    boxes: impl IntoIterator<Item = Option<(Voxel, Voxel)>>,
) -> Option<(Voxel, Voxel)> {
    boxes
        .into_iter()
        .flatten()
        .reduce(|(alo, ahi), (blo, bhi)| {
            (
                std::array::from_fn(|a| alo[a].min(blo[a])),
                std::array::from_fn(|a| ahi[a].max(bhi[a])),
            )
        })
}

/// A sample of where the leaves of `part`, moved by `by`, land in the space
/// `(depth, origin)`: the codes there of the lowest voxel of about `max` of its
/// leaves, evenly spaced, sorted (voxels landing outside are skipped).
#[must_use]
pub fn translated_sample(
    part: &LinearOctree,
    by: [i64; 3],
    depth: u8,
    origin: Voxel,
    max: usize,
) -> Vec<u64> {
    let Ok(target) = LinearOctree::empty(depth, origin) else {
        return Vec::new();
    };
    let leaves = part.leaves();
    let step = leaves.len().div_ceil(max.max(1)).max(1);
    let mut codes: Vec<u64> = leaves
        .iter()
        .step_by(step)
        .filter_map(|l| {
            let v = part.voxel_of(l.code());
            let mut w = [0i64; 3];
            for a in 0..3 {
                w[a] = v[a].checked_add(by[a])?;
            }
            target.code_of(w)
        })
        .collect();
    codes.sort_unstable();
    codes
}

/// Exactly `k` ranges tiling the depth-`depth` space (fewer only when the space
/// has fewer than `k` codes): [`balanced_ranges`] of the sorted sample `codes`,
/// the widest range halved while there are fewer than `k`.
#[must_use]
pub fn balanced_ranges_exact(depth: u8, k: usize, codes: &[u64]) -> Vec<Partition> {
    let w: Vec<Range<u64>> = codes.iter().map(|&c| c..c + 1).collect();
    let mut ranges = balanced_ranges(depth, k, &w);
    while ranges.len() < k {
        let (i, widest) = ranges
            .iter()
            .enumerate()
            .max_by_key(|(_, p)| p.hi - p.lo)
            .map(|(i, p)| (i, *p))
            .expect("at least one range");
        if widest.hi - widest.lo < 2 {
            break;
        }
        let mid = widest.lo + (widest.hi - widest.lo) / 2;
        ranges[i].hi = mid;
        ranges.insert(
            i + 1,
            Partition {
                lo: mid,
                hi: widest.hi,
            },
        );
    }
    ranges
}

/// Leaves sampled per part to balance the ranges of a translation.
pub const SAMPLE_PER_PART: usize = 4096;

impl PartitionedOctree {
    /// The tree translated by `by`, cut into `k` ranges of the result balanced on a
    /// sample of the moved leaves: each part is moved into the result's space (that
    /// of [`LinearOctree::translate`] on the whole tree) and cut by the new ranges,
    /// and the pieces of each range are joined. The in-process form of the shuffle
    /// that `tesseral.dask.translate` runs as tasks.
    ///
    /// # Errors
    /// As [`LinearOctree::translate`].
    pub fn translate(&self, by: [i64; 3], k: usize) -> Result<Self, PartitionError> {
        let bbox = union_bbox(self.parts.iter().map(|(_, t)| t.bbox()));
        let (depth, origin) = translated_space(self.depth, self.origin, bbox, by)?;
        let mut sample: Vec<u64> = self
            .parts
            .iter()
            .flat_map(|(_, t)| translated_sample(t, by, depth, origin, SAMPLE_PER_PART))
            .collect();
        sample.sort_unstable();
        let ranges = balanced_ranges_exact(depth, k, &sample);
        let pieces: Vec<Vec<LinearOctree>> = self
            .parts
            .par_iter()
            .map(|(_, t)| -> Result<_, PartitionError> {
                let (moved, _) = t.translate_into(by, depth, origin)?;
                let cut = PartitionedOctree::split(&moved, &ranges)?;
                Ok(cut.parts.into_iter().map(|(_, t)| t).collect())
            })
            .collect::<Result<_, _>>()?;
        let parts = ranges
            .par_iter()
            .enumerate()
            .map(|(j, p)| {
                let mine = pieces.iter().map(|v| v[j].clone()).collect();
                Ok((*p, join_pieces(depth, origin, mine)?))
            })
            .collect::<Result<_, PartitionError>>()?;
        Self::from_parts(depth, origin, parts)
    }
}

/// Where the leaves of each source range can land: for each of `src_ranges` (code
/// ranges of the space `src`), the indices, in order, of the `dst_ranges` (code
/// ranges of the space `dst`, sorted and disjoint) that its voxels, moved by `by`,
/// can fall in. Computed from the ranges alone, never from leaves: a superset of
/// where any tree's leaves go, so a shuffle sends each source part only to these
/// targets (its pieces for the others would be empty).
///
/// Each source range is cut into its maximal aligned cells (at most 14 per level);
/// a cell of side `2^k`, moved, meets at most eight aligned cells of that side in
/// `dst`, each one code interval; the targets are the ranges those intervals meet.
///
/// # Runtime
/// O(n · depth · (1 + log m)) plus the output, for n source and m target ranges.
///
/// # Errors
/// [`PartitionError::Ranges`] for a bad space or a range outside its space.
pub fn reach(
    src: (u8, Voxel),
    src_ranges: &[Partition],
    by: [i64; 3],
    dst: (u8, Voxel),
    dst_ranges: &[Partition],
) -> Result<Vec<Vec<usize>>, PartitionError> {
    LinearOctree::empty(src.0, src.1)?;
    LinearOctree::empty(dst.0, dst.1)?;
    let (src_end, dst_end) = (space_end(src.0), space_end(dst.0));
    let check = |ranges: &[Partition], end: u64, what: &str| {
        let mut at = 0;
        for (i, p) in ranges.iter().enumerate() {
            if p.lo < at || p.hi < p.lo || p.hi > end {
                return Err(PartitionError::Ranges(format!(
                    "{what} range {i} [{}, {}) is out of order or outside its space (codes below {end})",
                    p.lo, p.hi
                )));
            }
            at = p.hi;
        }
        Ok(())
    };
    check(src_ranges, src_end, "source")?;
    check(dst_ranges, dst_end, "target")?;
    Ok(src_ranges
        .iter()
        .map(|p| {
            let mut intervals = Vec::new();
            for (code, k) in aligned_cells(p.lo, p.hi, src.0) {
                moved_cell_intervals(src, code, k, by, dst, &mut intervals);
            }
            targets(&mut intervals, dst_ranges)
        })
        .collect())
}

fn space_end(depth: u8) -> u64 {
    // 8^21 = 2^63 fits; deeper spaces are refused by `LinearOctree::empty` first.
    1u64 << (3 * u32::from(depth))
}

/// The maximal aligned cells `(code, k)` (`8^k` codes from `code`, a multiple of
/// `8^k`) whose union is `[lo, hi)`, in order.
fn aligned_cells(lo: u64, hi: u64, depth: u8) -> Vec<(u64, u8)> {
    let mut out = Vec::new();
    let mut c = lo;
    while c < hi {
        let mut k = 0u8;
        while k < depth {
            let size = 1u64 << (3 * (u32::from(k) + 1));
            if c % size != 0 || hi - c < size {
                break;
            }
            k += 1;
        }
        out.push((c, k));
        c += 1u64 << (3 * u32::from(k));
    }
    out
}

/// Pushes the code intervals of `dst` that the source cell `(code, k)` of `src`,
/// moved by `by`, can meet: the aligned cells of side `2^min(k, dst depth)`
/// covering its moved box, clipped to the space.
fn moved_cell_intervals(
    src: (u8, Voxel),
    code: u64,
    k: u8,
    by: [i64; 3],
    dst: (u8, Voxel),
    out: &mut Vec<(u64, u64)>,
) {
    let rel = crate::code::decode(code);
    let dst_side = 1i128 << dst.0;
    let kk = k.min(dst.0);
    let mut cells = [(0u32, 0u32); 3];
    for a in 0..3 {
        let lo =
            i128::from(src.1[a]) + i128::from(rel[a]) + i128::from(by[a]) - i128::from(dst.1[a]);
        let hi = (lo + (1i128 << k)).min(dst_side);
        let lo = lo.max(0);
        if lo >= hi {
            return;
        }
        // Within the space: below 2^21, so the cell indices fit u32.
        cells[a] = ((lo >> kk) as u32, ((hi - 1) >> kk) as u32);
    }
    let size = 1u64 << (3 * u32::from(kk));
    for z in cells[2].0..=cells[2].1 {
        for y in cells[1].0..=cells[1].1 {
            for x in cells[0].0..=cells[0].1 {
                let c = crate::code::encode(x << kk, y << kk, z << kk);
                out.push((c, c + size));
            }
        }
    }
}

/// The indices of the sorted, disjoint `ranges` that meet any of `intervals`.
fn targets(intervals: &mut [(u64, u64)], ranges: &[Partition]) -> Vec<usize> {
    intervals.sort_unstable();
    let mut out: Vec<usize> = Vec::new();
    let mut from = 0usize;
    for &(lo, hi) in intervals.iter() {
        // The first range ending past lo, no earlier than the last one taken.
        let mut j = from + ranges[from..].partition_point(|p| p.hi <= lo);
        while j < ranges.len() && ranges[j].lo < hi {
            if ranges[j].hi > ranges[j].lo && out.last() != Some(&j) {
                out.push(j);
            }
            j += 1;
        }
        from = j.saturating_sub(1).max(from);
    }
    out
}

//! The canonical form of a leaf list (sorted, disjoint, aligned, no eight black
//! siblings left unmerged): merging while appending, and checking it.

use super::bricked::Bricked;
use super::{check_space, Leaf, LinearOctree, MAX_DEPTH};

impl LinearOctree {
    /// Panics with a description of the first broken invariant: leaves sorted, disjoint,
    /// aligned to their size, inside the space, and canonically merged; and, when the
    /// tree holds its bricked form, that form's invariants and its agreement with the
    /// leaves.
    ///
    /// # Runtime
    /// O(n).
    pub fn assert_valid(&self) {
        assert!(
            self.depth <= MAX_DEPTH,
            "depth {} > {MAX_DEPTH}",
            self.depth
        );
        assert!(
            check_space(self.depth, self.origin).is_ok(),
            "the space from {:?} runs past i64",
            self.origin
        );
        let space_end = 1u64 << (3 * u32::from(self.depth));
        // Checked without keeping a leaf list made from the bricked form, so that
        // the check leaves the tree as it found it.
        let made;
        let leaves: &[Leaf] = match (self.leaves.get(), self.bricked.get()) {
            (Some(l), _) => l,
            (None, Some(b)) => {
                made = b.to_leaves();
                &made
            }
            (None, None) => panic!("a tree holds neither form"),
        };
        if let Some(b) = self.bricked.get() {
            b.assert_valid(self.depth);
            assert!(
                *b == Bricked::from_leaves(leaves),
                "the bricked form and the leaves disagree"
            );
        }
        for (i, l) in leaves.iter().enumerate() {
            assert!(
                l.size_log2() <= self.depth,
                "leaf {i} larger than the space"
            );
            assert_eq!(
                l.code() % l.voxel_count(),
                0,
                "leaf {i} not aligned to its size"
            );
            assert!(l.end() <= space_end, "leaf {i} outside the space");
            if i > 0 {
                let p = leaves[i - 1];
                assert!(
                    p.end() <= l.code(),
                    "leaves {} and {i} unsorted or overlapping",
                    i - 1
                );
            }
            if i >= 7 {
                let run = &leaves[i - 7..=i];
                assert!(
                    !completes_parent(run),
                    "leaves {}..={i} are eight unmerged siblings",
                    i - 7
                );
            }
        }
    }
}

/// Whether eight leaves (sorted, disjoint) are the eight children of one parent.
pub(super) fn completes_parent(run: &[Leaf]) -> bool {
    let k = run[0].size_log2();
    let parent_cells = 8 * run[0].voxel_count();
    run.iter().all(|l| l.size_log2() == k)
        && run[0].code() % parent_cells == 0
        && run[7].code() == run[0].code() + 7 * run[0].voxel_count()
}

/// [`completes_parent`] on packed values: the eight leaves are children 0..=7 of one
/// parent exactly when their packed forms step by `2 · 8^k` from a child 0.
#[inline]
pub(super) fn completes_parent_fast(run: &[Leaf]) -> bool {
    let p0 = run[0].packed();
    let t = p0.trailing_ones(); // 3k
    if t + 4 > 64 {
        return false;
    }
    // Child 0: the code's digit k is zero (packed bits t+1 ..= t+3).
    if (p0 >> (t + 1)) & 7 != 0 {
        return false;
    }
    let step = 2u64 << t;
    let mut want = p0;
    for l in &run[1..8] {
        want += step;
        if l.packed() != want {
            return false;
        }
    }
    true
}

/// Appends `leaf` (which follows every leaf in `out`) and merges complete sibling
/// octets bottom-up, so that `out` stays canonical.
pub(crate) fn push_merging(out: &mut Vec<Leaf>, leaf: Leaf) {
    out.push(leaf);
    // Only the last child (label 7) of a parent can complete it: skip the check
    // for the other seven (read the label straight off the packed leaf).
    let p = leaf.packed();
    if p.checked_shr(p.trailing_ones() + 1).unwrap_or(0) & 7 != 7 {
        return;
    }
    while out.len() >= 8 && completes_parent_fast(&out[out.len() - 8..]) {
        let first = out[out.len() - 8];
        out.truncate(out.len() - 8);
        out.push(Leaf::new(first.code(), first.size_log2() + 1));
    }
}

/// Sorted, disjoint leaves merged into canonical form as they come, as
/// [`push_merging`] does, each given out (with the tag of the first leaf it was
/// merged from) as soon as no later leaf can merge it: when the leaves have passed
/// the end of its parent, or left a gap before that end. So a stream is made
/// canonical holding only the leaves that may still merge: about seven per level
/// for a canonical input.
///
/// # Runtime
/// O(1) amortized per leaf, plus O(held) when leaves are given out.
pub(crate) struct MergingStream<T> {
    held: Vec<Leaf>,
    tags: Vec<T>,
    /// The end of the last leaf pushed.
    end: Option<u64>,
    depth: u8,
}

impl<T: Copy> MergingStream<T> {
    /// An empty stream of a depth-`depth` space.
    pub(crate) fn new(depth: u8) -> Self {
        Self {
            held: Vec::new(),
            tags: Vec::new(),
            end: None,
            depth,
        }
    }

    /// Adds the next leaf (at or after the end of the one before it), tagged `tag`,
    /// and appends to `out` the merged leaves that are final.
    pub(crate) fn push(&mut self, leaf: Leaf, tag: T, out: &mut Vec<(Leaf, T)>) {
        if self.end.is_some_and(|e| e != leaf.code()) {
            // A gap: no parent of a held leaf can be completed any more.
            self.flush(out);
        }
        self.end = Some(leaf.end());
        push_merging(&mut self.held, leaf);
        self.tags.push(tag);
        // A merged leaf keeps the tag of its first child, which sits where it does.
        self.tags.truncate(self.held.len());
        let end = leaf.end();
        let done = self
            .held
            .iter()
            .take_while(|l| {
                let k = u32::from(l.size_log2()) + 1;
                k > u32::from(self.depth) || {
                    let parent_end = (l.code() >> (3 * k) << (3 * k)) + (1u64 << (3 * k));
                    end >= parent_end
                }
            })
            .count();
        out.extend(self.held.drain(..done).zip(self.tags.drain(..done)));
    }

    /// Appends every held leaf to `out` (at the end of the stream).
    pub(crate) fn flush(&mut self, out: &mut Vec<(Leaf, T)>) {
        out.extend(self.held.drain(..).zip(self.tags.drain(..)));
    }
}

/// Whether sorted, disjoint leaves are canonical: no eight of them, one after
/// another, complete their parent (the first merge [`push_merging`] would make is
/// of eight leaves in a row). Stops at the first error of `leaves`, which it
/// leaves to the reader.
///
/// # Runtime
/// O(n).
pub(crate) fn is_canonical_stream<E>(leaves: impl Iterator<Item = Result<Leaf, E>>) -> bool {
    let mut last = [Leaf::new(0, 0); 8];
    for (i, l) in leaves.enumerate() {
        let Ok(l) = l else { return true };
        last.copy_within(1.., 0);
        last[7] = l;
        if i >= 7 && completes_parent_fast(&last) {
            return false;
        }
    }
    true
}

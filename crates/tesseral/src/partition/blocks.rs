//! Sorted leaves kept in blocks that are decoded one at a time and found by code
//! range: the chunks of a `.tess` file (through its index), or a colour region cut
//! into stretches. The streamed translation reads each output cell's window from
//! them, holding a few decoded blocks, never the tree.

use crate::io::{ChunkInfo, FormatError, RegionLeaves, TessFile};
use crate::linear::Leaf;

/// Decoded blocks kept for the next windows (neighbouring output cells read
/// neighbouring blocks).
const CACHED: usize = 4;
/// Decodes between two releases of the whole map.
const SWEEP_EVERY: u64 = 64;

enum Source<'a> {
    File(&'a TessFile),
    Region(&'a TessFile, Vec<RegionLeaves<'a>>),
}

/// Leaves in sorted blocks of known code ranges and counts.
pub(super) struct Blocks<'a> {
    source: Source<'a>,
    info: Vec<ChunkInfo>,
    /// `before[i]`: the leaves of blocks `0..i`.
    before: Vec<u64>,
    cache: Vec<(usize, Vec<Leaf>)>,
    decodes: u64,
}

impl<'a> Blocks<'a> {
    fn new(source: Source<'a>, info: Vec<ChunkInfo>) -> Self {
        let mut before = Vec::with_capacity(info.len() + 1);
        let mut n = 0;
        before.push(0);
        for c in &info {
            n += c.count;
            before.push(n);
        }
        Self {
            source,
            info,
            before,
            cache: Vec::with_capacity(CACHED),
            decodes: 0,
        }
    }

    /// The chunks of `f`.
    pub(super) fn of_file(f: &'a TessFile) -> Self {
        Self::new(Source::File(f), f.chunks())
    }

    /// A colour region's stretches found as it was read (by the first pass of a
    /// streamed translation: `partition::scan`), with `f` the file it lies in.
    pub(super) fn of_stretches(
        f: &'a TessFile,
        stretches: Vec<(ChunkInfo, RegionLeaves<'a>)>,
    ) -> Self {
        let (info, parts): (Vec<ChunkInfo>, _) = stretches.into_iter().unzip();
        Self::new(Source::Region(f, parts), info)
    }

    /// The blocks meeting the code range `[lo, hi)`, as an index range.
    fn meeting(&self, lo: u64, hi: u64) -> std::ops::Range<usize> {
        let first = self.info.partition_point(|c| c.hi <= lo);
        let last = self.info.partition_point(|c| c.lo < hi);
        first..last.max(first)
    }

    /// At least the number of leaves meeting `[lo, hi)` (the counts of the blocks
    /// that meet it), and the number of those blocks: from the index, nothing is
    /// decoded.
    pub(super) fn bound(&self, lo: u64, hi: u64) -> (u64, usize) {
        let r = self.meeting(lo, hi);
        (self.before[r.end] - self.before[r.start], r.len())
    }

    /// Hands `take` the leaves meeting `[lo, hi)`, a block's share at a time, in
    /// order; blocks whose share of the range `wanted` refuses are not decoded.
    pub(super) fn read(
        &mut self,
        lo: u64,
        hi: u64,
        wanted: &dyn Fn(u64, u64) -> bool,
        take: &mut dyn FnMut(&[Leaf]),
    ) -> Result<(), FormatError> {
        for i in self.meeting(lo, hi) {
            let c = self.info[i];
            if !wanted(c.lo.max(lo), c.hi.min(hi)) {
                continue;
            }
            let leaves = self.block(i)?;
            let first = leaves.partition_point(|l| l.end() <= lo);
            let last = leaves.partition_point(|l| l.code() < hi);
            take(&leaves[first..last.max(first)]);
        }
        Ok(())
    }

    /// Lets the mapped bytes of block `i` leave resident memory (see
    /// [`TessFile::release`]); it may be decoded again later.
    pub(super) fn release(&self, i: usize) {
        let f = self.file();
        let end = self.info.get(i + 1).map_or(u64::MAX, |c| c.offset);
        f.release(self.info[i].offset..end);
    }

    fn file(&self) -> &'a TessFile {
        match &self.source {
            Source::File(f) | Source::Region(f, _) => f,
        }
    }

    /// The number of blocks.
    pub(super) fn len(&self) -> usize {
        self.info.len()
    }

    /// Block `i`, decoded (or from the cache).
    fn block(&mut self, i: usize) -> Result<&[Leaf], FormatError> {
        let at = match self.cache.iter().position(|(j, _)| *j == i) {
            Some(at) => at,
            None => {
                let leaves = match &self.source {
                    Source::File(f) => f.chunk(i)?,
                    Source::Region(_, parts) => parts[i].clone().collect::<Result<Vec<_>, _>>()?,
                };
                if self.cache.len() == CACHED {
                    let (j, _) = self.cache.remove(0);
                    self.release(j);
                }
                // Page faults map neighbouring pages too (fault-around), which the
                // releases above miss: now and then let the whole map go.
                self.decodes += 1;
                if self.decodes % SWEEP_EVERY == 0 {
                    self.file().release(0..u64::MAX);
                }
                self.cache.push((i, leaves));
                self.cache.len() - 1
            }
        };
        Ok(&self.cache[at].1)
    }
}

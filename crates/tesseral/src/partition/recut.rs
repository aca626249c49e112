//! A `.tess` file or a dataset, read as one stream of leaves in code order (its
//! files one after the other, a chunk decoded at a time), re-cut into a dataset
//! ([`stream_dataset`], with ranges of equal leaf counts from [`leaf_ranges`]) or
//! written as an `.xyz` voxel list ([`write_xyz`], after one counting pass,
//! [`leaf_facts`]). Memory: a decoded chunk, the writer's chunk and a spool buffer
//! per colour; the mapped pages of each chunk are let go once it is read
//! ([`TessFile::release`]), so the resident set does not grow with the input.

use std::io::{self, Write};
use std::path::Path;

use super::dataset::{part_name, write_manifest, ManifestPart};
use super::merge::operand_colours;
use super::{check_tiling, Partition, PartitionError};
use crate::io::{FormatError, LeafIter, LeafSpool, TessFile, TessWriter};
use crate::linear::{push_merging, Leaf};
use crate::model::Frame;
use crate::Voxel;

/// The space `(depth, origin)` of files that must share one.
fn space(files: &[TessFile]) -> Result<(u8, Voxel), PartitionError> {
    let f = files
        .first()
        .ok_or_else(|| PartitionError::Ranges("no files to read".into()))?;
    let s = (f.depth(), f.origin());
    if files.iter().any(|g| (g.depth(), g.origin()) != s) {
        return Err(PartitionError::Ranges(
            "the files are in different spaces".into(),
        ));
    }
    Ok(s)
}

/// The leaves of files that follow each other in code order, one chunk decoded
/// at a time, the mapped pages of a chunk let go once it is read; an error when
/// the leaves overlap or go back.
struct FileLeaves<'a> {
    files: &'a [TessFile],
    file: usize,
    chunks: Vec<crate::io::ChunkInfo>,
    chunk: usize,
    buf: std::vec::IntoIter<Leaf>,
    end: u64,
}

impl<'a> FileLeaves<'a> {
    fn new(files: &'a [TessFile]) -> Self {
        Self {
            files,
            file: 0,
            chunks: files.first().map(TessFile::chunks).unwrap_or_default(),
            chunk: 0,
            buf: Vec::new().into_iter(),
            end: 0,
        }
    }

    /// Decodes the next chunk into `buf`; `false` past the last file.
    fn refill(&mut self) -> Result<bool, FormatError> {
        loop {
            let Some(f) = self.files.get(self.file) else {
                return Ok(false);
            };
            if self.chunk < self.chunks.len() {
                let i = self.chunk;
                self.buf = f.chunk(i)?.into_iter();
                let next = self.chunks.get(i + 1).map_or(u64::MAX, |c| c.offset);
                f.release(self.chunks[i].offset..next);
                self.chunk += 1;
                return Ok(true);
            }
            self.file += 1;
            self.chunk = 0;
            self.chunks = self
                .files
                .get(self.file)
                .map(TessFile::chunks)
                .unwrap_or_default();
        }
    }
}

impl Iterator for FileLeaves<'_> {
    type Item = Result<Leaf, FormatError>;
    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(l) = self.buf.next() {
                if l.code() < self.end {
                    return Some(Err(out_of_order()));
                }
                self.end = l.end();
                return Some(Ok(l));
            }
            match self.refill() {
                Ok(true) => {}
                Ok(false) => return None,
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

fn out_of_order() -> FormatError {
    FormatError::corrupt("the parts overlap or are out of code order")
}

/// A colour region's leaves, checked to go forward.
fn ordered(mut it: LeafIter<'_>) -> LeafIter<'_> {
    let mut end = 0u64;
    Box::new(std::iter::from_fn(move || {
        let l = match it.next()? {
            Ok(l) => l,
            Err(e) => return Some(Err(e)),
        };
        if l.code() < end {
            return Some(Err(out_of_order()));
        }
        end = l.end();
        Some(Ok(l))
    }))
}

/// `k` (or fewer) ranges tiling the space of `files` with about equal leaf
/// counts: the cuts fall at the codes of the leaves numbered `j·n/k` of the `n`
/// leaves read in order, as [`super::balanced_ranges_of`] cuts a tree. The leaf
/// counts come from the chunk index; one chunk is decoded per cut.
///
/// # Errors
/// [`PartitionError`] for files of different spaces or a bad chunk.
pub fn leaf_ranges(files: &[TessFile], k: usize) -> Result<Vec<Partition>, PartitionError> {
    let (depth, _) = space(files)?;
    let end = 1u64 << (3 * u32::from(depth));
    // (file, chunk, leaves before it) for every chunk.
    let mut at = Vec::new();
    let mut n = 0u64;
    for (fi, f) in files.iter().enumerate() {
        for (ci, c) in f.chunks().iter().enumerate() {
            at.push((fi, ci, n));
            n += c.count;
        }
    }
    let k = k.max(1) as u128;
    let mut cuts = vec![0u64];
    let mut cached: Option<((usize, usize), Vec<Leaf>)> = None;
    for j in 1..k {
        let i = (j * u128::from(n) / k) as u64;
        if i == 0 || i >= n {
            continue;
        }
        let slot = at.partition_point(|&(_, _, before)| before <= i) - 1;
        let (fi, ci, before) = at[slot];
        if cached.as_ref().map(|(key, _)| *key) != Some((fi, ci)) {
            cached = Some(((fi, ci), files[fi].chunk(ci)?));
        }
        let leaves = &cached.as_ref().expect("decoded").1;
        let leaf = leaves.get((i - before) as usize).ok_or_else(|| {
            FormatError::corrupt(format!("chunk {ci} holds fewer leaves than its index says"))
                .with_path(files[fi].path())
        })?;
        let cut = leaf.code();
        if cut > *cuts.last().expect("a cut") && cut < end {
            cuts.push(cut);
        }
    }
    cuts.push(end);
    Ok(cuts
        .windows(2)
        .map(|w| Partition { lo: w[0], hi: w[1] })
        .collect())
}

/// Hands `push` the leaves of `it` inside `p`, clipped to it; a leaf that runs
/// past `p` is kept in `held` for the next range.
fn take(
    it: &mut dyn Iterator<Item = Result<Leaf, FormatError>>,
    held: &mut Option<Leaf>,
    p: Partition,
    push: &mut dyn FnMut(Leaf) -> io::Result<()>,
) -> Result<(), PartitionError> {
    let io = |e: io::Error| PartitionError::Format(FormatError::io(e));
    let mut pieces = Vec::new();
    loop {
        let l = match held.take() {
            Some(l) => l,
            None => match it.next() {
                None => return Ok(()),
                Some(r) => r?,
            },
        };
        if l.code() >= p.hi {
            *held = Some(l);
            return Ok(());
        }
        if p.lo <= l.code() && l.end() <= p.hi {
            push(l).map_err(io)?;
            continue;
        }
        pieces.clear();
        crate::csg::clip_leaf(l, &p.range(), &mut pieces);
        for &x in &pieces {
            push(x).map_err(io)?;
        }
        if l.end() > p.hi {
            *held = Some(l);
            return Ok(());
        }
    }
}

/// Writes the leaves and colour regions of `files` (one `.tess` file, or a
/// dataset's parts, read in code order as one stream) into the directory `dir`
/// (which must exist) as a dataset cut at `ranges`: `part-00000.tess`, … (each
/// written atomically, with `frame` and its share of the colours, a leaf across a
/// cut split into aligned blocks), then `manifest.json`. The parts hold the bytes
/// that [`super::write_model_part`] writes for the model cut into the same ranges.
/// Colour spools are temporary files in `dir`.
///
/// # Runtime
/// One pass over the leaves and colour regions.
///
/// # Errors
/// [`PartitionError::Ranges`] for ranges that do not tile the space, files of
/// different spaces, or files with layers other than colours;
/// [`PartitionError::Format`] for a bad chunk, files out of order or a write error.
pub fn stream_dataset(
    files: &[TessFile],
    frame: Frame,
    ranges: &[Partition],
    dir: &Path,
) -> Result<Vec<ManifestPart>, PartitionError> {
    let (depth, origin) = space(files)?;
    check_tiling(depth, ranges)?;
    let mut leaves = FileLeaves::new(files);
    let mut held = None;
    let mut colours: Vec<(crate::model::Rgba, LeafIter<'_>, Option<Leaf>)> =
        operand_colours(files)?
            .into_iter()
            .map(|(c, it)| (c, ordered(it), None))
            .collect();
    let mut parts = Vec::with_capacity(ranges.len());
    for (i, p) in ranges.iter().enumerate() {
        let name = part_name(i);
        let (mut count, mut voxels) = (0u64, 0u64);
        let mut failure = None;
        let written = crate::io::write_atomic(&dir.join(&name), |w| {
            let mut tw = TessWriter::new(w, depth, origin)?;
            let mut run = || -> Result<Vec<_>, PartitionError> {
                take(&mut leaves, &mut held, *p, &mut |l| {
                    voxels += l.voxel_count();
                    tw.push(l)
                })?;
                let mut spools = Vec::with_capacity(colours.len());
                for (c, it, h) in &mut colours {
                    let mut s = LeafSpool::new_in(dir).map_err(FormatError::io)?;
                    take(it, h, *p, &mut |l| s.push(l))?;
                    spools.push((*c, s));
                }
                Ok(spools)
            };
            match run() {
                Ok(spools) => {
                    count = tw.leaf_count();
                    tw.finish_spooled(frame, spools)?;
                    Ok(())
                }
                Err(e) => {
                    failure = Some(e);
                    Err(io::Error::other("stopped"))
                }
            }
        });
        if let Some(e) = failure {
            return Err(e);
        }
        written?;
        parts.push(ManifestPart::of_file(dir, name, *p, count, voxels)?);
    }
    write_manifest(dir, depth, origin, frame, &parts)?;
    Ok(parts)
}

/// What one pass over the leaves of files tells ([`leaf_facts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LeafFacts {
    /// Leaves once blocks split across the files are merged (the count of the
    /// joined tree).
    pub leaves: u64,
    /// Black voxels.
    pub voxels: u64,
    /// The lowest and highest black voxels on each axis (world voxel
    /// coordinates, inclusive), as [`crate::linear::LinearOctree::bbox`] gives.
    pub bbox: Option<(Voxel, Voxel)>,
}

/// Leaves held by the merging count: a leaf can merge only with the seven
/// siblings before it at each level.
const MERGE_WINDOW: usize = 7 * (crate::linear::MAX_DEPTH as usize + 1);

/// Counts the leaves (merged), the voxels and the bounding box of `files` (one
/// `.tess` file, or a dataset's parts in order) in one pass, a chunk at a time.
///
/// # Errors
/// [`PartitionError`] for files of different spaces, a bad chunk, or files out
/// of order.
pub fn leaf_facts(files: &[TessFile]) -> Result<LeafFacts, PartitionError> {
    let (_, origin) = space(files)?;
    let mut facts = LeafFacts::default();
    let mut pending: Vec<Leaf> = Vec::new();
    let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
    for l in FileLeaves::new(files) {
        let l = l?;
        facts.voxels += l.voxel_count();
        let r = crate::code::decode(l.code());
        let side = (1i64 << l.size_log2()) - 1;
        for a in 0..3 {
            let v = origin[a] + i64::from(r[a]);
            lo[a] = lo[a].min(v);
            hi[a] = hi[a].max(v + side);
        }
        push_merging(&mut pending, l);
        if pending.len() > 8 * MERGE_WINDOW {
            let settled = pending.len() - MERGE_WINDOW;
            pending.drain(..settled);
            facts.leaves += settled as u64;
        }
    }
    facts.leaves += pending.len() as u64;
    if facts.voxels > 0 {
        facts.bbox = Some((lo, hi));
    }
    Ok(facts)
}

/// Writes the `.xyz` voxel list of `files` (one `.tess` file, or a dataset's
/// parts in order) to `w`, one chunk at a time: the bytes [`crate::io::xyz::write`]
/// writes for the joined tree. `voxels` is the voxel count for the header
/// ([`leaf_facts`]).
///
/// # Errors
/// [`PartitionError`] for files of different spaces, a bad chunk, files out of
/// order, or a write error.
pub fn write_xyz(files: &[TessFile], voxels: u64, w: &mut dyn Write) -> Result<(), PartitionError> {
    let (_, origin) = space(files)?;
    let io = |e: io::Error| PartitionError::Format(FormatError::io(e));
    crate::io::xyz::write_header(w, voxels).map_err(io)?;
    for l in FileLeaves::new(files) {
        crate::io::xyz::write_leaf(w, origin, l?).map_err(io)?;
    }
    Ok(())
}

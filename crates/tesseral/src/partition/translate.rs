//! A `.tess` file translated into a `.tess` file with bounded memory: an external
//! merge sort by code ranges. The leaves are read in batches; each batch is moved
//! into the result's space (a leaf may split into several aligned blocks when the
//! displacement is not a multiple of its size), and its pieces, sorted, are written
//! as one run to a temporary file. The runs are then merged (a heap over one cursor
//! per run) and the result is written through a [`TessWriter`], which joins the
//! pieces back into maximal blocks. Each colour region is translated the same way,
//! as its own set of runs, into a [`LeafSpool`].
//!
//! Memory: one batch and its pieces while the runs are made; a cursor buffer per
//! run, the writer's chunk and a spool buffer per colour while they are merged.
//! The temporary files are unnamed: the system removes them however the process
//! ends.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::Path;

use super::shuffle::{translated_space, union_bbox};
use super::{PartitionError, StreamSummary};
use crate::io::{FormatError, LeafSpool, TessFile, TessWriter, DEFAULT_CHUNK_LEAVES};
use crate::linear::{Leaf, LinearOctree};
use crate::model::Rgba;
use crate::Voxel;

/// Leaves per run unless [`stream_translate_in`] is told otherwise: one chunk.
pub const RUN_LEAVES: usize = DEFAULT_CHUNK_LEAVES;
/// Leaves a run's cursor reads at a time.
const CURSOR_LEAVES: usize = 4096;
const LEAF_BYTES: usize = 8;

/// What [`stream_translate_in`] wrote: the result's space and its counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamTranslation {
    /// The depth of the result's space.
    pub depth: u8,
    /// The lowest voxel of the result's space.
    pub origin: Voxel,
    /// The inclusive bounding box of the result's voxels (`None` when empty).
    pub bbox: Option<(Voxel, Voxel)>,
    /// Leaves, voxels and colour regions written.
    pub summary: StreamSummary,
}

/// Sorted runs of leaves in one unnamed temporary file, each a stretch of packed
/// leaves (8 bytes, little-endian).
struct Runs {
    file: File,
    /// (byte offset, leaf count) of each run.
    runs: Vec<(u64, u64)>,
    end: u64,
    bytes: Vec<u8>,
}

impl Runs {
    fn new_in(dir: &Path) -> io::Result<Self> {
        Ok(Self {
            file: tempfile::tempfile_in(dir)?,
            runs: Vec::new(),
            end: 0,
            bytes: Vec::new(),
        })
    }

    /// Adds one run (sorted, disjoint leaves).
    fn add(&mut self, leaves: &[Leaf]) -> io::Result<()> {
        if leaves.is_empty() {
            return Ok(());
        }
        // A batch's pieces can be many: write them a slice at a time.
        for part in leaves.chunks(CURSOR_LEAVES) {
            self.bytes.clear();
            for l in part {
                self.bytes.extend_from_slice(&l.packed().to_le_bytes());
            }
            self.file.write_all(&self.bytes)?;
        }
        self.runs.push((self.end, leaves.len() as u64));
        self.end += (leaves.len() * LEAF_BYTES) as u64;
        Ok(())
    }

    /// Merges the runs, handing every leaf to `push` in code order; an error when
    /// two runs overlap.
    fn merge(&self, push: &mut dyn FnMut(Leaf) -> io::Result<()>) -> io::Result<()> {
        let mut cursors: Vec<Cursor> = self
            .runs
            .iter()
            .map(|&(pos, left)| Cursor {
                pos,
                left,
                buf: Vec::new(),
                at: 0,
            })
            .collect();
        let mut heap = BinaryHeap::with_capacity(cursors.len());
        let mut raw = vec![0u8; CURSOR_LEAVES * LEAF_BYTES];
        for (i, c) in cursors.iter_mut().enumerate() {
            if let Some(l) = c.next(&self.file, &mut raw)? {
                heap.push(Reverse((l.code(), l.packed(), i)));
            }
        }
        let mut end = 0u64;
        while let Some(Reverse((code, packed, i))) = heap.pop() {
            if code < end {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    "translated runs overlap",
                ));
            }
            let leaf = Leaf::from_packed(packed);
            end = leaf.end();
            push(leaf)?;
            if let Some(l) = cursors[i].next(&self.file, &mut raw)? {
                heap.push(Reverse((l.code(), l.packed(), i)));
            }
        }
        Ok(())
    }
}

/// A position in one run, with the leaves read ahead.
struct Cursor {
    pos: u64,
    left: u64,
    buf: Vec<Leaf>,
    at: usize,
}

impl Cursor {
    fn next(&mut self, mut file: &File, raw: &mut [u8]) -> io::Result<Option<Leaf>> {
        if self.at == self.buf.len() {
            if self.left == 0 {
                return Ok(None);
            }
            let n = (self.left as usize).min(CURSOR_LEAVES);
            let bytes = &mut raw[..n * LEAF_BYTES];
            file.seek(SeekFrom::Start(self.pos))?;
            file.read_exact(bytes)?;
            self.buf.clear();
            self.buf.extend(bytes.chunks_exact(LEAF_BYTES).map(|b| {
                let mut a = [0u8; LEAF_BYTES];
                a.copy_from_slice(b);
                Leaf::from_packed(u64::from_le_bytes(a))
            }));
            self.at = 0;
            self.pos += (n * LEAF_BYTES) as u64;
            self.left -= n as u64;
        }
        self.at += 1;
        Ok(Some(self.buf[self.at - 1]))
    }
}

/// The translation of the leaves of one space into another.
struct Move {
    depth: u8,
    origin: Voxel,
    by: [i64; 3],
    to: (u8, Voxel),
}

impl Move {
    /// The pieces of `batch` (sorted leaves) moved into the result's space, sorted.
    fn pieces(&self, batch: Vec<Leaf>) -> Result<Vec<Leaf>, PartitionError> {
        let t = LinearOctree::from_sorted_leaves(self.depth, self.origin, batch)?;
        let (moved, dropped) = t.translate_into(self.by, self.to.0, self.to.1)?;
        if dropped != 0 {
            return Err(PartitionError::Ranges(format!(
                "{dropped} voxel(s) left the translated space"
            )));
        }
        Ok(moved.leaves().to_vec())
    }

    /// Reads `leaves` in batches of `n`, moves each and adds its pieces as a run.
    fn runs(
        &self,
        leaves: impl Iterator<Item = Result<Leaf, FormatError>>,
        n: usize,
        runs: &mut Runs,
    ) -> Result<(), PartitionError> {
        let mut batch = Vec::with_capacity(n);
        let mut leaves = leaves.peekable();
        while leaves.peek().is_some() {
            batch.clear();
            for l in leaves.by_ref().take(n) {
                batch.push(l?);
            }
            let pieces = self.pieces(std::mem::take(&mut batch))?;
            runs.add(&pieces).map_err(io_err)?;
        }
        Ok(())
    }
}

fn io_err(e: io::Error) -> PartitionError {
    PartitionError::Format(FormatError::io(e))
}

/// [`stream_translate_in`] with runs of [`RUN_LEAVES`] leaves.
///
/// # Errors
/// As [`stream_translate_in`].
pub fn stream_translate(
    f: &TessFile,
    by: [i64; 3],
    w: &mut dyn Write,
    spool_dir: &Path,
) -> Result<StreamTranslation, PartitionError> {
    stream_translate_in(f, by, w, spool_dir, RUN_LEAVES)
}

/// The model of `f` moved by `by` voxels, streamed into a new `.tess` written to
/// `w` with the same frame (see the module docs): the result equals
/// [`crate::model::Model::translate`] of the file's model, in the same space (the
/// input's space when the moved leaves fit, else grown by root expansion). The
/// leaves are read in batches of `run_leaves` (at least one); the runs and the
/// colour spools are temporary files in `spool_dir`.
///
/// # Runtime
/// Two reads of the leaves (the first finds their bounding box), and
/// O(p log r) for p pieces in r runs.
///
/// # Errors
/// [`PartitionError::Octree`] when the grown space would be too deep or a
/// coordinate overflows; [`PartitionError::Ranges`] when the file has layers other
/// than colours or is version 1 with layers; [`PartitionError::Format`] for a bad
/// chunk or a read or write error.
pub fn stream_translate_in(
    f: &TessFile,
    by: [i64; 3],
    w: &mut dyn Write,
    spool_dir: &Path,
    run_leaves: usize,
) -> Result<StreamTranslation, PartitionError> {
    let n = run_leaves.max(1);
    let colours = super::merge::only_colours(f)?;
    let (depth, origin) = (f.depth(), f.origin());
    let mut bbox = None;
    for i in 0..f.chunks().len() {
        let t = LinearOctree::from_sorted_leaves(depth, origin, f.chunk(i)?)?;
        bbox = union_bbox([bbox, t.bbox()]);
    }
    let to = translated_space(depth, origin, bbox, by)?;
    let mv = Move {
        depth,
        origin,
        by,
        to,
    };
    let mut runs = Runs::new_in(spool_dir).map_err(io_err)?;
    mv.runs(f.leaves(), n, &mut runs)?;
    let mut tw = TessWriter::new(w, to.0, to.1).map_err(io_err)?;
    let mut voxels = 0u64;
    runs.merge(&mut |l| {
        voxels += l.voxel_count();
        tw.push(l)
    })
    .map_err(io_err)?;
    drop(runs);
    let mut spools: Vec<(Rgba, LeafSpool)> = Vec::with_capacity(colours.len());
    for (c, region) in colours {
        let mut runs = Runs::new_in(spool_dir).map_err(io_err)?;
        mv.runs(region, n, &mut runs)?;
        let mut spool = LeafSpool::new_in(spool_dir).map_err(io_err)?;
        runs.merge(&mut |l| spool.push(l)).map_err(io_err)?;
        spools.push((c, spool));
    }
    let leaves = tw.leaf_count();
    let colours = spools.iter().filter(|(_, s)| s.leaf_count() > 0).count() as u64;
    tw.finish_spooled(f.frame(), spools).map_err(io_err)?;
    Ok(StreamTranslation {
        depth: to.0,
        origin: to.1,
        bbox: bbox.map(|(lo, hi)| {
            (
                std::array::from_fn(|a| lo[a] + by[a]),
                std::array::from_fn(|a| hi[a] + by[a]),
            )
        }),
        summary: StreamSummary {
            leaves,
            voxels,
            colours,
        },
    })
}

//! The first pass of a streamed translation over a `.tess` file: the bounding box
//! of its leaves, and the checks the in-memory reader makes of its colour section
//! against them (colours only on black voxels, regions disjoint), so that a file
//! the in-memory path refuses is refused here too, before anything is written.
//! Each chunk is decoded once; the leaves and the colour regions are swept as
//! streams of code intervals ([`super::merge::sweep`]), holding a chunk. The same
//! pass cuts each colour region into stretches (their code ranges, counts and
//! resume points), which the translation then reads as it reads chunks: each
//! region is read once here and once when it is moved.

use std::cell::{Cell, RefCell};

use super::blocks::Blocks;
use super::merge::{intervals, sweep, Stream};
use super::shuffle::union_bbox;
use super::PartitionError;
use crate::io::{ChunkInfo, FormatError, RegionLeaves, TessFile};
use crate::linear::{Leaf, LinearOctree};
use crate::model::Rgba;
use crate::Voxel;

/// Leaves of a colour region decoded between two releases of the bytes read.
const RELEASE_EVERY: u64 = 1 << 16;

/// A region's stretches: where each starts (a stream of its leaves alone), its
/// code range and count.
pub(super) type Stretches<'a> = Vec<(ChunkInfo, RegionLeaves<'a>)>;

/// What the first pass finds: the bounding box and each region's stretches.
pub(super) type Scanned<'a> = (Option<(Voxel, Voxel)>, Vec<Stretches<'a>>);

/// A colour region's leaves, letting the mapped bytes behind them go as they are
/// read (see [`TessFile::release`]), and cutting the region into stretches of
/// `stretch` leaves as it goes (into `cut`).
struct Releasing<'a, 's> {
    f: &'a TessFile,
    r: RegionLeaves<'a>,
    last: u64,
    read: u64,
    stretch: u64,
    cut: &'s RefCell<Stretches<'a>>,
}

impl Iterator for Releasing<'_, '_> {
    type Item = Result<Leaf, FormatError>;

    fn next(&mut self) -> Option<Self::Item> {
        let starts = self.read % self.stretch == 0 && self.r.left() > 0;
        if starts {
            let part = self.r.limited(self.stretch);
            let info = ChunkInfo {
                offset: self.r.offset(),
                lo: 0,
                hi: 0,
                count: part.left(),
            };
            self.cut.borrow_mut().push((info, part));
        }
        let l = self.r.next();
        if let Some(Ok(leaf)) = &l {
            if let Some((info, _)) = self.cut.borrow_mut().last_mut() {
                if starts {
                    info.lo = leaf.code();
                }
                info.hi = leaf.end();
            }
        }
        self.read += 1;
        if l.is_none() || self.read % RELEASE_EVERY == 0 {
            let pos = self.r.offset();
            self.f.release(self.last..pos);
            self.last = pos;
        }
        l
    }
}

/// The inclusive bounding box of the leaves of `f` (whose chunks `blocks` are),
/// `None` when it has none, after checking the colour regions `colours` against
/// them; and each region cut into stretches of `stretch` leaves (at least one),
/// found in the same pass (empty when the file has no leaves).
///
/// # Errors
/// [`PartitionError::Format`] (corrupt, naming the file) for a bad chunk or colour
/// region, for colours on voxels that are not black ("colour section: colours on
/// voxels that are not black", as the in-memory reader says) and for colour
/// regions that overlap.
pub(super) fn scan<'a>(
    f: &'a TessFile,
    blocks: &Blocks<'_>,
    colours: &[(Rgba, RegionLeaves<'a>)],
    stretch: usize,
) -> Result<Scanned<'a>, PartitionError> {
    let (depth, origin) = (f.depth(), f.origin());
    let bbox = Cell::new(None);
    // Chunk `i`'s runs of touching leaves (when `runs`), its box joined to `bbox`.
    let chunk = |i: usize, runs: bool| -> Result<Vec<(u64, u64)>, FormatError> {
        let leaves = f.chunk(i);
        blocks.release(i);
        let t = LinearOctree::from_parts(depth, origin, leaves?);
        bbox.set(union_bbox([bbox.get(), t.bbox()]));
        let mut out: Vec<(u64, u64)> = Vec::new();
        if runs {
            for l in t.leaves() {
                match out.last_mut() {
                    Some(r) if r.1 == l.code() => r.1 = l.end(),
                    _ => out.push((l.code(), l.end())),
                }
            }
        }
        Ok(out)
    };
    if colours.is_empty() {
        for i in 0..blocks.len() {
            chunk(i, false)?;
        }
        return Ok((bbox.get(), Vec::new()));
    }
    // The leaves as intervals, chunk by chunk (intervals that touch across two
    // chunks stay two: the sweep takes touching intervals).
    let shape = (0..blocks.len()).flat_map(|i| match chunk(i, true) {
        Ok(runs) => runs.into_iter().map(Ok).collect::<Vec<_>>(),
        Err(e) => vec![Err(e)],
    });
    let cuts: Vec<RefCell<Stretches<'a>>> = colours.iter().map(|_| RefCell::default()).collect();
    let mut streams: Vec<Stream<'_>> = vec![Box::new(shape)];
    for ((_, r), cut) in colours.iter().zip(&cuts) {
        streams.push(intervals(Releasing {
            f,
            r: r.clone(),
            last: r.offset(),
            read: 0,
            stretch: stretch.max(1) as u64,
            cut,
        }));
    }
    let corrupt = |m: &str| PartitionError::Format(FormatError::corrupt(m).with_path(f.path()));
    sweep(
        streams,
        &mut |_, _, inside| match inside[1..].iter().filter(|&&c| c).count() {
            0 => Ok(()),
            1 if inside[0] => Ok(()),
            1 => Err(corrupt(
                "colour section: colours on voxels that are not black",
            )),
            _ => Err(corrupt("colour section: regions overlap")),
        },
    )?;
    // The sweep reads every stream to its end, so the stretches cover each region.
    Ok((
        bbox.get(),
        cuts.into_iter().map(RefCell::into_inner).collect(),
    ))
}

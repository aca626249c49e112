//! The first pass of a streamed translation over a `.tess` file: the bounding box
//! of its leaves, and the checks the in-memory reader makes of its colour section
//! against them (colours only on black voxels, regions disjoint), so that a file
//! the in-memory path refuses is refused here too, before anything is written.
//! Each chunk is decoded once; the leaves and the colour regions are swept as
//! streams of code intervals ([`super::merge::sweep`]), holding a chunk.

use std::cell::Cell;

use super::blocks::Blocks;
use super::merge::{intervals, sweep, Stream};
use super::shuffle::union_bbox;
use super::PartitionError;
use crate::io::{FormatError, RegionLeaves, TessFile};
use crate::linear::{Leaf, LinearOctree};
use crate::model::Rgba;
use crate::Voxel;

/// Leaves of a colour region decoded between two releases of the bytes read.
const RELEASE_EVERY: u64 = 1 << 16;

/// A colour region's leaves, letting the mapped bytes behind them go as they are
/// read (see [`TessFile::release`]).
struct Releasing<'a> {
    f: &'a TessFile,
    r: RegionLeaves<'a>,
    last: u64,
    read: u64,
}

impl Iterator for Releasing<'_> {
    type Item = Result<Leaf, FormatError>;

    fn next(&mut self) -> Option<Self::Item> {
        let l = self.r.next();
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
/// them.
///
/// # Errors
/// [`PartitionError::Format`] (corrupt, naming the file) for a bad chunk or colour
/// region, for colours on voxels that are not black ("colour section: colours on
/// voxels that are not black", as the in-memory reader says) and for colour
/// regions that overlap.
pub(super) fn scan(
    f: &TessFile,
    blocks: &Blocks<'_>,
    colours: &[(Rgba, RegionLeaves<'_>)],
) -> Result<Option<(Voxel, Voxel)>, PartitionError> {
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
        return Ok(bbox.get());
    }
    // The leaves as intervals, chunk by chunk (intervals that touch across two
    // chunks stay two: the sweep takes touching intervals).
    let shape = (0..blocks.len()).flat_map(|i| match chunk(i, true) {
        Ok(runs) => runs.into_iter().map(Ok).collect::<Vec<_>>(),
        Err(e) => vec![Err(e)],
    });
    let mut streams: Vec<Stream<'_>> = vec![Box::new(shape)];
    for (_, r) in colours {
        streams.push(intervals(Releasing {
            f,
            r: r.clone(),
            last: r.offset(),
            read: 0,
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
    Ok(bbox.get())
}

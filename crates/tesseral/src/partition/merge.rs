//! Set operations of two `.tess` files as a merge of two sorted streams: each file's
//! leaves are read a chunk at a time as code intervals, the intervals are merged, and
//! the result is cut back into maximal aligned blocks and written through a
//! [`TessWriter`]. Colour regions are streams too, merged in the same sweep.
//! Memory: one chunk per input and the writer's chunk, and a spool buffer per
//! colour.

use std::io::Write;
use std::path::Path;

use super::{PartitionError, StreamSummary};
use crate::io::{FormatError, LeafSpool, TessFile, TessWriter};
use crate::linear::{Leaf, SetOp};
use crate::model::{Frame, Rgba};

/// Runs of touching leaves joined into intervals `[start, end)`, in order.
struct Intervals<I: Iterator<Item = Result<Leaf, FormatError>>> {
    leaves: std::iter::Peekable<I>,
}

impl<I: Iterator<Item = Result<Leaf, FormatError>>> Iterator for Intervals<I> {
    type Item = Result<(u64, u64), FormatError>;
    fn next(&mut self) -> Option<Self::Item> {
        let first = match self.leaves.next()? {
            Ok(l) => l,
            Err(e) => return Some(Err(e)),
        };
        let (start, mut end) = (first.code(), first.end());
        while let Some(Ok(l)) = self.leaves.peek() {
            if l.code() != end {
                break;
            }
            end = l.end();
            self.leaves.next();
        }
        Some(Ok((start, end)))
    }
}

/// Cuts `[start, end)` into maximal aligned blocks, in order, handing each to `push`.
fn cut_interval(
    mut start: u64,
    end: u64,
    push: &mut dyn FnMut(Leaf) -> std::io::Result<()>,
) -> std::io::Result<()> {
    while start < end {
        let mut k = 0u8;
        while k < 21 {
            let size = 1u64 << (3 * u32::from(k + 1));
            if start % size != 0 || start + size > end {
                break;
            }
            k += 1;
        }
        let leaf = Leaf::new(start, k);
        push(leaf)?;
        start = leaf.end();
    }
    Ok(())
}

/// The colour regions of `f` as streams (none without layers); an error when it
/// has other layers or is version 1.
pub(super) fn only_colours(
    f: &TessFile,
) -> Result<Vec<(Rgba, crate::io::RegionLeaves<'_>)>, PartitionError> {
    if !f.has_layers() {
        return Ok(Vec::new());
    }
    f.colour_streams()?.ok_or_else(|| {
        PartitionError::Ranges(
            "an operand has layers other than colours, or is version 1: no streamed operation"
                .into(),
        )
    })
}

pub(super) type Stream<'a> = Box<dyn Iterator<Item = Result<(u64, u64), FormatError>> + 'a>;

/// The runs of touching leaves of a sorted stream, as code intervals.
pub(super) fn intervals<'a>(
    leaves: impl Iterator<Item = Result<Leaf, FormatError>> + 'a,
) -> Stream<'a> {
    Box::new(Intervals {
        leaves: leaves.peekable(),
    })
}

/// What [`sweep`] calls with each stretch.
pub(super) type Segment<'a> = dyn FnMut(u64, u64, &[bool]) -> Result<(), PartitionError> + 'a;

/// Sweeps the boundaries of `streams` (each sorted, disjoint intervals): calls
/// `segment(lo, hi, inside)` for each stretch `[lo, hi)` over which no stream
/// changes, `inside[i]` telling whether stream `i` covers it.
pub(super) fn sweep(
    mut streams: Vec<Stream<'_>>,
    segment: &mut Segment<'_>,
) -> Result<(), PartitionError> {
    let mut cur = Vec::with_capacity(streams.len());
    for s in &mut streams {
        cur.push(s.next().transpose()?);
    }
    let mut inside = vec![false; streams.len()];
    let mut pos = 0u64;
    loop {
        let mut next = u64::MAX;
        for (i, c) in cur.iter().enumerate() {
            let (is_in, n) = match *c {
                Some((s, e)) if s <= pos => (true, e),
                Some((s, _)) => (false, s),
                None => (false, u64::MAX),
            };
            inside[i] = is_in;
            next = next.min(n);
        }
        if next == u64::MAX {
            return Ok(());
        }
        if inside.iter().any(|&b| b) {
            segment(pos, next, &inside)?;
        }
        pos = next;
        for (c, s) in cur.iter_mut().zip(&mut streams) {
            if c.is_some_and(|(_, e)| e <= pos) {
                *c = s.next().transpose()?;
            }
        }
    }
}

/// [`stream_set_op_in`] with the colour spools in the system's temporary folder.
///
/// # Errors
/// As [`stream_set_op_in`].
pub fn stream_set_op(
    a: &TessFile,
    b: &TessFile,
    op: SetOp,
    frame: Frame,
    w: &mut dyn Write,
) -> Result<StreamSummary, PartitionError> {
    stream_set_op_in(a, b, op, frame, w, &std::env::temp_dir())
}

/// The set operation `op` of two `.tess` files of one space, streamed into a new
/// `.tess` written to `w` with `frame`: [`stream_set_op_files`] of one file each.
///
/// # Errors
/// As [`stream_set_op_files`].
pub fn stream_set_op_in(
    a: &TessFile,
    b: &TessFile,
    op: SetOp,
    frame: Frame,
    w: &mut dyn Write,
    spool_dir: &Path,
) -> Result<StreamSummary, PartitionError> {
    stream_set_op_files(
        std::slice::from_ref(a),
        std::slice::from_ref(b),
        op,
        frame,
        w,
        spool_dir,
    )
}

/// An operand's colour regions: each colour's regions of all its files, chained
/// in file order.
pub(super) fn operand_colours<'a>(
    files: &'a [TessFile],
) -> Result<Vec<(Rgba, crate::io::LeafIter<'a>)>, PartitionError> {
    let mut out: Vec<(Rgba, crate::io::LeafIter<'a>)> = Vec::new();
    for f in files {
        let regions = if f.has_layers() {
            f.colour_leaves()?.ok_or_else(|| {
                PartitionError::Ranges(
                    "an operand has free space or log-odds: no streamed operation".into(),
                )
            })?
        } else {
            Vec::new()
        };
        for (c, r) in regions {
            match out.iter().position(|(x, _)| *x == c) {
                Some(i) => {
                    let (_, prev) = out.swap_remove(i);
                    out.insert(i, (c, Box::new(prev.chain(r))));
                }
                None => out.push((c, r)),
            }
        }
    }
    Ok(out)
}

/// The leaves of files that follow each other in code order, as one stream; an
/// error when they overlap or are out of order.
fn chained(files: &[TessFile]) -> crate::io::LeafIter<'_> {
    let mut end = 0u64;
    Box::new(files.iter().flat_map(TessFile::leaves).map(move |l| {
        let l = l?;
        if l.code() < end {
            return Err(FormatError::corrupt(
                "the parts overlap or are out of code order",
            ));
        }
        end = l.end();
        Ok(l)
    }))
}

/// The set operation `op` of two operands of one space, each a list of `.tess`
/// files whose leaves follow each other in code order (one file, or the parts of
/// a dataset, read as one sorted stream), streamed into a new `.tess` written to
/// `w` with `frame` (see the module docs). Colours follow the in-memory rule
/// (`Model::set_op`): a voxel of the result keeps the first operand's colour where
/// it has one, else the second's; each colour region is spooled to a temporary
/// file in `spool_dir` and read from the inputs as a stream. A version-1 file is
/// read as a stream too when it was opened by [`TessFile::open_streaming`] (else
/// it was decoded whole and is streamed from memory). The result keeps a colour
/// layer, even an empty one, when an operand has one, as `Model::set_op` does: a
/// single file's layer even when empty, a dataset's (several files) when a part
/// has a colour region (as the joined model has).
///
/// # Runtime
/// O((leaves of both + colour leaves) × streams), reading each chunk once.
///
/// # Errors
/// [`PartitionError::Ranges`] when the spaces differ, an operand has no files, or
/// an input has layers other than colours (free space, log-odds);
/// [`PartitionError::Format`] for a bad chunk, parts out of order or a write error.
pub fn stream_set_op_files(
    a: &[TessFile],
    b: &[TessFile],
    op: SetOp,
    frame: Frame,
    w: &mut dyn Write,
    spool_dir: &Path,
) -> Result<StreamSummary, PartitionError> {
    let space = |fs: &[TessFile]| -> Result<(u8, crate::Voxel), PartitionError> {
        let f = fs
            .first()
            .ok_or_else(|| PartitionError::Ranges("an operand has no files".into()))?;
        let s = (f.depth(), f.origin());
        if fs.iter().any(|g| (g.depth(), g.origin()) != s) {
            return Err(PartitionError::Ranges(
                "an operand's files are in different spaces".into(),
            ));
        }
        Ok(s)
    };
    let ((da, oa), (db, ob)) = (space(a)?, space(b)?);
    if (da, oa) != (db, ob) {
        return Err(PartitionError::Ranges(format!(
            "the operands are in different spaces (depth {da} origin {oa:?}, depth {db} origin {ob:?})"
        )));
    }
    let (ca, cb) = (operand_colours(a)?, operand_colours(b)?);
    let has_layer = |fs: &[TessFile], regions: &[_]| {
        !regions.is_empty() || (fs.len() == 1 && fs[0].has_layers())
    };
    let keep_layer = has_layer(a, &ca) || has_layer(b, &cb);
    let io = |e: std::io::Error| PartitionError::Format(FormatError::io(e));
    // One spool per distinct colour; stream i+2 is a's region i, then b's.
    let mut colours: Vec<Rgba> = Vec::new();
    let mut target = Vec::new();
    for (c, _) in ca.iter().chain(&cb) {
        let at = colours.iter().position(|x| x == c).unwrap_or_else(|| {
            colours.push(*c);
            colours.len() - 1
        });
        target.push(at);
    }
    let mut spools = Vec::with_capacity(colours.len());
    for c in &colours {
        spools.push((*c, LeafSpool::new_in(spool_dir).map_err(io)?));
    }
    let na = ca.len();
    let mut streams = vec![intervals(chained(a)), intervals(chained(b))];
    streams.extend(ca.into_iter().chain(cb).map(|(_, r)| intervals(r)));
    let mut tw = TessWriter::new(w, da, oa).map_err(io)?;
    let mut voxels = 0u64;
    let keep = |in_a: bool, in_b: bool| match op {
        SetOp::Union => in_a || in_b,
        SetOp::Intersection => in_a && in_b,
        SetOp::Difference => in_a && !in_b,
        SetOp::SymmetricDifference => in_a != in_b,
    };
    sweep(streams, &mut |lo, hi, inside| {
        if !keep(inside[0], inside[1]) {
            return Ok(());
        }
        voxels += hi - lo;
        cut_interval(lo, hi, &mut |l| tw.push(l)).map_err(io)?;
        let regions = &inside[2..];
        let first = regions[..na]
            .iter()
            .position(|&x| x)
            .or_else(|| regions[na..].iter().position(|&x| x).map(|j| na + j));
        if let Some(j) = first {
            let spool = &mut spools[target[j]].1;
            cut_interval(lo, hi, &mut |l| spool.push(l)).map_err(io)?;
        }
        Ok(())
    })?;
    let leaves = tw.leaf_count();
    let colours = spools.iter().filter(|(_, s)| s.leaf_count() > 0).count() as u64;
    if keep_layer {
        tw.finish_spooled_layer(frame, spools).map_err(io)?;
    } else {
        tw.finish_spooled(frame, spools).map_err(io)?;
    }
    Ok(StreamSummary {
        leaves,
        voxels,
        colours,
    })
}

/// Concatenates `.tess` files of one space whose leaves follow each other in code
/// order (the parts of a dataset, or one file) into one `.tess` written to `w`
/// with `frame`, chunk by chunk, the colour regions streamed into spools in
/// `spool_dir`: a version-2 copy that never holds the tree or a layer.
///
/// # Errors
/// [`PartitionError::Ranges`] when the spaces differ, the files overlap or are out
/// of order, or one has layers other than colours or is version 1;
/// [`PartitionError::Format`] for a bad chunk or a write error.
pub fn stream_concat(
    files: &[TessFile],
    frame: Frame,
    w: &mut dyn Write,
    spool_dir: &Path,
) -> Result<StreamSummary, PartitionError> {
    let Some(first) = files.first() else {
        return Err(PartitionError::Ranges("no files to join".into()));
    };
    let (depth, origin) = (first.depth(), first.origin());
    if files
        .iter()
        .any(|f| (f.depth(), f.origin()) != (depth, origin))
    {
        return Err(PartitionError::Ranges(
            "the files are in different spaces".into(),
        ));
    }
    let io = |e: std::io::Error| PartitionError::Format(FormatError::io(e));
    let bad_order = || PartitionError::Ranges("the files overlap or are out of code order".into());
    let mut colours: Vec<(Rgba, LeafSpool)> = Vec::new();
    let mut tw = TessWriter::new(w, depth, origin).map_err(io)?;
    let (mut voxels, mut end) = (0u64, 0u64);
    for f in files {
        for l in f.leaves() {
            let l = l?;
            if l.code() < end {
                return Err(bad_order());
            }
            end = l.end();
            voxels += l.voxel_count();
            tw.push(l).map_err(io)?;
        }
        for (c, region) in only_colours(f)? {
            let at = match colours.iter().position(|(x, _)| *x == c) {
                Some(i) => i,
                None => {
                    colours.push((c, LeafSpool::new_in(spool_dir).map_err(io)?));
                    colours.len() - 1
                }
            };
            let spool = &mut colours[at].1;
            let mut last = spool.last_end();
            for l in region {
                let l = l?;
                if l.code() < last {
                    return Err(bad_order());
                }
                last = l.end();
                spool.push(l).map_err(io)?;
            }
        }
    }
    let leaves = tw.leaf_count();
    let n = colours.iter().filter(|(_, s)| s.leaf_count() > 0).count() as u64;
    tw.finish_spooled(frame, colours).map_err(io)?;
    Ok(StreamSummary {
        leaves,
        voxels,
        colours: n,
    })
}

//! Set operations of two `.tess` files as a merge of two sorted streams: each file's
//! leaves are read a chunk at a time as code intervals, the intervals are merged, and
//! the result is cut back into maximal aligned blocks and written through a
//! [`TessWriter`]. Memory: one chunk per input and the writer's chunk.

use std::io::Write;

use super::{PartitionError, StreamSummary};
use crate::io::{FormatError, TessFile, TessWriter};
use crate::linear::{Leaf, SetOp};
use crate::model::Frame;

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

/// Pushes the maximal aligned blocks of `[start, end)`, in order.
fn push_interval<W: Write>(
    w: &mut TessWriter<W>,
    mut start: u64,
    end: u64,
    voxels: &mut u64,
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
        *voxels += leaf.voxel_count();
        w.push(leaf)?;
        start = leaf.end();
    }
    Ok(())
}

/// The set operation `op` of two `.tess` files of one space, streamed into a new
/// `.tess` written to `w` with `frame` (see the module docs).
///
/// # Runtime
/// O(leaves of both), reading each chunk once.
///
/// # Errors
/// [`PartitionError::Ranges`] when the spaces differ; [`PartitionError::Format`]
/// for a bad chunk or a write error.
pub fn stream_set_op(
    a: &TessFile,
    b: &TessFile,
    op: SetOp,
    frame: Frame,
    w: &mut dyn Write,
) -> Result<StreamSummary, PartitionError> {
    if (a.depth(), a.origin()) != (b.depth(), b.origin()) {
        return Err(PartitionError::Ranges(format!(
            "the operands are in different spaces (depth {} origin {:?}, depth {} origin {:?})",
            a.depth(),
            a.origin(),
            b.depth(),
            b.origin()
        )));
    }
    let io = |e: std::io::Error| PartitionError::Format(FormatError::io(e));
    let mut tw = TessWriter::new(w, a.depth(), a.origin()).map_err(io)?;
    let mut ia = Intervals {
        leaves: a.leaves().peekable(),
    };
    let mut ib = Intervals {
        leaves: b.leaves().peekable(),
    };
    let (mut x, mut y) = (ia.next().transpose()?, ib.next().transpose()?);
    let mut voxels = 0u64;
    // Sweep the boundaries: at each point, which operands are inside decides.
    let keep = |in_a: bool, in_b: bool| match op {
        SetOp::Union => in_a || in_b,
        SetOp::Intersection => in_a && in_b,
        SetOp::Difference => in_a && !in_b,
        SetOp::SymmetricDifference => in_a != in_b,
    };
    let mut pos = 0u64;
    let mut open: Option<u64> = None;
    loop {
        // The next boundary after `pos`, and whether each operand covers [pos, next).
        let (in_a, next_a) = match x {
            Some((s, e)) if s <= pos => (true, e),
            Some((s, _)) => (false, s),
            None => (false, u64::MAX),
        };
        let (in_b, next_b) = match y {
            Some((s, e)) if s <= pos => (true, e),
            Some((s, _)) => (false, s),
            None => (false, u64::MAX),
        };
        let next = next_a.min(next_b);
        let k = keep(in_a, in_b);
        match (k, open) {
            (true, None) => open = Some(pos),
            (false, Some(s)) => {
                push_interval(&mut tw, s, pos, &mut voxels).map_err(io)?;
                open = None;
            }
            _ => {}
        }
        if next == u64::MAX {
            break;
        }
        pos = next;
        if x.is_some_and(|(_, e)| e <= pos) {
            x = ia.next().transpose()?;
        }
        if y.is_some_and(|(_, e)| e <= pos) {
            y = ib.next().transpose()?;
        }
    }
    if let Some(s) = open {
        push_interval(&mut tw, s, pos, &mut voxels).map_err(io)?;
    }
    let leaves = tw.leaf_count();
    tw.finish(frame).map_err(io)?;
    Ok(StreamSummary {
        leaves,
        voxels,
        colours: 0,
    })
}

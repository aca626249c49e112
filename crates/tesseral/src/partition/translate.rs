//! A `.tess` file translated into a `.tess` file with memory flat in its size,
//! driven by the output: the result's space is cut into aligned cells, visited in
//! tesseral order. An output cell of side `2^k` is the image of an unaligned cube
//! of the input, which meets at most 2 × 2 × 2 input cells of side `2^k` (its
//! *window*), each a code range of the input: their leaves that meet the cube are
//! read through the chunk index ([`Blocks`]), moved into the output cell by
//! [`LinearOctree::translate_into`], and the cell's final leaves are written at
//! once through a [`TessWriter`], which joins blocks across cells. No pieces, no
//! runs, no merge.
//!
//! The cells are chosen top-down from the chunk index alone: a cell is split while
//! the chunks meeting its window hold more than `cell_leaves` leaves (and are more
//! than eight: splitting cannot do better than one per input cell), and skipped
//! when its cube misses the input's bounding box or its window holds none. Each
//! colour region is translated the same way (cut into stretches of leaves that
//! play the chunks' part) into a [`LeafSpool`].
//!
//! Memory: one cell's leaves (at most about `cell_leaves`), a quarter of them at a
//! time moved (their copy, the resampler's index of them and its output), a few
//! decoded chunks, the writer's chunk, one spool buffer, and the cell list (16
//! bytes a cell). Time: each chunk is decoded once
//! per output cell whose cube meets it (about once, more along the cells'
//! boundaries), and the leaves are moved once.

use std::io::{self, Write};
use std::path::Path;

use super::blocks::Blocks;
use super::shuffle::translated_space;
use super::{PartitionError, StreamSummary};
use crate::code;
use crate::io::{FormatError, LeafSpool, TessFile, TessWriter, DEFAULT_CHUNK_LEAVES};
use crate::linear::{Leaf, LinearOctree, OctreeError};
use crate::Voxel;

/// The most leaves a cell's window may hold (by the chunk index) before the cell
/// is split, unless [`stream_translate_in`] is told otherwise.
pub const CELL_LEAVES: usize = 1 << 22;

/// A cell's window may hold `cell_leaves` leaves; they are moved at most
/// `cell_leaves / MOVE_SHARE` at a time (see [`Mover::move_into`]).
const MOVE_SHARE: u64 = 4;

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

/// A box of the input space, half-open, in voxels from the input's origin.
#[derive(Debug, Clone, Copy)]
struct Box3 {
    lo: [i64; 3],
    hi: [i64; 3],
}

impl Box3 {
    /// The cube of the cell `(code, k)` (its code's low `3k` bits zero).
    fn cube(code: u64, k: u8) -> Self {
        let v = code::decode(code).map(i64::from);
        Self {
            lo: v,
            hi: v.map(|x| x + (1i64 << k)),
        }
    }

    fn meets(&self, o: &Self) -> bool {
        (0..3).all(|a| self.lo[a] < o.hi[a] && o.lo[a] < self.hi[a])
    }

    fn holds(&self, o: &Self) -> bool {
        (0..3).all(|a| self.lo[a] <= o.lo[a] && o.hi[a] <= self.hi[a])
    }
}

/// Whether the code range `[lo, hi)` meets the box `b` (the range cut into
/// maximal aligned blocks, each tested).
fn range_meets(mut lo: u64, hi: u64, b: &Box3) -> bool {
    while lo < hi {
        let mut k = 0u8;
        while k < 21 {
            let size = 1u64 << (3 * u32::from(k + 1));
            if lo % size != 0 || lo + size > hi {
                break;
            }
            k += 1;
        }
        if Box3::cube(lo, k).meets(b) {
            return true;
        }
        lo += 1u64 << (3 * u32::from(k));
    }
    false
}

/// Appends `l` unless it is the last leaf already (a leaf bigger than a window
/// cell is met in each window cell it covers).
fn push_once(out: &mut Vec<Leaf>, l: Leaf) {
    if out.last() != Some(&l) {
        out.push(l);
    }
}

/// Appends the leaves of `leaves` (sorted, all inside the cell `(code, k)` or one
/// covering it) that meet the box `b`, whole.
fn select(leaves: &[Leaf], code: u64, k: u8, b: &Box3, out: &mut Vec<Leaf>) {
    let Some(&first) = leaves.first() else {
        return;
    };
    let cell = Box3::cube(code, k);
    if !cell.meets(b) {
        return;
    }
    if b.holds(&cell) {
        push_once(out, first);
        out.extend_from_slice(&leaves[1..]);
        return;
    }
    if first.size_log2() >= k {
        push_once(out, first);
        return;
    }
    let child = 1u64 << (3 * u32::from(k - 1));
    let mut rest = leaves;
    for d in 0..8 {
        let lo = code + d * child;
        let n = rest.partition_point(|l| l.code() < lo + child);
        select(&rest[..n], lo, k - 1, b, out);
        rest = &rest[n..];
    }
}

/// The translation of one space's leaves into the result's space, cell by cell.
struct Mover {
    depth: u8,
    origin: Voxel,
    by: [i64; 3],
    to: (u8, Voxel),
    /// The output voxel `p` (from the output's origin) is the image of the input
    /// voxel `p + shift` (from the input's origin).
    shift: [i64; 3],
    /// The input leaves' bounding box.
    bbox: Box3,
    cap: u64,
    /// The most leaves moved at once (see [`Mover::move_into`]).
    move_cap: u64,
}

impl Mover {
    fn new(
        (depth, origin): (u8, Voxel),
        by: [i64; 3],
        to: (u8, Voxel),
        (lo, hi): (Voxel, Voxel),
        cap: u64,
    ) -> Result<Self, PartitionError> {
        let mut shift = [0i64; 3];
        let mut bbox = Box3 {
            lo: [0; 3],
            hi: [0; 3],
        };
        for a in 0..3 {
            let s = i128::from(to.1[a]) - i128::from(by[a]) - i128::from(origin[a]);
            shift[a] = i64::try_from(s).map_err(|_| OctreeError::Overflow)?;
            bbox.lo[a] = lo[a] - origin[a];
            bbox.hi[a] = hi[a] - origin[a] + 1;
        }
        Ok(Self {
            depth,
            origin,
            by,
            to,
            shift,
            bbox,
            cap,
            move_cap: (cap / MOVE_SHARE).max(1),
        })
    }

    /// The input cube under the output cell `(code, k)`, and (for `k` at most the
    /// input's depth) the first codes of its window's input cells, sorted.
    fn window(&self, code: u64, k: u8) -> (Box3, Vec<u64>) {
        let p = code::decode(code);
        let side = 1i64 << k;
        let lo: [i64; 3] = std::array::from_fn(|a| i64::from(p[a]) + self.shift[a]);
        let b = Box3 {
            lo,
            hi: lo.map(|v| v + side),
        };
        let mut cells = Vec::with_capacity(8);
        if k > self.depth {
            return (b, cells);
        }
        let n = 1i64 << (self.depth - k);
        'e: for e in 0..8 {
            let mut w = [0u32; 3];
            for a in 0..3 {
                let bit = (e >> a) & 1;
                if bit == 1 && lo[a].rem_euclid(side) == 0 {
                    continue 'e;
                }
                let q = lo[a].div_euclid(side) + bit;
                if q < 0 || q >= n {
                    continue 'e;
                }
                w[a] = q as u32;
            }
            cells.push(code::encode(w[0], w[1], w[2]) << (3 * u32::from(k)));
        }
        cells.sort_unstable();
        (b, cells)
    }

    /// The output cells to translate, in tesseral order, under `(code, k)`.
    fn plan(&self, blocks: &Blocks<'_>, code: u64, k: u8, cells: &mut Vec<(u64, u8)>) {
        let (b, window) = self.window(code, k);
        if !b.meets(&self.bbox) {
            return;
        }
        if k <= self.depth {
            let size = 1u64 << (3 * u32::from(k));
            let (mut bound, mut met) = (0, 0);
            for &c in &window {
                let (n, m) = blocks.bound(c, c + size);
                bound += n;
                met += m;
            }
            if bound == 0 {
                return;
            }
            // Splitting cannot bring a window below one block per input cell: stop
            // at eight blocks whatever the cap.
            if bound <= self.cap || met <= 8 || k == 0 {
                cells.push((code, k));
                return;
            }
        }
        let child = 1u64 << (3 * u32::from(k - 1));
        for d in 0..8 {
            self.plan(blocks, code + d * child, k - 1, cells);
        }
    }

    /// Translates the leaves of `blocks` into `push`, in tesseral order.
    fn run(
        &self,
        blocks: &mut Blocks<'_>,
        push: &mut dyn FnMut(Leaf) -> io::Result<()>,
    ) -> Result<(), PartitionError> {
        let mut cells = Vec::new();
        self.plan(blocks, 0, self.to.0, &mut cells);
        for (code, k) in cells {
            self.cell(blocks, code, k, push)?;
        }
        Ok(())
    }

    /// Translates the output cell `(code, k)`.
    fn cell(
        &self,
        blocks: &mut Blocks<'_>,
        code: u64,
        k: u8,
        push: &mut dyn FnMut(Leaf) -> io::Result<()>,
    ) -> Result<(), PartitionError> {
        let (b, window) = self.window(code, k);
        let size = 1u64 << (3 * u32::from(k));
        let mut sel = Vec::new();
        for &c in &window {
            blocks.read(
                c,
                c + size,
                &|lo, hi| range_meets(lo, hi, &b),
                &mut |leaves| select(leaves, c, k, &b, &mut sel),
            )?;
        }
        self.move_into(sel, code, k, push)
    }

    /// Moves `sel`, the input leaves that meet the cube under the output cell
    /// `(code, k)` (sorted), into that cell. More than `move_cap` of them are first
    /// cut by the cell's eight children (each child's leaves selected from `sel`,
    /// which is then dropped), so that the resampler (its index and its output,
    /// several times the leaves' own size) never holds more than `move_cap` leaves
    /// whatever a window holds; nothing is decoded again.
    fn move_into(
        &self,
        sel: Vec<Leaf>,
        code: u64,
        k: u8,
        push: &mut dyn FnMut(Leaf) -> io::Result<()>,
    ) -> Result<(), PartitionError> {
        if sel.is_empty() {
            return Ok(());
        }
        if sel.len() as u64 > self.move_cap && k > 0 {
            let size = 1u64 << (3 * u32::from(k - 1));
            let mut parts = Vec::with_capacity(8);
            for d in 0..8 {
                let c = code + d * size;
                let (b, window) = self.window(c, k - 1);
                let mut part = Vec::new();
                for &w in &window {
                    let first = sel.partition_point(|l| l.end() <= w);
                    let last = sel.partition_point(|l| l.code() < w + size);
                    select(&sel[first..last.max(first)], w, k - 1, &b, &mut part);
                }
                parts.push((c, part));
            }
            drop(sel);
            for (c, part) in parts {
                self.move_into(part, c, k - 1, push)?;
            }
            return Ok(());
        }
        let tree = LinearOctree::from_parts(self.depth, self.origin, sel);
        let p = code::decode(code);
        let at: Voxel = std::array::from_fn(|a| self.to.1[a] + i64::from(p[a]));
        let (moved, _outside) = tree.translate_into(self.by, k, at)?;
        drop(tree);
        for &l in moved.leaves() {
            push(Leaf::new(code | l.code(), l.size_log2())).map_err(io_err)?;
        }
        Ok(())
    }
}

fn io_err(e: io::Error) -> PartitionError {
    PartitionError::Format(FormatError::io(e))
}

/// [`stream_translate_in`] with windows of at most [`CELL_LEAVES`] leaves.
///
/// # Errors
/// As [`stream_translate_in`].
pub fn stream_translate(
    f: &TessFile,
    by: [i64; 3],
    w: &mut dyn Write,
    spool_dir: &Path,
) -> Result<StreamTranslation, PartitionError> {
    stream_translate_in(f, by, w, spool_dir, CELL_LEAVES)
}

/// The model of `f` moved by `by` voxels, streamed into a new `.tess` written to
/// `w` with the same frame (see the module docs): the result equals
/// [`crate::model::Model::translate`] of the file's model, in the same space (the
/// input's space when the moved leaves fit, else grown by root expansion), byte for
/// byte as the in-memory path writes it. An output cell is split while its window
/// holds more than `cell_leaves` leaves (at least one), and its leaves are moved a
/// quarter of that at a time at most; the colour spools are temporary files in
/// `spool_dir`.
///
/// # Runtime
/// One pass over the chunks and the colour regions for the bounding box, the
/// colours' checks and the regions' stretches, then O(n) in the leaves (each chunk
/// or stretch decoded about once per output cell whose cube meets it).
///
/// # Errors
/// [`PartitionError::Octree`] when the grown space would be too deep or a
/// coordinate overflows; [`PartitionError::Ranges`] when the file has layers other
/// than colours or is version 1 with layers; [`PartitionError::Format`] for a bad
/// chunk or colour region, colours on voxels that are not black or colour regions
/// that overlap (which the in-memory reader refuses too: checked in a first pass,
/// before anything is written), or a read or write error.
pub fn stream_translate_in(
    f: &TessFile,
    by: [i64; 3],
    w: &mut dyn Write,
    spool_dir: &Path,
    cell_leaves: usize,
) -> Result<StreamTranslation, PartitionError> {
    let cap = cell_leaves.max(1) as u64;
    let colours = super::merge::only_colours(f)?;
    // A colour layer, even one with no region, is kept (as in memory).
    let layer = f.has_layers();
    // Finding the colour regions read the colour section: let it go.
    f.release(0..u64::MAX);
    let (depth, origin) = (f.depth(), f.origin());
    let mut blocks = Blocks::of_file(f);
    // Stretches of a colour region play the chunks' part; the first pass finds
    // them as it checks the colours.
    let stretch = (cell_leaves / 32).clamp(1, DEFAULT_CHUNK_LEAVES);
    let (bbox, stretches) = super::scan::scan(f, &blocks, &colours, stretch)?;
    let to = translated_space(depth, origin, bbox, by)?;
    let mut tw = TessWriter::new(w, to.0, to.1).map_err(io_err)?;
    let mut voxels = 0u64;
    let mut spools = Vec::with_capacity(colours.len());
    if let Some(bb) = bbox {
        let mover = Mover::new((depth, origin), by, to, bb, cap)?;
        mover.run(&mut blocks, &mut |l| {
            voxels += l.voxel_count();
            tw.push(l)
        })?;
        drop(blocks);
        for ((c, _), cut) in colours.into_iter().zip(stretches) {
            let mut blocks = Blocks::of_stretches(f, cut);
            let mut spool = LeafSpool::new_in(spool_dir).map_err(io_err)?;
            mover.run(&mut blocks, &mut |l| spool.push(l))?;
            spools.push((c, spool));
        }
    }
    let leaves = tw.leaf_count();
    let colours = spools.iter().filter(|(_, s)| s.leaf_count() > 0).count() as u64;
    if layer {
        tw.finish_spooled_layer(f.frame(), spools)
    } else {
        tw.finish_spooled(f.frame(), spools)
    }
    .map_err(io_err)?;
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

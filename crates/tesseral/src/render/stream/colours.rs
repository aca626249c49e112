//! Stored colours of a streamed tree. A version-2 `.tess` written by this version
//! has a colour index (`io/colour_index.rs`): opening reads it, not the colour
//! section, and a colour is found by binary search of the index's blocks (a code
//! per 4,096 leaves of a region) and of one decoded block, each block checked (its
//! CRC, its leaves, its place in the region) when it is decoded, blocks kept in a
//! [`Cache`]. So a render reads the colour bytes of the blocks its hits fall in.
//!
//! Files without the index (older version-2 files) are read through once when the
//! tree is opened, keeping a resume point every [`BLOCK`] leaves; the read-through
//! lets the mapped pages go as it goes, so resident memory stays flat.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use super::cache::{Cache, Cost};
use crate::io::tess_colours::{RegionLeaves, RegionPoint};
use crate::io::{FormatError, TessFile};
use crate::linear::Leaf;
use crate::model::Rgba;

/// Leaves per decoded colour block of a file without a colour index.
pub(super) const BLOCK: u64 = 1024;

/// Leaves read through between two releases of the file's mapped pages.
const RELEASE: u64 = 1 << 20;

/// Colour blocks decoded between two releases of the file's mapped pages.
const RELEASE_BLOCKS: u64 = 256;

/// Where a region's blocks come from.
enum Blocks {
    /// Resume points found by reading the region through, and where it ends.
    Scanned(Vec<RegionPoint>, u64),
    /// The file's colour index: the region's blocks start at this one.
    Indexed(usize),
}

/// One region of one part: its colour and where each block starts.
struct Region {
    rgba: Rgba,
    /// The code of each block's first leaf.
    firsts: Vec<u64>,
    blocks: Blocks,
}

/// The colour regions of every part.
pub(super) struct Colours {
    /// Per part: its regions.
    parts: Vec<Vec<Region>>,
    depth: u8,
    pub(super) cache: Cache<Vec<Leaf>>,
    /// Bytes of the colour sections read: at open (a file without an index) and
    /// for each block decoded.
    pub(super) bytes_read: AtomicU64,
}

impl Colours {
    /// Reads the colour indexes of `files`, or the colour sections of those that
    /// have none. `None` when no part has colours.
    ///
    /// # Errors
    /// [`FormatError`] naming the file, for a bad colour section, or for a part whose
    /// layers cannot be streamed (free space, log-odds, a version-1 file).
    pub(super) fn index(
        files: &[TessFile],
        depth: u8,
        budget: u64,
        holders: u64,
    ) -> Result<Option<Colours>, FormatError> {
        let mut parts = Vec::with_capacity(files.len());
        let mut any = false;
        let mut read = 0u64;
        for f in files {
            if let Some(ix) = f.colour_only_index() {
                let regions = ix
                    .regions
                    .iter()
                    .map(|r| Region {
                        rgba: r.rgba,
                        firsts: ix.blocks[r.blocks.0..r.blocks.1]
                            .iter()
                            .map(|b| b.first)
                            .collect(),
                        blocks: Blocks::Indexed(r.blocks.0),
                    })
                    .collect::<Vec<_>>();
                any |= !regions.is_empty();
                parts.push(regions);
                continue;
            }
            let Some(streams) = f.colour_streams()? else {
                return Err(FormatError::unsupported(
                    "layers other than colours (free space, log-odds) cannot be rendered streamed",
                )
                .with_path(f.path()));
            };
            let mut regions = Vec::with_capacity(streams.len());
            for (rgba, mut leaves) in streams {
                let (mut firsts, mut points) = (Vec::new(), Vec::new());
                let start = leaves.offset();
                let mut i = 0u64;
                loop {
                    let point = leaves.point();
                    let Some(leaf) = leaves.next() else { break };
                    let leaf = leaf.map_err(|e| e.with_path(f.path()))?;
                    if i % BLOCK == 0 {
                        firsts.push(leaf.code());
                        points.push(point);
                    }
                    i += 1;
                    if i % RELEASE == 0 {
                        // The pages read so far leave resident memory.
                        f.release(0..u64::MAX);
                    }
                }
                let end = leaves.offset();
                read += end - start;
                any |= i > 0;
                regions.push(Region {
                    rgba,
                    firsts,
                    blocks: Blocks::Scanned(points, end),
                });
            }
            parts.push(regions);
        }
        Ok(any.then(|| Colours {
            parts,
            depth,
            cache: Cache::new(budget, holders),
            bytes_read: AtomicU64::new(read),
        }))
    }

    /// Block `b` of region `r` of part `part`, decoded and checked.
    fn decode(
        &self,
        f: &TessFile,
        r: usize,
        region: &Region,
        b: usize,
    ) -> Result<Vec<Leaf>, FormatError> {
        match &region.blocks {
            Blocks::Indexed(base) => {
                let leaves = f.colour_block(r, base + b)?;
                let ix = f.colour_only_index().expect("an indexed part");
                self.bytes_read
                    .fetch_add(ix.blocks[base + b].len as u64, Ordering::Relaxed);
                Ok(leaves)
            }
            Blocks::Scanned(points, end) => {
                let bytes = f.mapped().expect("colour blocks come from mapped files");
                let mut it = RegionLeaves::resume(bytes, points[b], self.depth, BLOCK);
                let leaves = it
                    .by_ref()
                    .collect::<Result<Vec<Leaf>, FormatError>>()
                    .map_err(|e| e.with_path(f.path()))?;
                let stop = points.get(b + 1).map_or(*end, |_| it.offset());
                self.bytes_read
                    .fetch_add(stop - points[b].offset(), Ordering::Relaxed);
                Ok(leaves)
            }
        }
    }

    /// The colour of the voxel with code `code` in part `part`, if it has one: as
    /// `Layer::get`, the leaf with the greatest packed value among those starting
    /// at or before `code`, if it holds `code`.
    ///
    /// # Errors
    /// A damaged colour block, naming the file.
    pub(super) fn get(
        &self,
        files: &[TessFile],
        part: usize,
        code: u64,
    ) -> Result<Option<Rgba>, FormatError> {
        let mut best: Option<(Leaf, Rgba)> = None;
        for (r, region) in self.parts[part].iter().enumerate() {
            let i = region.firsts.partition_point(|&c| c <= code);
            if i == 0 {
                continue;
            }
            let key = ((part as u64) << 44) | ((r as u64) << 32) | (i as u64 - 1);
            let f = &files[part];
            let block: Arc<Vec<Leaf>> = self.cache.get(key, || {
                let leaves = self.decode(f, r, region, i - 1)?;
                let n = std::mem::size_of_val(leaves.as_slice()) as u64 + 64;
                if self.cache.loads.load(Ordering::Relaxed) % RELEASE_BLOCKS == 0 {
                    // Now and then the pages of the blocks decoded leave resident
                    // memory: the cache holds what was decoded from them.
                    f.release(0..u64::MAX);
                }
                Ok::<_, FormatError>((leaves, Cost::flat(n)))
            })?;
            let j = block.partition_point(|l| l.code() <= code);
            if j == 0 {
                continue;
            }
            let leaf = block[j - 1];
            if best.is_none_or(|(b, _)| leaf.packed() > b.packed()) {
                best = Some((leaf, region.rgba));
            }
        }
        Ok(best.and_then(|(l, c)| l.contains_code(code).then_some(c)))
    }
}

//! Stored colours of a streamed tree. The colour section of a version-2 `.tess` is
//! a list of regions (a colour and its leaves, delta-coded), with no index: it is
//! read through once when the tree is opened, keeping a resume point every
//! [`BLOCK`] leaves; a colour is then found by binary search of those points and of
//! one decoded block, blocks kept in a [`Cache`]. The read-through lets the mapped
//! pages go as it goes, so resident memory stays flat (the bytes are read once,
//! as the index checksum at open reads them anyway).

use std::sync::atomic::Ordering;
use std::sync::Arc;

use super::cache::Cache;
use crate::io::tess_colours::{RegionLeaves, RegionPoint};
use crate::io::{FormatError, TessFile};
use crate::linear::Leaf;
use crate::model::Rgba;

/// Leaves per decoded colour block.
pub(super) const BLOCK: u64 = 1024;

/// Leaves read through between two releases of the file's mapped pages.
const RELEASE: u64 = 1 << 20;

/// Colour blocks decoded between two releases of the file's mapped pages.
const RELEASE_BLOCKS: u64 = 256;

/// One region of one part: its colour and where each block starts.
struct Region {
    rgba: Rgba,
    /// The code of each block's first leaf, and where it starts.
    blocks: Vec<(u64, RegionPoint)>,
}

/// The colour regions of every part.
pub(super) struct Colours {
    /// Per part: its regions.
    parts: Vec<Vec<Region>>,
    depth: u8,
    pub(super) cache: Cache<Vec<Leaf>>,
}

impl Colours {
    /// Reads the colour sections of `files` once. `None` when no part has colours.
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
        for f in files {
            let Some(streams) = f.colour_streams()? else {
                return Err(FormatError::unsupported(
                    "layers other than colours (free space, log-odds) cannot be rendered streamed",
                )
                .with_path(f.path()));
            };
            let mut regions = Vec::with_capacity(streams.len());
            for (rgba, mut leaves) in streams {
                let mut blocks = Vec::new();
                let mut i = 0u64;
                loop {
                    let point = leaves.point();
                    let Some(leaf) = leaves.next() else { break };
                    let leaf = leaf.map_err(|e| e.with_path(f.path()))?;
                    if i % BLOCK == 0 {
                        blocks.push((leaf.code(), point));
                    }
                    i += 1;
                    if i % RELEASE == 0 {
                        // The pages read so far leave resident memory.
                        f.release(0..u64::MAX);
                    }
                }
                any |= i > 0;
                regions.push(Region { rgba, blocks });
            }
            parts.push(regions);
        }
        Ok(any.then(|| Colours {
            parts,
            depth,
            cache: Cache::new(budget, holders),
        }))
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
            let i = region.blocks.partition_point(|b| b.0 <= code);
            if i == 0 {
                continue;
            }
            let key = ((part as u64) << 44) | ((r as u64) << 32) | (i as u64 - 1);
            let point = region.blocks[i - 1].1;
            let f = &files[part];
            let block: Arc<Vec<Leaf>> = self.cache.get(key, || {
                let bytes = f.mapped().expect("colour blocks come from mapped files");
                let leaves = RegionLeaves::resume(bytes, point, self.depth, BLOCK)
                    .collect::<Result<Vec<Leaf>, FormatError>>()
                    .map_err(|e| e.with_path(f.path()))?;
                let n = std::mem::size_of_val(leaves.as_slice()) as u64 + 64;
                if self.cache.loads.load(Ordering::Relaxed) % RELEASE_BLOCKS == 0 {
                    // Now and then the pages of the blocks decoded leave resident
                    // memory: the cache holds what was decoded from them.
                    f.release(0..u64::MAX);
                }
                Ok::<_, FormatError>((leaves, n))
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

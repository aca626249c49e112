//! A dynamic octree's own `.tess` (magic `\x89TESSDY\n`): its voxels grouped by
//! world-aligned 8×8×8 block, each block keyed by its `i64` block coordinates. It
//! keeps the octree's full range, where a model (and so the model `.tess`) holds at
//! most 2^21 voxels on an axis: [`DynamicOctree::write_file`] writes it for a `.tess`
//! of an octree past that, and [`DynamicOctree::read_file`] reads both.
//!
//! Layout (little-endian; docs/formats.md has it too):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `89 54 45 53 53 44 59 0A` |
//! | 8 | 2 | version (1) |
//! | 10 | 2 | flags (0) |
//! | 12 | 4 | zero |
//! | 16 | 8 | voxel count |
//! | 24 | 8 | block count n |
//! | 32 | … | n blocks, keys strictly increasing (x, then y, then z) |
//! | end−4 | 4 | CRC-32 (IEEE) of all bytes before |
//!
//! A block holds the voxels `8·key + (x, y, z)`, `x, y, z` in 0..8 (so a key is the
//! voxel coordinates shifted right by three, −2^60..2^60). It is its key's
//! difference from the previous key (the first from 0), three zigzag LEB128
//! varints, then a tag byte:
//! - 0, full: all 512 voxels;
//! - 1, mask: 64 bytes, bit `i` (byte `i / 8`, bit `i % 8`) the voxel with
//!   `i = x + 8y + 64z`; neither empty nor full (a full block takes tag 0).
//!
//! The voxel count is the sum over the blocks.

use std::collections::BTreeMap;
use std::path::Path;

use super::blocks::leaf_axis_masks;
use super::{
    child_index, DynamicOctree, Small, EMPTY, FULL_BLOCK, LEAF_LOG2, NONE, SMALL_CAP, ZERO_BLOCK,
};
use crate::io::leafstream::{put_varint, unzigzag, zigzag, Reader};
use crate::io::native::DYN_MAGIC;
use crate::io::wide;
use crate::io::FormatError;
use crate::Voxel;

const HEADER_LEN: usize = 32;
const FULL_TAG: u8 = 0;
const MASK_TAG: u8 = 1;
/// The block keys' range: voxel coordinates shifted right by three.
const KEY_MIN: i64 = i64::MIN >> 3;
const KEY_MAX: i64 = i64::MAX >> 3;

/// The most bytes an octree read from a file may take: 64 times the file, and 64
/// MiB. A block costs the nodes above it that it does not share (36 bytes each,
/// up to 57 levels), and a full block takes as little as four bytes of file, so a
/// file of full blocks spread far apart would otherwise ask 170 times its size.
fn read_budget(file_len: usize) -> usize {
    file_len.saturating_mul(64).saturating_add(64 << 20)
}

/// The voxels of one world-aligned block: word `z`, bit `x + 8y`.
type Bits = [u64; 8];

/// Per block of an axis span: (block key, mask of the local coordinates) covering
/// `side` voxels from `lo` (wrapping at ±2^63, as the octree does).
fn axis_spans(lo: i64, side: u64) -> Vec<(i64, u8)> {
    let mut out = Vec::new();
    let mut t = 0u64;
    while t < side {
        let v = lo.wrapping_add(t as i64);
        let local = (v & 7) as u32;
        let n = (8 - u64::from(local)).min(side - t) as u32;
        out.push((v >> 3, (((1u32 << n) - 1) << local) as u8));
        t += u64::from(n);
    }
    out
}

impl DynamicOctree {
    /// Whether the octree fits a model (and so a model file): its root spans at
    /// most 2^[`MAX_DEPTH`](crate::linear::MAX_DEPTH) voxels on an axis. O(1).
    ///
    /// ```
    /// use tesseral::dynamic::DynamicOctree;
    /// assert!(DynamicOctree::from_voxels([[0, 0, 0], [1000, 0, 0]]).fits_model());
    /// assert!(!DynamicOctree::from_voxels([[0, 0, 0], [4_000_000, 0, 0]]).fits_model());
    /// ```
    #[must_use]
    pub fn fits_model(&self) -> bool {
        self.size_log2 <= u32::from(crate::linear::MAX_DEPTH)
    }

    /// The voxels grouped by world-aligned 8³ block, keys in order.
    fn world_blocks(&self) -> BTreeMap<[i64; 3], Bits> {
        let mut map: BTreeMap<[i64; 3], Bits> = BTreeMap::new();
        self.visit(|base, level, bits| {
            let w = self.world(base);
            match bits {
                Some(l) if w.iter().all(|&c| c & 7 == 0) => {
                    let e = map.entry(w.map(|c| c >> 3)).or_insert([0; 8]);
                    for z in 0..8 {
                        e[z] |= l[z];
                    }
                }
                Some(l) => {
                    for (z, &word) in l.iter().enumerate() {
                        let mut rest = word;
                        while rest != 0 {
                            let i = rest.trailing_zeros() as i64;
                            rest &= rest - 1;
                            let v = [
                                w[0].wrapping_add(i & 7),
                                w[1].wrapping_add(i >> 3),
                                w[2].wrapping_add(z as i64),
                            ];
                            let e = map.entry(v.map(|c| c >> 3)).or_insert([0; 8]);
                            e[(v[2] & 7) as usize] |= 1 << ((v[0] & 7) + 8 * (v[1] & 7));
                        }
                    }
                }
                None => {
                    // A full octant: a voxel count in u64 keeps its side below 2^22.
                    let side = 1u64 << level.min(63);
                    let (xs, ys, zs) = (
                        axis_spans(w[0], side),
                        axis_spans(w[1], side),
                        axis_spans(w[2], side),
                    );
                    for &(kx, mx) in &xs {
                        for &(ky, my) in &ys {
                            let plane = (0..8)
                                .filter(|y| my >> y & 1 == 1)
                                .fold(0u64, |p, y| p | u64::from(mx) << (8 * y));
                            for &(kz, mz) in &zs {
                                let e = map.entry([kx, ky, kz]).or_insert([0; 8]);
                                for z in (0..8).filter(|z| mz >> z & 1 == 1) {
                                    e[z] |= plane;
                                }
                            }
                        }
                    }
                }
            }
        });
        map
    }

    /// The number of world-aligned 8³ blocks holding a voxel (the blocks of
    /// [`encode_tess_dyn`](Self::encode_tess_dyn)). O(voxels + nodes).
    #[must_use]
    pub fn world_block_count(&self) -> usize {
        self.world_blocks().len()
    }

    /// The box of the voxels: the lowest and highest coordinates on each axis, or
    /// `None` when empty. O(voxels + nodes).
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[-3, 9, 0], [70, -1, 5]]);
    /// assert_eq!(t.bounds(), Some(([-3, -1, 0], [70, 9, 5])));
    /// ```
    #[must_use]
    pub fn bounds(&self) -> Option<(Voxel, Voxel)> {
        let mut out: Option<(Voxel, Voxel)> = None;
        for (key, bits) in self.world_blocks() {
            let m = leaf_axis_masks(&bits);
            let lo: Voxel = std::array::from_fn(|a| key[a] * 8 + i64::from(m[a].trailing_zeros()));
            let hi: Voxel =
                std::array::from_fn(|a| key[a] * 8 + 7 - i64::from(m[a].leading_zeros()));
            out = Some(match out {
                None => (lo, hi),
                Some((a, b)) => (
                    std::array::from_fn(|i| a[i].min(lo[i])),
                    std::array::from_fn(|i| b[i].max(hi[i])),
                ),
            });
        }
        out
    }

    /// The octree as its own `.tess` bytes (layout in docs/formats.md): the full
    /// `i64` range, every voxel exact. The face list is not kept.
    ///
    /// # Runtime
    /// O(voxels + b log b) for b blocks.
    ///
    /// ```
    /// use tesseral::dynamic::DynamicOctree;
    /// let t = DynamicOctree::from_voxels([[0, 0, 0], [1 << 40, -5, 3]]);
    /// let back = DynamicOctree::decode_tess_dyn(&t.encode_tess_dyn()).unwrap();
    /// assert_eq!(back.voxels(), t.voxels());
    /// ```
    #[must_use]
    pub fn encode_tess_dyn(&self) -> Vec<u8> {
        let blocks = self.world_blocks();
        let mut out = Vec::with_capacity(HEADER_LEN + 8 * blocks.len() + 4);
        wide::start(&mut out, &DYN_MAGIC);
        out.extend_from_slice(&self.voxels.to_le_bytes());
        out.extend_from_slice(&(blocks.len() as u64).to_le_bytes());
        let mut prev = [0i64; 3];
        for (key, bits) in &blocks {
            for a in 0..3 {
                put_varint(&mut out, zigzag(key[a].wrapping_sub(prev[a])));
            }
            prev = *key;
            if *bits == FULL_BLOCK {
                out.push(FULL_TAG);
            } else {
                out.push(MASK_TAG);
                for w in bits {
                    out.extend_from_slice(&w.to_le_bytes());
                }
            }
        }
        wide::seal(&mut out);
        out
    }

    /// Reads a dynamic octree's own `.tess` bytes
    /// ([`encode_tess_dyn`](Self::encode_tess_dyn)) into a tree without face
    /// bookkeeping.
    ///
    /// # Runtime
    /// O(len + b · depth) for b blocks.
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] naming the block and byte offset or the field at
    /// fault (the checksum first); [`FormatError::TooLarge`] for an octree that would
    /// take more than 64 times the bytes' length and 64 MiB in memory;
    /// [`FormatError::Unsupported`] for another version or flags.
    pub fn decode_tess_dyn(bytes: &[u8]) -> Result<Self, FormatError> {
        let bad = |m: String| FormatError::corrupt(m);
        let mut r = wide::open(bytes, &DYN_MAGIC, "dynamic octree", HEADER_LEN)?;
        let body = r.bytes;
        let voxels = r.u64().map_err(bad)?;
        let count = r.u64().map_err(bad)?;
        // Every block takes at least four bytes (three varints and a tag).
        let room = (body.len() - HEADER_LEN) as u64 / 4;
        if count > room {
            return Err(bad(format!(
                "bytes 24..32: {count} blocks cannot fit in {} bytes",
                body.len() - HEADER_LEN
            )));
        }
        // First pass: check every block and find the box; second: build.
        let mut lo = [KEY_MAX; 3];
        let mut hi = [KEY_MIN; 3];
        let mut sum = 0u64;
        for_each_block(body, count, |_, key, bits| {
            for a in 0..3 {
                lo[a] = lo[a].min(key[a]);
                hi[a] = hi[a].max(key[a]);
            }
            sum += bits.iter().map(|w| u64::from(w.count_ones())).sum::<u64>();
            Ok(())
        })?;
        if sum != voxels {
            return Err(bad(format!(
                "bytes 16..24: voxel count {voxels}, where the blocks hold {sum}"
            )));
        }
        let mut t = Self::new();
        if count == 0 {
            return Ok(t);
        }
        t.root_min = lo.map(|k| k * 8);
        let extent = (0..3).map(|a| (hi[a] - lo[a]) as u64).max().unwrap_or(0);
        // The root: blocks' side 8 times the smallest power of two past the extent.
        t.size_log2 = (LEAF_LOG2 + (u64::BITS - extent.leading_zeros())).min(64);
        let budget = read_budget(bytes.len());
        for_each_block(body, count, |n, key, bits| {
            let u: [u64; 3] = std::array::from_fn(|a| (key[a].wrapping_sub(lo[a]) as u64) << 3);
            t.put_block(u, bits);
            if n % 1024 == 1023 && t.bytes() > budget {
                return Err(too_large(budget));
            }
            Ok(())
        })?;
        t.voxels = voxels;
        t.contract();
        t.rebuild_dir();
        if t.bytes() > budget {
            return Err(too_large(budget));
        }
        Ok(t)
    }

    /// Stores the new block `bits` (neither empty nor already present) at the
    /// block-aligned offsets `u`, creating the nodes above it; small when it holds
    /// few voxels, small blocks are on and it is not the root, a full slot when full.
    fn put_block(&mut self, u: [u64; 3], bits: &Bits) {
        if *bits == FULL_BLOCK {
            self.fill_aligned(u, LEAF_LOG2);
            return;
        }
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > LEAF_LOG2 {
            if cur == EMPTY {
                cur = self.alloc_node(parent, EMPTY);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        debug_assert_eq!(cur, EMPTY, "a block is stored once");
        let ones: u32 = bits.iter().map(|w| w.count_ones()).sum();
        // A root block is always a bitmap block (it shifts inside).
        let slot = if self.small_blocks && parent != NONE && ones as usize <= SMALL_CAP {
            self.alloc_small(parent, Small::from_words(bits))
        } else {
            let leaf = self.alloc_leaf(parent, 0);
            self.leaves[leaf as usize].0 = *bits;
            leaf
        };
        self.set_slot(parent, ci, slot, LEAF_LOG2, u);
    }

    /// Writes the octree, atomically, in the format named by the extension: a
    /// model's (through [`to_linear`](Self::to_linear) over the root) when it
    /// [fits a model](Self::fits_model), else its own `.tess`
    /// ([`encode_tess_dyn`](Self::encode_tess_dyn)).
    ///
    /// # Errors
    /// [`FormatError::Unsupported`] for an octree past a model's extent in a format
    /// other than `.tess`, named with the path; the errors of
    /// [`crate::io::write_model`].
    pub fn write_file(&self, path: &Path) -> Result<(), FormatError> {
        if self.fits_model() {
            let depth = self.size_log2 as u8;
            let lin = self
                .to_linear(depth, self.root_min)
                .map_err(|e| FormatError::unsupported(e.to_string()).with_path(path))?;
            return crate::io::write_model(path, &crate::model::Model::new(lin));
        }
        if crate::io::extension(path) != "tess" {
            return Err(FormatError::unsupported(format!(
                "the octree spans 2^{} voxels on an axis, past a model's 2^{}: only .tess \
                 keeps it (its own format)",
                self.size_log2,
                crate::linear::MAX_DEPTH
            ))
            .with_path(path));
        }
        let bytes = self.encode_tess_dyn();
        crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &bytes))
    }

    /// Reads an octree: a dynamic octree's own `.tess`
    /// ([`decode_tess_dyn`](Self::decode_tess_dyn)), or any model file
    /// ([`from_linear`](Self::from_linear); the model's frame is not kept).
    ///
    /// # Errors
    /// The reader's [`FormatError`], named with the path.
    pub fn read_file(path: &Path) -> Result<Self, FormatError> {
        if let Some(bytes) = crate::io::wide::read_if(path, &DYN_MAGIC)? {
            return Self::decode_tess_dyn(&bytes).map_err(|e| e.with_path(path));
        }
        let model = crate::io::read_model(path)?;
        Ok(Self::from_linear(&model.tree))
    }
}

fn too_large(budget: usize) -> FormatError {
    FormatError::too_large(format!(
        "the dynamic octree would take more than {budget} bytes in memory \
         (64 times the file's size, and 64 MiB): its blocks lie too far apart"
    ))
}

/// Reads the `count` blocks after the header of `body` (checksum off), checking
/// each, and calls `f(index, key, bits)`; every error names the block and its byte.
fn for_each_block(
    body: &[u8],
    count: u64,
    mut f: impl FnMut(u64, [i64; 3], &Bits) -> Result<(), FormatError>,
) -> Result<(), FormatError> {
    let mut r = Reader {
        bytes: body,
        pos: HEADER_LEN,
    };
    let mut key = [0i64; 3];
    let mut prev: Option<[i64; 3]> = None;
    let mut bits: Bits = [0; 8];
    for n in 0..count {
        let at = r.pos;
        let fail = |m: String| FormatError::corrupt(format!("block {n} (byte {at}): {m}"));
        for k in &mut key {
            *k = k.wrapping_add(unzigzag(r.varint().map_err(fail)?));
        }
        if key.iter().any(|k| !(KEY_MIN..=KEY_MAX).contains(k)) {
            return Err(fail(format!(
                "key {key:?} is past the i64 voxel range (keys {KEY_MIN}..={KEY_MAX})"
            )));
        }
        if prev.is_some_and(|p| p >= key) {
            return Err(fail(format!(
                "key {key:?} does not follow {:?} (keys increase strictly)",
                prev.unwrap_or_default()
            )));
        }
        prev = Some(key);
        match r.u8().map_err(fail)? {
            FULL_TAG => bits = FULL_BLOCK,
            MASK_TAG => {
                let mask = r.take(64).map_err(fail)?;
                for (w, b) in bits.iter_mut().zip(mask.chunks_exact(8)) {
                    *w = u64::from_le_bytes(b.try_into().unwrap_or_default());
                }
                if bits == ZERO_BLOCK {
                    return Err(fail("an empty mask (such blocks are not stored)".into()));
                }
                if bits == FULL_BLOCK {
                    return Err(fail("a full mask (a full block takes tag 0)".into()));
                }
            }
            t => return Err(fail(format!("tag {t} is neither 0 (full) nor 1 (mask)"))),
        }
        f(n, key, &bits)?;
    }
    if r.pos != body.len() {
        return Err(FormatError::corrupt(format!(
            "{} bytes after the last block (byte {}), before the checksum",
            body.len() - r.pos,
            r.pos
        )));
    }
    Ok(())
}

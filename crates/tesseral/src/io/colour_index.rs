//! The colour index of a version-2 `.tess` file (section flag bit 5): where each
//! colour region's leaf stream lies, and a resume point every [`INDEX_BLOCK`]
//! leaves of it, each with the CRC-32 of its bytes. A streamed reader opens a file
//! by reading this index instead of the colour section, and decodes the colours of
//! a code range block by block ([`decode_block`]), each block checked on its own.
//!
//! Layout (little-endian), the last section, offsets counted from the first byte of
//! the sections (their flags):
//!
//! | size | field |
//! |---|---|
//! | 8 | leaves per block B (1 to 2^20) |
//! | 8 | region count r (the colour layer's) |
//! | 40 × r | per region: RGBA, CRC-32 of its leaf stream, leaf count, stream offset, stream length, last packed leaf |
//! | 32 × Σ⌈nᵢ/B⌉ | per block, region by region: offset, packed leaf before it (0 for a region's first), code of its first leaf, CRC-32 of its bytes, its length in bytes |
//! | 4 | CRC-32 of the section's bytes before it |
//! | 4 | zero |
//! | 8 | the section's length, these 8 bytes included (so it is found from the end) |
//!
//! Writing it costs one pass over the colour bytes as they are emitted
//! ([`IndexBuilder`], O(bytes)) and 32 bytes per block held until the end (a
//! depth-15 scene's 10⁹ colour leaves: 8 MiB).

use super::leafstream::Reader;
use super::sections::{FLAG_COLORS, FLAG_COLOR_LAYER, FLAG_FRAME, FLAG_FREE, FLAG_LOG_ODDS};
use super::tess_colours::RegionLeaves;
use crate::linear::Leaf;
use crate::model::Rgba;

/// Section flag of the colour index (version 2 only).
pub(crate) const FLAG_COLOUR_INDEX: u16 = 32;
/// Leaves per indexed block.
pub(crate) const INDEX_BLOCK: u64 = 4096;
/// The largest block size a reader accepts.
const MAX_BLOCK: u64 = 1 << 20;
const REGION_ENTRY: usize = 40;
const BLOCK_ENTRY: usize = 32;
/// B, r before the entries; CRC, zero, length after.
const FIXED: usize = 16 + 16;

/// One indexed region: where its stream lies (absolute byte offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct IxRegion {
    pub(crate) rgba: Rgba,
    pub(crate) crc: u32,
    pub(crate) count: u64,
    pub(crate) start: usize,
    pub(crate) end: usize,
    pub(crate) last: u64,
    /// Its blocks in [`ColourIndex::blocks`].
    pub(crate) blocks: (usize, usize),
}

/// One indexed block of a region (absolute byte offset).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct IxBlock {
    pub(crate) offset: usize,
    pub(crate) len: usize,
    pub(crate) prev: u64,
    pub(crate) first: u64,
    pub(crate) crc: u32,
}

/// A parsed colour index, checked against the colour section's region headers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ColourIndex {
    pub(crate) block: u64,
    pub(crate) regions: Vec<IxRegion>,
    pub(crate) blocks: Vec<IxBlock>,
    /// Where the index section starts.
    pub(crate) start: usize,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// The colour index of the version-2 sections `bytes[start..end]` of a depth-`depth`
/// space, `None` when the flags have no index. Checks its own CRC, its counts and
/// lengths exactly, and every region against the colour section's region headers
/// (colour, count, position), reading r × 12 bytes of the colour section. Not
/// checked here: the blocks' bytes (see [`decode_block`], [`verify_blocks`]).
///
/// O(r + blocks).
pub(crate) fn parse(
    bytes: &[u8],
    (start, end): (usize, usize),
    depth: u8,
) -> Result<Option<ColourIndex>, String> {
    let bad = |m: String| format!("colour index: {m}");
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start,
    };
    let flags = r.u16()?;
    if flags & FLAG_COLOUR_INDEX == 0 {
        return Ok(None);
    }
    if flags & FLAG_COLOR_LAYER == 0 || flags & FLAG_COLORS != 0 {
        return Err(bad(
            "flagged without a colour layer, or with a legacy colour list".into(),
        ));
    }
    let body = end - r.pos;
    if body < FIXED {
        return Err(bad(format!("{body} byte(s) cannot hold it")));
    }
    let len = u64_at(bytes, end - 8);
    let len = usize::try_from(len)
        .ok()
        .filter(|&l| l >= FIXED && l <= body)
        .ok_or_else(|| bad(format!("length {len} does not fit the sections")))?;
    let ix = end - len;
    let stored = u32_at(bytes, end - 16);
    let actual = crc32fast::hash(&bytes[ix..end - 16]);
    if stored != actual {
        return Err(bad(format!(
            "checksum mismatch (stored {stored:08x}, computed {actual:08x})"
        )));
    }
    if u32_at(bytes, end - 12) != 0 {
        return Err(bad("reserved bytes are not zero".into()));
    }
    let block = u64_at(bytes, ix);
    if !(1..=MAX_BLOCK).contains(&block) {
        return Err(bad(format!("block size {block} is not in 1..={MAX_BLOCK}")));
    }
    let count = u64_at(bytes, ix + 8);
    if count > ((len - FIXED) / REGION_ENTRY) as u64 {
        return Err(bad(format!("region count {count} cannot fit")));
    }
    let count = count as usize;
    // The colour layer's head: flags, frame, region count.
    let mut p = start + 2 + if flags & FLAG_FRAME != 0 { 32 } else { 0 };
    if p + 8 > ix || u64_at(bytes, p) != count as u64 {
        return Err(bad(format!(
            "{count} region(s) where the colour section has another count"
        )));
    }
    p += 8;
    let space_end = 1u64 << (3 * u32::from(depth));
    let mut regions = Vec::with_capacity(count);
    let mut nblocks = 0usize;
    let mut seen = std::collections::HashSet::new();
    for i in 0..count {
        let e = ix + 16 + i * REGION_ENTRY;
        let rgba = [bytes[e], bytes[e + 1], bytes[e + 2], bytes[e + 3]];
        let (crc, leaves) = (u32_at(bytes, e + 4), u64_at(bytes, e + 8));
        let (off, slen, last) = (
            u64_at(bytes, e + 16),
            u64_at(bytes, e + 24),
            u64_at(bytes, e + 32),
        );
        let at = |m: &str| bad(format!("region {i}: {m}"));
        if p + 12 > ix || bytes[p..p + 4] != rgba || u64_at(bytes, p + 4) != leaves {
            return Err(at("its colour or count disagrees with the colour section"));
        }
        if !seen.insert(rgba) {
            return Err(at("repeats a colour"));
        }
        let s = p + 12;
        if off != (s - start) as u64 {
            return Err(at(&format!(
                "offset {off} where {} was expected",
                s - start
            )));
        }
        let e_abs = usize::try_from(slen)
            .ok()
            .and_then(|l| s.checked_add(l))
            .filter(|&x| x <= ix)
            .ok_or_else(|| at(&format!("length {slen} runs past the colour section")))?;
        if leaves == 0 || slen < leaves || slen / 10 > leaves {
            return Err(at(&format!("{leaves} leaves cannot take {slen} bytes")));
        }
        let nb = leaves.div_ceil(block) as usize;
        let b0 = nblocks;
        nblocks = nblocks
            .checked_add(nb)
            .filter(|&n| n <= (len - FIXED - count * REGION_ENTRY) / BLOCK_ENTRY)
            .ok_or_else(|| at("too many blocks"))?;
        regions.push(IxRegion {
            rgba,
            crc,
            count: leaves,
            start: s,
            end: e_abs,
            last,
            blocks: (b0, nblocks),
        });
        p = e_abs;
    }
    if FIXED + count * REGION_ENTRY + nblocks * BLOCK_ENTRY != len {
        return Err(bad(format!(
            "length {len} is not that of {count} region(s) and {nblocks} block(s)"
        )));
    }
    if flags & (FLAG_FREE | FLAG_LOG_ODDS) == 0 && p != ix {
        return Err(bad(format!(
            "{} byte(s) between the colour layer and the index",
            ix as i64 - p as i64
        )));
    }
    let mut blocks = Vec::with_capacity(nblocks);
    for (i, reg) in regions.iter().enumerate() {
        let mut expect = reg.start;
        let mut prev_first = None;
        for k in reg.blocks.0..reg.blocks.1 {
            let e = ix + 16 + count * REGION_ENTRY + k * BLOCK_ENTRY;
            let b = IxBlock {
                offset: u64_at(bytes, e) as usize,
                prev: u64_at(bytes, e + 8),
                first: u64_at(bytes, e + 16),
                crc: u32_at(bytes, e + 24),
                len: u32_at(bytes, e + 28) as usize,
            };
            let j = k - reg.blocks.0;
            let at = |m: &str| bad(format!("region {i} block {j}: {m}"));
            let n = (reg.count - j as u64 * block).min(block) as usize;
            if u64_at(bytes, e) != (expect - start) as u64 || b.len < n || b.len / 10 > n {
                return Err(at("offset or length disagrees with the blocks before it"));
            }
            let b = IxBlock {
                offset: expect,
                ..b
            };
            expect += b.len;
            if b.first >= space_end || prev_first.is_some_and(|f| f >= b.first) {
                return Err(at("first code out of order or outside the space"));
            }
            if j == 0 {
                if b.prev != 0 {
                    return Err(at("a region's first block has a leaf before it"));
                }
            } else if !valid(b.prev, depth) || Leaf::from_packed(b.prev).end() > b.first {
                return Err(at("the leaf before it is invalid or overlaps its first"));
            }
            prev_first = Some(b.first);
            blocks.push(b);
        }
        if expect != reg.end {
            return Err(bad(format!("region {i}: its blocks do not end with it")));
        }
        if !valid(reg.last, depth)
            || prev_first.is_some_and(|f| Leaf::from_packed(reg.last).code() < f)
        {
            return Err(bad(format!("region {i}: its last leaf is invalid")));
        }
    }
    Ok(Some(ColourIndex {
        block,
        regions,
        blocks,
        start: ix,
    }))
}

/// Whether `packed` is a leaf of a depth-`depth` space.
fn valid(packed: u64, depth: u8) -> bool {
    let l = Leaf::from_packed(packed);
    let k = l.size_log2();
    packed.trailing_ones() == 3 * u32::from(k)
        && k <= depth
        && packed >> 63 == 0
        && l.end() <= 1u64 << (3 * u32::from(depth))
}

/// The leaves of block `k` (of [`ColourIndex::blocks`]) of region `i`, checked:
/// the CRC of its bytes, each leaf (packing, bounds, order), its count, that they
/// fill its bytes exactly, that the first has the indexed code and that the last is
/// the leaf the next block says comes before it (or the region's last).
///
/// O(B).
pub(crate) fn decode_block(
    bytes: &[u8],
    ix: &ColourIndex,
    i: usize,
    k: usize,
    depth: u8,
) -> Result<Vec<Leaf>, String> {
    let reg = &ix.regions[i];
    let b = ix.blocks[k];
    let j = k - reg.blocks.0;
    let at = |m: String| format!("colour section: region {i} block {j}: {m}");
    let end = b.offset + b.len;
    let actual = crc32fast::hash(&bytes[b.offset..end]);
    if actual != b.crc {
        return Err(at(format!(
            "checksum mismatch (stored {:08x}, computed {actual:08x})",
            b.crc
        )));
    }
    let n = (reg.count - j as u64 * ix.block).min(ix.block);
    let prev_end = (j > 0).then(|| Leaf::from_packed(b.prev).end());
    let mut it = RegionLeaves::block(bytes, (b.offset, end), b.prev, prev_end, n, depth);
    let mut out = Vec::with_capacity(n as usize);
    for l in it.by_ref() {
        out.push(l.map_err(|e| at(e.to_string()))?);
    }
    let next = ix
        .blocks
        .get(k + 1)
        .filter(|_| k + 1 < reg.blocks.1)
        .map_or(reg.last, |nb| nb.prev);
    if it.offset() != end as u64 {
        return Err(at("its leaves do not fill its bytes".into()));
    }
    if out.first().map(|l| l.code()) != Some(b.first)
        || out.last().map(|l| l.packed()) != Some(next)
    {
        return Err(at("its leaves disagree with the index".into()));
    }
    Ok(out)
}

/// Checks every block of every region ([`decode_block`]): the index agrees with
/// the colour section throughout. O(colour bytes).
pub(crate) fn verify_blocks(bytes: &[u8], ix: &ColourIndex, depth: u8) -> Result<(), String> {
    for (i, r) in ix.regions.iter().enumerate() {
        for k in r.blocks.0..r.blocks.1 {
            decode_block(bytes, ix, i, k, depth)?;
        }
    }
    Ok(())
}

/// Checks the CRC of every block, and of every region against its blocks' bytes,
/// without decoding: what a reader that skipped the colour bytes at open (see
/// [`skips`]) does before reading the regions as streams. O(colour bytes).
pub(crate) fn verify_crcs(bytes: &[u8], ix: &ColourIndex) -> Result<(), String> {
    for (i, r) in ix.regions.iter().enumerate() {
        let mut whole = crc32fast::Hasher::new();
        for (j, b) in ix.blocks[r.blocks.0..r.blocks.1].iter().enumerate() {
            let s = &bytes[b.offset..b.offset + b.len];
            let c = crc32fast::hash(s);
            if c != b.crc {
                return Err(format!(
                    "colour section: region {i} block {j}: checksum mismatch (stored {:08x}, computed {c:08x})",
                    b.crc
                ));
            }
            whole.combine(&crc32fast::Hasher::new_with_initial_len(c, s.len() as u64));
        }
        if whole.finalize() != r.crc {
            return Err(format!("colour section: region {i}: checksum mismatch"));
        }
    }
    Ok(())
}

/// The stretches of bytes whose CRC the index holds, for a reader checking the
/// file's checksum without reading them: the regions' streams, `(start, end, crc)`.
pub(crate) fn skips(ix: &ColourIndex) -> Vec<(usize, usize, u32)> {
    ix.regions.iter().map(|r| (r.start, r.end, r.crc)).collect()
}

#[path = "colour_index_write.rs"]
mod write;
pub(crate) use write::{index_of_sections, IndexBuilder};

#[cfg(test)]
#[path = "colour_index_tests.rs"]
mod tests;

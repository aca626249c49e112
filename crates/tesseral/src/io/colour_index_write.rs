//! Writing the colour index (see `super`): built in one pass as the colour
//! layer's bytes go by.

use super::{FIXED, MAX_BLOCK};
use crate::io::leafstream::Reader;
use crate::io::sections::{FLAG_COLORS, FLAG_COLOR_LAYER, FLAG_FRAME};
use crate::linear::Leaf;
use crate::model::Rgba;

/// Builds a colour index from the colour layer's bytes as they are written, in one
/// pass: [`IndexBuilder::region`] before each region's stream, [`IndexBuilder::feed`]
/// with its bytes (in pieces of any size), [`IndexBuilder::finish`] at the end.
pub(crate) struct IndexBuilder {
    block: u64,
    regions: Vec<u8>,
    region_count: u64,
    blocks: Vec<u8>,
    cur: Option<Current>,
}

struct Current {
    rgba: Rgba,
    count: u64,
    start: u64,
    /// Offset of the next byte fed.
    pos: u64,
    /// Leaves begun.
    begun: u64,
    packed: u64,
    delta: u64,
    shift: u32,
    /// Whether the next byte starts a leaf.
    at_leaf: bool,
    whole: crc32fast::Hasher,
    part: crc32fast::Hasher,
    /// The open block: its offset, the leaf before it; its first code once known.
    open: Option<(u64, u64, Option<u64>)>,
}

impl IndexBuilder {
    /// A builder with blocks of `block` leaves.
    pub(crate) fn new(block: u64) -> Self {
        Self {
            block: block.clamp(1, MAX_BLOCK),
            regions: Vec::new(),
            region_count: 0,
            blocks: Vec::new(),
            cur: None,
        }
    }

    /// Starts a region of `count` leaves whose stream starts at `offset` (from the
    /// sections' first byte). Ends the region before.
    pub(crate) fn region(&mut self, rgba: Rgba, count: u64, offset: u64) {
        self.end_region();
        self.cur = Some(Current {
            rgba,
            count,
            start: offset,
            pos: offset,
            begun: 0,
            packed: 0,
            delta: 0,
            shift: 0,
            at_leaf: true,
            whole: crc32fast::Hasher::new(),
            part: crc32fast::Hasher::new(),
            open: None,
        });
    }

    /// Writes the open block's entry, the block ending at offset `at`.
    fn close_block(blocks: &mut Vec<u8>, c: &mut Current, at: u64) {
        if let Some((off, prev, first)) = c.open.take() {
            let part = std::mem::take(&mut c.part);
            for v in [off, prev, first.unwrap_or(0)] {
                blocks.extend_from_slice(&v.to_le_bytes());
            }
            blocks.extend_from_slice(&part.finalize().to_le_bytes());
            blocks.extend_from_slice(&((at - off) as u32).to_le_bytes());
        }
    }

    /// The next bytes of the current region's stream.
    pub(crate) fn feed(&mut self, bytes: &[u8]) {
        let Some(c) = self.cur.as_mut() else { return };
        c.whole.update(bytes);
        let mut from = 0;
        for (i, &b) in bytes.iter().enumerate() {
            if c.at_leaf {
                if c.begun % self.block == 0 {
                    c.part.update(&bytes[from..i]);
                    from = i;
                    let at = c.pos + i as u64;
                    Self::close_block(&mut self.blocks, c, at);
                    c.open = Some((at, c.packed, None));
                }
                c.begun += 1;
                c.at_leaf = false;
            }
            c.delta |= u64::from(b & 0x7f) << c.shift.min(63);
            c.shift += 7;
            if b & 0x80 == 0 {
                c.packed = c.packed.wrapping_add(c.delta);
                if let Some((_, _, first @ None)) = c.open.as_mut() {
                    *first = Some(Leaf::from_packed(c.packed).code());
                }
                c.delta = 0;
                c.shift = 0;
                c.at_leaf = true;
            }
        }
        c.part.update(&bytes[from..]);
        c.pos += bytes.len() as u64;
    }

    fn end_region(&mut self) {
        if let Some(mut c) = self.cur.take() {
            let at = c.pos;
            Self::close_block(&mut self.blocks, &mut c, at);
            self.regions.extend_from_slice(&c.rgba);
            self.regions
                .extend_from_slice(&c.whole.finalize().to_le_bytes());
            for v in [c.count, c.start, c.pos - c.start, c.packed] {
                self.regions.extend_from_slice(&v.to_le_bytes());
            }
            self.region_count += 1;
        }
    }

    /// The index section's bytes.
    pub(crate) fn finish(mut self) -> Vec<u8> {
        self.end_region();
        let mut out = Vec::with_capacity(FIXED + self.regions.len() + self.blocks.len());
        out.extend_from_slice(&self.block.to_le_bytes());
        out.extend_from_slice(&self.region_count.to_le_bytes());
        out.extend_from_slice(&self.regions);
        out.extend_from_slice(&self.blocks);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out.extend_from_slice(&[0; 4]);
        let len = out.len() as u64 + 8;
        out.extend_from_slice(&len.to_le_bytes());
        out
    }
}

/// The colour index (blocks of `block` leaves) of sections already written whole
/// (`sections`, flags first, as [`put_sections`](crate::io::sections::put_sections)
/// writes them): walks the colour layer's regions. `None` when there is no colour
/// layer or it has no region.
pub(crate) fn index_of_sections(sections: &[u8], flags: u16, block: u64) -> Option<Vec<u8>> {
    if flags & FLAG_COLOR_LAYER == 0 || flags & FLAG_COLORS != 0 {
        return None;
    }
    let mut r = Reader {
        bytes: sections,
        pos: 2 + if flags & FLAG_FRAME != 0 { 32 } else { 0 },
    };
    let count = r.u64().ok()?;
    if count == 0 {
        return None;
    }
    let mut b = IndexBuilder::new(block);
    for _ in 0..count {
        let v = r.take(4).ok()?;
        let n = r.u64().ok()?;
        b.region([v[0], v[1], v[2], v[3]], n, r.pos as u64);
        let s = r.pos;
        for _ in 0..n {
            while r.u8().ok()? & 0x80 != 0 {}
        }
        b.feed(&sections[s..r.pos]);
    }
    Some(b.finish())
}

//! The colour regions of a `.tess` file read as streams: each region's leaves
//! decoded from the mapped bytes as they are needed, so a streamed command (the
//! merge of two files, see `partition::stream_set_op`) never holds a layer.

use super::leafstream::Reader;
use super::sections::{FLAG_COLOR_LAYER, FLAG_FRAME};
use super::FormatError;
use crate::linear::Leaf;
use crate::model::Rgba;

/// The leaves of one colour region, decoded lazily and checked as
/// the whole-file reader checks them (packing, size, bounds, order).
#[derive(Clone)]
pub struct RegionLeaves<'a> {
    r: Reader<'a>,
    left: u64,
    packed: u64,
    prev_end: Option<u64>,
    space_end: u64,
    depth: u8,
    failed: bool,
    /// Whether the stream must end exactly where its bytes do (a whole region).
    whole: bool,
    /// What the leaves are, in errors.
    what: &'static str,
}

impl Iterator for RegionLeaves<'_> {
    type Item = Result<Leaf, FormatError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.left == 0 || self.failed {
            return None;
        }
        self.left -= 1;
        let mut r = self.step();
        if r.is_ok() && self.left == 0 && self.whole && self.r.pos != self.r.bytes.len() {
            r = Err(format!(
                "{} byte(s) after the region's last leaf",
                self.r.bytes.len() - self.r.pos
            ));
        }
        self.failed = r.is_err();
        let what = self.what;
        Some(r.map_err(|m| FormatError::corrupt(format!("{what}: {m}"))))
    }
}

/// Where the decoding of a colour region can resume (see [`RegionLeaves::point`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RegionPoint {
    pos: usize,
    end: usize,
    packed: u64,
    prev_end: Option<u64>,
    /// The leaves left from here to the region's end.
    pub(crate) left: u64,
}

impl RegionPoint {
    /// The byte offset (in the file) of the leaf it resumes at.
    pub(crate) fn offset(&self) -> u64 {
        self.pos as u64
    }
}

impl<'a> RegionLeaves<'a> {
    /// Where the next leaf starts: decoding resumes there with
    /// [`RegionLeaves::resume`], with the same checks.
    pub(crate) fn point(&self) -> RegionPoint {
        RegionPoint {
            pos: self.r.pos,
            end: self.r.bytes.len(),
            packed: self.packed,
            prev_end: self.prev_end,
            left: self.left,
        }
    }

    /// The byte offset (in the file) of the next leaf to decode.
    pub(crate) fn offset(&self) -> u64 {
        self.r.pos as u64
    }

    /// The leaves left to decode.
    pub(crate) fn left(&self) -> u64 {
        self.left
    }

    /// The next `n` leaves (or those left, if fewer) as a stream of their own,
    /// with the same checks; `self` does not move.
    pub(crate) fn limited(&self, n: u64) -> Self {
        let mut part = self.clone();
        part.whole = part.whole && part.left <= n;
        part.left = part.left.min(n);
        part
    }

    /// The leaves from `p` (a point of a region of these same `bytes`, the whole
    /// file) on, at most `most` of them.
    pub(crate) fn resume(bytes: &'a [u8], p: RegionPoint, depth: u8, most: u64) -> Self {
        let left = p.left.min(most);
        Self::block(bytes, (p.pos, p.end), p.packed, p.prev_end, left, depth)
    }

    /// The `count` leaves of one indexed block `bytes[start..end]`, decoding from
    /// the packed leaf `packed` before it (`prev_end` its end, `None` at a region's
    /// start).
    pub(crate) fn block(
        bytes: &'a [u8],
        (start, end): (usize, usize),
        packed: u64,
        prev_end: Option<u64>,
        count: u64,
        depth: u8,
    ) -> Self {
        RegionLeaves {
            r: Reader {
                bytes: &bytes[..end],
                pos: start,
            },
            left: count,
            packed,
            prev_end,
            space_end: 1u64 << (3 * u32::from(depth)),
            depth,
            failed: false,
            whole: false,
            what: "colour section",
        }
    }

    /// The whole region of `count` leaves in `bytes[start..end]`, which its leaves
    /// must fill exactly.
    pub(crate) fn region(
        bytes: &'a [u8],
        (start, end): (usize, usize),
        count: u64,
        depth: u8,
    ) -> Self {
        RegionLeaves {
            whole: true,
            ..Self::block(bytes, (start, end), 0, None, count, depth)
        }
    }

    /// The `count` leaves written from `bytes[start..end]` as one stream (a
    /// version-1 file's payload), checked as they are decoded; `what` names them in
    /// errors.
    pub(crate) fn over(
        bytes: &'a [u8],
        (start, end): (usize, usize),
        count: u64,
        depth: u8,
        what: &'static str,
    ) -> Self {
        RegionLeaves {
            what,
            ..Self::block(bytes, (start, end), 0, None, count, depth)
        }
    }
}

impl<'a> RegionLeaves<'a> {
    /// Cuts the region into stretches of at most `n` leaves (at least one), each
    /// with its code range, count and byte offset in the file, and a stream of its leaves
    /// alone, so that a reader can decode the stretches that meet a code range
    /// without reading the region from its start. Reads (and checks) the region
    /// once; holds one small cursor per stretch.
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] for a bad leaf.
    ///
    /// `done(pos)` is called after each stretch with the byte offset read up to,
    /// so that a mapped reader can let the bytes before it go.
    pub fn stretches(
        mut self,
        n: usize,
        done: &mut dyn FnMut(u64),
    ) -> Result<Vec<(super::ChunkInfo, RegionLeaves<'a>)>, FormatError> {
        let n = n.max(1) as u64;
        let mut out = Vec::new();
        while self.left > 0 && !self.failed {
            let part = self.limited(n);
            let count = part.left;
            let mut lo = None;
            let mut hi = 0;
            for _ in 0..count {
                let l = self.next().expect("a leaf is left")?;
                lo.get_or_insert(l.code());
                hi = l.end();
            }
            let info = super::ChunkInfo {
                offset: part.r.pos as u64,
                lo: lo.unwrap_or(0),
                hi,
                count,
            };
            out.push((info, part));
            done(self.r.pos as u64);
        }
        Ok(out)
    }

    fn step(&mut self) -> Result<Leaf, String> {
        let delta = self.r.varint()?;
        if self.prev_end.is_some() && delta == 0 {
            return Err("a leaf repeats the leaf before it".into());
        }
        self.packed = self
            .packed
            .checked_add(delta)
            .ok_or_else(|| "a leaf code overflows".to_string())?;
        let leaf = Leaf::from_packed(self.packed);
        let k = leaf.size_log2();
        if self.packed.trailing_ones() != 3 * u32::from(k)
            || k > self.depth
            || self.packed >> 63 != 0
            || leaf.end() > self.space_end
        {
            return Err(format!("invalid leaf {:#x}", self.packed));
        }
        if self.prev_end.is_some_and(|e| e > leaf.code()) {
            return Err("a leaf overlaps or precedes the one before it".into());
        }
        self.prev_end = Some(leaf.end());
        Ok(leaf)
    }
}

/// The colour regions of the sections `bytes[start..end]` of a version-2 file in a
/// depth-`depth` space: `None` when the sections hold more than a frame and a
/// colour layer (a legacy colour list, free space or log-odds).
///
/// `done(start, end)` is called after each stretch of bytes is scanned, so that a
/// mapped reader can let it go.
pub(crate) fn colour_regions<'a>(
    bytes: &'a [u8],
    (start, end): (usize, usize),
    depth: u8,
    done: &dyn Fn(usize, usize),
) -> Result<Option<Vec<(Rgba, RegionLeaves<'a>)>>, String> {
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start,
    };
    let flags = r.u16()?;
    colour_regions_flagged(bytes, flags, (r.pos, end), depth, done)
}

/// As [`colour_regions`], for sections `bytes[start..end]` that do not start with
/// their flags (a version-1 file keeps them in its header).
pub(crate) fn colour_regions_flagged<'a>(
    bytes: &'a [u8],
    flags: u16,
    (start, end): (usize, usize),
    depth: u8,
    done: &dyn Fn(usize, usize),
) -> Result<Option<Vec<(Rgba, RegionLeaves<'a>)>>, String> {
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start,
    };
    if flags & !(FLAG_FRAME | FLAG_COLOR_LAYER) != 0 {
        return Ok(None);
    }
    if flags & FLAG_FRAME != 0 {
        r.take(32)?;
    }
    let mut out = Vec::new();
    if flags & FLAG_COLOR_LAYER == 0 {
        return Ok(Some(out));
    }
    let count = r.u64()?;
    if count > (end - r.pos) as u64 / 12 {
        return Err(format!("colour region count {count} cannot fit"));
    }
    for i in 0..count {
        let v = r.take(4)?;
        let rgba = [v[0], v[1], v[2], v[3]];
        let leaves = r.u64()?;
        let at = r.pos;
        // Skip the region's varints to find the next region.
        let mut last = at;
        for _ in 0..leaves {
            while r.u8()? & 0x80 != 0 {}
            if r.pos - last >= super::chunked::RELEASE_STRETCH {
                done(last, r.pos);
                last = r.pos;
            }
        }
        done(last, r.pos);
        if out.iter().any(|(c, _): &(Rgba, _)| *c == rgba) {
            return Err(format!("colour region {i}: repeats a colour"));
        }
        out.push((
            rgba,
            RegionLeaves::region(bytes, (at, r.pos), leaves, depth),
        ));
    }
    if r.pos != end {
        return Err(format!(
            "{} unexpected byte(s) after the colours",
            end - r.pos
        ));
    }
    Ok(Some(out))
}

//! The pieces `.tess` sections are made of: LEB128 varints, a bounds-checked reader
//! of untrusted bytes, and a leaf stream (first packed leaf, then positive deltas).

use crate::linear::Leaf;

/// Appends `v` as an unsigned LEB128 varint.
pub(crate) fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Maps a signed number to an unsigned one, small magnitudes to small numbers
/// (0, −1, 1, −2, … to 0, 1, 2, 3, …), for [`put_varint`].
pub(crate) fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

/// The inverse of [`zigzag`].
pub(crate) fn unzigzag(u: u64) -> i64 {
    (u >> 1) as i64 ^ -((u & 1) as i64)
}

/// `bytes` less their last four, which must hold the CRC-32 (IEEE, little-endian)
/// of all before them (the trailer of a version-1 `.tess` and of a map's own
/// `.tess`); the caller has checked that there are four.
pub(crate) fn crc_checked(bytes: &[u8]) -> Result<&[u8], String> {
    let (body, tail) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]);
    let actual = crc32fast::hash(body);
    if stored != actual {
        return Err(format!(
            "checksum mismatch (stored {stored:08x}, computed {actual:08x}): \
             the file is truncated or corrupted"
        ));
    }
    Ok(body)
}

/// A bounds-checked cursor over untrusted bytes.
#[derive(Clone)]
pub(crate) struct Reader<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) pos: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| format!("truncated at byte {} (needed {n} more)", self.pos))?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    pub(crate) fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    pub(crate) fn u16(&mut self) -> Result<u16, String> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    pub(crate) fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    pub(crate) fn i64(&mut self) -> Result<i64, String> {
        self.u64().map(|v| v as i64)
    }
    pub(crate) fn f64(&mut self) -> Result<f64, String> {
        self.u64().map(f64::from_bits)
    }
    pub(crate) fn varint(&mut self) -> Result<u64, String> {
        let mut v = 0u64;
        for i in 0..10 {
            let b = self.u8()?;
            let bits = u64::from(b & 0x7f);
            if i == 9 && bits > 1 {
                return Err(format!("varint overflows 64 bits at byte {}", self.pos - 1));
            }
            v |= bits << (7 * i);
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err(format!("varint longer than 10 bytes at byte {}", self.pos))
    }
}

/// Appends the leaves as varints: the first packed leaf, then each one's difference
/// from the one before.
pub(crate) fn put_leaves(out: &mut Vec<u8>, leaves: &[Leaf]) {
    let mut prev = 0u64;
    for leaf in leaves {
        put_varint(out, leaf.packed() - prev);
        prev = leaf.packed();
    }
}

/// Reads `count` leaves of a depth-`depth` space written by [`put_leaves`], checking
/// each (packing, size, bounds, order); `what` names them in errors ("leaf",
/// "free leaf", ...).
pub(crate) fn read_leaves(
    r: &mut Reader<'_>,
    count: u64,
    depth: u8,
    what: &str,
) -> Result<Vec<Leaf>, String> {
    let remaining = (r.bytes.len() - r.pos) as u64;
    // Every leaf takes at least one byte, so the bytes left bound the count.
    if count > remaining {
        return Err(format!(
            "{what} count {count} cannot fit in {remaining} bytes"
        ));
    }
    let space_end = 1u64 << (3 * u32::from(depth));
    let mut leaves = Vec::with_capacity(count as usize);
    let mut prev: Option<Leaf> = None;
    let mut packed = 0u64;
    for index in 0..count {
        let delta = r.varint().map_err(|m| format!("{what} {index}: {m}"))?;
        if prev.is_some() && delta == 0 {
            return Err(format!("{what} {index}: repeats the leaf before it"));
        }
        packed = packed
            .checked_add(delta)
            .ok_or_else(|| format!("{what} {index}: code overflows"))?;
        let leaf = Leaf::from_packed(packed);
        let k = leaf.size_log2();
        if packed.trailing_ones() != 3 * u32::from(k) || k > depth || packed >> 63 != 0 {
            return Err(format!("{what} {index}: invalid packed leaf {packed:#x}"));
        }
        if leaf.end() > space_end {
            return Err(format!(
                "{what} {index}: lies outside the depth-{depth} space"
            ));
        }
        if let Some(p) = prev {
            if p.end() > leaf.code() {
                return Err(format!(
                    "{what} {index}: overlaps or precedes the leaf before it"
                ));
            }
        }
        prev = Some(leaf);
        leaves.push(leaf);
    }
    Ok(leaves)
}

//! A map's own `.tess` (magic `\x89TESSOM\n`): every stored block with its `i64`
//! key and its cells' fixed-point log-odds, with the resolution and the sensor
//! model. It keeps the map's full range, where a model (and so the model `.tess`)
//! holds at most 2^21 cells on an axis: [`OccupancyMap::write_file`] writes it for
//! a `.tess` of a map past that, and [`OccupancyMap::read_file`] reads both.
//!
//! Layout (little-endian; docs/formats.md has it too):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `89 54 45 53 53 4F 4D 0A` |
//! | 8 | 2 | version (1) |
//! | 10 | 2 | flags (0) |
//! | 12 | 4 | zero |
//! | 16 | 8 | resolution (`f64`) |
//! | 24 | 20 | log-odds of a hit, a miss, the lower and upper clamps, the threshold (`f32`) |
//! | 44 | 4 | the fixed point's scale, log2 (`u32`; it follows from the sensor model) |
//! | 48 | 8 | block count n |
//! | 56 | … | n blocks, keys strictly increasing (x, then y, then z) |
//! | end−4 | 4 | CRC-32 (IEEE) of all bytes before |
//!
//! A block: its key's difference from the previous key (the first from 0), three
//! zigzag LEB128 varints, then a tag byte:
//! - 0, uniform: every cell holds one known value (`i16`);
//! - 1, sparse: a count m (`u16`, 1–512), then m cells, each its index
//!   `x + 8y + 64z` (`u16`, increasing) and value (`i16`);
//! - 2, palette: a count k (`u16`, 2–512), k values (`i16`, unknown as −32768),
//!   then 512 numbers into them of `ceil(log2 k)` bits each, packed from the low
//!   bit of the first byte.
//!
//! Known values lie within the clamps; a block holds at least one known cell.

use super::sensor::{Fixed, UNKNOWN};
use super::store::{BlockKey, Cells, BLOCK_CELLS};
use super::{OccupancyMap, SensorModel};
use crate::io::leafstream::{put_varint, unzigzag, zigzag, Reader};
use crate::io::native::MAP_MAGIC;
use crate::io::wide;
use crate::io::FormatError;

const HEADER_LEN: usize = 56;
const UNIFORM: u8 = 0;
const SPARSE: u8 = 1;
const PALETTE: u8 = 2;

/// The most bytes a map read from a file may take: 64 times the file, and 64 MiB
/// (a map takes a 2 KiB table for each 8³ blocks it reaches, so a file of blocks
/// spread one to a table would otherwise ask 300 times its size).
fn read_budget(file_len: usize) -> usize {
    file_len.saturating_mul(64).saturating_add(64 << 20)
}

/// The bits of a palette number for `k` values.
fn width(k: usize) -> u32 {
    usize::BITS - (k - 1).leading_zeros()
}

impl OccupancyMap {
    /// The map as its own `.tess` bytes (layout in docs/formats.md): the full
    /// `i64` range, the values exact, the sensor model kept.
    ///
    /// # Runtime
    /// O(b log b + 512 b) for b blocks.
    #[must_use]
    pub fn encode_tess_map(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_LEN + 64 * self.store.block_count());
        wide::start(&mut out, &MAP_MAGIC);
        out.extend_from_slice(&self.resolution.to_le_bytes());
        let s = &self.sensor;
        for l in [
            s.hit(),
            s.miss(),
            s.clamp_min(),
            s.clamp_max(),
            s.threshold(),
        ] {
            out.extend_from_slice(&l.to_le_bytes());
        }
        out.extend_from_slice(&self.fixed.scale_log2.to_le_bytes());
        out.extend_from_slice(&(self.store.block_count() as u64).to_le_bytes());
        let mut prev = [0i64; 3];
        self.store.for_each_block(|b, cells| {
            for a in 0..3 {
                put_varint(&mut out, zigzag(b[a].wrapping_sub(prev[a])));
            }
            prev = b;
            put_block(&mut out, cells);
        });
        wide::seal(&mut out);
        out
    }

    /// Reads a map's own `.tess` bytes ([`encode_tess_map`](Self::encode_tess_map)).
    ///
    /// # Runtime
    /// O(len + 512 b) for b blocks.
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] naming the byte offset or field at fault (the
    /// checksum first); [`FormatError::TooLarge`] for a map that would take more
    /// than 64 times the bytes' length and 64 MiB in memory;
    /// [`FormatError::Unsupported`] for another version or flags.
    pub fn decode_tess_map(bytes: &[u8]) -> Result<Self, FormatError> {
        let bad = |m: String| FormatError::corrupt(m);
        let mut r = wide::open(bytes, &MAP_MAGIC, "occupancy map", HEADER_LEN)?;
        let body = r.bytes;
        let resolution = r.f64().map_err(bad)?;
        let mut l = [0f32; 5];
        for x in &mut l {
            *x = f32::from_bits(r.u32().map_err(bad)?);
        }
        let sensor = SensorModel::from_log_odds(l[0], l[1], (l[2], l[3]), l[4])
            .map_err(|e| bad(format!("bytes 24..44: {e}")))?;
        let mut map =
            Self::new(resolution, sensor).map_err(|e| bad(format!("bytes 16..24: {e}")))?;
        let scale = r.u32().map_err(bad)?;
        if scale != map.fixed.scale_log2 {
            return Err(bad(format!(
                "bytes 44..48: fixed-point scale 2^{scale}, where the sensor model gives 2^{}",
                map.fixed.scale_log2
            )));
        }
        let count = r.u64().map_err(bad)?;
        // Every block takes at least five bytes (three varints, a tag, a value).
        let room = (body.len() - HEADER_LEN) as u64 / 5;
        if count > room {
            return Err(bad(format!(
                "bytes 48..56: {count} blocks cannot fit in {} bytes",
                body.len() - HEADER_LEN
            )));
        }
        let budget = read_budget(bytes.len());
        let mut prev: Option<BlockKey> = None;
        let mut key = [0i64; 3];
        let mut cells: Cells = [UNKNOWN; BLOCK_CELLS];
        for n in 0..count {
            let at = r.pos;
            let fail = |m: String| bad(format!("block {n} (byte {at}): {m}"));
            for k in &mut key {
                *k = k.wrapping_add(unzigzag(r.varint().map_err(fail)?));
            }
            let limit = i64::MAX >> 3;
            if key.iter().any(|&k| !(-limit - 1..=limit).contains(&k)) {
                return Err(fail(format!("key {key:?} is past the i64 cell range")));
            }
            if prev.is_some_and(|p| p >= key) {
                return Err(fail(format!(
                    "key {key:?} does not follow {:?} (keys increase strictly)",
                    prev.unwrap_or_default()
                )));
            }
            prev = Some(key);
            read_block(&mut r, map.fixed, &mut cells).map_err(fail)?;
            map.store.put(key, &cells, map.fixed);
            if n % 1024 == 1023 && map.store.bytes() > budget {
                return Err(too_large(budget));
            }
        }
        if r.pos != body.len() {
            return Err(bad(format!(
                "{} bytes after the last block, before the checksum",
                body.len() - r.pos
            )));
        }
        if map.store.overflowed() {
            return Err(FormatError::too_large(format!(
                "the map's blocks pass {} bytes in an arena, the most a map holds",
                map.store.limit_bytes()
            )));
        }
        map.store.pack(map.fixed);
        if map.store.bytes() > budget {
            return Err(too_large(budget));
        }
        Ok(map)
    }
}

fn too_large(budget: usize) -> FormatError {
    FormatError::too_large(format!(
        "the map would take more than {budget} bytes in memory \
         (64 times the file's size, and 64 MiB): its blocks lie too far apart"
    ))
}

/// Appends a block's tag and cells: uniform when every cell holds one known value,
/// else the smaller of sparse and palette.
fn put_block(out: &mut Vec<u8>, cells: &Cells) {
    let first = cells[0];
    if first != UNKNOWN && cells.iter().all(|&v| v == first) {
        out.push(UNIFORM);
        out.extend_from_slice(&first.to_le_bytes());
        return;
    }
    let mut values: Vec<i16> = cells.to_vec();
    values.sort_unstable();
    values.dedup();
    let known = cells.iter().filter(|&&v| v != UNKNOWN).count();
    let w = width(values.len());
    if 4 * known <= 2 * values.len() + 64 * w as usize {
        out.push(SPARSE);
        out.extend_from_slice(&(known as u16).to_le_bytes());
        for (i, &v) in cells.iter().enumerate().filter(|&(_, &v)| v != UNKNOWN) {
            out.extend_from_slice(&(i as u16).to_le_bytes());
            out.extend_from_slice(&v.to_le_bytes());
        }
        return;
    }
    out.push(PALETTE);
    out.extend_from_slice(&(values.len() as u16).to_le_bytes());
    for v in &values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut acc = 0u64;
    let mut bits = 0;
    for v in cells {
        let j = values.binary_search(v).unwrap_or_default() as u64;
        acc |= j << bits;
        bits += w;
        while bits >= 8 {
            out.push(acc as u8);
            acc >>= 8;
            bits -= 8;
        }
    }
    debug_assert_eq!(bits, 0, "512 numbers fill whole bytes");
}

/// Reads a block's tag and cells into `cells`, checking every value (known ones
/// within the clamps) and that one is known.
fn read_block(r: &mut Reader<'_>, fixed: Fixed, cells: &mut Cells) -> Result<(), String> {
    let value = |r: &mut Reader<'_>, unknown_ok: bool| -> Result<i16, String> {
        let at = r.pos;
        let v = r.u16()? as i16;
        if (v == UNKNOWN && unknown_ok) || (fixed.min..=fixed.max).contains(&v) {
            Ok(v)
        } else {
            Err(format!(
                "value {v} at byte {at} is outside the clamps ({}..={})",
                fixed.min, fixed.max
            ))
        }
    };
    let tag = r.u8()?;
    match tag {
        UNIFORM => cells.fill(value(r, false)?),
        SPARSE => {
            let m = usize::from(r.u16()?);
            if !(1..=BLOCK_CELLS).contains(&m) {
                return Err(format!("sparse count {m} is not in 1..=512"));
            }
            cells.fill(UNKNOWN);
            let mut next = 0;
            for _ in 0..m {
                let i = usize::from(r.u16()?);
                if i < next || i >= BLOCK_CELLS {
                    return Err(format!(
                        "cell index {i} at byte {} is not increasing within 0..512",
                        r.pos - 2
                    ));
                }
                cells[i] = value(r, false)?;
                next = i + 1;
            }
        }
        PALETTE => {
            let k = usize::from(r.u16()?);
            if !(2..=BLOCK_CELLS).contains(&k) {
                return Err(format!("palette count {k} is not in 2..=512"));
            }
            let mut values = [UNKNOWN; BLOCK_CELLS];
            for v in &mut values[..k] {
                *v = value(r, true)?;
            }
            let w = width(k);
            let at = r.pos;
            let packed = r.take(64 * w as usize)?;
            let (mut acc, mut bits, mut bytes) = (0u64, 0, packed.iter());
            for c in cells.iter_mut() {
                while bits < w {
                    acc |= u64::from(*bytes.next().unwrap_or(&0)) << bits;
                    bits += 8;
                }
                let j = (acc & ((1 << w) - 1)) as usize;
                acc >>= w;
                bits -= w;
                if j >= k {
                    return Err(format!(
                        "palette number {j} past its {k} values (numbers from byte {at})"
                    ));
                }
                *c = values[j];
            }
            if cells.iter().all(|&v| v == UNKNOWN) {
                return Err("every cell is unknown (such blocks are not stored)".into());
            }
        }
        t => {
            return Err(format!(
                "tag {t} is none of 0 (uniform), 1 (sparse), 2 (palette)"
            ))
        }
    }
    Ok(())
}

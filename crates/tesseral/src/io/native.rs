//! tesseral's native binary format, extension `.tess`: a linear octree as delta-coded
//! varints, with a versioned header and a CRC-32 checksum.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `89 54 45 53 53 52 4C 0A` (`\x89TESSRL\n`) |
//! | 8 | 2 | version, `1` |
//! | 10 | 2 | flags: bit 0 a frame follows the leaves, bit 1 colours follow |
//! | 12 | 1 | depth D (≤ 21) |
//! | 13 | 3 | zero |
//! | 16 | 24 | origin, three `i64` |
//! | 40 | 8 | leaf count n |
//! | 48 | 8 | payload length p in bytes |
//! | 56 | p | n varints (LEB128): the first packed leaf, then the difference of each packed leaf from the one before |
//! | … | 32 | if flag 0: voxel size and translate, four `f64` |
//! | … | … | if flag 1: colour count m (`u64`), then m × (varint code delta, 4 bytes RGBA) |
//! | end − 4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! A packed leaf ([`Leaf::packed`]) holds the code and the block size, and packed
//! leaves increase strictly, so the deltas are positive and small: one byte for most
//! leaves of a solid. The layout has no pointers, so the file can be memory-mapped
//! and decoded in one pass ([`read`] maps it with `memmap2`).
//!
//! The reader trusts no stored count: it checks the checksum first, allocates no more
//! than the file's own length can justify, validates every leaf (packing, size,
//! bounds, order) and checks that the counts and lengths add up exactly.

use std::io::{self, Write};
use std::path::Path;

use super::{ColorMap, FormatError, Frame, VoxelModel};
use crate::linear::{Leaf, LinearOctree, MAX_DEPTH};

/// The eight bytes every `.tess` file starts with.
pub const MAGIC: [u8; 8] = *b"\x89TESSRL\n";
/// The version this code writes and reads.
pub const VERSION: u16 = 1;
const FLAG_FRAME: u16 = 1;
const FLAG_COLORS: u16 = 2;
const KNOWN_FLAGS: u16 = FLAG_FRAME | FLAG_COLORS;
const HEADER_LEN: usize = 56;

/// Reads a `.tess` file by memory-mapping it, falling back to reading it into memory
/// when mapping fails (for example on a pipe).
///
/// # Runtime
/// O(file size + n) for n leaves.
///
/// # Errors
/// [`FormatError::Corrupt`] naming the field for a truncated, corrupted or hostile
/// file; [`FormatError::Io`] when the file cannot be read.
pub fn read(path: &Path) -> Result<VoxelModel, FormatError> {
    let file = std::fs::File::open(path).map_err(|e| FormatError::io(path, e))?;
    // SAFETY: the map is read-only and dropped before we return. Another process
    // truncating or rewriting the file while we decode could change the bytes under
    // us; `decode` treats the slice as untrusted input (every read is bounds-checked
    // against the slice length, taken once), so such a race gives at worst a checksum
    // or format error, or SIGBUS on truncation, which memory-mapped readers accept.
    // `write_atomic` replaces files by rename, so our own writers never do this.
    match unsafe { memmap2::Mmap::map(&file) } {
        Ok(map) => decode(&map, path),
        Err(_) => {
            let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
            decode(&bytes, path)
        }
    }
}

/// Reads a `.tess` file into memory with plain reads (the safe fallback of [`read`]).
///
/// # Errors
/// As [`read`].
pub fn read_unmapped(path: &Path) -> Result<VoxelModel, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    decode(&bytes, path)
}

/// Encodes a model into `.tess` bytes.
///
/// ```
/// use tesseral::io::{native, VoxelModel};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(4, [-8, 0, 0], [[-8, 0, 0], [3, 2, 1]]).unwrap();
/// let bytes = native::encode(&VoxelModel::new(tree.clone()));
/// let back = native::decode(&bytes, "mem.tess".as_ref()).unwrap();
/// assert_eq!(back.tree, tree);
/// ```
#[must_use]
pub fn encode(model: &VoxelModel) -> Vec<u8> {
    let mut out = Vec::new();
    write(&mut out, model).expect("writing to a Vec cannot fail");
    out
}

/// Writes a model in the `.tess` format.
///
/// # Runtime
/// O(n) for n leaves (plus the colours).
///
/// # Errors
/// Any I/O error of `w`.
pub fn write(w: &mut dyn Write, model: &VoxelModel) -> io::Result<()> {
    let tree = &model.tree;
    let mut payload = Vec::with_capacity(tree.leaf_count() + 16);
    let mut prev = 0u64;
    for leaf in tree.leaves() {
        put_varint(&mut payload, leaf.packed() - prev);
        prev = leaf.packed();
    }
    let mut flags = 0u16;
    let mut tail = Vec::new();
    if let Some(frame) = &model.frame {
        flags |= FLAG_FRAME;
        tail.extend_from_slice(&frame.voxel_size.to_le_bytes());
        for t in frame.translate {
            tail.extend_from_slice(&t.to_le_bytes());
        }
    }
    if let Some(colors) = &model.colors {
        flags |= FLAG_COLORS;
        let mut coded: Vec<(u64, [u8; 4])> = colors
            .iter()
            .filter_map(|(v, c)| {
                if tree.contains(*v) {
                    tree.code_of(*v).map(|code| (code, *c))
                } else {
                    None
                }
            })
            .collect();
        coded.sort_unstable_by_key(|e| e.0);
        tail.extend_from_slice(&(coded.len() as u64).to_le_bytes());
        let mut prev = 0u64;
        for (code, rgba) in coded {
            put_varint(&mut tail, code - prev);
            prev = code;
            tail.extend_from_slice(&rgba);
        }
    }
    let mut header = Vec::with_capacity(HEADER_LEN);
    header.extend_from_slice(&MAGIC);
    header.extend_from_slice(&VERSION.to_le_bytes());
    header.extend_from_slice(&flags.to_le_bytes());
    header.push(tree.depth());
    header.extend_from_slice(&[0, 0, 0]);
    for o in tree.origin() {
        header.extend_from_slice(&o.to_le_bytes());
    }
    header.extend_from_slice(&(tree.leaf_count() as u64).to_le_bytes());
    header.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    for part in [&header, &payload, &tail] {
        crc.update(part);
        w.write_all(part)?;
    }
    w.write_all(&crc.finalize().to_le_bytes())
}

/// Decodes `.tess` bytes; `path` names the source in errors.
///
/// # Runtime
/// O(len + n).
///
/// # Errors
/// [`FormatError::Corrupt`] naming the field at fault.
pub fn decode(bytes: &[u8], path: &Path) -> Result<VoxelModel, FormatError> {
    let bad = |m: String| FormatError::corrupt(path, m);
    if bytes.len() < 8 || bytes[..8] != MAGIC {
        return Err(bad("not a tesseral .tess file (bad magic number)".into()));
    }
    if bytes.len() < HEADER_LEN + 4 {
        return Err(bad(format!(
            "truncated: {} bytes, a header needs {}",
            bytes.len(),
            HEADER_LEN + 4
        )));
    }
    let version = u16::from_le_bytes([bytes[8], bytes[9]]);
    if version != VERSION {
        return Err(FormatError::unsupported(
            path,
            format!("format version {version}; this build reads version {VERSION}"),
        ));
    }
    let (body, stored) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes([stored[0], stored[1], stored[2], stored[3]]);
    let actual = crc32fast::hash(body);
    if stored != actual {
        return Err(bad(format!(
            "checksum mismatch (stored {stored:08x}, computed {actual:08x}): the file is truncated or corrupted"
        )));
    }
    let mut r = Reader {
        bytes: body,
        pos: 10,
    };
    let flags = r.u16().map_err(&bad)?;
    if flags & !KNOWN_FLAGS != 0 {
        return Err(FormatError::unsupported(
            path,
            format!("unknown flags {flags:#06x}"),
        ));
    }
    let depth = r.u8().map_err(&bad)?;
    if depth > MAX_DEPTH {
        return Err(bad(format!(
            "depth {depth} exceeds the maximum {MAX_DEPTH}"
        )));
    }
    r.pos += 3;
    let origin = [
        r.i64().map_err(&bad)?,
        r.i64().map_err(&bad)?,
        r.i64().map_err(&bad)?,
    ];
    let leaf_count = r.u64().map_err(&bad)?;
    let payload_len = r.u64().map_err(&bad)?;
    let payload_end = usize::try_from(payload_len)
        .ok()
        .and_then(|p| p.checked_add(HEADER_LEN))
        .filter(|&e| e <= body.len())
        .ok_or_else(|| {
            bad(format!(
                "payload length {payload_len} runs past the end of the file"
            ))
        })?;
    // Every leaf takes at least one byte, so the payload length bounds the count.
    if leaf_count > payload_len {
        return Err(bad(format!(
            "leaf count {leaf_count} cannot fit in a payload of {payload_len} bytes"
        )));
    }
    let space_end = 1u64 << (3 * u32::from(depth));
    let mut leaves = Vec::with_capacity(leaf_count as usize);
    let mut payload = Reader {
        bytes: &body[..payload_end],
        pos: HEADER_LEN,
    };
    let mut prev: Option<Leaf> = None;
    let mut packed = 0u64;
    for index in 0..leaf_count {
        let delta = payload
            .varint()
            .map_err(|m| bad(format!("leaf {index}: {m}")))?;
        if prev.is_some() && delta == 0 {
            return Err(bad(format!("leaf {index}: repeats the leaf before it")));
        }
        packed = packed
            .checked_add(delta)
            .ok_or_else(|| bad(format!("leaf {index}: code overflows")))?;
        let leaf = Leaf::from_packed(packed);
        let k = leaf.size_log2();
        if packed.trailing_ones() != 3 * u32::from(k) || k > depth || packed >> 63 != 0 {
            return Err(bad(format!(
                "leaf {index}: invalid packed leaf {packed:#x}"
            )));
        }
        if leaf.end() > space_end {
            return Err(bad(format!(
                "leaf {index}: lies outside the depth-{depth} space"
            )));
        }
        if let Some(p) = prev {
            if p.end() > leaf.code() {
                return Err(bad(format!(
                    "leaf {index}: overlaps or precedes the leaf before it"
                )));
            }
        }
        prev = Some(leaf);
        leaves.push(leaf);
    }
    if payload.pos != payload_end {
        return Err(bad(format!(
            "payload has {} byte(s) after the last of {leaf_count} leaves",
            payload_end - payload.pos
        )));
    }
    let tree = LinearOctree::from_sorted_leaves(depth, origin, leaves)
        .map_err(|e| FormatError::octree(path, e))?;
    let mut tail = Reader {
        bytes: body,
        pos: payload_end,
    };
    let frame = if flags & FLAG_FRAME != 0 {
        let voxel_size = tail.f64().map_err(&bad)?;
        let translate = [
            tail.f64().map_err(&bad)?,
            tail.f64().map_err(&bad)?,
            tail.f64().map_err(&bad)?,
        ];
        if !(voxel_size.is_finite() && voxel_size > 0.0) || translate.iter().any(|t| !t.is_finite())
        {
            return Err(bad(format!("frame: voxel size {voxel_size} or translate {translate:?} is not finite and positive")));
        }
        Some(Frame {
            voxel_size,
            translate,
        })
    } else {
        None
    };
    let colors = if flags & FLAG_COLORS != 0 {
        let count = tail.u64().map_err(&bad)?;
        let remaining = (body.len() - tail.pos) as u64;
        if count > remaining / 5 {
            return Err(bad(format!(
                "colour count {count} cannot fit in {remaining} bytes"
            )));
        }
        let mut map = ColorMap::new();
        let mut code = 0u64;
        for index in 0..count {
            let delta = tail
                .varint()
                .map_err(|m| bad(format!("colour {index}: {m}")))?;
            code = code
                .checked_add(delta)
                .filter(|&c| c < space_end && (index == 0 || delta > 0))
                .ok_or_else(|| bad(format!("colour {index}: bad voxel code")))?;
            let rgba = tail.take(4).map_err(&bad)?;
            map.insert(tree.voxel_of(code), [rgba[0], rgba[1], rgba[2], rgba[3]]);
        }
        Some(map)
    } else {
        None
    };
    if tail.pos != body.len() {
        return Err(bad(format!(
            "{} unexpected byte(s) before the checksum",
            body.len() - tail.pos
        )));
    }
    Ok(VoxelModel {
        tree,
        frame,
        colors,
    })
}

/// Appends `v` as an unsigned LEB128 varint.
pub(crate) fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// A bounds-checked cursor over untrusted bytes.
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_tree(seed: u64) -> LinearOctree {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let depth = rng.random_range(0..=6u8);
        let side = 1i64 << depth;
        let origin = [rng.random_range(-100..100), rng.random_range(-100..100), 7];
        let n = rng.random_range(0..300);
        let blob = rng.random_bool(0.5);
        let voxels: Vec<_> = (0..n)
            .map(|_| {
                let r = if blob { side / 2 + 1 } else { side };
                [
                    origin[0] + rng.random_range(0..r),
                    origin[1] + rng.random_range(0..r),
                    origin[2] + rng.random_range(0..r),
                ]
            })
            .collect();
        LinearOctree::from_voxels(depth, origin, voxels).unwrap()
    }

    #[test]
    fn round_trips_random_trees_with_frame_and_colours() {
        for seed in 0..200 {
            let tree = random_tree(seed);
            let colors: ColorMap = tree
                .voxels()
                .step_by(3)
                .map(|v| (v, [v[0] as u8, v[1] as u8, 9, 255]))
                .collect();
            let model = VoxelModel {
                tree: tree.clone(),
                frame: (seed % 2 == 0).then_some(Frame {
                    voxel_size: 0.05,
                    translate: [1.5, -2.0, 0.25],
                }),
                colors: (seed % 3 == 0).then_some(colors),
            };
            let bytes = encode(&model);
            let back =
                decode(&bytes, Path::new("t.tess")).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            back.tree.assert_valid();
            assert_eq!(back, model, "seed {seed}");
        }
    }

    #[test]
    fn every_truncation_and_bit_flip_is_an_error() {
        let tree = random_tree(7);
        let bytes = encode(&VoxelModel::new(tree));
        for len in 0..bytes.len() {
            assert!(
                decode(&bytes[..len], Path::new("t.tess")).is_err(),
                "truncated to {len}"
            );
        }
        for i in 0..bytes.len() {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                assert!(
                    decode(&b, Path::new("t.tess")).is_err(),
                    "flip byte {i} bit {bit}"
                );
            }
        }
    }

    #[test]
    fn hostile_counts_with_valid_checksums_are_refused() {
        // A forged header claiming 2^60 leaves, with a correct checksum.
        let tree = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 1, 1]]).unwrap();
        let mut bytes = encode(&VoxelModel::new(tree));
        bytes[40..48].copy_from_slice(&(1u64 << 60).to_le_bytes());
        let n = bytes.len();
        let crc = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
        let err = decode(&bytes, Path::new("t.tess")).unwrap_err().to_string();
        assert!(err.contains("leaf count"), "{err}");
        // Depth beyond the limit.
        let mut bytes = encode(&VoxelModel::new(LinearOctree::empty(2, [0; 3]).unwrap()));
        bytes[12] = 40;
        let crc = crc32fast::hash(&bytes[..bytes.len() - 4]);
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
        let err = decode(&bytes, Path::new("t.tess")).unwrap_err().to_string();
        assert!(err.contains("depth 40"), "{err}");
    }

    #[test]
    fn varint_round_trip_and_overflow() {
        for v in [0, 1, 127, 128, 300, u64::MAX >> 1, u64::MAX] {
            let mut out = Vec::new();
            put_varint(&mut out, v);
            assert_eq!(
                Reader {
                    bytes: &out,
                    pos: 0
                }
                .varint(),
                Ok(v)
            );
        }
        let over = [0xffu8; 10];
        assert!(Reader {
            bytes: &over,
            pos: 0
        }
        .varint()
        .is_err());
    }

    #[test]
    fn mapped_and_unmapped_reads_agree() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.tess");
        let model = VoxelModel::new(random_tree(3));
        crate::io::write_model(&path, &model).unwrap();
        assert_eq!(read(&path).unwrap(), model);
        assert_eq!(read_unmapped(&path).unwrap(), model);
        assert_eq!(crate::io::read_octree(&path).unwrap(), model.tree);
    }
}

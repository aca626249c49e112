//! A version-1 `.tess` file (one payload of leaves, one checksum over the whole
//! file) read as a stream: the checksum is computed over the mapped bytes, then
//! the payload is walked once to index it in stretches of
//! [`super::DEFAULT_CHUNK_LEAVES`] leaves (code range, count, byte offset and a
//! decoder's resume point each), which play the chunks of a version-2 file. The
//! leaves are sorted in the payload, so nothing else is needed; the colour layer
//! is read as streams from the sections after the payload.
//!
//! The stretches hold the leaves the whole-file decoder gives, so that a file
//! has one answer however it is read: a payload with eight sibling leaves in a
//! row (no writer makes one, but the decoder has always accepted it and merged
//! them, as it does in a version-2 file) is merged as it is read, each stretch
//! cut between merged leaves and decoded from the first leaf its first merges
//! from, past its end as far as it takes to know its last merges no further
//! (`MergingStream`, holding about seven leaves a level). A colour layer with
//! such a region is not streamed (see `TessFile::colour_streams`).

use super::chunked::{check_crc, crc_released, MERGE_TAIL, RELEASE_STRETCH};
use super::leafstream::Reader;
use super::sections::{read_sections, FLAG_FRAME, KNOWN_FLAGS};
use super::tess_colours::{RegionLeaves, RegionPoint};
use super::{ChunkInfo, FormatError};
use crate::linear::{Leaf, LinearOctree, MergingStream, MAX_DEPTH};
use crate::model::Frame;
use crate::Voxel;

/// The header's length: magic, version, flags, depth, origin, leaf count and
/// payload length.
const HEADER_LEN: usize = 56;

/// The index of a version-1 file's payload.
pub(crate) struct V1Index {
    pub(crate) depth: u8,
    pub(crate) origin: Voxel,
    pub(crate) flags: u16,
    pub(crate) leaf_count: u64,
    pub(crate) chunks: Vec<ChunkInfo>,
    points: Vec<RegionPoint>,
    /// The sections, after the payload and before the checksum.
    pub(crate) sections: (usize, usize),
    /// Whether every colour region is canonical (found when they are first read
    /// as streams).
    pub(crate) colours_canonical: std::sync::OnceLock<bool>,
}

/// Checks a version-1 file's checksum and header and indexes its payload,
/// calling `done(start, end)` after each stretch of bytes is read so that a
/// mapped reader can let it go. Gives the index and the frame.
pub(crate) fn index_v1(
    bytes: &[u8],
    done: &dyn Fn(usize, usize),
) -> Result<(V1Index, Frame), String> {
    if bytes.len() < HEADER_LEN + 4 {
        return Err(format!(
            "truncated: {} bytes, a header needs {}",
            bytes.len(),
            HEADER_LEN + 4
        ));
    }
    let body_len = bytes.len() - 4;
    let s = &bytes[body_len..];
    let stored = u32::from_le_bytes([s[0], s[1], s[2], s[3]]);
    let mut crc = crc32fast::Hasher::new();
    crc_released(&mut crc, bytes, 0, body_len, done);
    check_crc("checksum", stored, crc.finalize())?;
    let body = &bytes[..body_len];
    let mut r = Reader {
        bytes: body,
        pos: 10,
    };
    let flags = r.u16()?;
    if flags & !KNOWN_FLAGS != 0 {
        return Err(format!("unknown flags {flags:#06x}"));
    }
    let depth = r.u8()?;
    if depth > MAX_DEPTH {
        return Err(format!("depth {depth} exceeds the maximum {MAX_DEPTH}"));
    }
    r.pos += 3;
    let origin = [r.i64()?, r.i64()?, r.i64()?];
    let space = LinearOctree::empty(depth, origin).map_err(|e| e.to_string())?;
    let leaf_count = r.u64()?;
    let payload_len = r.u64()?;
    let payload_end = usize::try_from(payload_len)
        .ok()
        .and_then(|p| p.checked_add(HEADER_LEN))
        .filter(|&e| e <= body.len())
        .ok_or_else(|| format!("payload length {payload_len} runs past the end of the file"))?;
    if leaf_count > payload_len {
        return Err(format!(
            "leaf count {leaf_count} cannot fit in a payload of {payload_len} bytes"
        ));
    }
    let mut released = HEADER_LEN;
    let mut payload = RegionLeaves::over(
        body,
        (HEADER_LEN, payload_end),
        leaf_count,
        depth,
        "leaf payload",
    );
    let index = index_merged(&mut payload, depth, &mut |pos| {
        if pos - released >= RELEASE_STRETCH {
            done(released, pos);
            released = pos;
        }
    })
    .map_err(|e| e.to_string())?;
    let read_to = payload.offset() as usize;
    done(released, read_to);
    if read_to != payload_end {
        return Err(format!(
            "payload has {} byte(s) after the last of {leaf_count} leaves",
            payload_end - read_to
        ));
    }
    let (chunks, points) = index;
    let mut tail = Reader {
        bytes: body,
        pos: payload_end,
    };
    let frame = read_sections(&mut tail, flags & FLAG_FRAME, &space)?.frame;
    let leaf_count = chunks.iter().map(|c: &ChunkInfo| c.count).sum();
    Ok((
        V1Index {
            depth,
            origin,
            flags,
            leaf_count,
            chunks,
            points,
            sections: (payload_end, body_len),
            colours_canonical: std::sync::OnceLock::new(),
        },
        frame,
    ))
}

/// Reads the payload's leaves, merged into canonical form as the whole-file
/// decoder merges them (`LinearOctree::from_sorted_leaves`), and cuts them into
/// stretches of [`super::DEFAULT_CHUNK_LEAVES`] merged leaves, each with the
/// point where the first leaf it merges from starts. `done(pos)` is called as
/// the bytes before `pos` are read.
fn index_merged(
    payload: &mut RegionLeaves<'_>,
    depth: u8,
    done: &mut dyn FnMut(usize),
) -> Result<(Vec<ChunkInfo>, Vec<RegionPoint>), FormatError> {
    let n = super::DEFAULT_CHUNK_LEAVES as u64;
    let mut merging = MergingStream::new(depth);
    let mut out = Vec::new();
    let (mut chunks, mut points) = (Vec::<ChunkInfo>::new(), Vec::new());
    let mut add = |out: &mut Vec<(Leaf, RegionPoint)>| {
        for (l, p) in out.drain(..) {
            match chunks.last_mut() {
                Some(c) if c.count < n => {
                    c.count += 1;
                    c.hi = l.end();
                }
                _ => {
                    chunks.push(ChunkInfo {
                        offset: p.offset(),
                        lo: l.code(),
                        hi: l.end(),
                        count: 1,
                    });
                    points.push(p);
                }
            }
        }
    };
    loop {
        let p = payload.point();
        let Some(l) = payload.next() else { break };
        merging.push(l?, p, &mut out);
        add(&mut out);
        done(payload.offset() as usize);
    }
    merging.flush(&mut out);
    add(&mut out);
    Ok((chunks, points))
}

/// The leaves of stretch `i` of the payload, checked and merged: decoded from the
/// first leaf they merge from, past the stretch's end as far as it takes to know
/// that its last leaf merges no further.
pub(crate) fn v1_chunk(bytes: &[u8], index: &V1Index, i: usize) -> Result<Vec<Leaf>, FormatError> {
    let count = index.chunks[i].count as usize;
    let mut merging = MergingStream::new(index.depth);
    let mut out = Vec::with_capacity(count + MERGE_TAIL);
    let mut stored = RegionLeaves::resume(bytes, index.points[i], index.depth, u64::MAX);
    while out.len() < count {
        match stored.next() {
            Some(l) => merging.push(l?, (), &mut out),
            None => {
                merging.flush(&mut out);
                break;
            }
        }
    }
    if out.len() < count {
        return Err(FormatError::corrupt(format!(
            "leaf payload: stretch {i} holds {} leaves where the index counted {count}",
            out.len()
        )));
    }
    out.truncate(count);
    Ok(out.into_iter().map(|(l, ())| l).collect())
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};

    use crate::io::native::{self, write_v1};
    use crate::io::TessFile;
    use crate::linear::{Leaf, LinearOctree};
    use crate::model::{Frame, Layer, Model};

    /// A checkerboard of the depth-`depth` space (no two voxels merge: 8^depth / 2
    /// leaves) at `origin`, with a colour on every third leaf and another on every
    /// fifth, and a frame.
    fn checkerboard(depth: u8, origin: [i64; 3]) -> Model {
        let side = 1i64 << depth;
        let mut voxels = Vec::new();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    if (x + y + z) % 2 == 0 {
                        voxels.push([origin[0] + x, origin[1] + y, origin[2] + z]);
                    }
                }
            }
        }
        let tree = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
        let pick = |m: usize, skip: usize| -> LinearOctree {
            let ls: Vec<Leaf> = tree
                .leaves()
                .iter()
                .enumerate()
                .filter(|(i, _)| i % m == 0 && i % skip != 0)
                .map(|(_, l)| *l)
                .collect();
            LinearOctree::from_sorted_leaves(depth, origin, ls).unwrap()
        };
        let layer = Layer::from_regions(
            depth,
            origin,
            [
                ([200, 0, 0, 255], pick(3, 5)),
                ([0, 0, 200, 255], pick(5, 1 << 40)),
            ],
        )
        .unwrap();
        Model::new(tree.clone())
            .with_frame(Frame::new(0.5, [1.0, 2.0, -3.0]))
            .with_colors(layer)
            .unwrap()
    }

    fn v1_bytes(model: &Model) -> Vec<u8> {
        let mut out = Vec::new();
        write_v1(&mut out, model).unwrap();
        out
    }

    /// A version-1 file of 131,072 leaves opened for streaming: its stretches
    /// (two, of 65,536 leaves) hold the tree's leaves, by code range too; its
    /// colour streams hold the layer's regions; frame, counts and the whole model
    /// are those of the whole-file decoder.
    #[test]
    fn a_version_1_file_streams_as_the_decoder_reads_it() {
        let model = checkerboard(6, [-7, 3, 100]);
        let tree = &model.tree;
        let f = TessFile::from_bytes_streaming(v1_bytes(&model), std::path::Path::new("m.tess"))
            .unwrap();
        assert!(f.is_streamed());
        assert_eq!((f.depth(), f.origin()), (6, [-7, 3, 100]));
        assert_eq!(f.frame(), model.frame);
        assert_eq!(f.leaf_count(), 131_072);
        assert!(f.has_layers());
        let chunks = f.chunks();
        assert_eq!(chunks.len(), 2);
        let mut all = Vec::new();
        for (i, c) in chunks.iter().enumerate() {
            let ls = f.chunk(i).unwrap();
            assert_eq!(ls.len() as u64, c.count);
            assert_eq!((ls[0].code(), ls[ls.len() - 1].end()), (c.lo, c.hi));
            all.extend(ls);
        }
        assert_eq!(all, tree.leaves());
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for _ in 0..20 {
            let lo = rng.random_range(0..1u64 << 18);
            let hi = rng.random_range(lo..=1u64 << 18);
            let got: Vec<Leaf> = f.leaves_in(lo, hi).map(Result::unwrap).collect();
            let want: Vec<Leaf> = tree
                .leaves()
                .iter()
                .filter(|l| l.end() > lo && l.code() < hi)
                .copied()
                .collect();
            assert_eq!(got, want);
        }
        let streams = f.colour_streams().unwrap().unwrap();
        let regions = model.colors.as_ref().unwrap().regions();
        assert_eq!(streams.len(), regions.len());
        for ((c, s), (rc, rt)) in streams.into_iter().zip(regions) {
            assert_eq!(c, *rc);
            assert_eq!(s.map(Result::unwrap).collect::<Vec<_>>(), rt.leaves());
        }
        assert_eq!(f.to_model().unwrap(), model);
        // Empty, and without layers.
        let empty = Model::new(LinearOctree::empty(3, [1, 1, 1]).unwrap());
        let f = TessFile::from_bytes_streaming(v1_bytes(&empty), std::path::Path::new("e.tess"))
            .unwrap();
        assert!(f.chunks().is_empty() && !f.has_layers());
        assert_eq!(f.leaves().count(), 0);
        assert_eq!(f.colour_streams().unwrap().map(|v| v.len()), Some(0));
    }

    /// Every truncation and bit flip is an error naming the file, never a panic;
    /// with the checksum made right again (as the fuzz target does), whatever
    /// opens reads as the whole-file decoder reads it, or gives an error.
    #[test]
    fn damaged_version_1_files_are_errors() {
        let tree =
            LinearOctree::from_voxels(4, [0, 0, 0], (0..40).map(|i| [i % 16, i / 3, 5])).unwrap();
        let layer = Layer::from_regions(4, [0, 0, 0], [([1, 2, 3, 4], tree.clone())]).unwrap();
        let model = Model::new(tree).with_colors(layer).unwrap();
        let bytes = v1_bytes(&model);
        let path = std::path::Path::new("d.tess");
        for n in 0..bytes.len() {
            let e = TessFile::from_bytes_streaming(bytes[..n].to_vec(), path).err();
            assert!(e.is_some_and(|e| e.to_string().contains("d.tess")), "{n}");
        }
        for i in 10..bytes.len() - 4 {
            for bit in [0, 3, 7] {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                assert!(TessFile::from_bytes_streaming(b.clone(), path).is_err());
                let n = b.len();
                let crc = crc32fast::hash(&b[..n - 4]);
                b[n - 4..].copy_from_slice(&crc.to_le_bytes());
                let whole = native::decode(&b);
                let Ok(f) = TessFile::from_bytes_streaming(b, path) else {
                    continue;
                };
                let leaves: Result<Vec<_>, _> = (0..f.chunks().len()).map(|i| f.chunk(i)).collect();
                let colours = f.colour_streams().map(|o| {
                    o.map(|v| {
                        v.into_iter()
                            .map(|(c, r)| (c, r.collect::<Result<Vec<_>, _>>()))
                            .collect::<Vec<_>>()
                    })
                });
                if let (Ok(m), Ok(leaves)) = (&whole, leaves) {
                    assert_eq!(leaves.concat(), m.tree.leaves());
                    if let Ok(Some(cs)) = colours {
                        let want = m.colors.as_ref().map_or(&[][..], |l| l.regions());
                        for ((c, r), (wc, wt)) in cs.into_iter().zip(want) {
                            if let Ok(r) = r {
                                assert_eq!((c, &r[..]), (*wc, wt.leaves()));
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "tess_v1_canonical_tests.rs"]
mod canonical_tests;

//! The colour index against the colour layer it indexes (seeded random coloured
//! models, blocks of several sizes, both writers), forged indexes with valid
//! checksums, and files without an index.

use std::path::Path;

use rand::{Rng, SeedableRng};

use super::*;
use crate::io::chunked::{parse_layout, TessWriter};
use crate::io::sections::Sections;
use crate::io::{native, LeafSpool, TessFile};
use crate::linear::LinearOctree;
use crate::model::{Layer, Model};

/// Random voxels in a depth-`depth` space (a solid block now and then), each leaf
/// coloured from up to five colours or left uncoloured.
fn random_model(rng: &mut rand_pcg::Pcg64, depth: u8) -> Model {
    let side = 1i64 << depth;
    let mut voxels: Vec<[i64; 3]> = (0..rng.random_range(1..900))
        .map(|_| [0; 3].map(|_| rng.random_range(0..side)))
        .collect();
    if rng.random_bool(0.3) {
        let s = side / 2;
        voxels.extend((0..s * s * s).map(|i| [i % s, (i / s) % s, i / (s * s)]));
    }
    let tree = LinearOctree::from_voxels(depth, [0, 0, 0], voxels).unwrap();
    let n = rng.random_range(1..=5);
    let mut regions = vec![Vec::new(); n];
    for &l in tree.leaves() {
        let i = rng.random_range(0..=n);
        if i < n {
            regions[i].push(l);
        }
    }
    let layer = Layer::from_regions(
        depth,
        [0, 0, 0],
        regions.into_iter().enumerate().map(|(i, ls)| {
            (
                [i as u8 * 40, 7, 200 - i as u8, 255],
                LinearOctree::from_sorted_leaves(depth, [0, 0, 0], ls).unwrap(),
            )
        }),
    )
    .unwrap();
    Model::new(tree).with_colors(layer).unwrap()
}

/// `model` written by the in-memory writer, chunks of 5 leaves, an index of
/// `block` leaves per block (or none).
fn written(model: &Model, block: Option<u64>) -> Vec<u8> {
    let t = &model.tree;
    let mut w = TessWriter::new(Vec::new(), t.depth(), t.origin())
        .unwrap()
        .with_chunk_leaves(5)
        .with_colour_index(block);
    for &l in t.leaves() {
        w.push(l).unwrap();
    }
    w.finish_sections(&Sections::of(model)).unwrap()
}

/// As [`written`], by the spooled writer.
fn spooled(model: &Model, block: u64) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let t = &model.tree;
    let mut w = TessWriter::new(Vec::new(), t.depth(), t.origin())
        .unwrap()
        .with_chunk_leaves(5)
        .with_colour_index(Some(block));
    for &l in t.leaves() {
        w.push(l).unwrap();
    }
    let mut spools = Vec::new();
    for (c, r) in model.colors.as_ref().unwrap().regions() {
        let mut s = LeafSpool::new_in(dir.path()).unwrap();
        for &l in r.leaves() {
            s.push(l).unwrap();
        }
        spools.push((*c, s));
    }
    w.finish_spooled_layer(model.frame, spools).unwrap()
}

fn index_of(bytes: &[u8]) -> ColourIndex {
    parse_layout(bytes).unwrap().colour_index.expect("an index")
}

#[test]
fn the_index_agrees_with_the_colour_layer() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x1dec);
    for case in 0..40 {
        let depth = rng.random_range(1..=6);
        let model = random_model(&mut rng, depth);
        let layer = model.colors.as_ref().unwrap();
        for block in [1, 2, 3, 7, 64, INDEX_BLOCK] {
            let bytes = written(&model, Some(block));
            assert_eq!(spooled(&model, block), bytes, "case {case} block {block}");
            let back = native::decode(&bytes).unwrap();
            assert_eq!(back, model);
            back.colors.as_ref().unwrap().assert_valid();
            // The regions as written: non-empty ones, in the layer's order.
            let regions: Vec<_> = layer
                .regions()
                .iter()
                .filter(|(_, t)| !t.is_empty())
                .collect();
            if regions.is_empty() {
                // An empty layer has nothing to index.
                assert!(parse_layout(&bytes).unwrap().colour_index.is_none());
                continue;
            }
            let ix = index_of(&bytes);
            assert_eq!(ix.block, block);
            assert_eq!(ix.regions.len(), regions.len());
            for (i, ((c, t), r)) in regions.iter().zip(&ix.regions).enumerate() {
                assert_eq!((r.rgba, r.count), (*c, t.leaf_count() as u64));
                let leaves = t.leaves();
                let want: Vec<_> = leaves.chunks(block as usize).collect();
                assert_eq!(r.blocks.1 - r.blocks.0, want.len());
                for (j, w) in want.iter().enumerate() {
                    let k = r.blocks.0 + j;
                    assert_eq!(ix.blocks[k].first, w[0].code());
                    assert_eq!(decode_block(&bytes, &ix, i, k, depth).unwrap(), *w);
                }
            }
            // Opened without reading the colours, the file reads as the model.
            let f = TessFile::from_bytes_lazy_colours(bytes.clone(), Path::new("x.tess")).unwrap();
            assert_eq!(f.to_model().unwrap(), model);
            let streams = f.colour_streams().unwrap().unwrap();
            for ((c, t), (rgba, s)) in regions.iter().zip(streams) {
                assert_eq!(*c, rgba);
                assert_eq!(s.collect::<Result<Vec<_>, _>>().unwrap(), t.leaves());
            }
        }
    }
}

/// Sets the index's own CRC and the file's trailer CRC right again.
fn reseal(bytes: &mut [u8], ix_start: usize, sections_end: usize) {
    let c = crc32fast::hash(&bytes[ix_start..sections_end - 16]);
    bytes[sections_end - 16..sections_end - 12].copy_from_slice(&c.to_le_bytes());
    let n = bytes.len();
    let t = n - 48;
    let s = u64::from_le_bytes(bytes[t..t + 8].try_into().unwrap()) as usize;
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..40]);
    crc.update(&bytes[s..n - 12]);
    let c = crc.finalize();
    bytes[t + 36..t + 40].copy_from_slice(&c.to_le_bytes());
}

/// Every byte of the index changed (three ways), its checksums made valid again:
/// every reader either refuses the file or reads the right colours; none panics.
#[test]
fn a_forged_index_gives_an_error_or_the_right_colours() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0xf0_46e);
    let mut refused = 0;
    for case in 0..6 {
        let model = random_model(&mut rng, 4);
        let layer = model.colors.as_ref().unwrap();
        let bytes = written(&model, Some(3));
        let layout = parse_layout(&bytes).unwrap();
        let ix = layout.colour_index.clone().unwrap();
        let end = layout.sections.1;
        for at in ix.start..end {
            for change in [1u8, 2, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= change;
                if !(end - 16..end - 12).contains(&at) {
                    reseal(&mut b, ix.start, end);
                }
                let whole = native::decode(&b);
                if let Ok(m) = &whole {
                    assert_eq!(m, &model, "case {case} byte {at} ^ {change}");
                }
                let Ok(f) = TessFile::from_bytes_lazy_colours(b.clone(), Path::new("x.tess"))
                else {
                    refused += 1;
                    continue;
                };
                let mut any_error = false;
                if let Some(fx) = f.colour_only_index() {
                    for (i, r) in fx.regions.iter().enumerate() {
                        for k in r.blocks.0..r.blocks.1 {
                            match f.colour_block(i, k) {
                                Ok(leaves) => {
                                    // Each leaf is one of the region's, as stored.
                                    let t = &layer.regions().iter().find(|(c, _)| *c == r.rgba);
                                    let t = &t.expect("a colour of the layer").1;
                                    for l in leaves {
                                        assert!(
                                            t.leaves().contains(&l),
                                            "case {case} byte {at} ^ {change}: a wrong colour"
                                        );
                                    }
                                }
                                Err(e) => {
                                    assert!(e.to_string().contains("x.tess"), "{e}");
                                    any_error = true;
                                }
                            }
                        }
                    }
                }
                refused += usize::from(any_error);
            }
        }
    }
    assert!(refused > 0);
}

/// A file written without an index (as older versions wrote) reads the same
/// through every reader; the index changes nothing but the bytes after the colour
/// layer and a flag.
#[test]
fn files_without_the_index_read_as_before() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x01d);
    for _ in 0..10 {
        let model = random_model(&mut rng, 5);
        let plain = written(&model, None);
        let indexed = written(&model, Some(INDEX_BLOCK));
        assert!(parse_layout(&plain).unwrap().colour_index.is_none());
        assert!(indexed.len() > plain.len());
        for bytes in [plain, indexed] {
            assert_eq!(native::decode(&bytes).unwrap(), model);
            for lazy in [false, true] {
                let f = if lazy {
                    TessFile::from_bytes_lazy_colours(bytes.clone(), Path::new("x.tess"))
                } else {
                    TessFile::from_bytes(bytes.clone(), Path::new("x.tess"))
                }
                .unwrap();
                assert_eq!(f.to_model().unwrap(), model);
                let n: usize = f
                    .colour_streams()
                    .unwrap()
                    .unwrap()
                    .into_iter()
                    .map(|(_, s)| s.map(Result::unwrap).count())
                    .sum();
                let want: usize = model
                    .colors
                    .as_ref()
                    .unwrap()
                    .regions()
                    .iter()
                    .map(|(_, t)| t.leaf_count())
                    .sum();
                assert_eq!(n, want);
            }
        }
    }
}

/// Damaged colour bytes of a file opened without reading them are found when the
/// block holding them is read, and when the regions are read as streams.
#[test]
fn damaged_colour_bytes_are_found_when_read() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0xdead);
    let model = random_model(&mut rng, 5);
    let bytes = written(&model, Some(4));
    let ix = index_of(&bytes);
    let r = ix.regions[0];
    let mut b = bytes.clone();
    b[r.start] ^= 0x40;
    // The trailer's CRC is not made right again: the damage is the colours'.
    let f = TessFile::from_bytes_lazy_colours(b.clone(), Path::new("d.tess")).unwrap();
    let e = f.colour_block(0, r.blocks.0).unwrap_err().to_string();
    assert!(e.contains("d.tess") && e.contains("checksum"), "{e}");
    assert!(f.colour_block(0, r.blocks.0 + 1).is_ok() || r.blocks.1 - r.blocks.0 == 1);
    let e = f
        .colour_streams()
        .err()
        .expect("streams check the CRCs")
        .to_string();
    assert!(e.contains("checksum"), "{e}");
    // Opened as before, the file's checksum names the damage.
    assert!(TessFile::from_bytes(b.clone(), Path::new("d.tess")).is_err());
    assert!(native::decode(&b).is_err());
}

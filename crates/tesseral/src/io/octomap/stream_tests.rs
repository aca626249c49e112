//! The streaming writer against a recursive one (each node's pieces split among its
//! eight children, which is obviously a preorder walk), and the merger against
//! canonical octrees built per class.

use super::stream::{encode_pieces, Encoder, Kind, Merger, Piece, UNSET_RGB};
use super::tests::random_model;
use super::write::{pieces, to_key_space};
use super::OCTOMAP_DEPTH;
use crate::linear::{Leaf, LinearOctree};
use crate::model::{Layer, Model};
use rand::{Rng, SeedableRng};

/// The pieces inside the cell `[code, code + 8^k)` per child.
fn children(pieces: &[Piece], code: u64, k: u8) -> Vec<(u64, &[Piece])> {
    let size = 1u64 << (3 * u32::from(k - 1));
    (0..8)
        .map(|i| {
            let c = code + i * size;
            let lo = pieces.partition_point(|p| p.leaf.code() < c);
            let hi = pieces.partition_point(|p| p.leaf.code() < c + size);
            (c, &pieces[lo..hi])
        })
        .collect()
}

/// The one piece covering a cell of size `2^k`, if `pieces` is that.
fn covers(pieces: &[Piece], k: u8) -> Option<Piece> {
    match pieces {
        [p] if p.leaf.size_log2() >= k => Some(*p),
        _ => None,
    }
}

fn reference_bt(pieces: &[Piece], code: u64, k: u8, out: &mut Vec<u8>, nodes: &mut u64) {
    let mut bits = 0u16;
    let mut inner = Vec::new();
    let whole = covers(pieces, k);
    for (i, (c, mine)) in children(pieces, code, k).into_iter().enumerate() {
        if let Some(p) = whole.or_else(|| covers(mine, k - 1)) {
            bits |= if p.occupied { 0b10 } else { 0b01 } << (2 * i);
            *nodes += 1;
        } else if !mine.is_empty() {
            bits |= 0b11 << (2 * i);
            *nodes += 1;
            inner.push((c, mine));
        }
    }
    out.extend_from_slice(&bits.to_le_bytes());
    for (c, mine) in inner {
        reference_bt(mine, c, k - 1, out, nodes);
    }
}

fn reference_ot(
    pieces: &[Piece],
    code: u64,
    k: u8,
    colour: bool,
    out: &mut Vec<u8>,
    nodes: &mut u64,
) -> (f32, [u8; 3]) {
    *nodes += 1;
    let at = out.len();
    let extra = if colour { 3 } else { 0 };
    out.resize(at + 4 + extra + 1, 0);
    let (value, rgb) = if let Some(p) = covers(pieces, k) {
        (p.value, p.rgb)
    } else {
        let (mut mask, mut max, mut sum, mut n) = (0u8, f32::NEG_INFINITY, [0u32; 3], 0);
        for (i, (c, mine)) in children(pieces, code, k).into_iter().enumerate() {
            if mine.is_empty() {
                continue;
            }
            mask |= 1 << i;
            let (v, rgb) = reference_ot(mine, c, k - 1, colour, out, nodes);
            max = max.max(v);
            if rgb != UNSET_RGB {
                (0..3).for_each(|j| sum[j] += u32::from(rgb[j]));
                n += 1;
            }
        }
        out[at + 4 + extra] = mask;
        let rgb = if n == 0 {
            UNSET_RGB
        } else {
            sum.map(|s| (s / n) as u8)
        };
        (max, rgb)
    };
    out[at..at + 4].copy_from_slice(&value.to_le_bytes());
    if colour {
        out[at + 4..at + 7].copy_from_slice(&rgb);
    }
    (value, rgb)
}

/// The reference's data and node count for maximal pieces.
fn reference(kind: Kind, pieces: &[Piece]) -> (Vec<u8>, u64) {
    let (mut out, mut nodes) = (Vec::new(), 0);
    if pieces.is_empty() {
        return (out, nodes);
    }
    match kind {
        Kind::Bt => {
            nodes = 1;
            reference_bt(pieces, 0, OCTOMAP_DEPTH, &mut out, &mut nodes);
        }
        Kind::Ot { colour } => {
            reference_ot(pieces, 0, OCTOMAP_DEPTH, colour, &mut out, &mut nodes);
        }
    }
    (out, nodes)
}

/// The model with colours on its black voxels (a `ColorOcTree`), for odd seeds.
fn model(seed: u64) -> Model {
    let m = random_model(seed);
    if seed % 2 == 0 {
        return m;
    }
    let pairs = m
        .tree
        .voxels()
        .map(|v| (v, [(v[0] & 1) as u8 * 9, 3, 7, 255]));
    let colors = Layer::from_voxels(m.tree.depth(), m.tree.origin(), pairs).unwrap();
    Model {
        colors: Some(colors),
        ..m
    }
}

/// Every model's `.bt` and `.ot` data are the recursive writer's, byte for byte,
/// with the same node count; and cutting the pieces into cells first (so that the
/// merger has all the joining to do) changes nothing.
#[test]
fn the_stream_writes_what_the_recursive_writer_writes() {
    for seed in 0..120 {
        let km = to_key_space(&model(seed)).unwrap();
        let colour = km.colors.is_some();
        for (kind, values) in [(Kind::Bt, false), (Kind::Ot { colour }, true)] {
            let pieces = pieces(&km, values);
            let want = reference(kind, &pieces);
            assert_eq!(
                encode_pieces(kind, pieces.iter().copied()),
                want,
                "seed {seed} {kind:?}"
            );
            let cells = pieces.iter().flat_map(|p| {
                let n = p.leaf.voxel_count();
                (0..n).map(move |i| Piece {
                    leaf: Leaf::new(p.leaf.code() + i, 0),
                    ..*p
                })
            });
            assert_eq!(
                encode_pieces(kind, cells),
                want,
                "seed {seed} {kind:?}, as cells"
            );
        }
    }
}

/// A piece covering the whole key cube: a `.bt` root with eight leaf children, an
/// `.ot` root that is a leaf.
#[test]
fn the_whole_key_cube_is_written_as_the_reference_writes_it() {
    let whole = Piece {
        leaf: Leaf::new(0, OCTOMAP_DEPTH),
        occupied: false,
        value: -2.0,
        rgb: UNSET_RGB,
    };
    for kind in [
        Kind::Bt,
        Kind::Ot { colour: false },
        Kind::Ot { colour: true },
    ] {
        let mut enc = Encoder::new(kind);
        enc.push(whole);
        assert_eq!(enc.finish(), reference(kind, &[whole]), "{kind:?}");
    }
    assert_eq!(reference(Kind::Bt, &[whole]).1, 9);
    assert_eq!(reference(Kind::Ot { colour: false }, &[whole]).1, 1);
}

/// The merger's output is, for every class, the canonical leaves of that class's
/// cells (`LinearOctree::from_voxels`), all in tesseral order: random cells of
/// three classes in an 8³ to 32³ cube, dense enough that whole blocks join.
#[test]
fn merged_pieces_are_each_classes_canonical_leaves() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(13);
    for round in 0..200 {
        let depth: u8 = rng.random_range(3..=5);
        let side = 1i64 << depth;
        let fill = rng.random_range(0.5..1.0);
        let skew = rng.random_range(0.0..1.0);
        // Class by coarse cell (so that runs of one class are common), sometimes
        // by cell.
        let coarse = rng.random_range(0..=3u32);
        let mut cells: Vec<(u64, u8)> = Vec::new();
        let mut seen = std::collections::HashMap::<u64, u8>::new();
        for code in 0..(side * side * side) as u64 {
            if !rng.random_bool(fill) {
                continue;
            }
            let class = if rng.random_bool(skew) {
                (seen.len() % 3) as u8
            } else {
                *seen
                    .entry(code >> (3 * coarse))
                    .or_insert_with(|| rng.random_range(0..3))
            };
            cells.push((code, class));
        }
        let piece = |leaf, class: u8| Piece {
            leaf,
            occupied: class == 0,
            value: f32::from(class),
            rgb: UNSET_RGB,
        };
        let mut got = Vec::new();
        let mut m = Merger::new(|a: &Piece, b: &Piece| a.same_node(b));
        for &(code, class) in &cells {
            m.push(piece(Leaf::new(code, 0), class), &mut |p| got.push(p));
        }
        m.flush(&mut |p| got.push(p));
        let mut want = Vec::new();
        for class in 0..3u8 {
            let voxels = cells.iter().filter(|c| c.1 == class).map(|&(code, _)| {
                let [x, y, z] = crate::code::decode(code);
                [i64::from(x), i64::from(y), i64::from(z)]
            });
            let tree = LinearOctree::from_voxels(depth, [0; 3], voxels).unwrap();
            want.extend(tree.leaves().iter().map(|&l| piece(l, class)));
        }
        want.sort_by_key(|p| p.leaf.code());
        assert_eq!(got, want, "round {round}");
    }
}

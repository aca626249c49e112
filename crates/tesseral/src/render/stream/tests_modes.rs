//! Cuts, slices and contact sheets of a streamed tree against the in-memory ones,
//! byte for byte, on seeded random coloured models in several chunkings, and the
//! cropped view ([`Clipped`]) against the cropped tree itself.

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_model, random_options, terrain, write_v2};
use super::{contact_sheet_streamed, render_streamed, section_streamed, StreamedTree};
use crate::linear::LinearOctree;
use crate::model::Model;
use crate::render::clipped::Clipped;
use crate::render::nodes::Trace;
use crate::render::{
    contact_sheet, crop_to_clip, render, section, Clip, Image, RayTree, RenderOptions, Surface,
    View, DEFAULT_COLOUR,
};

/// A plane through the model, on its edges, or far outside on either side.
fn random_clip(rng: &mut rand_pcg::Pcg64, depth: u8) -> Clip {
    let side = 1i64 << depth;
    let at = match rng.random_range(0..5) {
        0 => -1000.0,
        1 => 1000.0,
        2 => rng.random_range(0..=side) as f64,
        _ => rng.random_range(-2.0..side as f64 + 2.0),
    };
    Clip {
        axis: rng.random_range(0..3),
        at,
        keep_above: rng.random_bool(0.5),
    }
}

/// The stored colours of `model` as the CLI paints them.
fn model_shader(model: &Model) -> impl Fn([f64; 3]) -> [u8; 3] + Sync + '_ {
    move |p: [f64; 3]| {
        model
            .colors
            .as_ref()
            .and_then(|l| l.get(p.map(|c| c.floor() as i64)))
            .map_or(DEFAULT_COLOUR, |c| [c[0], c[1], c[2]])
    }
}

fn tree_shader(st: &StreamedTree) -> impl Fn([f64; 3]) -> [u8; 3] + Sync + '_ {
    move |p: [f64; 3]| {
        st.colour(p.map(|c| c.floor() as i64))
            .map_or(DEFAULT_COLOUR, |c| [c[0], c[1], c[2]])
    }
}

fn surface(f: &(dyn Fn([f64; 3]) -> [u8; 3] + Sync)) -> Surface<'_> {
    Surface {
        colour: Some(f),
        normal: None,
    }
}

/// The node-by-node crop has the cropped tree's voxels, bounding box and root.
#[test]
fn the_clipped_view_is_the_cropped_tree() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0xc11b);
    for case in 0..60 {
        let depth = rng.random_range(1..=5);
        let tree = random_model(&mut rng, depth).tree;
        let clip = random_clip(&mut rng, depth);
        let kept = crop_to_clip(&tree, clip);
        kept.assert_valid();
        let whole = RayTree::new(&tree);
        let view = Clipped::new(&whole, clip);
        let want = RayTree::new(&kept);
        assert_eq!(view.bbox(), kept.bbox(), "case {case} {clip:?}");
        assert_eq!(view.root().0, want.root, "case {case} {clip:?}");
        let side = 1i64 << depth;
        for x in -1..=side {
            for y in -1..=side {
                for z in -1..=side {
                    assert_eq!(
                        crate::render::trace::contains(&view, [x, y, z]),
                        kept.contains([x, y, z]),
                        "case {case} {clip:?} voxel {:?}",
                        [x, y, z]
                    );
                }
            }
        }
    }
}

/// Streamed cross-sections (views and contact sheets) equal the in-memory ones.
#[test]
fn streamed_cuts_and_sheets_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x0c07_0015);
    let mut through = 0;
    for case in 0..12 {
        let depth = rng.random_range(2..=6);
        let model = random_model(&mut rng, depth);
        let shade_m = model_shader(&model);
        for chunk in [1, 5, 1 << 16] {
            let path = dir.path().join(format!("c{case}-{chunk}.tess"));
            write_v2(&path, &model, chunk);
            let st = StreamedTree::open(&path, if chunk == 5 { 1 } else { 1 << 20 }).unwrap();
            let shade_s = tree_shader(&st);
            for pose in 0..6 {
                let clip = random_clip(&mut rng, depth);
                let kept = crop_to_clip(&model.tree, clip).voxel_count();
                through += usize::from(kept > 0 && kept < model.tree.voxel_count());
                let opts = RenderOptions {
                    clip: Some(clip),
                    ..random_options(&mut rng, pose)
                };
                let want = render(&model.tree, surface(&shade_m), &opts);
                let got = render_streamed(&st, surface(&shade_s), &opts).unwrap();
                assert!(
                    got == want,
                    "case {case} chunk {chunk} pose {pose}: {opts:?}"
                );
            }
            let opts = RenderOptions {
                clip: (case % 3 != 0).then(|| random_clip(&mut rng, depth)),
                ..random_options(&mut rng, case)
            };
            let want = contact_sheet(&model.tree, surface(&shade_m), &opts, &View::ALL, 2);
            let got = contact_sheet_streamed(&st, surface(&shade_s), &opts, &View::ALL, 2).unwrap();
            assert!(got == want, "case {case} chunk {chunk} sheet: {opts:?}");
        }
    }
    assert!(through >= 20, "only {through} planes cut the solid");
}

/// Streamed slices equal the in-memory ones, on every axis, at layers inside and
/// outside the space.
#[test]
fn streamed_slices_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x511c_e015);
    for case in 0..12 {
        let depth = rng.random_range(1..=6);
        let model = random_model(&mut rng, depth);
        let shade_m = model_shader(&model);
        let side = 1i64 << depth;
        for chunk in [1, 7, 1 << 16] {
            let path = dir.path().join(format!("s{case}-{chunk}.tess"));
            write_v2(&path, &model, chunk);
            let st = StreamedTree::open(&path, 1 << 20).unwrap();
            let shade_s = tree_shader(&st);
            for axis in 0..3 {
                for at in [-1, 0, rng.random_range(0..side), side - 1, side] {
                    let px = rng.random_range(1..4);
                    let want = section(&model.tree, surface(&shade_m), axis, at, px);
                    let got = section_streamed(&st, surface(&shade_s), axis, at, px).unwrap();
                    assert!(got == want, "case {case} chunk {chunk} axis {axis} at {at}");
                }
            }
        }
    }
}

/// The slice against a naive drawing: each voxel of the layer painted if the tree
/// holds it, then the outline of every leaf the layer crosses.
#[test]
fn a_slice_equals_the_naive_drawing() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5a1e);
    for _ in 0..20 {
        let depth = rng.random_range(1..=5);
        let tree = random_model(&mut rng, depth).tree;
        let (axis, at) = (rng.random_range(0..3), rng.random_range(0..1i64 << depth));
        let px = 2usize;
        let side = 1usize << depth;
        let size = side * px;
        let mut want = Image::new(size, size, [255, 255, 255]);
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for j in 0..side {
            for i in 0..side {
                let mut p = [0i64; 3];
                p[axis] = at;
                p[u] = i as i64;
                p[v] = j as i64;
                if tree.contains(p) {
                    for (dx, dy) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                        want.pixels[(size - 1 - (j * px + dy)) * size + i * px + dx] =
                            DEFAULT_COLOUR;
                    }
                }
            }
        }
        for b in tree.blocks() {
            if at < b.min[axis] || at > b.max()[axis] {
                continue;
            }
            let s = b.size() as usize * px;
            let (x0, y0) = (b.min[u] as usize * px, b.min[v] as usize * px);
            for i in 0..s {
                for (x, y) in [
                    (x0 + i, y0),
                    (x0 + i, y0 + s - 1),
                    (x0, y0 + i),
                    (x0 + s - 1, y0 + i),
                ] {
                    want.pixels[(size - 1 - y) * size + x] = [60, 60, 70];
                }
            }
        }
        assert!(section(&tree, Surface::default(), axis, at, px) == want);
    }
}

/// A cut that keeps a thin slab and a slice read only the chunks near them.
#[test]
fn cuts_and_slices_read_only_the_chunks_they_need() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(15);
    let model = coloured(&mut rng, terrain(32));
    let path = dir.path().join("t.tess");
    write_v2(&path, &model, 8);
    let opts = RenderOptions {
        width: 48,
        height: 36,
        clip: Some(Clip {
            axis: 0,
            at: 4.0,
            keep_above: false,
        }),
        ..Default::default()
    };
    let shade_m = model_shader(&model);
    let st = StreamedTree::open(&path, 1 << 30).unwrap();
    let shade_s = tree_shader(&st);
    let got = render_streamed(&st, surface(&shade_s), &opts).unwrap();
    assert!(got == render(&model.tree, surface(&shade_m), &opts));
    let s = st.stats();
    assert!(s.chunks_decoded * 2 < s.chunks, "a cut decoded {s:?}");
    let st = StreamedTree::open(&path, 1 << 30).unwrap();
    let got = section_streamed(&st, Surface::default(), 1, 30, 1).unwrap();
    assert!(got == section(&model.tree, Surface::default(), 1, 30, 1));
    let s = st.stats();
    assert!(s.chunks_decoded * 2 < s.chunks, "a slice decoded {s:?}");
}

/// An empty tree and a tree of one full block, cut and sliced.
#[test]
fn empty_and_full_trees_cut_and_slice() {
    let dir = tempfile::tempdir().unwrap();
    for (i, tree) in [
        LinearOctree::empty(3, [0, 0, 0]).unwrap(),
        LinearOctree::full(3, [0, 0, 0]).unwrap(),
    ]
    .into_iter()
    .enumerate()
    {
        let model = Model::new(tree.clone());
        let path = dir.path().join(format!("e{i}.tess"));
        write_v2(&path, &model, 4);
        let st = StreamedTree::open(&path, 1 << 20).unwrap();
        for at in [-3.0, 0.0, 2.5, 8.0, 20.0] {
            for keep_above in [false, true] {
                let opts = RenderOptions {
                    width: 32,
                    height: 24,
                    clip: Some(Clip {
                        axis: 2,
                        at,
                        keep_above,
                    }),
                    ..Default::default()
                };
                let got = render_streamed(&st, Surface::default(), &opts).unwrap();
                assert!(got == render(&tree, Surface::default(), &opts), "{opts:?}");
            }
        }
        for at in [-1, 0, 5, 8] {
            let got = section_streamed(&st, Surface::default(), 0, at, 2).unwrap();
            assert!(got == section(&tree, Surface::default(), 0, at, 2));
        }
    }
}

/// A colour section damaged past its checksum (the checksum recomputed, as a file
/// rewritten by a faulty tool would carry it) is an error naming the file, at open
/// or while drawing, never a panic; the checksum alone catches the rest.
#[test]
fn a_damaged_colour_section_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0xc010);
    let model = coloured(&mut rng, terrain(16));
    let path = dir.path().join("good.tess");
    write_v2(&path, &model, 64);
    let good = std::fs::read(&path).unwrap();
    let n = good.len();
    let t = n - 48;
    let sections = u64::from_le_bytes(good[t..t + 8].try_into().unwrap()) as usize;
    let index = u64::from_le_bytes(good[t + 8..t + 16].try_into().unwrap()) as usize;
    // Past the flags, the frame and the region count: the regions.
    let first = sections + 2 + 32 + 8;
    let bad = dir.path().join("bad.tess");
    let mut errors = 0;
    for (i, at) in (first..index).step_by(7).enumerate() {
        let mut bytes = good.clone();
        bytes[at] ^= [0x80, 0x7f, 0xff, 0x01][i % 4];
        if i % 5 != 0 {
            let mut crc = crc32fast::Hasher::new();
            crc.update(&bytes[..40]);
            crc.update(&bytes[sections..n - 12]);
            let c = crc.finalize();
            bytes[t + 36..t + 40].copy_from_slice(&c.to_le_bytes());
        }
        std::fs::write(&bad, &bytes).unwrap();
        let drawn = StreamedTree::open(&bad, 1 << 20).and_then(|st| {
            let shade = tree_shader(&st);
            let opts = RenderOptions {
                width: 32,
                height: 24,
                ..Default::default()
            };
            render_streamed(&st, surface(&shade), &opts)?;
            section_streamed(&st, surface(&shade), 2, 1, 1)
        });
        if let Err(e) = drawn {
            let e = e.to_string();
            assert!(e.contains("bad.tess"), "byte {at}: {e}");
            errors += 1;
        }
    }
    assert!(errors > 10, "only {errors} damaged files were refused");
}

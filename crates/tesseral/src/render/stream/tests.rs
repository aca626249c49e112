//! The streamed render against the in-memory one, byte for byte, on seeded random
//! coloured models cut into chunks of several sizes, from several camera poses.

use rand::{Rng, SeedableRng};

use super::{render_streamed, StreamedTree};
use crate::io::sections::Sections;
use crate::io::TessWriter;
use crate::linear::LinearOctree;
use crate::model::{Layer, Model, Rgba};
use crate::partition::{open_part, read_manifest, write_dataset, Partition, PartitionedOctree};
use crate::render::{
    render, Camera, Normals, Projection, RenderOptions, Surface, View, DEFAULT_COLOUR,
};

/// A blob of random voxels, sometimes with a big block, coloured leaf by leaf from
/// three colours (some leaves left uncoloured).
pub(super) fn random_model(rng: &mut rand_pcg::Pcg64, depth: u8) -> Model {
    let side = 1i64 << depth;
    let n = rng.random_range(1..600);
    let blob = rng.random_range(1..=side);
    let mut voxels: Vec<[i64; 3]> = (0..n)
        .map(|_| [0; 3].map(|_| rng.random_range(0..blob)))
        .collect();
    if rng.random_bool(0.5) {
        let s = side / 2;
        let c = [0; 3].map(|_| rng.random_range(0..2) * s);
        for x in 0..s {
            for y in 0..s {
                for z in 0..s {
                    voxels.push([c[0] + x, c[1] + y, c[2] + z]);
                }
            }
        }
    }
    coloured(
        rng,
        LinearOctree::from_voxels(depth, [0, 0, 0], voxels).unwrap(),
    )
}

/// `tree` with its leaves coloured at random from three colours (some left
/// uncoloured).
pub(super) fn coloured(rng: &mut rand_pcg::Pcg64, tree: LinearOctree) -> Model {
    let depth = tree.depth();
    let palette: [Rgba; 3] = [[200, 40, 40, 255], [40, 180, 60, 255], [50, 70, 220, 255]];
    let mut regions = vec![Vec::new(); 3];
    for &l in tree.leaves() {
        let i = rng.random_range(0..4);
        if i < 3 {
            regions[i].push(l);
        }
    }
    let layer = Layer::from_regions(
        depth,
        [0, 0, 0],
        palette.iter().zip(regions).map(|(c, ls)| {
            (
                *c,
                LinearOctree::from_sorted_leaves(depth, [0, 0, 0], ls).unwrap(),
            )
        }),
    )
    .unwrap();
    Model::new(tree).with_colors(layer).unwrap()
}

/// Writes `model` as a version-2 `.tess` of `chunk` leaves per chunk, with a
/// colour index of `chunk` leaves per block, or none (as older versions wrote)
/// when `chunk` is 17.
pub(super) fn write_v2(path: &std::path::Path, model: &Model, chunk: usize) {
    let t = &model.tree;
    let index = (chunk != 17).then_some(chunk as u64);
    let mut w = TessWriter::new(Vec::new(), t.depth(), t.origin())
        .unwrap()
        .with_chunk_leaves(chunk)
        .with_colour_index(index);
    for &l in t.leaves() {
        w.push(l).unwrap();
    }
    std::fs::write(path, w.finish_sections(&Sections::of(model)).unwrap()).unwrap();
}

pub(super) fn random_options(rng: &mut rand_pcg::Pcg64, pose: usize) -> RenderOptions {
    let mut camera = Camera::view(View::ALL[pose % 4]);
    if pose >= 4 {
        camera.azimuth_deg = rng.random_range(-180.0..180.0);
        camera.elevation_deg = rng.random_range(-80.0..80.0);
        camera.zoom = rng.random_range(0.7..3.0);
    }
    if pose % 3 == 2 {
        camera.projection = Projection::Perspective {
            fov_deg: rng.random_range(20.0..70.0),
        };
    }
    RenderOptions {
        width: 40,
        height: 30,
        camera,
        outline: pose % 5 == 1,
        shadows: pose % 4 != 3,
        ao_samples: if pose % 6 == 5 { 3 } else { 0 },
        normals: [Normals::Auto, Normals::Faces, Normals::Smooth][pose % 3],
        ..Default::default()
    }
}

/// The in-memory render with the stored colours, as the CLI draws a file.
pub(super) fn in_memory(model: &Model, opts: &RenderOptions) -> crate::render::Image {
    let colours = model.colors.as_ref();
    let shader = |p: [f64; 3]| {
        colours
            .and_then(|l| l.get(p.map(|c| c.floor() as i64)))
            .map_or(DEFAULT_COLOUR, |c| [c[0], c[1], c[2]])
    };
    let surface = Surface {
        colour: Some(&shader),
        normal: None,
    };
    render(&model.tree, surface, opts)
}

pub(super) fn streamed(st: &StreamedTree, opts: &RenderOptions) -> crate::render::Image {
    let shader = |p: [f64; 3]| {
        st.colour(p.map(|c| c.floor() as i64))
            .map_or(DEFAULT_COLOUR, |c| [c[0], c[1], c[2]])
    };
    let surface = Surface {
        colour: Some(&shader),
        normal: None,
    };
    render_streamed(st, surface, opts).unwrap()
}

#[test]
fn the_streamed_render_equals_the_in_memory_render() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5eed_0015);
    for case in 0..14 {
        let depth = rng.random_range(2..=6);
        let model = random_model(&mut rng, depth);
        model.tree.assert_valid();
        for chunk in [1, 3, 17, 1 << 16] {
            let path = dir.path().join(format!("m{case}-{chunk}.tess"));
            write_v2(&path, &model, chunk);
            let budget = if chunk == 3 { 1 } else { 1 << 20 };
            let st = StreamedTree::open(&path, budget).unwrap();
            assert_eq!(st.bbox(), model.tree.bbox(), "case {case} chunk {chunk}");
            assert_eq!(st.leaf_count(), model.tree.leaf_count() as u64);
            if depth <= 4 {
                let colours = model.colors.as_ref().unwrap();
                for v in model.tree.voxels() {
                    assert_eq!(st.colour(v), colours.get(v), "case {case} voxel {v:?}");
                }
            }
            for pose in 0..8 {
                let opts = random_options(&mut rng, pose);
                let want = in_memory(&model, &opts);
                let got = streamed(&st, &opts);
                assert!(
                    got == want,
                    "case {case} depth {depth} chunk {chunk} pose {pose}: {opts:?}"
                );
            }
        }
    }
}

/// A bumpy slab `side` voxels across (a power of two).
pub(super) fn terrain(side: i64) -> LinearOctree {
    let mut voxels = Vec::new();
    for x in 0..side {
        for y in 0..side {
            for z in 0..(3 + (x * y) % 5) {
                voxels.push([x, y, z]);
            }
        }
    }
    LinearOctree::from_voxels(side.trailing_zeros() as u8, [0, 0, 0], voxels).unwrap()
}

/// A cache budget far smaller than the model: chunks are evicted and decoded
/// again, and the image does not change.
#[test]
fn a_cache_smaller_than_the_model_gives_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(77);
    let model = coloured(&mut rng, terrain(32));
    let path = dir.path().join("m.tess");
    write_v2(&path, &model, 4);
    let opts = RenderOptions {
        width: 64,
        height: 48,
        ..Default::default()
    };
    let want = in_memory(&model, &opts);
    let roomy = StreamedTree::open(&path, 1 << 30).unwrap();
    assert!(streamed(&roomy, &opts) == want);
    let all = roomy.stats();
    assert!(all.chunks > 20, "{all:?}");
    let tight = StreamedTree::open(&path, 2048).unwrap();
    assert!(streamed(&tight, &opts) == want);
    let s = tight.stats();
    assert!(
        s.cached_bytes < all.cached_bytes / 4,
        "{s:?} against {all:?}"
    );
    assert!(
        s.chunks_decoded > all.chunks_decoded,
        "{s:?} against {all:?}"
    );
}

/// A close-up reads only the chunks its rays reach.
#[test]
fn a_close_up_reads_only_the_chunks_its_rays_reach() {
    let dir = tempfile::tempdir().unwrap();
    let model = Model::new(terrain(32));
    let path = dir.path().join("terrain.tess");
    write_v2(&path, &model, 8);
    let mut opts = RenderOptions {
        width: 32,
        height: 24,
        camera: Camera::view(View::Top),
        ..Default::default()
    };
    opts.camera.zoom = 6.0;
    let st = StreamedTree::open(&path, 1 << 30).unwrap();
    assert!(streamed(&st, &opts) == in_memory(&model, &opts));
    let s = st.stats();
    assert!(
        s.chunks_decoded * 2 < s.chunks,
        "a close-up decoded {} of {} chunks",
        s.chunks_decoded,
        s.chunks
    );
}

/// With a colour index, opening reads no colour bytes and a close-up reads only
/// the colour blocks its hits fall in; without one (a file as older versions
/// wrote it), the whole colour section is read at open. Same images.
#[test]
fn a_close_up_reads_only_the_colour_blocks_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0xc010);
    let model = coloured(&mut rng, terrain(32));
    let mut opts = RenderOptions {
        width: 32,
        height: 24,
        camera: Camera::view(View::Top),
        ..Default::default()
    };
    opts.camera.zoom = 6.0;
    let want = in_memory(&model, &opts);
    let (indexed, plain) = (dir.path().join("i.tess"), dir.path().join("p.tess"));
    write_v2(&indexed, &model, 8);
    write_v2(&plain, &model, 17);
    let f = crate::io::TessFile::open(&indexed).unwrap();
    let ix = f.colour_only_index().expect("written with an index");
    let section: u64 = ix.regions.iter().map(|r| (r.end - r.start) as u64).sum();
    assert!(crate::io::TessFile::open(&plain)
        .unwrap()
        .colour_only_index()
        .is_none());
    let st = StreamedTree::open(&indexed, 1 << 30).unwrap();
    assert_eq!(st.stats().colour_bytes_read, 0, "opening read colours");
    assert!(streamed(&st, &opts) == want);
    let s = st.stats();
    assert!(
        s.colour_bytes_read > 0 && s.colour_bytes_read * 4 < section,
        "a close-up read {} of {section} colour bytes",
        s.colour_bytes_read
    );
    let old = StreamedTree::open(&plain, 1 << 30).unwrap();
    assert!(old.stats().colour_bytes_read >= section);
    assert!(streamed(&old, &opts) == want);
}

/// A dataset whose part boundaries cut full blocks: the parts join as the
/// in-memory `concat` joins them (siblings merged across parts), outlines included.
#[test]
fn a_dataset_renders_as_its_joined_model() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(4242);
    for case in 0..10 {
        let depth = rng.random_range(2..=5);
        let tree = random_model(&mut rng, depth).tree;
        let end = 1u64 << (3 * u32::from(depth));
        let mut cuts: Vec<u64> = (0..rng.random_range(1..5))
            .map(|_| rng.random_range(1..end))
            .collect();
        cuts.sort_unstable();
        cuts.dedup();
        let bounds: Vec<u64> = std::iter::once(0).chain(cuts).chain([end]).collect();
        let ranges: Vec<Partition> = bounds
            .windows(2)
            .map(|w| Partition { lo: w[0], hi: w[1] })
            .collect();
        let parts = PartitionedOctree::split(&tree, &ranges).unwrap();
        let d = dir.path().join(format!("ds{case}"));
        write_dataset(&d, &parts, Default::default()).unwrap();
        let m = read_manifest(&d).unwrap();
        let files = (0..m.parts.len())
            .map(|i| open_part(&d, &m, i).unwrap())
            .collect();
        let st = StreamedTree::from_parts(
            files,
            m.parts.iter().map(|p| (p.lo, p.hi)).collect(),
            1 << 20,
        )
        .unwrap();
        let joined = Model::new(parts.concat());
        assert_eq!(st.bbox(), joined.tree.bbox());
        for pose in 0..6 {
            let mut opts = random_options(&mut rng, pose);
            opts.outline = pose % 2 == 0;
            assert!(
                streamed(&st, &opts) == in_memory(&joined, &opts),
                "case {case} pose {pose}"
            );
        }
    }
}

/// A damaged chunk is an error naming the file and the chunk.
#[test]
fn a_damaged_chunk_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let side = 16i64;
    let voxels = (0..side).flat_map(|x| (0..side).map(move |y| [x, y, (x + y) % 7]));
    let model = Model::new(LinearOctree::from_voxels(4, [0, 0, 0], voxels).unwrap());
    let path = dir.path().join("bad.tess");
    write_v2(&path, &model, 16);
    let f = crate::io::TessFile::open(&path).unwrap();
    let chunks = f.chunks();
    assert!(chunks.len() > 4);
    let victim = chunks.len() / 2;
    drop(f);
    let mut bytes = std::fs::read(&path).unwrap();
    // The first payload byte of the chunk (past its 32-byte head).
    bytes[chunks[victim].offset as usize + 32] ^= 0x55;
    std::fs::write(&path, bytes).unwrap();
    let opts = RenderOptions {
        width: 64,
        height: 48,
        camera: Camera::view(View::Top),
        ..Default::default()
    };
    let err = match StreamedTree::open(&path, 1 << 20) {
        Err(e) => e,
        Ok(st) => render_streamed(&st, Surface::default(), &opts).unwrap_err(),
    }
    .to_string();
    assert!(
        err.contains("bad.tess") && err.contains(&format!("chunk {victim}")),
        "{err}"
    );
}

/// A cache too small for every thread of the pool to hold its chunks: the drawing
/// runs on fewer threads, the image does not change, and the chunks are decoded
/// about as often as on that many threads alone.
#[test]
fn a_small_cache_draws_on_fewer_threads() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(78);
    let model = coloured(&mut rng, terrain(64));
    let path = dir.path().join("m.tess");
    write_v2(&path, &model, 512);
    let opts = RenderOptions {
        width: 96,
        height: 72,
        ..Default::default()
    };
    let want = in_memory(&model, &opts);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    // Chunks of 512 leaves: a thread's three at 8,448 bytes each (the estimate),
    // 25,344 bytes a thread, two thirds of 90,000 (the chunks' three quarters of
    // the budget) holding two of them.
    let (tight, decoded) = pool(8).install(|| {
        let st = StreamedTree::open(&path, 120_000).unwrap();
        assert!(streamed(&st, &opts) == want);
        let s = st.stats();
        (st, s.chunks_decoded)
    });
    assert_eq!(tight.threads(), 2);
    let on_two = pool(2).install(|| {
        let st = StreamedTree::open(&path, 120_000).unwrap();
        assert_eq!(st.threads(), 2);
        assert!(streamed(&st, &opts) == want);
        st.stats().chunks_decoded
    });
    assert!(decoded <= 2 * on_two, "{decoded} decodes against {on_two}");
    let roomy = pool(8).install(|| StreamedTree::open(&path, 1 << 30).unwrap());
    assert_eq!(roomy.threads(), 8);
    assert!(streamed(&roomy, &opts) == want);
}

#[test]
fn the_threads_fit_two_thirds_of_the_chunks_budget() {
    use super::threads_within;
    // A chunk of 1,000 leaves: 16,256 bytes at its peak, 48,768 a thread.
    assert_eq!(threads_within(3 * 48_768 / 2, 1_000, 16), 1);
    assert_eq!(threads_within(3 * 48_768 / 2 * 5, 1_000, 16), 5);
    assert_eq!(threads_within(3 * 48_768 / 2 * 5, 1_000, 4), 4);
    // Too small for one thread: still one.
    assert_eq!(threads_within(1, 1_000, 16), 1);
    assert_eq!(threads_within(u64::MAX, u64::MAX, 16), 1);
    assert_eq!(threads_within(u64::MAX, 1_000, 16), 16);
    assert_eq!(threads_within(1 << 30, 0, 0), 1);
}

//! The packed tree against the tree it came from: point queries against a set of
//! voxels, rays against the renderer's traversal and brute force, colours against
//! the layer, coarse trees against "any voxel black".

use std::collections::HashSet;

use super::trace::{cast, lookup};
use super::*;
use crate::csg::tests::Rng;
use crate::render::{crop_to_clip, Clip, Ray, RayTree};
use crate::Voxel;

/// Random boxes and scattered voxels: big leaves and small ones.
fn random_voxels(rng: &mut Rng, depth: u8, origin: Voxel) -> HashSet<Voxel> {
    let side = 1i64 << depth;
    let mut set = HashSet::new();
    for _ in 0..rng.next() % 4 {
        let lo: [i64; 3] = [0; 3].map(|_| (rng.next() % side as u64) as i64);
        let ext: [i64; 3] = [0; 3].map(|_| 1 + (rng.next() % side as u64) as i64);
        for x in lo[0]..(lo[0] + ext[0]).min(side) {
            for y in lo[1]..(lo[1] + ext[1]).min(side) {
                for z in lo[2]..(lo[2] + ext[2]).min(side) {
                    set.insert([origin[0] + x, origin[1] + y, origin[2] + z]);
                }
            }
        }
    }
    for _ in 0..rng.next() % 40 {
        let v = [0; 3].map(|_| (rng.next() % side as u64) as i64);
        set.insert([origin[0] + v[0], origin[1] + v[1], origin[2] + v[2]]);
    }
    set
}

fn pack(tree: &LinearOctree, max: usize) -> Result<(Vec<u32>, PackedTree), ViewError> {
    let mut palette = Palette::default();
    let leaves = coloured_leaves(tree, Colouring::Fixed([1, 2, 3]), &mut palette)?;
    let mut entries = Vec::new();
    let packed = PackedTree::build(&mut entries, tree.depth(), &leaves, max)?;
    Ok((entries, packed))
}

fn sub(a: Voxel, b: Voxel) -> Voxel {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[test]
fn lookup_matches_the_set_of_voxels() {
    let mut rng = Rng(0x5eed_0001);
    for round in 0..60 {
        let depth = (round % 5) as u8;
        let origin = [-3, 5, (round as i64) - 20];
        let set = random_voxels(&mut rng, depth, origin);
        let tree = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
        tree.assert_valid();
        let (entries, packed) = pack(&tree, MAX_ENTRIES).unwrap();
        assert_eq!(packed.levels, depth);
        assert_eq!(packed.empty, set.is_empty());
        let side = 1i64 << depth;
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let cell = lookup(&entries, &packed, [x, y, z]);
                    let v = [origin[0] + x, origin[1] + y, origin[2] + z];
                    assert_eq!(cell.colour.is_some(), set.contains(&v), "{v:?}");
                    // The cell holds the voxel and is uniform.
                    let size = 1i64 << cell.size_log2;
                    assert!((0..3).all(|a| {
                        let c = [x, y, z][a];
                        cell.min[a] <= c && c < cell.min[a] + size && cell.min[a] % size == 0
                    }));
                    let corner = [0, 1, 2].map(|a| origin[a] + cell.min[a] + size - 1);
                    assert_eq!(set.contains(&corner), cell.colour.is_some());
                }
            }
        }
        // No entry is wasted: one per node of the tree, white cells excluded.
        if !set.is_empty() {
            assert!(entries.len() <= 1 + 8 * tree.leaf_count() * usize::from(depth.max(1)));
        }
    }
}

#[test]
fn rays_match_the_renderers_traversal() {
    let mut rng = Rng(0x5eed_0002);
    let (mut hits, mut grazes) = (0, 0);
    for round in 0..40 {
        let depth = 1 + (round % 5) as u8;
        let origin = [7, -9, 2];
        let set = random_voxels(&mut rng, depth, origin);
        let tree = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
        let (entries, packed) = pack(&tree, MAX_ENTRIES).unwrap();
        let rt = RayTree::new(&tree);
        let side = (1i64 << depth) as f64;
        for _ in 0..300 {
            // From outside the space, towards a random point in it.
            let from = [0; 3].map(|_| rng.range(-1.0, 2.0) * side);
            let mut to = [0; 3].map(|_| rng.range(0.0, 1.0) * side);
            if rng.next() % 4 == 0 {
                // Through lattice lines: the ties between axes.
                to = to.map(f64::round);
            }
            let d = sub_f(to, from);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if len < 1e-9 {
                continue;
            }
            let mut dir = d.map(|c| c / len);
            if rng.next() % 5 == 0 {
                dir[(rng.next() % 3) as usize] = 0.0;
            }
            let world = [0, 1, 2].map(|a| from[a] + origin[a] as f64);
            let want = rt.cast(&Ray::new(world, dir), 0.0, f64::INFINITY);
            let got = cast(&entries, &packed, from, dir, [0; 3], [1 << depth; 3]);
            match (want, got) {
                (None, None) => {}
                (Some(w), Some(g)) if (w.t - g.t).abs() < 1e-9 * (1.0 + w.t) => {
                    hits += 1;
                    assert!((w.t - g.t).abs() < 1e-9 * (1.0 + w.t), "{w:?} {g:?}");
                    let v = [0, 1, 2].map(|a| origin[a] + g.voxel[a]);
                    assert!(set.contains(&v), "hit voxel {v:?} is white");
                    // The point hit lies on the voxel's boundary or inside it.
                    let p = [0, 1, 2].map(|a| from[a] + dir[a] * g.t);
                    for a in 0..3 {
                        let c = g.voxel[a] as f64;
                        assert!(p[a] >= c - 1e-6 && p[a] <= c + 1.0 + 1e-6, "{p:?} {g:?}");
                    }
                }
                (w, g) => {
                    // Only a ray grazing an edge or corner of the lattice (two
                    // coordinates whole at the hit) may be decided either way.
                    let t = match (w, g) {
                        (Some(w), Some(g)) => w.t.min(g.t),
                        (Some(w), None) => w.t,
                        (None, Some(g)) => g.t,
                        (None, None) => unreachable!(),
                    };
                    let p = [0, 1, 2].map(|a| from[a] + dir[a] * t);
                    let whole = p.iter().filter(|c| (*c - c.round()).abs() < 1e-9).count();
                    assert!(
                        whole >= 2,
                        "renderer {w:?}, packed {g:?}, from {from:?} dir {dir:?}"
                    );
                    if let Some(g) = g {
                        assert!(set.contains(&[0, 1, 2].map(|a| origin[a] + g.voxel[a])));
                    }
                    grazes += 1;
                }
            }
        }
    }
    assert!(hits > 1000, "too few hits to mean anything: {hits}");
    assert!(grazes * 10 < hits, "{grazes} grazing rays of {hits}");
}

fn sub_f(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[test]
fn a_cut_box_matches_the_cropped_tree() {
    let mut rng = Rng(0x5eed_0003);
    for round in 0..30 {
        let depth = 2 + (round % 4) as u8;
        let origin = [0, 0, 0];
        let set = random_voxels(&mut rng, depth, origin);
        let tree = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
        let (entries, packed) = pack(&tree, MAX_ENTRIES).unwrap();
        let side = 1i64 << depth;
        let axis = (rng.next() % 3) as usize;
        let at = (rng.next() % (side as u64 + 1)) as f64 - 0.5;
        let keep_above = rng.next() % 2 == 0;
        let clip = Clip {
            axis,
            at,
            keep_above,
        };
        let cropped = crop_to_clip(&tree, clip);
        cropped.assert_valid();
        let rt = RayTree::new(&cropped);
        let (mut lo, mut hi) = ([0; 3], [side; 3]);
        if keep_above {
            lo[axis] = clip.boundary();
        } else {
            hi[axis] = clip.boundary();
        }
        for _ in 0..200 {
            let from = [0; 3].map(|_| rng.range(-1.0, 2.0) * side as f64);
            let to = [0; 3].map(|_| rng.range(0.0, 1.0) * side as f64);
            let d = sub_f(to, from);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let dir = d.map(|c| c / len);
            let want = rt.cast(&Ray::new(from, dir), 0.0, f64::INFINITY);
            let got = cast(&entries, &packed, from, dir, lo, hi);
            assert_eq!(want.is_some(), got.is_some(), "{want:?} {got:?}");
            if let (Some(w), Some(g)) = (want, got) {
                assert!((w.t - g.t).abs() < 1e-9 * (1.0 + w.t));
                assert!(clip.keeps(g.voxel) && set.contains(&g.voxel));
            }
        }
    }
}

#[test]
fn layer_colours_reach_every_voxel() {
    let mut rng = Rng(0x5eed_0004);
    for round in 0..30 {
        let depth = 1 + (round % 4) as u8;
        let origin = [4, 4, -4];
        let set = random_voxels(&mut rng, depth, origin);
        let tree = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
        // Colours on some of the voxels, in a few values so that regions merge.
        let coloured: Vec<(Voxel, Rgba)> = set
            .iter()
            .filter(|_| rng.next() % 3 != 0)
            .map(|&v| {
                (
                    v,
                    [
                        v[0].rem_euclid(2) as u8 * 200,
                        10,
                        v[2].rem_euclid(3) as u8 * 50,
                        255,
                    ],
                )
            })
            .collect();
        let layer = Layer::from_voxels(depth, origin, coloured.iter().copied()).unwrap();
        let mut palette = Palette::default();
        let fallback = [9, 9, 9];
        let leaves =
            coloured_leaves(&tree, Colouring::Layer(&layer, fallback), &mut palette).unwrap();
        // The pieces cover exactly the tree.
        let again =
            LinearOctree::from_sorted_leaves(depth, origin, leaves.iter().map(|l| l.0)).unwrap();
        assert_eq!(again, tree);
        let mut entries = Vec::new();
        let packed = PackedTree::build(&mut entries, depth, &leaves, MAX_ENTRIES).unwrap();
        for &v in &set {
            let cell = lookup(&entries, &packed, sub(v, origin));
            let rgb = palette.colours()[cell.colour.unwrap() as usize];
            let want = layer.get(v).map_or(fallback, |c| [c[0], c[1], c[2]]);
            assert_eq!(rgb, want, "{v:?}");
        }
    }
}

#[test]
fn a_budget_gives_a_coarser_tree_black_where_any_voxel_is() {
    let mut rng = Rng(0x5eed_0005);
    for round in 0..30 {
        let depth = 3 + (round % 3) as u8;
        let origin = [0, 0, 0];
        let set = random_voxels(&mut rng, depth, origin);
        let tree = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
        let (full, _) = pack(&tree, MAX_ENTRIES).unwrap();
        let budget = 1 + (rng.next() as usize % full.len().max(1));
        let Ok((entries, packed)) = pack(&tree, budget) else {
            // Only a budget below the root's children fails.
            assert!(budget < 9);
            continue;
        };
        assert!(entries.len() <= budget, "{} > {budget}", entries.len());
        if entries.len() < full.len() {
            assert!(packed.levels < depth);
        }
        let unit = 1i64 << (depth - packed.levels);
        let side = 1i64 << depth;
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let cell = lookup(&entries, &packed, [x, y, z]);
                    let c = [x, y, z].map(|v| v / unit * unit);
                    let any = (0..unit).any(|i| {
                        (0..unit).any(|j| {
                            (0..unit).any(|k| set.contains(&[c[0] + i, c[1] + j, c[2] + k]))
                        })
                    });
                    assert_eq!(cell.colour.is_some(), any, "{x} {y} {z} unit {unit}");
                }
            }
        }
    }
}

#[test]
fn a_page_is_self_contained_and_within_its_budget() {
    let mut rng = Rng(0x5eed_0006);
    let set = random_voxels(&mut rng, 5, [0; 3]);
    let tree = LinearOctree::from_voxels(5, [0; 3], set.iter().copied()).unwrap();
    let mut page = Page::new(
        "a </script> test",
        crate::model::Frame::new(0.5, [1.0, 2.0, 3.0]),
    );
    let budget = page.entry_budget(64 << 20);
    page.add(&tree, Colouring::Fixed([200, 100, 50]), "only", budget)
        .unwrap();
    let html = page.html();
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert_eq!(
        html.matches("</script>").count(),
        html.matches("<script").count()
    );
    assert!(html.contains("\"voxel_size\":0.5"));
    assert!(
        html.len() as u64
            <= PAGE_OVERHEAD + (page.entries().len() as f64 * ENTRY_BYTES) as u64 + 64
    );
    // A budget too small for the top level is refused, naming the numbers.
    let mut small = Page::new("x", crate::model::Frame::new(1.0, [0.0; 3]));
    let err = small.add(&tree, Colouring::Fixed([1, 1, 1]), "x", 1);
    assert!(tree.leaf_count() < 2 || matches!(err, Err(ViewError::TooLarge { .. })));
}

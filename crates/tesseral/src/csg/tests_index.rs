//! The union index against brute force: the parts a query meets, and whole builds of
//! large unions against a per-part point test (no index anywhere in the model).

use std::collections::BTreeSet;
use std::ops::ControlFlow;

use super::index::{Bounds, BoxIndex};
use super::tests::Rng;
use super::*;
use crate::linear::LinearOctree;
use crate::Voxel;

#[test]
fn the_index_finds_exactly_the_boxes_a_query_meets() {
    let seed = 0x1d_e7_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for trial in 0..50 {
        let n = 1 + (rng.next() % 300) as usize;
        let mut parts = Vec::new();
        for id in 0..n as u32 {
            let b = if rng.next() % 10 == 0 {
                None
            } else {
                let lo = [0; 3].map(|_| rng.range(-100.0, 100.0));
                let size = [0; 3].map(|_| rng.range(0.0, 20.0));
                Some((lo, std::array::from_fn(|a| lo[a] + size[a])))
            };
            parts.push((id, b));
        }
        let index = BoxIndex::new(&parts);
        for _ in 0..50 {
            let lo = [0; 3].map(|_| rng.range(-120.0, 120.0));
            let size = rng.range(0.0, 40.0);
            let query: Bounds = (lo, lo.map(|v| v + size));
            let mut got = BTreeSet::new();
            let _ = index.for_each_meeting(&query, |id| {
                assert!(got.insert(id), "part {id} twice");
                ControlFlow::Continue(())
            });
            let want: BTreeSet<u32> = parts
                .iter()
                .filter(|(_, b)| match b {
                    None => true,
                    Some((l, h)) => (0..3).all(|a| l[a] <= query.1[a] && query.0[a] <= h[a]),
                })
                .map(|p| p.0)
                .collect();
            assert_eq!(got, want, "seed {seed:#x} trial {trial}");
        }
    }
}

/// A random part: a turned box, a ball, a cylinder, now and then an unbounded one
/// (the complement of a ball) or a small nested union.
fn part(rng: &mut Rng, depth: u32) -> Solid {
    let at = [0; 3].map(|_| rng.range(0.0, 32.0));
    match rng.next() % 8 {
        0..=2 => Solid::shape(Shape::cuboid([0; 3].map(|_| rng.range(0.5, 6.0))))
            .rotate([0; 3].map(|_| rng.range(0.0, 90.0)))
            .at(at),
        3 | 4 => Solid::shape(Shape::sphere(rng.range(0.5, 4.0))).at(at),
        5 => Solid::shape(Shape::Torus {
            major: rng.range(1.0, 4.0),
            minor: rng.range(0.3, 1.0),
        })
        .rotate([rng.range(0.0, 90.0), 0.0, 0.0])
        .at(at),
        6 if depth == 0 => Solid::union((0..20).map(|_| part(rng, 1))),
        _ if rng.next() % 4 == 0 => Solid::Not(Box::new(
            Solid::shape(Shape::sphere(rng.range(20.0, 40.0))).at([16.0; 3]),
        )),
        _ => Solid::shape(Shape::sphere(1.0)).at(at),
    }
}

#[test]
fn large_unions_build_as_the_per_part_point_test_says() {
    let seed = 0xb0c5_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for trial in 0..6 {
        let parts: Vec<Solid> = (0..150).map(|_| part(&mut rng, 0)).collect();
        let csg = Solid::union(parts.clone()).compile().unwrap();
        // The model: each part compiled alone (no union, so no index), any contains.
        let alone: Vec<Csg> = parts.iter().map(|p| p.compile().unwrap()).collect();
        let depth = 5;
        let tree = csg.build(depth, [0, 0, 0]).unwrap();
        tree.assert_valid();
        let classified = LinearOctree::from_classifier(depth, [0, 0, 0], &csg).unwrap();
        classified.assert_valid();
        let mut want: Vec<Voxel> = Vec::new();
        for z in 0..32 {
            for y in 0..32 {
                for x in 0..32 {
                    let c = [x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5];
                    if alone.iter().any(|p| p.contains(c)) {
                        want.push([x, y, z]);
                    }
                }
            }
        }
        let got: Vec<Voxel> = tree.voxels().collect();
        let mut want_sorted = want.clone();
        let mut got_sorted = got.clone();
        want_sorted.sort_unstable();
        got_sorted.sort_unstable();
        assert_eq!(
            got_sorted, want_sorted,
            "seed {seed:#x} trial {trial}: build"
        );
        let mut from_classifier: Vec<Voxel> = classified.voxels().collect();
        from_classifier.sort_unstable();
        assert_eq!(
            from_classifier, want_sorted,
            "seed {seed:#x} trial {trial}: classify"
        );
    }
}

/// The colour layer cuts each union part only by the later parts whose boxes meet
/// it: on 300 overlapping parts of four colours, it still equals `colour_at` (the
/// walk from the root, no index) voxel for voxel.
#[test]
fn colours_of_large_overlapping_unions_equal_colour_at() {
    let seed = 0xc0_1002_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    let colours = ["red", "green", "blue", "yellow"];
    let mut text = String::from("depth 5\nbounds [0, 0, 0] [32, 32, 32]\nunion {\n");
    for i in 0..300 {
        let at = [0; 3].map(|_| rng.range(0.0, 32.0));
        let c = colours[(rng.next() % 4) as usize];
        if i % 3 == 0 {
            let r = rng.range(1.0, 5.0);
            text += &format!(
                "sphere(r = {r}) at [{}, {}, {}] colour \"{c}\"\n",
                at[0], at[1], at[2]
            );
        } else {
            let s = [0; 3].map(|_| rng.range(1.0, 9.0));
            text += &format!(
                "box(size = [{}, {}, {}]) rotate [0, 0, {}] at [{}, {}, {}] colour \"{c}\"\n",
                s[0],
                s[1],
                s[2],
                rng.range(0.0, 90.0),
                at[0],
                at[1],
                at[2]
            );
        }
    }
    text += "}\nsphere(r = 3) at [4, 4, 4]\n";
    let scene = scene::Scene::parse(&text, "many.tss".as_ref()).unwrap();
    let m = scene.build_model_limited(1 << 24).unwrap();
    m.assert_valid();
    let csg = scene.csg().unwrap();
    let colors = m.colors.as_ref().expect("coloured");
    let mut checked = 0;
    for v in m.tree.voxels() {
        let p = v.map(|c| c as f64 + 0.5);
        let want = csg.colour_at(p).map(|c| [c.0[0], c.0[1], c.0[2], 255]);
        assert_eq!(colors.get(v), want, "seed {seed:#x}: voxel {v:?}");
        checked += 1;
    }
    assert!(checked > 1000, "{checked}");
}

//! Brute-force checks of the motion module on seeded random voxel sets.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;
use crate::linear::LinearOctree;
use crate::Voxel;

/// A random solid: a few boxes (so the octree has large blocks) plus loose voxels.
pub(crate) fn random_solid(
    rng: &mut Pcg64,
    depth: u8,
    origin: Voxel,
) -> (LinearOctree, Vec<Voxel>) {
    let side = 1i64 << depth;
    let mut set = HashSet::new();
    for _ in 0..rng.random_range(0..=4) {
        let lo: Vec<i64> = (0..3).map(|_| rng.random_range(0..side)).collect();
        let ext: Vec<i64> = (0..3).map(|a| rng.random_range(1..=side - lo[a])).collect();
        for x in 0..ext[0] {
            for y in 0..ext[1] {
                for z in 0..ext[2] {
                    set.insert([
                        origin[0] + lo[0] + x,
                        origin[1] + lo[1] + y,
                        origin[2] + lo[2] + z,
                    ]);
                }
            }
        }
    }
    for _ in 0..rng.random_range(0..12) {
        set.insert([
            origin[0] + rng.random_range(0..side),
            origin[1] + rng.random_range(0..side),
            origin[2] + rng.random_range(0..side),
        ]);
    }
    let voxels: Vec<Voxel> = set.into_iter().collect();
    let tree = LinearOctree::from_voxels(depth, origin, voxels.iter().copied()).unwrap();
    tree.assert_valid();
    (tree, voxels)
}

fn unit_gap2(p: Voxel, q: Voxel) -> u128 {
    (0..3)
        .map(|a| {
            let g = ((p[a] - q[a]).abs() - 1).max(0) as u128;
            g * g
        })
        .sum()
}

/// An offset that puts the rotated `b` near `a` (within `jitter` voxels of centring).
fn offset_near(
    rng: &mut Pcg64,
    va: &[Voxel],
    vb: &[Voxel],
    rotation: Rotation,
    jitter: i64,
) -> Voxel {
    let centre = |vs: &mut dyn Iterator<Item = Voxel>| {
        let (mut sum, mut n) = ([0i64; 3], 0i64);
        for v in vs {
            for a in 0..3 {
                sum[a] += v[a];
            }
            n += 1;
        }
        let n = n.max(1);
        [sum[0] / n, sum[1] / n, sum[2] / n]
    };
    let ca = centre(&mut va.iter().copied());
    let cb = centre(&mut vb.iter().map(|&v| rotation.apply_voxel(v)));
    [0, 1, 2].map(|a| ca[a] - cb[a] + rng.random_range(-jitter..=jitter))
}

fn seeded(test: &str, seed: u64) -> Pcg64 {
    eprintln!("{test}: seed {seed}");
    Pcg64::seed_from_u64(seed)
}

#[test]
fn rotations_are_24_distinct_and_form_a_group() {
    let all = Rotation::all();
    assert_eq!(all.len(), 24);
    assert!(all[0].is_identity());
    let set: HashSet<_> = all.iter().copied().collect();
    assert_eq!(set.len(), 24);
    for &r in &all {
        assert!(r.compose(r.inverse()).is_identity());
        for &s in &all {
            assert!(set.contains(&r.compose(s)));
        }
    }
    // Four quarter turns about any axis are the identity; parsing composes in order.
    for axis in 0..3 {
        assert!(Rotation::about_axis(axis, 4).is_identity());
        assert!(!Rotation::about_axis(axis, 1).is_identity());
    }
    let zx: Rotation = "z90,x90".parse().unwrap();
    assert_eq!(
        zx,
        Rotation::about_axis(0, 1).compose(Rotation::about_axis(2, 1))
    );
    assert_eq!(zx.apply_point([1, 0, 0]), [0, 0, 1]);
    assert!("q90".parse::<Rotation>().is_err());
    assert!("x45".parse::<Rotation>().is_err());
    assert!("24".parse::<Rotation>().is_err());
    assert_eq!("7".parse::<Rotation>().unwrap(), all[7]);
}

#[test]
fn rotated_voxels_of_a_cube_fill_a_cube() {
    for r in Rotation::all() {
        let n = 3i64;
        let img: HashSet<Voxel> = (0..n * n * n)
            .map(|i| r.apply_voxel([i % n, i / n % n, i / n / n]))
            .collect();
        assert_eq!(img.len(), 27);
        let lo = img.iter().fold([i64::MAX; 3], |m, v| {
            [m[0].min(v[0]), m[1].min(v[1]), m[2].min(v[2])]
        });
        for v in &img {
            assert!((0..3).all(|a| v[a] - lo[a] < n));
        }
        // apply_cube agrees with the voxels of the cube.
        assert_eq!(r.apply_cube([0, 0, 0], n), lo);
    }
}

#[test]
fn interference_matches_brute_force() {
    let mut hits = [0; 2];
    for seed in 0..1000u64 {
        let mut rng = seeded("interference_matches_brute_force", seed);
        let da = rng.random_range(0..=4);
        let db = rng.random_range(0..=3);
        let oa = [rng.random_range(-5..5), rng.random_range(-5..5), 0];
        let ob = [0, rng.random_range(-3..3), rng.random_range(-3..3)];
        let (a, va) = random_solid(&mut rng, da, oa);
        let (b, vb) = random_solid(&mut rng, db, ob);
        let all = Rotation::all();
        let rotation = all[rng.random_range(0..24)];
        let offset = offset_near(&mut rng, &va, &vb, rotation, 2);
        let place = Placement { rotation, offset };
        let sa: HashSet<Voxel> = va.iter().copied().collect();
        let moved: Vec<Voxel> = vb.iter().map(|&v| place.apply_voxel(v)).collect();
        let shared: HashSet<Voxel> = moved.iter().copied().filter(|v| sa.contains(v)).collect();

        let got = interference(&a, &b, place, true);
        let (pa, pb) = (BoxTree::new(&a), BoxTree::new(&b));
        pa.assert_valid();
        pb.assert_valid();
        assert_eq!(pa.voxel_count(), a.voxel_count());
        // Prepared trees, alone or mixed with plain ones, give the same answers.
        assert_eq!(
            intersects(&pa, &pb, place),
            !shared.is_empty(),
            "seed {seed}"
        );
        assert_eq!(
            intersects(&a, &pb, place),
            !shared.is_empty(),
            "seed {seed}"
        );
        let prepared = interference(&pa, &pb, place, true);
        assert_eq!(prepared.overlap_voxels, shared.len() as u64, "seed {seed}");
        let mut cells: Vec<Aabb> = prepared.contacts.clone();
        let mut plain: Vec<Aabb> = got.contacts.clone();
        cells.sort_by_key(|b| (b.min, b.max));
        plain.sort_by_key(|b| (b.min, b.max));
        assert_eq!(cells, plain, "seed {seed}");
        assert_eq!(
            interference(&pa, &b, place, false).overlap_voxels,
            shared.len() as u64
        );
        assert_eq!(
            clearance_squared(Placed::fixed(&pa), Placed::new(&pb, place)),
            clearance_squared(Placed::fixed(&a), Placed::new(&b, place)),
            "seed {seed}"
        );
        assert_eq!(got.intersects, !shared.is_empty(), "seed {seed}");
        assert_eq!(got.overlap_voxels, shared.len() as u64, "seed {seed}");
        assert_eq!(intersects(&a, &b, place), !shared.is_empty(), "seed {seed}");
        // Contact boxes: disjoint and covering exactly the shared voxels.
        let mut covered = HashSet::new();
        for c in &got.contacts {
            for x in c.min[0]..=c.max[0] {
                for y in c.min[1]..=c.max[1] {
                    for z in c.min[2]..=c.max[2] {
                        assert!(covered.insert([x, y, z]), "seed {seed}: contacts overlap");
                    }
                }
            }
        }
        assert_eq!(covered, shared, "seed {seed}");
        // Symmetry: swapping the roles gives the same overlap.
        let swapped = interference_placed(Placed::new(&b, place), Placed::fixed(&a), false);
        assert_eq!(swapped.overlap_voxels, got.overlap_voxels, "seed {seed}");

        // Clearance.
        let brute = va
            .iter()
            .flat_map(|&p| moved.iter().map(move |&q| unit_gap2(p, q)))
            .min();
        assert_eq!(
            clearance_squared(Placed::fixed(&a), Placed::new(&b, place)),
            brute,
            "seed {seed}"
        );
        assert_eq!(
            clearance(&a, &b, place),
            brute.map(|d| (d as f64).sqrt()),
            "seed {seed}"
        );
        hits[usize::from(got.intersects)] += 1;
    }
    // Both outcomes are well represented, so the comparison is not vacuous.
    assert!(hits[0] > 150 && hits[1] > 150, "{hits:?}");
}

#[test]
fn prepared_trees_without_rotation_match_brute_force() {
    // Identity rotations let prepared trees compare 4³ cells as bit masks.
    let mut hits = [0; 2];
    for seed in 0..600u64 {
        let mut rng = seeded("prepared_trees_without_rotation_match_brute_force", seed);
        let (da, db) = (rng.random_range(0..=4), rng.random_range(0..=4));
        let (xa, yb) = (rng.random_range(-9..9), rng.random_range(-9..9));
        let (a, va) = random_solid(&mut rng, da, [xa, 0, 3]);
        let (b, vb) = random_solid(&mut rng, db, [1, yb, -2]);
        let offset = offset_near(&mut rng, &va, &vb, Rotation::IDENTITY, 3);
        let place = Placement::at(offset);
        let sa: HashSet<Voxel> = va.iter().copied().collect();
        let shared = vb
            .iter()
            .filter(|v| sa.contains(&place.apply_voxel(**v)))
            .count() as u64;
        let (pa, pb) = (BoxTree::new(&a), BoxTree::new(&b));
        pa.assert_valid();
        pb.assert_valid();
        assert_eq!(intersects(&pa, &pb, place), shared > 0, "seed {seed}");
        assert_eq!(
            interference(&pa, &pb, place, false).overlap_voxels,
            shared,
            "seed {seed}"
        );
        assert_eq!(
            interference(&a, &pb, place, false).overlap_voxels,
            shared,
            "seed {seed}"
        );
        hits[usize::from(shared > 0)] += 1;
    }
    assert!(hits[0] > 100 && hits[1] > 100, "{hits:?}");
}

#[test]
fn mask_shifts_match_moving_voxels() {
    let mut rng = seeded("mask_shifts_match_moving_voxels", 7);
    for _ in 0..2000 {
        let m: u64 = rng.random();
        let d = [0, 1, 2].map(|_| rng.random_range(-3..=3));
        let mut want = 0u64;
        for i in 0..64i64 {
            if m >> i & 1 == 1 {
                let p = [i & 3, (i >> 2) & 3, i >> 4];
                let q = [0, 1, 2].map(|a| p[a] + d[a]);
                if q.iter().all(|c| (0..4).contains(c)) {
                    want |= 1 << (q[0] + 4 * q[1] + 16 * q[2]);
                }
            }
        }
        assert_eq!(super::view::shift_mask(m, d), want, "{m:x} by {d:?}");
    }
}

#[test]
fn first_contact_matches_brute_force_and_sampling() {
    let mut hits = [0; 3];
    for seed in 0..1000u64 {
        let mut rng = seeded("first_contact_matches_brute_force_and_sampling", seed);
        let (da, db) = (rng.random_range(0..=4), rng.random_range(0..=3));
        let (a, va) = random_solid(&mut rng, da, [0, 0, 0]);
        let (b, vb) = random_solid(&mut rng, db, [0, 0, 0]);
        let all = Rotation::all();
        let rotation = all[rng.random_range(0..24)];
        let near = offset_near(&mut rng, &va, &vb, rotation, 4);
        // Start away from `a` and move back through it (or near it).
        let v = [
            rng.random_range(-20..20),
            rng.random_range(-20..20),
            rng.random_range(-3..3),
        ];
        let back = rng.random_range(0..=2);
        let offset = [0, 1, 2].map(|ax| near[ax] - v[ax] * back / 4);
        let place = Placement { rotation, offset };
        let moved: Vec<Voxel> = vb.iter().map(|&q| place.apply_voxel(q)).collect();
        let got = first_contact(Placed::fixed(&a), [0; 3], Placed::new(&b, place), v);
        let brute = first_contact_brute(&va, &moved, v);
        assert_eq!(got.map(|c| c.time), brute, "seed {seed}");
        let (pa, pb) = (BoxTree::new(&a), BoxTree::new(&b));
        let prepared = first_contact(Placed::fixed(&pa), [0; 3], Placed::new(&pb, place), v);
        assert_eq!(prepared.map(|c| c.time), brute, "seed {seed}");
        // Independent check by sampling: no overlap strictly before the time, overlap
        // just after it.
        let overlap_at = |t: f64| {
            va.iter().any(|p| {
                moved.iter().any(|q| {
                    (0..3).all(|ax| (q[ax] as f64 + t * v[ax] as f64 - p[ax] as f64).abs() < 1.0)
                })
            })
        };
        let end = got.map_or(1.0, |c| c.time.to_f64());
        for i in 0..64 {
            let t = end * f64::from(i) / 64.0;
            if t < end {
                assert!(!overlap_at(t), "seed {seed}: overlap at {t} before {end}");
            }
        }
        if let Some(c) = got {
            assert!(
                overlap_at(c.time.to_f64() + 1e-7),
                "seed {seed}: no overlap after {}",
                c.time
            );
            assert!(c.time < Fraction::ONE);
        }
        hits[match got {
            None => 0,
            Some(c) if c.time == Fraction::ZERO => 1,
            Some(_) => 2,
        }] += 1;
    }
    assert!(hits.iter().all(|&h| h > 100), "{hits:?}");
}

#[test]
fn thin_wall_tunnelling_is_caught_by_the_swept_test() {
    // A wall one voxel thick at x = 20; a 4x4x4 cube crossing it in one 40-voxel step.
    let wall = LinearOctree::from_voxels(
        6,
        [0, 0, 0],
        (0..16).flat_map(|y| (0..16).map(move |z| [20, y, z])),
    )
    .unwrap();
    let cube = LinearOctree::from_voxels(2, [0, 0, 0], (0..64).map(|i| [i % 4, i / 4 % 4, i / 16]))
        .unwrap();
    let start = Placement::at([0, 4, 4]);
    let end = Placement::at([40, 4, 4]);
    // Sampled at the two steps, nothing touches: a per-step test misses the wall.
    assert!(!intersects(&wall, &cube, start));
    assert!(!intersects(&wall, &cube, end));
    let hit = first_contact(
        Placed::fixed(&wall),
        [0; 3],
        Placed::new(&cube, start),
        [40, 0, 0],
    )
    .expect("the swept test catches the wall");
    // The cube's front face x = 4 reaches the wall's face x = 20 after 16 of 40 voxels.
    assert_eq!(hit.time, Fraction::new(2, 5));
    assert_eq!(hit.a_block.min[0], 20);
}

#[test]
fn sliding_along_a_face_is_not_a_collision() {
    let floor =
        LinearOctree::from_voxels(3, [0, 0, 0], (0..64).map(|i| [i % 8, i / 8, 0])).unwrap();
    let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
    assert!(first_contact(
        Placed::fixed(&floor),
        [0; 3],
        Placed::new(&dot, Placement::at([0, 0, 1])),
        [7, 7, 0]
    )
    .is_none());
    assert_eq!(clearance(&floor, &dot, Placement::at([3, 3, 1])), Some(0.0));
    // Already overlapping at the start: time 0.
    let hit = first_contact(
        Placed::fixed(&floor),
        [0; 3],
        Placed::new(&dot, Placement::at([0, 0, 0])),
        [1, 0, 0],
    )
    .unwrap();
    assert_eq!(hit.time, Fraction::ZERO);
}

#[test]
fn empty_trees_never_interfere() {
    let e = LinearOctree::empty(3, [0, 0, 0]).unwrap();
    let f = LinearOctree::full(3, [0, 0, 0]).unwrap();
    assert!(!intersects(&e, &f, Placement::default()));
    assert_eq!(clearance(&e, &f, Placement::default()), None);
    assert!(first_contact(Placed::fixed(&f), [0; 3], Placed::fixed(&e), [1, 1, 1]).is_none());
    assert_eq!(
        interference(&f, &f, Placement::at([1, 2, 3]), false).overlap_voxels,
        7 * 6 * 5
    );
}

fn cube(side: i64) -> LinearOctree {
    LinearOctree::from_voxels_fitted(
        &(0..side * side * side)
            .map(|i| [i % side, i / side % side, i / side / side])
            .collect::<Vec<_>>(),
    )
    .unwrap()
}

/// Two runs agree on every contact and overlap; block decompositions may differ
/// (a translated tree has other blocks, Ahuja & Nash §1), so contact boxes are
/// compared as voxel sets.
fn assert_same_run(x: &Simulation, y: &Simulation, seed: u64) {
    let key = |s: &Simulation| -> Vec<_> {
        s.contacts
            .iter()
            .map(|c| {
                (
                    c.step,
                    c.fraction,
                    c.a.clone(),
                    c.b.clone(),
                    c.between_steps,
                    c.time.to_bits(),
                )
            })
            .collect()
    };
    assert_eq!(key(x), key(y), "seed {seed}");
    assert_eq!(x.frames.len(), y.frames.len());
    let voxels = |boxes: &[Aabb]| -> HashSet<Voxel> {
        let mut out = HashSet::new();
        for b in boxes {
            for i in b.min[0]..=b.max[0] {
                for j in b.min[1]..=b.max[1] {
                    for k in b.min[2]..=b.max[2] {
                        out.insert([i, j, k]);
                    }
                }
            }
        }
        out
    };
    for (f, g) in x.frames.iter().zip(&y.frames) {
        assert_eq!(
            (f.step, &f.offsets, &f.overlaps),
            (g.step, &g.offsets, &g.overlaps),
            "seed {seed}"
        );
        assert_eq!(
            voxels(&f.contact_boxes),
            voxels(&g.contact_boxes),
            "seed {seed}"
        );
    }
}

#[test]
fn world_catches_a_fast_object_tunnelling_through_a_thin_wall() {
    let wall = LinearOctree::from_voxels(
        6,
        [0, 0, 0],
        (0..16).flat_map(|y| (0..16).map(move |z| [30, y, z])),
    )
    .unwrap();
    let mut world = World::new(wall);
    world.objects.push(MovingObject {
        name: "bullet".into(),
        tree: cube(2),
        rotation: Rotation::IDENTITY,
        trajectory: Trajectory::Constant {
            start: [0.0, 4.0, 4.0],
            velocity: [25.0, 0.0, 0.0],
        },
    });
    let sim = world.simulate(1.0, 3).unwrap();
    for method in [TranslationMethod::Linear, TranslationMethod::Labels] {
        world.method = method;
        assert_same_run(&world.simulate(1.0, 3).unwrap(), &sim, 0);
    }
    // No step samples the bullet inside the wall (x = 0, 25, 50, 75).
    assert!(sim.frames.iter().all(|f| f.overlaps.is_empty()));
    assert_eq!(sim.contacts.len(), 1);
    let c = &sim.contacts[0];
    assert!(c.between_steps);
    assert_eq!((c.step, c.fraction), (1, Fraction::new(3, 25)));
    assert_eq!(c.time, 1.12); // x = 25 + 3 puts the front face x = 30 on the wall
    assert_eq!(c.a, Body::Environment);
}

#[test]
fn world_matches_brute_force_step_by_step() {
    let (mut swept, mut at_start) = (0, 0);
    for seed in 0..150u64 {
        let mut rng = seeded("world_matches_brute_force_step_by_step", seed);
        let (env, venv) = random_solid(&mut rng, 4, [0, 0, 0]);
        let mut world = World::new(env);
        let mut voxels = Vec::new();
        for k in 0..3 {
            let d = rng.random_range(0..=2);
            let (tree, vs) = random_solid(&mut rng, d, [0, 0, 0]);
            let rotation = Rotation::all()[rng.random_range(0..24)];
            let start = [0, 1, 2].map(|_| f64::from(rng.random_range(-4..16)));
            let velocity = [0, 1, 2].map(|_| f64::from(rng.random_range(-30..30)) / 4.0);
            world.objects.push(MovingObject {
                name: format!("o{k}"),
                tree,
                rotation,
                trajectory: Trajectory::Constant { start, velocity },
            });
            voxels.push(vs);
        }
        let steps = 8;
        let sim = world.simulate(0.5, steps).unwrap();
        // Keeping each object's tree current by linear translation gives the same run.
        for method in [TranslationMethod::Linear, TranslationMethod::Labels] {
            world.method = method;
            assert_same_run(&world.simulate(0.5, steps).unwrap(), &sim, seed);
        }
        assert_eq!(sim.frames.len(), steps as usize + 1);
        let placed = |k: usize, off: Voxel| -> Vec<Voxel> {
            let place = Placement {
                rotation: world.objects[k].rotation,
                offset: off,
            };
            voxels[k].iter().map(|&v| place.apply_voxel(v)).collect()
        };
        let shared = |a: &[Voxel], b: &[Voxel]| {
            let s: HashSet<Voxel> = a.iter().copied().collect();
            b.iter().filter(|v| s.contains(*v)).count() as u64
        };
        let mut expected_contacts = Vec::new();
        for f in &sim.frames {
            let n = f.step;
            let off: Vec<Voxel> = (0..3)
                .map(|k| world.objects[k].trajectory.offset_at(n as f64 * 0.5))
                .collect();
            assert_eq!(f.offsets, off, "seed {seed}");
            let mut overlaps = Vec::new();
            let bodies: Vec<(Option<usize>, usize)> = vec![
                (None, 0),
                (None, 1),
                (None, 2),
                (Some(0), 1),
                (Some(0), 2),
                (Some(1), 2),
            ];
            for &(i, j) in &bodies {
                let va = i.map_or(venv.clone(), |i| placed(i, off[i]));
                let vb = placed(j, off[j]);
                let s = shared(&va, &vb);
                if s > 0 {
                    overlaps.push((i, j, s));
                    if n == 0 {
                        expected_contacts.push((0, Fraction::ZERO, i, j));
                    }
                } else if n < steps {
                    let next: Vec<Voxel> = (0..3)
                        .map(|k| world.objects[k].trajectory.offset_at((n + 1) as f64 * 0.5))
                        .collect();
                    let mv = |k: usize| [0, 1, 2].map(|a| next[k][a] - off[k][a]);
                    let rel = {
                        let (mb, ma) = (mv(j), i.map_or([0; 3], mv));
                        [0, 1, 2].map(|a| mb[a] - ma[a])
                    };
                    if let Some(t) = first_contact_brute(&va, &vb, rel) {
                        expected_contacts.push((n, t, i, j));
                    }
                }
            }
            assert_eq!(f.overlaps, overlaps, "seed {seed} step {n}");
        }
        let got: Vec<_> = sim
            .contacts
            .iter()
            .map(|c| {
                let idx = |b: &Body| match b {
                    Body::Environment => None,
                    Body::Object { index, .. } => Some(*index),
                };
                (c.step, c.fraction, idx(&c.a), idx(&c.b).unwrap())
            })
            .collect();
        let mut want = expected_contacts.clone();
        let mut got_sorted = got.clone();
        want.sort();
        got_sorted.sort();
        assert_eq!(got_sorted, want, "seed {seed}");
        swept += want.iter().filter(|c| c.1 > Fraction::ZERO).count();
        at_start += want.iter().filter(|c| c.1 == Fraction::ZERO).count();
    }
    assert!(swept > 10 && at_start > 10, "{swept} {at_start}");
}

#[test]
fn minkowski_sum_matches_brute_force() {
    for seed in 0..150u64 {
        let mut rng = seeded("minkowski_sum_matches_brute_force", seed);
        let (da, db) = (rng.random_range(0..=3), rng.random_range(0..=2));
        let oa = [rng.random_range(-4..4), 0, rng.random_range(-4..4)];
        let ob = [0, rng.random_range(-4..4), 0];
        let (a, va) = random_solid(&mut rng, da, oa);
        let (b, vb) = random_solid(&mut rng, db, ob);
        let sum = minkowski_sum(&a, &b).unwrap();
        sum.assert_valid();
        let brute: HashSet<Voxel> = va
            .iter()
            .flat_map(|p| {
                vb.iter()
                    .map(move |q| [p[0] + q[0], p[1] + q[1], p[2] + q[2]])
            })
            .collect();
        let got: HashSet<Voxel> = sum.voxels().collect();
        assert_eq!(got, brute, "seed {seed}");
    }
}

#[test]
fn rotated_and_reflected_trees_match_their_voxels() {
    for seed in 0..100u64 {
        let mut rng = seeded("rotated_and_reflected_trees_match_their_voxels", seed);
        let o = [
            rng.random_range(-9..9),
            rng.random_range(-9..9),
            rng.random_range(-9..9),
        ];
        let (t, vs) = random_solid(&mut rng, 3, o);
        let r = Rotation::all()[rng.random_range(0..24)];
        let rt = rotated(&t, r);
        rt.assert_valid();
        let want: HashSet<Voxel> = vs.iter().map(|&v| r.apply_voxel(v)).collect();
        assert_eq!(rt.voxels().collect::<HashSet<_>>(), want, "seed {seed}");
        let ft = reflected(&t);
        ft.assert_valid();
        let want: HashSet<Voxel> = vs.iter().map(|v| v.map(|c| -c)).collect();
        assert_eq!(ft.voxels().collect::<HashSet<_>>(), want, "seed {seed}");
    }
}

#[test]
fn config_obstacles_match_brute_force_interference() {
    for seed in 0..60u64 {
        let mut rng = seeded("config_obstacles_match_brute_force_interference", seed);
        let (env, venv) = random_solid(&mut rng, 3, [0, 0, 0]);
        let d = rng.random_range(0..=2);
        let (obj, vobj) = random_solid(&mut rng, d, [0, 0, 0]);
        let r = Rotation::all()[rng.random_range(0..24)];
        let cobs = config_obstacles(&env, &obj, r).unwrap();
        cobs.assert_valid();
        let senv: HashSet<Voxel> = venv.iter().copied().collect();
        for x in -12..12 {
            for y in -12..12 {
                for z in -12..12 {
                    let place = Placement {
                        rotation: r,
                        offset: [x, y, z],
                    };
                    let brute = vobj.iter().any(|&v| senv.contains(&place.apply_voxel(v)));
                    assert_eq!(
                        cobs.contains([x, y, z]),
                        brute,
                        "seed {seed} at {x},{y},{z}"
                    );
                }
            }
        }
    }
}

/// Every lattice position of the raw path, step by step, is free and in bounds; every
/// smoothed segment is free by the brute-force swept test and by sampling.
fn check_path(
    plan: &Plan,
    venv: &HashSet<Voxel>,
    vobj: &[Voxel],
    r: Rotation,
    bounds: (Voxel, Voxel),
    seed: u64,
) {
    let free = |p: Voxel| {
        let place = Placement {
            rotation: r,
            offset: p,
        };
        (0..3).all(|a| bounds.0[a] <= p[a] && p[a] <= bounds.1[a])
            && vobj.iter().all(|&v| !venv.contains(&place.apply_voxel(v)))
    };
    let mut steps = 0u64;
    for w in plan.raw.windows(2) {
        // Axis by axis, staying in the box spanned by the two points.
        let mut p = w[0];
        assert!(free(p), "seed {seed}: raw point {p:?} blocked");
        for a in 0..3 {
            while p[a] != w[1][a] {
                p[a] += (w[1][a] - p[a]).signum();
                steps += 1;
                assert!(free(p), "seed {seed}: raw path blocked at {p:?}");
            }
        }
    }
    assert_eq!(steps, plan.steps, "seed {seed}: raw length");
    let venv_list: Vec<Voxel> = venv.iter().copied().collect();
    let moved = |p: Voxel| -> Vec<Voxel> {
        let place = Placement {
            rotation: r,
            offset: p,
        };
        vobj.iter().map(|&v| place.apply_voxel(v)).collect()
    };
    for w in plan.waypoints.windows(2) {
        assert!(free(w[0]) && free(w[1]), "seed {seed}");
        let mv = [0, 1, 2].map(|a| w[1][a] - w[0][a]);
        assert_eq!(
            first_contact_brute(&venv_list, &moved(w[0]), mv),
            None,
            "seed {seed}: segment {w:?}"
        );
        let start = moved(w[0]);
        for k in 0..=40 {
            let t = f64::from(k) / 40.0;
            let hit = start.iter().any(|q| {
                venv.iter().any(|e| {
                    (0..3).all(|a| (q[a] as f64 + t * mv[a] as f64 - e[a] as f64).abs() < 1.0)
                })
            });
            assert!(!hit, "seed {seed}: segment {w:?} blocked at t = {t}");
        }
    }
    assert_eq!(plan.waypoints.first(), plan.raw.first());
    assert_eq!(plan.waypoints.last(), plan.raw.last());
    assert!(plan.length <= plan.steps as f64 + 1e-9);
}

/// BFS on the dense grid of positions (unit costs: Dijkstra).
fn dense_shortest(free: &dyn Fn(Voxel) -> bool, from: Voxel, to: Voxel) -> Option<u64> {
    let mut dist = std::collections::HashMap::new();
    let mut queue = std::collections::VecDeque::new();
    dist.insert(from, 0u64);
    queue.push_back(from);
    while let Some(p) = queue.pop_front() {
        let d = dist[&p];
        if p == to {
            return Some(d);
        }
        for a in 0..3 {
            for s in [-1, 1] {
                let mut q = p;
                q[a] += s;
                if !dist.contains_key(&q) && free(q) {
                    dist.insert(q, d + 1);
                    queue.push_back(q);
                }
            }
        }
    }
    None
}

#[test]
fn plans_are_optimal_against_dense_dijkstra_and_collision_free() {
    let mut outcomes = [0; 3];
    for seed in 0..120u64 {
        let mut rng = seeded(
            "plans_are_optimal_against_dense_dijkstra_and_collision_free",
            seed,
        );
        // Walls with holes make mazes; plus random blocks.
        let side = 16i64;
        let mut env_set: HashSet<Voxel> = HashSet::new();
        for _ in 0..rng.random_range(1..=3) {
            let axis = rng.random_range(0..3);
            let at = rng.random_range(2..side - 2);
            let hole = [rng.random_range(0..side - 3), rng.random_range(0..side - 3)];
            let hs = rng.random_range(0..=3);
            for u in 0..side {
                for w in 0..side {
                    if (hole[0]..hole[0] + hs).contains(&u) && (hole[1]..hole[1] + hs).contains(&w)
                    {
                        continue;
                    }
                    let mut v = [0; 3];
                    v[axis] = at;
                    v[(axis + 1) % 3] = u;
                    v[(axis + 2) % 3] = w;
                    env_set.insert(v);
                }
            }
        }
        let (_, extra) = random_solid(&mut rng, 4, [0, 0, 0]);
        env_set.extend(extra.into_iter().take(40));
        let env = LinearOctree::from_voxels(4, [0, 0, 0], env_set.iter().copied()).unwrap();
        let d = rng.random_range(0..=1);
        let (obj, vobj) = random_solid(&mut rng, d, [0, 0, 0]);
        if vobj.is_empty() {
            continue;
        }
        let r = Rotation::all()[rng.random_range(0..24)];
        let obj_box = rotated(&obj, r).bbox().unwrap();
        let bounds = (
            [0, 1, 2].map(|a| -obj_box.0[a]),
            [0, 1, 2].map(|a| side - 1 - obj_box.1[a]),
        );
        let free = |p: Voxel| {
            let place = Placement {
                rotation: r,
                offset: p,
            };
            (0..3).all(|a| bounds.0[a] <= p[a] && p[a] <= bounds.1[a])
                && vobj
                    .iter()
                    .all(|&v| !env_set.contains(&place.apply_voxel(v)))
        };
        let pick = |rng: &mut Pcg64| [0, 1, 2].map(|a| rng.random_range(bounds.0[a]..=bounds.1[a]));
        let (from, to) = (pick(&mut rng), pick(&mut rng));
        let options = PlanOptions {
            rotation: r,
            region: Some(Aabb {
                min: [0; 3],
                max: [side - 1; 3],
            }),
            ..PlanOptions::default()
        };
        let got = plan(&env, &obj, from, to, &options);
        match (free(from), free(to)) {
            (false, _) => {
                assert!(
                    matches!(got, Err(NoPath::StartBlocked { .. })),
                    "seed {seed}: {got:?}"
                );
                continue;
            }
            (true, false) => {
                assert!(
                    matches!(got, Err(NoPath::GoalBlocked { .. })),
                    "seed {seed}: {got:?}"
                );
                continue;
            }
            _ => {}
        }
        match dense_shortest(&free, from, to) {
            Some(cost) => {
                let p = got.unwrap_or_else(|e| panic!("seed {seed}: {e}"));
                assert_eq!(p.steps, cost, "seed {seed}: A* cost against dense Dijkstra");
                check_path(&p, &env_set, &vobj, r, bounds, seed);
                outcomes[0] += 1;
                if p.waypoints.len() < p.raw.len() {
                    outcomes[2] += 1;
                }
            }
            None => {
                assert!(
                    matches!(got, Err(NoPath::Unreachable { .. })),
                    "seed {seed}: {got:?}"
                );
                outcomes[1] += 1;
            }
        }
    }
    // Found paths, enclosed goals and actual smoothing all occur.
    assert!(
        outcomes[0] > 30 && outcomes[1] > 3 && outcomes[2] > 10,
        "{outcomes:?}"
    );
}

#[test]
fn no_path_says_why() {
    let mut walls = Vec::new();
    // A closed 8x8x8 box shell (outside 0..8), an object of one voxel inside.
    for x in 0..8 {
        for y in 0..8 {
            for z in 0..8 {
                if [x, y, z].iter().any(|&c| c == 0 || c == 7) {
                    walls.push([x, y, z]);
                }
            }
        }
    }
    let env = LinearOctree::from_voxels(4, [0, 0, 0], walls).unwrap();
    let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
    let o = PlanOptions {
        region: Some(Aabb {
            min: [0; 3],
            max: [15; 3],
        }),
        ..PlanOptions::default()
    };
    let e = plan(&env, &dot, [3, 3, 3], [12, 12, 12], &o).unwrap_err();
    assert!(
        matches!(
            e,
            NoPath::Unreachable {
                cells: _,
                positions: 216
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("no path"));
    assert!(matches!(
        plan(&env, &dot, [0, 3, 3], [4, 4, 4], &o),
        Err(NoPath::StartBlocked { overlap_voxels: 1 })
    ));
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [7, 4, 4], &o),
        Err(NoPath::GoalBlocked { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [16, 4, 4], &o),
        Err(NoPath::GoalOutOfBounds { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [-1, 3, 3], [4, 4, 4], &o),
        Err(NoPath::StartOutOfBounds { .. })
    ));
    let big = LinearOctree::full(5, [0, 0, 0]).unwrap();
    assert!(matches!(
        plan(&env, &big, [0; 3], [0; 3], &o),
        Err(NoPath::ObjectTooLarge)
    ));
    let empty = LinearOctree::empty(1, [0, 0, 0]).unwrap();
    assert!(matches!(
        plan(&env, &empty, [0; 3], [0; 3], &o),
        Err(NoPath::EmptyObject)
    ));
    // Inside the box a path exists, and start = goal is the empty move.
    // The default region is the bounding box: going around the outside needs a margin.
    let d = PlanOptions::default();
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [9, 3, 3], &d),
        Err(NoPath::Unreachable { .. })
    ));
    let around = PlanOptions {
        margin: 1,
        ..PlanOptions::default()
    };
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [9, 3, 3], &around),
        Err(NoPath::Unreachable { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [-1, 3, 3], [9, 3, 3], &d),
        Err(NoPath::Unreachable { .. })
    ));
    let p = plan(&env, &dot, [-1, 3, 3], [9, 3, 3], &around).unwrap();
    assert_eq!(p.steps, 10 + 2 * 4); // around the side: y from 3 to -1 and back
    assert_eq!(p.clearance, Some(0.0));
    let p = plan(&env, &dot, [1, 1, 1], [6, 6, 6], &o).unwrap();
    assert_eq!(p.steps, 15);
    assert_eq!(p.waypoints, vec![[1, 1, 1], [6, 6, 6]]);
    assert!((p.length - 75f64.sqrt()).abs() < 1e-9);
    assert_eq!(p.clearance, Some(0.0));
    let p = plan(&env, &dot, [2, 2, 2], [2, 2, 2], &o).unwrap();
    assert_eq!((p.steps, p.waypoints.len()), (0, 1));
    assert_eq!(p.clearance, Some(1.0));
}

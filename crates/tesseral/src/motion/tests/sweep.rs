//! The swept test (first contact) against brute force and sampling.

use super::*;

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
    let wall = thin_wall(20);
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

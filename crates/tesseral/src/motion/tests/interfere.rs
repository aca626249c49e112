//! Rotations, interference and clearance against brute force.

use super::*;

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

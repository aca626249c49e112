//! The face list: its order rule worked by hand, uniform sampling, and finds from
//! any node.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

#[test]
fn face_list_order_follows_the_contract() {
    // Worked by hand: insert a, then b to its +x, then remove a.
    let mut t = DynamicOctree::with_faces();
    t.insert([0, 0, 0]);
    t.insert([1, 0, 0]);
    // a's +x face (index 1) is swap-removed: a's +z face (index 5) moves there, then
    // b pushes −y, +y, −z, +z after the +x face (b's −x is covered).
    let face = |voxel, dir| Face { voxel, dir };
    let a = |dir| face([0, 0, 0], dir);
    let b = |dir| face([1, 0, 0], dir);
    use Direction::{NegX, NegY, NegZ, PosX, PosY, PosZ};
    let want = [
        a(NegX),
        a(PosZ),
        a(NegY),
        a(PosY),
        a(NegZ),
        b(PosX),
        b(NegY),
        b(PosY),
        b(NegZ),
        b(PosZ),
    ];
    assert_eq!(t.faces(), want);
    t.remove([0, 0, 0]);
    t.assert_valid();
    // Worked by hand through the six swap_removes and one push.
    assert_eq!(
        t.faces(),
        [b(PosZ), b(NegY), b(NegX), b(NegZ), b(PosY), b(PosX)]
    );
}

#[test]
fn random_face_is_uniform_chi_square() {
    let seed = 77;
    eprintln!("chi-square seed {seed}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = DynamicOctree::with_faces();
    // A random blob, with deletions so the list has been shuffled by swap_remove.
    for _ in 0..400 {
        let v = std::array::from_fn(|_| rng.random_range(-4..4));
        if rng.random_bool(0.7) {
            t.insert(v);
        } else {
            t.remove(v);
        }
    }
    t.assert_valid();
    let faces: Vec<Face> = t.faces();
    let n = faces.len();
    assert!(n > 50);
    let index: std::collections::HashMap<Face, usize> =
        faces.iter().enumerate().map(|(i, &f)| (f, i)).collect();
    let per = 200usize;
    let draws = per * n;
    let mut counts = vec![0usize; n];
    for _ in 0..draws {
        let f = t.random_face(&mut rng).unwrap();
        counts[index[&f]] += 1;
    }
    let e = per as f64;
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    let df = (n - 1) as f64;
    // Wilson–Hilferty: the 1e-6 upper tail of chi-square(df) is about
    // df·(1 − 2/(9df) + 4.75·sqrt(2/(9df)))³.
    let z = 4.75;
    let hi = df * (1.0 - 2.0 / (9.0 * df) + z * (2.0 / (9.0 * df)).sqrt()).powi(3);
    let lo = df * (1.0 - 2.0 / (9.0 * df) - z * (2.0 / (9.0 * df)).sqrt()).powi(3);
    assert!(
        chi2 < hi && chi2 > lo,
        "chi2 {chi2} df {df} outside [{lo}, {hi}]"
    );
}

#[test]
fn random_face_sampling_catches_a_biased_list() {
    // The same statistic rejects a sampler that never draws the last face: the test
    // above can fail.
    let n = 100usize;
    let per = 200usize;
    let mut rng = Pcg64::seed_from_u64(5);
    let mut counts = vec![0usize; n];
    for _ in 0..per * n {
        counts[rng.random_range(0..n - 1)] += 1;
    }
    let e = per as f64;
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    let df = (n - 1) as f64;
    let hi = df * (1.0 - 2.0 / (9.0 * df) + 4.75 * (2.0 / (9.0 * df)).sqrt()).powi(3);
    assert!(chi2 > hi);
}

#[test]
fn find_from_any_node_agrees_with_find_from_root() {
    let seed = 99;
    eprintln!("find_from seed {seed}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = DynamicOctree::new();
    for _ in 0..3000 {
        let v = std::array::from_fn(|_| rng.random_range(-200..200));
        t.insert(v);
    }
    for x in 0..16 {
        for y in 0..16 {
            for z in 0..16 {
                t.insert([x, y, z]);
            }
        }
    }
    t.assert_valid();
    let mut starts = Vec::new();
    for _ in 0..200 {
        let v = std::array::from_fn(|_| rng.random_range(-220..220));
        if let Some(o) = t.find(v) {
            starts.push(o);
        }
    }
    for _ in 0..5000 {
        let s = starts[rng.random_range(0..starts.len())];
        let v = std::array::from_fn(|_| rng.random_range(-230..230));
        let a = t.find_from(&s, v);
        let b = t.find(v);
        assert_eq!(
            a.map(|o| (o.min(), o.size_log2(), o.is_full())),
            b.map(|o| (o.min(), o.size_log2(), o.is_full()))
        );
        if let Some(a) = a {
            assert_eq!(a.is_full(), t.contains(v));
        }
    }
    // A stale handle is not trusted.
    let s = starts[0];
    t.insert([1000, 0, 0]);
    assert_eq!(
        t.find_from(&s, [1000, 0, 0]).map(|o| o.is_full()),
        Some(true)
    );
}

/// The exposed faces of a set of voxels, counted face by face.
fn naive_exposed(set: &HashSet<Voxel>) -> u64 {
    let open = |&v: &Voxel| {
        Direction::ALL
            .into_iter()
            .filter(move |d| !set.contains(&d.step(v)))
    };
    set.iter().flat_map(open).count() as u64
}

/// `exposed_faces` without the face list counts pairs piece by piece (inside a
/// block by popcounts, inside a full octant by its side, across each piece's
/// positive faces by lookups); against the faces of a `HashSet` counted one by one:
/// scattered, clustered and far-apart voxels, some removed again, voxels across the
/// wrapping edge of i64, and solids whose octants are stored full.
#[test]
fn exposed_faces_by_pieces_match_a_set_count() {
    let mut rng = Pcg64::seed_from_u64(24);
    for case in 0..80 {
        let spread = [3i64, 9, 40, 1 << 40][case % 4];
        let origin = match case % 5 {
            4 => [i64::MAX - 5, i64::MIN + 2, 7],
            _ => [0, 0, 0],
        };
        let (mut set, mut t) = (HashSet::new(), DynamicOctree::new());
        for k in 0..rng.random_range(1..500) {
            let v = [0, 1, 2].map(|a| origin[a].wrapping_add(rng.random_range(-spread..spread)));
            if k % 4 == 3 {
                assert_eq!(t.remove(v), set.remove(&v));
            } else {
                assert_eq!(t.insert(v), set.insert(v));
            }
        }
        t.assert_valid();
        let want = naive_exposed(&set);
        assert_eq!(t.exposed_faces(), want, "case {case}");
        assert!(t.exposed_faces_work() <= 3 * t.voxel_count());
        let mut tracked = DynamicOctree::with_faces();
        set.iter().for_each(|&v| assert!(tracked.insert(v)));
        assert_eq!(tracked.exposed_faces(), want, "case {case}, face list");
    }
    // Boxes, some touching: whole octants are stored full.
    for case in 0..20 {
        let mut set = HashSet::new();
        for _ in 0..rng.random_range(1..4) {
            let lo: [i64; 3] = [0, 1, 2].map(|_| rng.random_range(-20..20));
            let side: [i64; 3] = [0, 1, 2].map(|_| rng.random_range(1..33));
            for x in 0..side[0] {
                for y in 0..side[1] {
                    for z in 0..side[2] {
                        set.insert([lo[0] + x, lo[1] + y, lo[2] + z]);
                    }
                }
            }
        }
        let t = DynamicOctree::from_voxels(set.iter().copied());
        t.assert_valid();
        assert_eq!(t.exposed_faces(), naive_exposed(&set), "box case {case}");
    }
    // A solid octant of 2^18 voxels costs lookups on its faces only.
    let lin = LinearOctree::from_voxels(
        6,
        [0, 0, 0],
        (0..64 * 64 * 64).map(|i| [i % 64, i / 64 % 64, i / 4096]),
    )
    .unwrap();
    let t = DynamicOctree::from_linear(&lin);
    assert_eq!(t.exposed_faces(), 6 * 64 * 64);
    assert_eq!(t.exposed_faces_work(), 3 * 64 * 64);
}

//! Tests of the dynamic octree against naive models: a `HashSet` of voxels for
//! occupancy, and a dense `Vec<Face>` with linear search that applies the face-list
//! order rule literally.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

/// The face-list rule of the contract, applied to a plain `Vec` with linear search.
#[derive(Default)]
struct Model {
    set: HashSet<Voxel>,
    faces: Vec<Face>,
}

impl Model {
    fn remove_face(&mut self, f: Face) {
        let i = self.faces.iter().position(|&g| g == f).expect("model face");
        self.faces.swap_remove(i);
    }
    fn insert(&mut self, v: Voxel) -> bool {
        if !self.set.insert(v) {
            return false;
        }
        for dir in 0..6u8 {
            let n = step(v, dir);
            if self.set.contains(&n) {
                self.remove_face(Face {
                    voxel: n,
                    dir: opposite(dir),
                });
            } else {
                self.faces.push(Face { voxel: v, dir });
            }
        }
        true
    }
    fn remove(&mut self, v: Voxel) -> bool {
        if !self.set.remove(&v) {
            return false;
        }
        for dir in 0..6u8 {
            let n = step(v, dir);
            if self.set.contains(&n) {
                self.faces.push(Face {
                    voxel: n,
                    dir: opposite(dir),
                });
            } else {
                self.remove_face(Face { voxel: v, dir });
            }
        }
        true
    }
    fn neighbourhood(&self, v: Voxel) -> u32 {
        let mut r = 0;
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let n = [
                        v[0].wrapping_add(dx),
                        v[1].wrapping_add(dy),
                        v[2].wrapping_add(dz),
                    ];
                    if self.set.contains(&n) {
                        r |= 1 << ((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1));
                    }
                }
            }
        }
        r
    }
}

fn check_against(t: &DynamicOctree, m: &Model, probes: &[Voxel]) {
    assert_eq!(t.voxel_count(), m.set.len() as u64);
    for &p in probes {
        assert_eq!(t.contains(p), m.set.contains(&p), "contains {p:?}");
        assert_eq!(
            t.neighbourhood(p),
            m.neighbourhood(p),
            "neighbourhood {p:?}"
        );
    }
    if t.tracks_faces() {
        assert_eq!(t.faces(), m.faces, "face list order");
    }
}

/// Random create/delete sequences in a box `[lo, lo + side)³`, checked after every
/// operation.
fn random_ops(seed: u64, lo: Voxel, side: i64, steps: usize, p_insert: f64, faces: bool) {
    random_ops_in(seed, lo, side, steps, p_insert, faces, !faces);
}

/// [`random_ops`] with the block form chosen: `small` makes new blocks start small
/// (the default without faces), otherwise they are bitmaps (the default with faces).
fn random_ops_in(
    seed: u64,
    lo: Voxel,
    side: i64,
    steps: usize,
    p_insert: f64,
    faces: bool,
    small: bool,
) {
    eprintln!("random_ops seed {seed} lo {lo:?} side {side} faces {faces} small {small}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = if faces {
        DynamicOctree::with_faces()
    } else {
        DynamicOctree::new()
    };
    t.set_small_blocks(small);
    let mut m = Model::default();
    let pick = |rng: &mut Pcg64| -> Voxel {
        std::array::from_fn(|a| lo[a].wrapping_add(rng.random_range(0..side)))
    };
    for step_no in 0..steps {
        let v = if !m.set.is_empty() && rng.random_bool(0.3) {
            // hit an existing voxel or its neighbour so deletions and contacts happen
            let i = rng.random_range(0..m.set.len());
            let w = *m.set.iter().nth(i).unwrap();
            step(w, rng.random_range(0..6))
        } else {
            pick(&mut rng)
        };
        // Every other step goes through the variants that take the neighbourhood
        // from the caller (as the RS/MC chain does).
        let known = step_no % 2 == 1;
        let nb = t.neighbourhood(v);
        if rng.random_bool(p_insert) {
            let got = if known {
                t.insert_with_neighbourhood(v, nb)
            } else {
                t.insert(v)
            };
            assert_eq!(got, m.insert(v), "insert {v:?} at step {step_no}");
        } else {
            let got = if known {
                t.remove_with_neighbourhood(v, nb)
            } else {
                t.remove(v)
            };
            assert_eq!(got, m.remove(v), "remove {v:?} at step {step_no}");
        }
        t.assert_valid();
        let probes: Vec<Voxel> = (0..4)
            .map(|_| pick(&mut rng))
            .chain([v, step(v, 0), step(v, 5)])
            .collect();
        check_against(&t, &m, &probes);
    }
    let mut got = t.voxels();
    let mut want: Vec<Voxel> = m.set.iter().copied().collect();
    got.sort_unstable();
    want.sort_unstable();
    assert_eq!(got, want);
}

#[test]
fn random_sequences_small_dense_box_with_faces() {
    for seed in 0..6 {
        random_ops(seed, [-5, -3, -8], 12, 1500, 0.7, true);
    }
}

#[test]
fn random_sequences_sparse_box_with_faces() {
    for seed in 10..13 {
        random_ops(seed, [-300, -40, 7], 400, 800, 0.6, true);
    }
}

#[test]
fn random_sequences_without_faces() {
    for seed in 20..24 {
        random_ops(seed, [-20, -20, -20], 40, 1500, 0.65, false);
    }
}

#[test]
fn random_sequences_with_the_other_block_form() {
    // Faces over small blocks, and bitmap blocks without faces.
    for seed in 30..33 {
        random_ops_in(seed, [-6, -6, -6], 14, 1200, 0.7, true, true);
        random_ops_in(seed, [-20, -20, -20], 40, 1200, 0.65, false, false);
    }
    // Sparse: most blocks stay small, some are promoted, all are released again.
    random_ops_in(34, [-100, -100, -100], 200, 2000, 0.55, true, true);
}

#[test]
fn small_blocks_grow_into_bitmaps_and_go_away() {
    let mut t = DynamicOctree::new();
    let cells: Vec<Voxel> = (0..12).map(|i| [i % 8, i / 8, 3]).collect();
    // The first block is the root (a bitmap); its corner makes the blocks world-aligned.
    t.insert([-1024, -1024, -1024]);
    for (n, &c) in cells.iter().enumerate() {
        assert!(t.insert(c));
        assert!(!t.insert(c));
        t.assert_valid();
        let small = t.small.live();
        let bitmaps = t.leaves.live();
        // Up to eight voxels the new block is small; the ninth makes it a bitmap.
        if n < SMALL_CAP {
            assert_eq!((small, bitmaps), (1, 1), "after {} voxels", n + 1);
        } else {
            assert_eq!((small, bitmaps), (0, 2), "after {} voxels", n + 1);
        }
        for &d in &cells {
            assert_eq!(t.contains(d), cells[..=n].contains(&d));
        }
    }
    for (n, &c) in cells.iter().enumerate() {
        assert!(t.remove(c));
        assert!(!t.remove(c));
        t.assert_valid();
        // Down to four voxels the bitmap turns small again; the last one frees it.
        let left = cells.len() - n - 1;
        let forms = (t.small.live(), t.leaves.live());
        let want = match left {
            0 => (0, 1),
            1..=4 => (1, 1),
            _ => (0, 2),
        };
        assert_eq!(forms, want, "with {left} voxels left");
        for &d in &cells {
            assert_eq!(t.contains(d), cells[n + 1..].contains(&d));
        }
    }
    assert_eq!(t.voxel_count(), 1);
    assert_eq!(t.node_count(), 1); // the far voxel's block, the root again
    assert_eq!(t.small.live(), 0);
}

#[test]
fn the_root_contracts_onto_a_small_block() {
    let mut t = DynamicOctree::new();
    t.insert([1, 2, 3]);
    t.insert([4, 2, 3]);
    t.insert([1 << 20, 0, 0]);
    t.assert_valid();
    assert!(t.small.live() >= 1);
    t.remove([1 << 20, 0, 0]);
    t.assert_valid();
    assert!(t.root_size_log2() <= 3);
    assert!(t.contains([1, 2, 3]) && t.contains([4, 2, 3]));
    assert!(!t.contains([2, 2, 3]));
    // The root block shifts inside itself when it grows and shrinks again.
    t.insert([-3, 2, 3]);
    t.remove([4, 2, 3]);
    t.assert_valid();
    assert_eq!(t.voxels(), vec![[-3, 2, 3], [1, 2, 3]]);
}

#[test]
fn the_directory_follows_a_large_tree_up_and_down() {
    let mut rng = Pcg64::seed_from_u64(77);
    let mut t = DynamicOctree::new();
    let mut m: HashSet<Voxel> = HashSet::new();
    let mut deepest = 0;
    let cells: Vec<Voxel> = (0..40_000)
        .map(|_| std::array::from_fn(|_| rng.random_range(-256..256)))
        .collect();
    for (i, &c) in cells.iter().enumerate() {
        assert_eq!(t.insert(c), m.insert(c));
        deepest = deepest.max(t.dir_levels);
        if i % 10_000 == 0 {
            t.assert_valid();
        }
    }
    t.assert_valid();
    assert!(deepest >= 5, "directory skipped only {deepest} levels");
    for _ in 0..20_000 {
        let q: Voxel = std::array::from_fn(|_| rng.random_range(-260..260));
        assert_eq!(t.contains(q), m.contains(&q), "{q:?}");
    }
    // Drain in random order: the directory shrinks with the tree.
    let mut order: Vec<Voxel> = m.iter().copied().collect();
    order.sort_unstable();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    for (i, &c) in order.iter().enumerate() {
        assert!(t.remove(c));
        m.remove(&c);
        if i % 5_000 == 0 || m.len() < 50 {
            t.assert_valid();
            for &d in order.iter().skip(i).take(20) {
                assert_eq!(t.contains(d), m.contains(&d));
            }
        }
    }
    assert!(t.is_empty());
    assert_eq!(t.dir_levels, 0);
    assert_eq!(t.node_count(), 0);
}

#[test]
fn random_sequences_near_two_to_the_62() {
    let e = 1i64 << 62;
    for (seed, lo) in [
        (30, [e - 6, -e - 6, 0]),
        (31, [-e - 3, e - 3, e - 3]),
        (32, [i64::MAX - 10, i64::MIN, 0]),
    ] {
        random_ops(seed, lo, 12, 600, 0.6, true);
    }
}

#[test]
fn far_apart_voxels_near_two_to_the_62() {
    let e = 1i64 << 62;
    let pts = [
        [e, -e, 0],
        [-e, e, 5],
        [e + 1, -e, 0],
        [0, 0, 0],
        [-e, -e, -e],
        [i64::MAX, i64::MIN, 1],
        [i64::MIN, i64::MAX, -1],
    ];
    let mut t = DynamicOctree::with_faces();
    let mut m = Model::default();
    for p in pts {
        assert!(t.insert(p));
        m.insert(p);
        t.assert_valid();
        check_against(&t, &m, &pts);
    }
    assert_eq!(t.root_size_log2(), 64);
    assert_eq!(t.face_count(), 6 * 7 - 2);
    for p in pts {
        assert!(t.remove(p));
        m.remove(p);
        t.assert_valid();
        check_against(&t, &m, &pts);
    }
    assert!(t.is_empty());
    assert_eq!(t.node_count(), 0);
}

#[test]
fn clusters_at_the_ends_of_the_i64_range_with_the_directory() {
    // A 2^64 root with thousands of blocks: the directory skips six levels, and the
    // clusters sit where offsets wrap.
    let mut rng = Pcg64::seed_from_u64(62);
    let centres = [
        [i64::MIN, i64::MIN, i64::MIN],
        [i64::MAX, 0, i64::MAX],
        [0, 0, 0],
    ];
    let mut t = DynamicOctree::new();
    let mut m: HashSet<Voxel> = HashSet::new();
    let mut cells = Vec::new();
    for (k, c) in centres.iter().cycle().take(6000).enumerate() {
        let v: Voxel = std::array::from_fn(|a| c[a].wrapping_add(rng.random_range(-200..200)));
        cells.push(v);
        assert_eq!(t.insert(v), m.insert(v));
        if k % 1000 == 999 {
            t.assert_valid();
        }
    }
    assert_eq!(t.root_size_log2(), 64);
    assert!(t.dir_levels >= 4, "directory skips {} levels", t.dir_levels);
    for _ in 0..5000 {
        let c = centres[rng.random_range(0..3)];
        let q: Voxel = std::array::from_fn(|a| c[a].wrapping_add(rng.random_range(-210..210)));
        assert_eq!(t.contains(q), m.contains(&q), "{q:?}");
    }
    for (k, v) in cells.iter().enumerate() {
        assert_eq!(t.remove(*v), m.remove(v));
        if k % 1000 == 999 {
            t.assert_valid();
        }
    }
    assert!(t.is_empty());
    t.assert_valid();
}

#[test]
fn string_to_two_to_the_60_costs_sixty_expansions() {
    // Libes §5: "a surface that grows from a single voxel to a long string of 2^60
    // voxels will only cause octree expansion to occur sixty times".
    let mut t = DynamicOctree::new();
    t.insert([0, 0, 0]);
    assert_eq!((t.root_size_log2(), t.expansions()), (0, 0));
    for i in 0..60 {
        t.insert([1 << i, 0, 0]);
        t.insert([(1 << i) + (1 << i) / 2, 0, 0]);
        assert_eq!(t.expansions(), i + 1);
        t.assert_valid();
    }
    t.insert([(1 << 60) - 1, 0, 0]);
    assert_eq!(t.expansions(), 60);
    assert_eq!(t.root_size_log2(), 60);
    assert_eq!(t.root_min(), [0, 0, 0]);
    assert_eq!(t.contractions(), 0);
    t.insert([1 << 60, 0, 0]);
    assert_eq!(t.expansions(), 61);
    // And back: removing the far end shrinks the root again.
    t.remove([1 << 60, 0, 0]);
    assert_eq!(t.root_size_log2(), 60);
    assert_eq!(t.contractions(), 1);
    t.assert_valid();
}

#[test]
fn negative_growth_and_contraction_to_one_voxel() {
    let mut t = DynamicOctree::new();
    t.insert([0, 0, 0]);
    t.insert([-1, 0, 0]);
    assert_eq!((t.root_size_log2(), t.root_min()), (1, [-1, 0, 0]));
    t.insert([-3, -5, 9]);
    t.assert_valid();
    assert_eq!(t.root_size_log2(), 4);
    t.remove([0, 0, 0]);
    t.remove([-1, 0, 0]);
    t.assert_valid();
    assert_eq!((t.root_size_log2(), t.root_min()), (0, [-3, -5, 9]));
    assert_eq!(t.node_count(), 1);
    t.remove([-3, -5, 9]);
    assert!(t.is_empty());
    t.assert_valid();
}

#[test]
fn full_octants_are_implicit() {
    let mut t = DynamicOctree::with_faces();
    let mut m = Model::default();
    for x in -8..8 {
        for y in -8..8 {
            for z in -8..8 {
                t.insert([x, y, z]);
                m.insert([x, y, z]);
            }
        }
    }
    t.assert_valid();
    // A 16³ cube aligned to the root: the root itself is one full slot.
    assert_eq!(t.node_count(), 0);
    assert_eq!(t.root_size_log2(), 4);
    assert_eq!(t.face_count(), 6 * 16 * 16);
    let o = t.find([0, 0, 0]).unwrap();
    assert!(o.is_full());
    assert_eq!((o.min(), o.size_log2()), ([-8, -8, -8], 4));
    // Deleting one voxel instantiates the path down to its block only.
    t.remove([0, 0, 0]);
    m.remove([0, 0, 0]);
    t.assert_valid();
    assert_eq!(t.node_count(), 2);
    check_against(
        &t,
        &m,
        &[[0, 0, 0], [1, 0, 0], [-1, -1, -1], [7, 7, 7], [8, 0, 0]],
    );
    t.insert([0, 0, 0]);
    m.insert([0, 0, 0]);
    t.assert_valid();
    assert_eq!(t.node_count(), 0);
    check_against(&t, &m, &[[0, 0, 0], [8, 8, 8], [-9, 0, 0]]);
}

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
    let want = [a(0), a(5), a(2), a(3), a(4), b(1), b(2), b(3), b(4), b(5)];
    assert_eq!(t.faces(), want);
    t.remove([0, 0, 0]);
    t.assert_valid();
    // Worked by hand through the six swap_removes and one push.
    assert_eq!(t.faces(), [b(5), b(2), b(0), b(4), b(3), b(1)]);
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

#[test]
fn conversions_to_and_from_voxel_lists() {
    let mut rng = Pcg64::seed_from_u64(3);
    let vs: Vec<Voxel> = (0..2000)
        .map(|_| std::array::from_fn(|_| rng.random_range(-1000..1000)))
        .collect();
    let t = DynamicOctree::from_voxels(vs.iter().copied());
    t.assert_valid();
    let mut got = t.voxels();
    let mut want = vs.clone();
    want.sort_unstable();
    want.dedup();
    got.sort_unstable();
    assert_eq!(got, want);
    let u: DynamicOctree = got.iter().copied().collect();
    assert_eq!(u.voxel_count(), want.len() as u64);
}

#[test]
fn memory_per_voxel_is_small_for_random_cells() {
    // Not a timing test: a structural bound. 20,000 random cells in a 128³ box.
    let mut rng = Pcg64::seed_from_u64(4);
    let mut t = DynamicOctree::new();
    for _ in 0..20_000 {
        t.insert(std::array::from_fn(|_| rng.random_range(-64..64)));
    }
    t.shrink_to_fit();
    let per = t.bytes() as f64 / t.voxel_count() as f64;
    assert!(per < 30.0, "{per} bytes per voxel");
}

#[test]
fn fill_then_drain_a_block_in_random_order() {
    // Full octants appear and are split again; every operation is checked.
    for (seed, lo, side) in [
        (40u64, [-4i64, -4, -4], 12i64),
        (41, [0, 0, 0], 8),
        (42, [-9, 3, 5], 10),
    ] {
        eprintln!("fill/drain seed {seed}");
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut cells: Vec<Voxel> = Vec::new();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    cells.push([lo[0] + x, lo[1] + y, lo[2] + z]);
                }
            }
        }
        let mut t = DynamicOctree::with_faces();
        let mut m = Model::default();
        for round in 0..2 {
            for i in (1..cells.len()).rev() {
                cells.swap(i, rng.random_range(0..=i));
            }
            for &c in &cells {
                if round == 0 {
                    assert_eq!(t.insert(c), m.insert(c));
                } else {
                    assert_eq!(t.remove(c), m.remove(c));
                }
                t.assert_valid();
                check_against(
                    &t,
                    &m,
                    &[c, step(c, 1), step(c, 2), [lo[0] + 3, lo[1] + 3, lo[2] + 3]],
                );
            }
            if round == 0 {
                assert_eq!(t.face_count() as i64, 6 * side * side);
            }
        }
        assert!(t.is_empty());
        assert_eq!(t.node_count(), 0);
    }
}

#[test]
fn voxel_table_matches_a_hashmap() {
    // Small key range so probe runs collide, wrap around and get backward-shifted.
    // The table keeps hashes and values; the keys live in `keys[value]`.
    let seed = 17;
    eprintln!("voxel table seed {seed}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = faces::VoxelTable::default();
    let mut keys: Vec<Voxel> = Vec::new();
    let mut m = std::collections::HashMap::new();
    for _ in 0..20_000u32 {
        let k: Voxel = std::array::from_fn(|_| rng.random_range(-6..6));
        match rng.random_range(0..3) {
            0 => {
                let got = t.get(k, |v| keys[v as usize]);
                assert_eq!(got, m.get(&k).copied());
                if got.is_none() {
                    keys.push(k);
                    let v = (keys.len() - 1) as u32;
                    t.insert(k, v);
                    m.insert(k, v);
                }
            }
            1 => assert_eq!(t.remove(k, |v| keys[v as usize]), m.remove(&k)),
            _ => assert_eq!(t.get(k, |v| keys[v as usize]), m.get(&k).copied()),
        }
        assert_eq!(t.len(), m.len());
    }
    let mut a: Vec<u32> = t.values().collect();
    let mut b: Vec<u32> = m.values().copied().collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    t.shrink_to_fit();
    for (k, v) in m {
        assert_eq!(t.get(k, |v| keys[v as usize]), Some(v));
    }
}

/// A random solid with some full octants: random voxels plus a few filled cubes.
fn random_solid(rng: &mut Pcg64, lo: i64, side: i64) -> HashSet<Voxel> {
    let mut set = HashSet::new();
    for _ in 0..rng.random_range(0..400) {
        set.insert(std::array::from_fn(|_| lo + rng.random_range(0..side)));
    }
    for _ in 0..3 {
        let c: Voxel = std::array::from_fn(|_| lo + rng.random_range(0..side));
        let s = rng.random_range(1..12);
        for x in 0..s {
            for y in 0..s {
                for z in 0..s {
                    let v = [c[0] + x, c[1] + y, c[2] + z];
                    if (0..3).all(|a| v[a] < lo + side) {
                        set.insert(v);
                    }
                }
            }
        }
    }
    set
}

#[test]
fn linear_round_trip_and_windows_match_the_model() {
    use crate::linear::LinearOctree;
    for seed in 50..62u64 {
        eprintln!("linear seed {seed}");
        let mut rng = Pcg64::seed_from_u64(seed);
        let lo = rng.random_range(-40..10);
        let set = random_solid(&mut rng, lo, 32);
        let t = DynamicOctree::from_voxels(set.iter().copied());
        t.assert_valid();
        // A window that holds everything, on a grid not aligned with the tree's.
        let origin = [lo - 3, lo - 1, lo - 2];
        let lin = t.to_linear(6, origin).unwrap();
        lin.assert_valid();
        let want = LinearOctree::from_voxels(6, origin, set.iter().copied()).unwrap();
        assert_eq!(lin, want);
        // Back again.
        let back = DynamicOctree::from_linear(&lin);
        back.assert_valid();
        let mut a = back.voxels();
        let mut b: Vec<Voxel> = set.iter().copied().collect();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
        // A window that cuts the solid.
        let o2: Voxel = std::array::from_fn(|_| lo + rng.random_range(0..24));
        let d2 = rng.random_range(0..5u8);
        let cut = t.to_linear(d2, o2).unwrap();
        let side = 1i64 << d2;
        let want = LinearOctree::from_voxels(
            d2,
            o2,
            set.iter()
                .copied()
                .filter(|v| (0..3).all(|a| v[a] >= o2[a] && v[a] < o2[a] + side)),
        )
        .unwrap();
        assert_eq!(cut, want);
        // Every cell class agrees with the model on random cubes.
        for _ in 0..200 {
            let m: Voxel = std::array::from_fn(|_| lo - 4 + rng.random_range(0..40));
            let k = rng.random_range(0..4u8);
            let s = 1i64 << k;
            let mut black = 0;
            for x in 0..s {
                for y in 0..s {
                    for z in 0..s {
                        black += i64::from(set.contains(&[m[0] + x, m[1] + y, m[2] + z]));
                    }
                }
            }
            let want = if black == 0 {
                crate::linear::CellClass::Outside
            } else if black == s * s * s {
                crate::linear::CellClass::Inside
            } else {
                crate::linear::CellClass::Partial
            };
            assert_eq!(t.classify(m, k), want, "cube {m:?} size 2^{k}");
        }
    }
}

#[test]
fn linear_conversion_of_big_solids_and_far_coordinates() {
    use crate::linear::LinearOctree;
    // A 2^20 cube costs one full slot each way.
    let e = 1i64 << 62;
    let lin = LinearOctree::from_sorted_leaves(20, [-e, 5, e], [crate::linear::Leaf::new(0, 20)])
        .unwrap();
    let t = DynamicOctree::from_linear(&lin);
    t.assert_valid();
    assert_eq!(t.voxel_count(), 1 << 60);
    assert_eq!(t.node_count(), 0);
    assert!(t.contains([-e + 12345, 5 + 777, e + (1 << 20) - 1]));
    assert!(!t.contains([-e - 1, 5, e]));
    assert_eq!(t.to_linear(20, [-e, 5, e]).unwrap(), lin);
    // A window shifted by one voxel: the cube is cut and misaligned.
    let w = t.to_linear(3, [-e - 1, 4, e - 1]).unwrap();
    assert_eq!(w.voxel_count(), 7 * 7 * 7);
    // Small depths use the logical root inside one block.
    for depth in 0..4u8 {
        let vs = [[-3, 0, 0], [-3 + (1 << depth) - 1, 0, 0]];
        let lin = LinearOctree::from_voxels(depth, [-3, 0, 0], vs).unwrap();
        let t = DynamicOctree::from_linear(&lin);
        t.assert_valid();
        assert!(vs.iter().all(|&v| t.contains(v)));
        assert_eq!(t.voxel_count(), lin.voxel_count());
    }
}

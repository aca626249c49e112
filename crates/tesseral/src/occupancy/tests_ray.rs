//! The fast ray walk of a scan's scratch against the reference walk.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::ray::{walk, Scratch};

fn key(p: [f64; 3], res: f64) -> [i64; 3] {
    let inv = 1.0 / res;
    p.map(|c| (c * inv).floor() as i64)
}

/// Every missed cell of a scratch.
fn missed(s: &Scratch) -> HashSet<[i64; 3]> {
    let mut out = HashSet::new();
    for m in &s.blocks {
        for (z, &w) in m.miss.iter().enumerate() {
            for bit in 0..64 {
                if w >> bit & 1 == 1 {
                    out.insert([
                        m.key[0] * 8 + (bit & 7),
                        m.key[1] * 8 + (bit >> 3),
                        m.key[2] * 8 + z as i64,
                    ]);
                }
            }
        }
    }
    out
}

#[test]
fn fast_walk_marks_the_cells_of_the_reference_walk() {
    let mut rng = Pcg64::seed_from_u64(11);
    for case in 0..4000 {
        let res = [0.25, 0.05, 0.125, 1.0][case % 4];
        // Long rays (up to 400 cells: many blocks, inside and beyond the dense
        // index), dyadic coordinates (faces, edges, corners, ties between axes),
        // axis-parallel rays, negative keys, origins far from zero.
        let span = res * [4.0, 40.0, 400.0][case % 3];
        let shift = [0.0, -1.0e4, 3.3e5][case % 3] * res;
        let snap = |rng: &mut Pcg64, v: f64| {
            if rng.random_range(0..3) == 0 {
                (v / res * 4.0).round() * res / 4.0
            } else {
                v
            }
        };
        let o = [0, 1, 2].map(|_| {
            let v = rng.random_range(-res * 8.0..res * 8.0);
            snap(&mut rng, v) + shift
        });
        let mut e = [0, 1, 2].map(|i| {
            let v = rng.random_range(-span..span);
            snap(&mut rng, v) + o[i]
        });
        if case % 7 == 0 {
            let a = rng.random_range(0..3);
            for b in 0..3 {
                if b != a {
                    e[b] = o[b];
                }
            }
        }
        let (ko, ke) = (key(o, res), key(e, res));
        let mut want = HashSet::new();
        walk(o, e, ko, ke, res, |c| {
            want.insert(c);
        });
        // The dense index centred on the ray's block, or far from it.
        let centre = if case % 2 == 0 {
            ko.map(|c| c >> 3)
        } else {
            ko.map(|c| (c >> 3) + 40)
        };
        let mut s = Scratch::new(centre);
        s.miss_ray(o, e, ko, ke, res);
        assert_eq!(missed(&s), want, "case {case}: {o:?} -> {e:?} at {res}");
    }
}

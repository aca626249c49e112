//! The fast ray walk of a scan's scratch against the reference walk.

use std::collections::HashSet;
use std::sync::atomic::Ordering;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::dda::{exit_block, walk, walk_from, Dda, JUMPS, RUN_JUMPS};
use super::ray::Scratch;

fn key(p: [f64; 3], res: f64) -> [i64; 3] {
    let inv = 1.0 / res;
    p.map(|c| (c * inv).floor() as i64)
}

/// Every missed cell of a scratch.
fn missed(s: &Scratch) -> HashSet<[i64; 3]> {
    let mut out = HashSet::new();
    for (i, key) in s.keys().iter().enumerate() {
        for (z, &w) in s.miss(i).iter().enumerate() {
            for bit in 0..64 {
                if w >> bit & 1 == 1 {
                    out.insert([
                        key[0] * 8 + (bit & 7),
                        key[1] * 8 + (bit >> 3),
                        key[2] * 8 + z as i64,
                    ]);
                }
            }
        }
    }
    out
}

/// A random ray for case `case`: its resolution, origin and end. Long rays (up to
/// 400 cells: many blocks, inside and beyond the dense index), dyadic coordinates
/// (faces, edges, corners, ties between axes), negative keys, origins far from zero.
fn random_ray(rng: &mut Pcg64, case: usize) -> (f64, [f64; 3], [f64; 3]) {
    let res = [0.25, 0.05, 0.125, 1.0][case % 4];
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
        snap(rng, v) + shift
    });
    let e = [0, 1, 2].map(|i| {
        let v = rng.random_range(-span..span);
        snap(rng, v) + o[i]
    });
    (res, o, e)
}

#[test]
fn fast_walk_marks_the_cells_of_the_reference_walk() {
    let mut rng = Pcg64::seed_from_u64(11);
    for case in 0..4000 {
        let (res, o, mut e) = random_ray(&mut rng, case);
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
        let mut s = Scratch::new(centre, None);
        s.miss_ray(o, e, ko, ke, res);
        assert_eq!(missed(&s), want, "case {case}: {o:?} -> {e:?} at {res}");
    }
}

/// The walk's own steps from a cell of a block to the step out of it: the axis, the
/// steps along each axis, the ray parameters after.
fn steps_out(
    mut t: [f64; 3],
    d: [f64; 3],
    step: [i64; 3],
    mut c: [i64; 3],
) -> (usize, [i64; 3], [f64; 3]) {
    let mut n = [0i64; 3];
    loop {
        // The reference walk's choice, ties included.
        let dim = if t[0] < t[1] {
            if t[0] < t[2] {
                0
            } else {
                2
            }
        } else if t[1] < t[2] {
            1
        } else {
            2
        };
        n[dim] += 1;
        t[dim] += d[dim];
        c[dim] += step[dim];
        if !(0..8).contains(&c[dim]) {
            return (dim, n, t);
        }
    }
}

#[test]
fn exit_block_takes_the_steps_of_the_walk() {
    let mut rng = Pcg64::seed_from_u64(12);
    let mut ties = 0;
    for case in 0..200_000 {
        let step = [0, 1, 2].map(|_| [-1i64, 1, 0][rng.random_range(0..3)]);
        if step == [0; 3] {
            continue;
        }
        // Deltas and starts on a coarse dyadic grid in a third of the cases, so that
        // borders of different axes often fall on one parameter.
        let coarse = case % 3 == 0;
        let d = [0, 1, 2].map(|i| {
            if step[i] == 0 {
                f64::MAX
            } else if coarse {
                f64::from(rng.random_range(1..8u32)) / 4.0
            } else {
                rng.random_range(0.05..3.0)
            }
        });
        let t = [0, 1, 2].map(|i| {
            if step[i] == 0 {
                f64::MAX
            } else if coarse {
                f64::from(rng.random_range(0..16u32)) / 8.0
            } else {
                rng.random_range(0.0..d[i])
            }
        });
        let c = [0, 1, 2].map(|_| rng.random_range(0..8i64));
        let want = steps_out(t, d, step, c);
        let got = exit_block(t, d, step, c);
        assert_eq!(got.0, want.0, "case {case}: axis");
        assert_eq!(got.1, want.1, "case {case}: steps");
        assert_eq!(
            got.2.map(f64::to_bits),
            want.2.map(f64::to_bits),
            "case {case}: parameters"
        );
        let e = [0, 1, 2].map(|i| want.2[i] - d[i]);
        if (0..3).any(|i| i != want.0 && step[i] != 0 && e[i] == e[want.0]) {
            ties += 1;
        }
    }
    assert!(ties > 1000, "ties at the exit were exercised ({ties})");
}

#[test]
fn jumps_over_full_blocks_keep_the_cells_of_the_reference_walk() {
    let mut rng = Pcg64::seed_from_u64(13);
    let before = JUMPS.load(Ordering::Relaxed);
    let runs_before = RUN_JUMPS.load(Ordering::Relaxed);
    for case in 0..4000 {
        let (res, o, mut e) = random_ray(&mut rng, case);
        match case % 7 {
            // Along an axis.
            0 => {
                let a = rng.random_range(0..3);
                for b in 0..3 {
                    if b != a {
                        e[b] = o[b];
                    }
                }
            }
            // Zero length.
            1 if case % 5 == 0 => e = o,
            _ => {}
        }
        let (ko, ke) = (key(o, res), key(e, res));
        let mut path = Vec::new();
        walk(o, e, ko, ke, res, |c| path.push(c));
        // Fill some of the blocks the walk crosses (the first, the last, the one
        // holding the end cell, others at random: a third, most or all of them, so
        // that rays cross runs of full blocks) before the ray is cast.
        let fill = [3, 8, 10][case % 3];
        let mut blocks: Vec<[i64; 3]> = path.iter().map(|c| c.map(|k| k >> 3)).collect();
        blocks.dedup();
        blocks.push(ke.map(|k| k >> 3));
        let mut s = Scratch::new(ko.map(|c| c >> 3), None);
        let mut want: HashSet<[i64; 3]> = path.iter().copied().collect();
        for (i, b) in blocks.iter().enumerate() {
            if i == 0 || i + 1 == blocks.len() || rng.random_range(0..10) < fill {
                s.fill(*b);
                for bit in 0..512 {
                    want.insert([
                        b[0] * 8 + (bit & 7),
                        b[1] * 8 + (bit >> 3 & 7),
                        b[2] * 8 + (bit >> 6),
                    ]);
                }
            }
        }
        s.miss_ray(o, e, ko, ke, res);
        assert_eq!(missed(&s), want, "case {case}: {o:?} -> {e:?} at {res}");
    }
    assert!(
        JUMPS.load(Ordering::Relaxed) > before + 4000,
        "the jumps were taken"
    );
    let runs = RUN_JUMPS.load(Ordering::Relaxed) - runs_before;
    assert!(
        runs > 20_000,
        "runs of full blocks were crossed ({runs} blocks)"
    );
}

/// A scratch's slots against a map from block to hit cells: one slot per block, in
/// the dense index, in the hash index of packed offsets (up to and past its 2^20
/// blocks either way, where keys would collide if an offset were cut short), and
/// beyond it, to blocks near both ends of the key range.
#[test]
fn a_scratch_holds_one_slot_per_block_near_far_and_beyond_packing() {
    let mut rng = Pcg64::seed_from_u64(21);
    for round in 0..20 {
        let centre = [0, 1, 2].map(|_| rng.random_range(-1000i64..1000));
        let mut s = Scratch::new(centre, None);
        let mut want: std::collections::HashMap<[i64; 3], HashSet<i64>> =
            std::collections::HashMap::new();
        for _ in 0..3000 {
            let b: [i64; 3] = [0, 1, 2].map(|i| {
                let p = 1i64 << 20;
                let off = match rng.random_range(0..5) {
                    0 => rng.random_range(-40..40),
                    1 => rng.random_range(-3000..3000),
                    2 => [-p - 1, -p, -p + 1, p - 1, p, p + 1][rng.random_range(0..6)],
                    3 => rng.random_range(-4..4) * p + rng.random_range(-2..2),
                    _ => return [-(1i64 << 60), (1 << 60) - 1][rng.random_range(0..2)],
                };
                centre[i] + off
            });
            let l = [0, 1, 2].map(|_| rng.random_range(0..8i64));
            s.hit([0, 1, 2].map(|i| b[i] * 8 + l[i]));
            want.entry(b)
                .or_default()
                .insert(l[0] | l[1] << 3 | l[2] << 6);
        }
        let keys = s.keys();
        assert_eq!(keys.len(), want.len(), "round {round}: one slot per block");
        for (i, k) in keys.iter().enumerate() {
            let h = s.hits(i);
            let got: HashSet<i64> = (0..512)
                .filter(|c| h[*c as usize >> 6] >> (c & 63) & 1 == 1)
                .collect();
            assert_eq!(Some(&got), want.get(k), "round {round}: block {k:?}");
        }
    }
}

/// Runs of full blocks on walks whose parameters are coarse dyadic numbers, so that
/// borders of different axes often fall on one parameter at a block's face (where
/// the order of the steps decides the cells): the walk marks the cells of the
/// reference walk from the same state.
#[test]
fn runs_of_full_blocks_keep_the_reference_order_on_ties() {
    let mut rng = Pcg64::seed_from_u64(14);
    let runs_before = RUN_JUMPS.load(Ordering::Relaxed);
    for case in 0..3000 {
        let step = [0, 1, 2].map(|_| [-1i64, 1, 1, 0][rng.random_range(0..4)]);
        if step == [0; 3] {
            continue;
        }
        let d = [0, 1, 2].map(|i| {
            if step[i] == 0 {
                f64::MAX
            } else {
                f64::from(rng.random_range(1..5u32)) / 4.0
            }
        });
        let t_max = [0, 1, 2].map(|i| {
            if step[i] == 0 {
                f64::MAX
            } else {
                f64::from(rng.random_range(1..=(d[i] * 8.0) as u32)) / 8.0
            }
        });
        let left_axis = [0, 1, 2].map(|i| {
            if step[i] == 0 {
                0
            } else {
                rng.random_range(0..70)
            }
        });
        let make = || Dda {
            step,
            t_max,
            t_delta: d,
            left_axis,
            left: left_axis.iter().sum(),
        };
        if make().left == 0 {
            continue;
        }
        let ko = [0, 1, 2].map(|_| rng.random_range(-40..40i64));
        let mut path = Vec::new();
        walk_from(make(), ko, |c| path.push(c));
        let mut blocks: Vec<[i64; 3]> = path.iter().map(|c| c.map(|k| k >> 3)).collect();
        blocks.dedup();
        let mut s = Scratch::new(ko.map(|c| c >> 3), None);
        let mut want: HashSet<[i64; 3]> = path.iter().copied().collect();
        // Most blocks full, a few (where the walk goes cell by cell again) not.
        for b in &blocks {
            if rng.random_range(0..10) < [7, 9, 10][case % 3] {
                s.fill(*b);
                want.extend((0..512).map(|bit| {
                    [
                        b[0] * 8 + (bit & 7),
                        b[1] * 8 + (bit >> 3 & 7),
                        b[2] * 8 + (bit >> 6),
                    ]
                }));
            }
        }
        s.miss_walk(&make(), ko);
        let got = missed(&s);
        let extra: Vec<_> = got.difference(&want).collect();
        let lost: Vec<_> = want.difference(&got).collect();
        assert!(
            extra.is_empty() && lost.is_empty(),
            "case {case}: step {step:?} t {t_max:?} d {d:?} left {left_axis:?} from {ko:?}: \
             extra {extra:?}, lost {lost:?}"
        );
    }
    let runs = RUN_JUMPS.load(Ordering::Relaxed) - runs_before;
    assert!(
        runs > 10_000,
        "runs of full blocks were crossed ({runs} blocks)"
    );
}

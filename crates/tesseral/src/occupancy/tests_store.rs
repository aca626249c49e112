//! The block store (uniform, sparse and dense blocks) against a `HashMap` of cells.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::sensor::{Fixed, UNKNOWN};
use super::store::{Kind, Store, SPARSE_MAX};
use super::SensorModel;

#[test]
fn blocks_change_form_and_keep_their_cells() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let values = [fixed.min, fixed.max, fixed.miss, fixed.hit, 0, UNKNOWN];
    for seed in 0..6u64 {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut store = Store::default();
        let mut model: HashMap<[i64; 3], i16> = HashMap::new();
        let mut forms = [0usize; 3];
        // Four blocks (one with negative keys); set cells one by one, and now and then
        // apply a whole scan's masks or fill a block with one clamp.
        for op in 0..6000 {
            let b = [[0i64, 0, 0], [1, 0, 0], [-1, -3, 2], [7, 7, -7]][rng.random_range(0..4)];
            match rng.random_range(0..20) {
                0 => {
                    let mut miss = [0u64; 8];
                    let mut hit = [0u64; 8];
                    for w in 0..8 {
                        miss[w] = rng.random::<u64>() & rng.random::<u64>();
                        hit[w] = rng.random::<u64>()
                            & rng.random::<u64>()
                            & rng.random::<u64>()
                            & !miss[w];
                    }
                    store.update(b, &miss, &hit, fixed);
                    for i in 0..512 {
                        let c = [
                            b[0] * 8 + (i & 7) as i64,
                            b[1] * 8 + (i >> 3 & 7) as i64,
                            b[2] * 8 + (i >> 6) as i64,
                        ];
                        let old = model.get(&c).copied().unwrap_or(UNKNOWN);
                        if hit[i >> 6] >> (i & 63) & 1 == 1 {
                            model.insert(c, fixed.apply_hit(old));
                        } else if miss[i >> 6] >> (i & 63) & 1 == 1 {
                            model.insert(c, fixed.apply_miss(old));
                        }
                    }
                }
                1 => {
                    let v = [fixed.min, fixed.max][rng.random_range(0..2)];
                    store.put(b, &[v; 512], fixed);
                    for i in 0..512 {
                        model.insert(
                            [
                                b[0] * 8 + (i & 7),
                                b[1] * 8 + (i >> 3 & 7),
                                b[2] * 8 + (i >> 6),
                            ],
                            v,
                        );
                    }
                }
                _ => {
                    let c = [0, 1, 2].map(|a| b[a] * 8 + rng.random_range(0..8));
                    // Mostly known values, so blocks grow past the sparse limit.
                    let v = if op % 3000 < 2400 {
                        values[rng.random_range(0..5)]
                    } else {
                        values[rng.random_range(0..6)]
                    };
                    store.set(c, v, fixed);
                    if v == UNKNOWN {
                        model.remove(&c);
                    } else {
                        model.insert(c, v);
                    }
                }
            }
            store.assert_valid(fixed);
            if op % 97 == 0 {
                for (&c, &v) in &model {
                    assert_eq!(store.get(c), v, "seed {seed} op {op}: cell {c:?}");
                }
                let mut n = 0;
                store.for_each(|c, v| {
                    n += 1;
                    assert_eq!(model.get(&c), Some(&v), "seed {seed} op {op}: cell {c:?}");
                });
                assert_eq!(n, model.len(), "seed {seed} op {op}: cells");
            }
            for b in [[0i64, 0, 0], [1, 0, 0], [-1, -3, 2], [7, 7, -7]] {
                match store.entry(b).map(|e| e.kind()) {
                    Some(Kind::Uniform(_)) => forms[0] += 1,
                    Some(Kind::Sparse(_)) => forms[1] += 1,
                    Some(Kind::Dense(_)) => forms[2] += 1,
                    None => {}
                }
            }
        }
        assert!(
            forms.iter().all(|&f| f > 0),
            "seed {seed}: forms seen {forms:?} (sparse up to {SPARSE_MAX})"
        );
    }
}

//! Lookups (`Store::get`, the batched `Store::get_many`, `OccupancyMap::log_odds_many`)
//! through the read index (live, then mirroring writes or retired by a block outside
//! its box), the dense superblock directory and its hash-map fallback, against a
//! `HashMap` of cells; and the arena's limit.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::sensor::{Fixed, UNKNOWN};
use super::store::{Kind, Store};
use super::{OccupancyError, OccupancyMap, SensorModel};

/// Where a map's blocks lie.
#[derive(Debug, Clone, Copy)]
enum Layout {
    /// Within a few superblocks around `at` (a dense directory).
    Near([i64; 3]),
    /// Clusters far apart (superblocks up to 2^40 cells apart): a box far larger than
    /// the superblocks stored, so the hash map alone.
    Scattered,
    /// Near the ends of the i64 range (the directory's index arithmetic at its edges).
    Extremes,
}

fn random_block(rng: &mut Pcg64, layout: Layout, centres: &[[i64; 3]]) -> [i64; 3] {
    let c = centres[rng.random_range(0..centres.len())];
    let spread = match layout {
        Layout::Near(_) => 16,
        Layout::Scattered | Layout::Extremes => 6,
    };
    c.map(|x| {
        x.saturating_add(rng.random_range(-spread..=spread))
            .clamp(i64::MIN >> 3, i64::MAX >> 3)
    })
}

fn centres(rng: &mut Pcg64, layout: Layout) -> Vec<[i64; 3]> {
    match layout {
        Layout::Near(at) => vec![at.map(|c| c >> 3)],
        Layout::Scattered => (0..6)
            .map(|_| [0i64; 3].map(|_| rng.random_range(-(1i64 << 37)..1 << 37)))
            .collect(),
        // Blocks: cells >> 3, so the ends of the block range.
        Layout::Extremes => vec![
            [i64::MAX >> 3; 3],
            [i64::MIN >> 3; 3],
            [i64::MIN >> 3, i64::MAX >> 3, 0],
        ],
    }
}

/// Cells to look up: the model's, their neighbours, and cells of no block.
fn probes(rng: &mut Pcg64, model: &HashMap<[i64; 3], i16>, blocks: &[[i64; 3]]) -> Vec<[i64; 3]> {
    let mut out: Vec<[i64; 3]> = model.keys().copied().collect();
    for _ in 0..2000 {
        let b = blocks[rng.random_range(0..blocks.len())];
        // A cell of the block or of one near it (often in no superblock stored).
        let far = [0i64; 3].map(|_| rng.random_range(-80i64..=80));
        let near = [0i64; 3].map(|_| rng.random_range(-9i64..=16));
        let d = if rng.random_range(0..4) == 0 {
            far
        } else {
            near
        };
        out.push([0, 1, 2].map(|a| (b[a] << 3).saturating_add(d[a])));
    }
    for _ in 0..200 {
        out.push([0i64; 3].map(|_| rng.random::<i64>()));
    }
    out.extend([[i64::MIN; 3], [i64::MAX; 3], [0; 3], [-1; 3]]);
    out
}

/// Every probe through `get` and `get_many` (in slices of odd lengths, with and
/// without its prefetching passes) agrees with the model.
pub(super) fn check_lookups(
    store: &Store,
    model: &HashMap<[i64; 3], i16>,
    probes: &[[i64; 3]],
    what: &str,
) {
    let want: Vec<i16> = probes
        .iter()
        .map(|c| model.get(c).copied().unwrap_or(UNKNOWN))
        .collect();
    for (c, &w) in probes.iter().zip(&want) {
        assert_eq!(store.get(*c), w, "{what}: get {c:?}");
    }
    let mut got = vec![0i16; probes.len()];
    for passes in [false, true] {
        for len in [1, 31, 32, 33, 1000] {
            got.fill(0);
            for (c, g) in probes.chunks(len).zip(got.chunks_mut(len)) {
                store.get_many(c, g, passes);
            }
            assert_eq!(
                got, want,
                "{what}: get_many in slices of {len}, passes {passes}"
            );
        }
    }
}

/// Random updates of every kind to a store, each followed by `assert_valid` and
/// lookups against the model; the read index rebuilt (`settle`) after one
/// operation in five (or only asked to, when too little work was done since the
/// last rebuild), so that later ones are mirrored in it or retire it. `dense`:
/// whether the directory and the read index end up dense (live after a last
/// `settle`).
fn run(seed: u64, layout: Layout, dense: Option<bool>) {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut rng = Pcg64::seed_from_u64(seed);
    let centres = centres(&mut rng, layout);
    let mut store = Store::default();
    let mut model: HashMap<[i64; 3], i16> = HashMap::new();
    let mut blocks: Vec<[i64; 3]> = Vec::new();
    let few = [fixed.min, fixed.max, fixed.miss, fixed.hit, 0];
    for op in 0..1500 {
        let b = if blocks.is_empty() || rng.random_range(0..3) == 0 {
            let b = random_block(&mut rng, layout, &centres);
            blocks.push(b);
            b
        } else {
            blocks[rng.random_range(0..blocks.len())]
        };
        let cell = |i: usize| {
            [
                b[0] << 3 | (i & 7) as i64,
                b[1] << 3 | (i >> 3 & 7) as i64,
                b[2] << 3 | (i >> 6) as i64,
            ]
        };
        match rng.random_range(0..4) {
            0 => {
                // A scan's masks: every form of block comes out of these.
                let mut miss = [0u64; 8];
                let mut hit = [0u64; 8];
                let density = rng.random_range(1..5);
                for w in 0..8 {
                    miss[w] = (0..density).fold(u64::MAX, |m, _| m & rng.random::<u64>());
                    hit[w] = (0..density + 1).fold(!miss[w], |m, _| m & rng.random::<u64>());
                }
                store.update(b, &miss, &hit, fixed);
                for i in 0..512 {
                    let c = cell(i);
                    let old = model.get(&c).copied().unwrap_or(UNKNOWN);
                    if hit[i >> 6] >> (i & 63) & 1 == 1 {
                        model.insert(c, fixed.apply_hit(old));
                    } else if miss[i >> 6] >> (i & 63) & 1 == 1 {
                        model.insert(c, fixed.apply_miss(old));
                    }
                }
            }
            1 => {
                // Many values in one block (palettes of 8 bits, dense blocks).
                for _ in 0..rng.random_range(1..300) {
                    let c = cell(rng.random_range(0..512));
                    let v = rng.random_range(fixed.min..=fixed.max);
                    store.set(c, v, fixed);
                    model.insert(c, v);
                }
            }
            _ => {
                let c = cell(rng.random_range(0..512));
                let v = if rng.random_range(0..4) == 0 {
                    UNKNOWN
                } else {
                    few[rng.random_range(0..few.len())]
                };
                store.set(c, v, fixed);
                if v == UNKNOWN {
                    model.remove(&c);
                } else {
                    model.insert(c, v);
                }
            }
        }
        if rng.random_range(0..5) == 0 {
            // Half the time with the work that pays for a rebuild.
            if rng.random_range(0..2) == 0 {
                store.worked(u64::MAX);
            }
            store.settle();
        }
        store.assert_valid(fixed);
        let what = format!(
            "seed {seed} {layout:?} op {op} (read index live: {})",
            store.flat_live()
        );
        // The block just changed, and now and then every probe.
        let changed: Vec<[i64; 3]> = (0..512).map(cell).collect();
        check_lookups(&store, &model, &changed, &what);
        if op % 250 == 0 {
            let p = probes(&mut rng, &model, &blocks);
            check_lookups(&store, &model, &p, &what);
        }
    }
    let p = probes(&mut rng, &model, &blocks);
    check_lookups(&store, &model, &p, &format!("seed {seed} {layout:?}"));
    store.worked(u64::MAX);
    store.settle();
    store.assert_valid(fixed);
    check_lookups(
        &store,
        &model,
        &p,
        &format!("seed {seed} {layout:?} settled"),
    );
    if let Some(dense) = dense {
        assert_eq!(store.dense_directory(), dense, "seed {seed} {layout:?}");
        assert_eq!(
            store.flat_live(),
            dense,
            "seed {seed} {layout:?}: read index"
        );
    }
}

#[test]
fn lookups_near_the_origin_agree_with_the_model() {
    for seed in 0..3 {
        run(seed, Layout::Near([0; 3]), Some(true));
    }
}

#[test]
fn lookups_far_from_the_origin_and_negative_agree_with_the_model() {
    for (seed, at) in [
        [-1_000_000_007, 5_000_000_000_003, -17],
        [1 << 50, -(1 << 50), 3],
        [-3, -5, -7],
    ]
    .into_iter()
    .enumerate()
    {
        run(10 + seed as u64, Layout::Near(at), Some(true));
    }
}

#[test]
fn lookups_over_huge_sparse_extents_use_the_hash_map_and_agree() {
    for seed in 0..3 {
        run(20 + seed, Layout::Scattered, Some(false));
    }
    for seed in 0..2 {
        run(30 + seed, Layout::Extremes, Some(false));
    }
}

#[test]
fn the_directory_goes_dense_again_once_the_superblocks_fill_their_box() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut store = Store::default();
    let mut model = HashMap::new();
    let mut put = |store: &mut Store, c: [i64; 3], check: bool| {
        store.set(c, fixed.hit, fixed);
        model.insert(c, fixed.hit);
        if check {
            store.assert_valid(fixed);
        }
    };
    // Two superblocks 2^12 superblocks apart: a box of some 55,000 slots, over
    // budget.
    put(&mut store, [0, 0, 0], true);
    put(&mut store, [64 << 12, 0, 0], true);
    assert!(!store.dense_directory());
    // Then a line of superblocks between them, until the box's slots are few enough
    // per superblock.
    let mut x = 0;
    while !store.dense_directory() {
        x += 64;
        put(&mut store, [x, 0, 0], x % 6400 == 0);
        assert!(x < 64 << 12, "never dense again");
    }
    store.assert_valid(fixed);
    let probes: Vec<[i64; 3]> = (-5..70_000)
        .map(|i| [i * 7, i % 5 - 2, 0])
        .chain(model.keys().copied())
        .collect();
    check_lookups(&store, &model, &probes, "dense again");
}

/// Sparse blocks grown one cell at a time past every length a sparse block takes
/// (1 to about 72 cells of up to six values: past the 64 that `get` compares at
/// once; longer, a patched palette takes fewer units),
/// two at a time so that one lies inside the arena and the other often at its end;
/// near the origin, far and negative, and with the hash-map directory. After every
/// cell set: `assert_valid`, and every cell of both blocks and of their neighbours
/// against the model.
#[test]
fn sparse_blocks_of_every_length_agree_with_the_model() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let far = [-(1i64 << 40) - 5, 7, -(1 << 33) + 3];
    for (seed, at, scattered) in [(40, [0i64; 3], false), (41, far, false), (42, far, true)] {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut store = Store::default();
        let mut model: HashMap<[i64; 3], i16> = HashMap::new();
        if scattered {
            // A cell 2^45 cells away: the directory's box is over budget.
            let c = [1i64 << 45, -(1 << 45), 0];
            store.set(c, fixed.hit, fixed);
            model.insert(c, fixed.hit);
        }
        let blocks = [at, [at[0] + 1, at[1] - 1, at[2]]];
        // Six distinct values inside the clamps for the second block, and six free
        // ones for the first: a surface whose values fit a palette of two bits takes
        // it, so only the first is sparse at every length.
        let spread = |top: i16| {
            let step = (i32::from(top) - i32::from(fixed.min)) / 7;
            (1..=6)
                .map(|k| (i32::from(fixed.min) + k * step) as i16)
                .collect::<Vec<i16>>()
        };
        let values = [spread(fixed.threshold), spread(fixed.max)];
        let mut order: Vec<Vec<usize>> = Vec::new();
        for _ in blocks {
            let mut o: Vec<usize> = (0..512).collect();
            for k in 0..511 {
                o.swap(k, rng.random_range(k..512));
            }
            order.push(o);
        }
        let mut sparse_lengths = Vec::new();
        for len in 1..=140 {
            for ((b, o), values) in blocks.iter().zip(&order).zip(&values) {
                let i = o[len - 1];
                let c = [
                    b[0] << 3 | (i & 7) as i64,
                    b[1] << 3 | (i >> 3 & 7) as i64,
                    b[2] << 3 | (i >> 6) as i64,
                ];
                let v = values[rng.random_range(0..values.len())];
                store.set(c, v, fixed);
                model.insert(c, v);
                store.assert_valid(fixed);
                if store.entry(*b).map(|e| e.kind()) == Some(Kind::Sparse) {
                    sparse_lengths.push(len);
                }
            }
            let probes: Vec<[i64; 3]> = blocks
                .iter()
                .flat_map(|b| {
                    (-8..16).flat_map(move |x| {
                        (0..8).flat_map(move |y| {
                            (0..8).map(move |z| [b[0] * 8 + x, b[1] * 8 + y, b[2] * 8 + z])
                        })
                    })
                })
                .collect();
            check_lookups(
                &store,
                &model,
                &probes,
                &format!("seed {seed} length {len}"),
            );
        }
        assert_eq!(store.dense_directory(), !scattered, "seed {seed}");
        // Both the compares (up to 64 cells) and the search beyond were exercised,
        // and the longer lists took a patched palette, in fewer units.
        assert!(
            [1, 64, 65, 70].iter().all(|n| sparse_lengths.contains(n)),
            "seed {seed}: sparse at {sparse_lengths:?}"
        );
        assert_eq!(
            store.entry(blocks[0]).map(|e| e.kind()),
            Some(Kind::Patched),
            "seed {seed}"
        );
    }
}

#[test]
fn log_odds_many_agrees_with_log_odds() {
    let mut rng = Pcg64::seed_from_u64(5);
    let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    for _ in 0..4 {
        let origin = [0.0f64; 3].map(|_| rng.random_range(-1.0..1.0));
        let points: Vec<[f64; 3]> = (0..300)
            .map(|_| [0.0f64; 3].map(|_| rng.random_range(-6.0..6.0)))
            .collect();
        map.insert_scan(origin, &points, None);
        map.assert_valid();
    }
    let cells: Vec<[i64; 3]> = (0..5000)
        .map(|_| [0i64; 3].map(|_| rng.random_range(-70..70)))
        .collect();
    let mut out = vec![Some(-9.0); cells.len()];
    map.log_odds_many(&cells, &mut out);
    let want: Vec<Option<f32>> = cells.iter().map(|&c| map.log_odds(c)).collect();
    assert_eq!(out, want);
    assert!(want.iter().any(Option::is_some) && want.iter().any(Option::is_none));
}

#[test]
fn a_full_arena_refuses_blocks_with_an_error_and_stays_valid() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut rng = Pcg64::seed_from_u64(9);
    let mut store = Store::default();
    // 200 units of 16 bytes: a few blocks.
    store.set_limit_units(200);
    let mut model: HashMap<[i64; 3], i16> = HashMap::new();
    let mut refused = 0;
    for op in 0..400 {
        let b = [rng.random_range(0..40), rng.random_range(-3..3), 0];
        let c = [
            b[0] << 3 | rng.random_range(0..8),
            b[1] << 3 | rng.random_range(0..8),
            rng.random_range(0..8),
        ];
        let v = rng.random_range(fixed.min..=fixed.max);
        let was = store.overflowed();
        let before = store.cells(b);
        store.set(c, v, fixed);
        store.assert_valid(fixed);
        assert!(
            store.arena_units().iter().all(|&u| u <= 200),
            "op {op}: an arena passed its limit"
        );
        if store.get(c) == v {
            model.insert(c, v);
        } else {
            // Refused: the block is as it was, and the store says so.
            assert!(store.overflowed(), "op {op}: a dropped update unreported");
            assert_eq!(store.cells(b), before, "op {op}: a refused block changed");
            refused += 1;
        }
        assert!(!was || store.overflowed(), "op {op}: the flag is kept");
        for (&c, &v) in &model {
            assert_eq!(store.get(c), v, "op {op}: cell {c:?}");
        }
    }
    assert!(refused > 0, "the limit was reached");
    // Through the map: the error names the limit.
    let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    assert_eq!(map.check_capacity(), Ok(()));
    map.store.set_limit_units(100);
    let points: Vec<[f64; 3]> = (0..2000)
        .map(|_| [0.0f64; 3].map(|_| rng.random_range(-20.0..20.0)))
        .collect();
    map.insert_scan([0.0; 3], &points, None);
    map.assert_valid();
    let e = map.check_capacity().unwrap_err();
    assert_eq!(e, OccupancyError::Capacity { limit_bytes: 1600 });
    assert!(e.to_string().contains("1600 bytes"), "{e}");
}

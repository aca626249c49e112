//! The block store (uniform, sparse, palette and dense blocks, the directory, the
//! arena's compaction) against a `HashMap` of cells.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::sensor::{Fixed, UNKNOWN};
use super::store::{Kind, Store};
use super::SensorModel;

/// Blocks in four superblocks, negative keys among them.
const BLOCKS: [[i64; 3]; 6] = [
    [0, 0, 0],
    [1, 0, 0],
    [-1, -3, 2],
    [7, 7, -7],
    [8, 0, 0],
    [-9, 100, 3],
];

fn cell_of(b: [i64; 3], i: usize) -> [i64; 3] {
    [
        b[0] * 8 + (i & 7) as i64,
        b[1] * 8 + (i >> 3 & 7) as i64,
        b[2] * 8 + (i >> 6) as i64,
    ]
}

/// Every cell of the model, the store's cells against it, and the store's census
/// (counted form by form, without decoding) against counts of the model.
fn check(store: &Store, model: &HashMap<[i64; 3], i16>, fixed: Fixed, what: &str) {
    for (&c, &v) in model {
        assert_eq!(store.get(c), v, "{what}: cell {c:?}");
    }
    let mut n = 0;
    store.for_each(|c, v| {
        n += 1;
        assert_eq!(model.get(&c), Some(&v), "{what}: cell {c:?}");
    });
    assert_eq!(n, model.len(), "{what}: cells");
    let occupied = model.values().filter(|&&v| v >= fixed.threshold).count() as u64;
    // One entry per uniform block, one per known cell of the others.
    let uniform: Vec<[i64; 3]> = BLOCKS
        .into_iter()
        .filter(|&b| matches!(store.entry(b).map(|e| e.kind()), Some(Kind::Uniform(_))))
        .collect();
    let in_uniform = |c: &[i64; 3]| uniform.contains(&c.map(|x| x >> 3));
    let leaves = uniform.len() as u64 + model.keys().filter(|c| !in_uniform(c)).count() as u64;
    let got = store.census(fixed.threshold);
    assert_eq!(
        (got.occupied, got.free, got.leaves),
        (occupied, model.len() as u64 - occupied, leaves),
        "{what}: census"
    );
}

/// The forms of the blocks stored: uniform, sparse, palettes of 1, 2, 4, 8 bits,
/// dense, patched palette.
fn forms_of(store: &Store) -> [bool; 8] {
    let mut forms = [false; 8];
    for b in BLOCKS {
        let f = match store.entry(b).map(|e| e.kind()) {
            Some(Kind::Uniform(_)) => 0,
            Some(Kind::Sparse) => 1,
            Some(Kind::Palette(w)) => 2 + w.trailing_zeros() as usize,
            Some(Kind::Dense) => 6,
            Some(Kind::Patched) => 7,
            None => continue,
        };
        forms[f] = true;
    }
    forms
}

#[test]
fn blocks_change_form_and_keep_their_cells() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let few = [fixed.min, fixed.max, fixed.miss, fixed.hit, 0];
    let mut compactions = 0;
    // Forms seen: uniform, sparse, palettes of 1, 2, 4, 8 bits, dense, patched;
    // and those seen by the whole-store checks (the census among them).
    let mut forms = [0usize; 8];
    let mut checked = [false; 8];
    for seed in 0..8u64 {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut store = Store::default();
        let mut model: HashMap<[i64; 3], i16> = HashMap::new();
        for op in 0..8000 {
            // Phases: few values; many, mostly in one block (to make dense blocks);
            // forgetting (to shrink blocks); the two clamps only (1-bit palettes).
            let phase = op / 700 % 4;
            let b = if phase == 1 && rng.random_range(0..3) > 0 {
                BLOCKS[0]
            } else {
                BLOCKS[rng.random_range(0..BLOCKS.len())]
            };
            // (No whole-block writes while values pile up in phase 1.)
            match if phase == 1 {
                19
            } else {
                rng.random_range(0..20)
            } {
                0 | 1 => {
                    // A scan's masks, of random density.
                    let dense = rng.random_range(1..4);
                    let mut miss = [0u64; 8];
                    let mut hit = [0u64; 8];
                    for w in 0..8 {
                        miss[w] = (0..dense).fold(u64::MAX, |m, _| m & rng.random::<u64>());
                        hit[w] = (0..dense + 1).fold(!miss[w], |m, _| m & rng.random::<u64>());
                    }
                    store.update(b, &miss, &hit, fixed);
                    for i in 0..512 {
                        let c = cell_of(b, i);
                        let old = model.get(&c).copied().unwrap_or(UNKNOWN);
                        if hit[i >> 6] >> (i & 63) & 1 == 1 {
                            model.insert(c, fixed.apply_hit(old));
                        } else if miss[i >> 6] >> (i & 63) & 1 == 1 {
                            model.insert(c, fixed.apply_miss(old));
                        }
                    }
                }
                2 => {
                    let v = [fixed.min, fixed.max][rng.random_range(0..2)];
                    store.put(b, &[v; 512], fixed);
                    for i in 0..512 {
                        model.insert(cell_of(b, i), v);
                    }
                }
                _ => {
                    let c = cell_of(b, rng.random_range(0..512));
                    let v = match phase {
                        0 => few[rng.random_range(0..5)],
                        1 => rng.random_range(fixed.min..=fixed.max),
                        2 if rng.random_range(0..3) == 0 => few[rng.random_range(0..5)],
                        2 => UNKNOWN,
                        _ => [fixed.min, fixed.max][rng.random_range(0..2)],
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
            // The block just changed, every cell, and now and then the whole map.
            for i in 0..512 {
                let c = cell_of(b, i);
                let want = model.get(&c).copied().unwrap_or(UNKNOWN);
                assert_eq!(store.get(c), want, "seed {seed} op {op}: cell {c:?}");
            }
            let now = forms_of(&store);
            if op % 97 == 0 {
                check(&store, &model, fixed, &format!("seed {seed} op {op}"));
                for (c, n) in checked.iter_mut().zip(now) {
                    *c |= n;
                }
            }
            for (f, n) in forms.iter_mut().zip(now) {
                *f += usize::from(n);
            }
        }
        check(&store, &model, fixed, &format!("seed {seed}"));
        let blocks = BLOCKS.iter().filter(|&&b| store.entry(b).is_some()).count();
        assert_eq!(store.block_count(), blocks, "seed {seed}: block count");
        compactions += store.compactions();
    }
    assert!(forms.iter().all(|&f| f > 0), "forms seen {forms:?}");
    assert!(checked.iter().all(|&c| c), "forms checked {checked:?}");
    assert!(compactions > 0, "the arena was compacted");
}

#[test]
fn blocks_take_the_smallest_form() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut store = Store::default();
    let b = [3, -2, 5];
    let kind = |s: &Store| s.entry(b).map(|e| e.kind());
    // Ten known cells of one value: sparse (one header unit and two of cells).
    let mut cells = [UNKNOWN; 512];
    for c in cells.iter_mut().step_by(50) {
        *c = fixed.miss;
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Sparse));
    // The same cells occupied: a surface, whose palette is never narrower than two
    // bits, takes one though the sparse form is smaller (9 units against 3, just
    // within the slack).
    for c in cells.iter_mut().step_by(50) {
        *c = fixed.max;
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(2)));
    // A surface of two cells, one free and one occupied, with unknown: a 2-bit
    // palette would take 9 units against the sparse form's 2, past the slack.
    let mut two = [UNKNOWN; 512];
    two[7] = fixed.min;
    two[300] = fixed.max;
    store.put(b, &two, fixed);
    assert_eq!(kind(&store), Some(Kind::Sparse));
    // Twenty such cells (sparse: 4 units): the palette is within the slack.
    for (k, c) in two.iter_mut().step_by(25).enumerate() {
        *c = [fixed.min, fixed.max][k % 2];
    }
    store.put(b, &two, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(2)));
    // Five known values, one occupied, and unknown: past two bits, so sparse again.
    for (k, c) in cells.iter_mut().step_by(50).enumerate() {
        *c = [fixed.min, fixed.miss, fixed.hit, fixed.max, fixed.min + 1][k % 5];
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Sparse));
    store.assert_valid(fixed);
    // Half the cells known, two values and unknown: 2-bit palette.
    for (i, c) in cells.iter_mut().enumerate() {
        *c = [UNKNOWN, fixed.min, fixed.max][i % 3];
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(2)));
    // All known, two values: 1 bit; a surface (one value occupied): 2 bits.
    for (i, c) in cells.iter_mut().enumerate() {
        *c = [fixed.min, fixed.miss][i % 2];
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(1)));
    for (i, c) in cells.iter_mut().enumerate() {
        *c = [fixed.min, fixed.max][i % 2];
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(2)));
    // Sixteen values: 4 bits; 256: 8 bits; 512: dense.
    for (i, c) in cells.iter_mut().enumerate() {
        *c = (i % 16) as i16;
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(4)));
    for (i, c) in cells.iter_mut().enumerate() {
        *c = (i % 255) as i16;
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(8)));
    for (i, c) in cells.iter_mut().enumerate() {
        *c = i as i16;
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Dense));
    store.assert_valid(fixed);
    // A surface seen from many viewpoints: unknown, clamped free and clamped
    // occupied, and 40 cells of ten other values: a patched palette (13 units
    // against a 4-bit palette's 19).
    for (i, c) in cells.iter_mut().enumerate() {
        *c = match i % 13 {
            0 if i < 520 => fixed.min / 2 + (i / 13 % 10) as i16 * 100,
            1..=4 => UNKNOWN,
            5..=9 => fixed.min,
            _ => fixed.max,
        };
    }
    store.put(b, &cells, fixed);
    assert_eq!(kind(&store), Some(Kind::Patched));
    assert_eq!(store.cells(b), cells);
    for (i, &v) in cells.iter().enumerate() {
        assert_eq!(store.get(cell_of(b, i)), v, "cell {i}");
    }
    store.assert_valid(fixed);
    // Clamped free everywhere: one entry; then a miss on a clamped-free block
    // changes nothing, and a hit makes it a 1-bit palette.
    store.put(b, &[fixed.min; 512], fixed);
    assert_eq!(kind(&store), Some(Kind::Uniform(fixed.min)));
    store.update(b, &[u64::MAX; 8], &[0; 8], fixed);
    assert_eq!(kind(&store), Some(Kind::Uniform(fixed.min)));
    let mut hit = [0u64; 8];
    hit[3] = 1 << 9;
    store.update(b, &[0; 8], &hit, fixed);
    assert_eq!(kind(&store), Some(Kind::Palette(1)));
    assert_eq!(
        store.get([3 * 8 + 1, -2 * 8 + 1, 5 * 8 + 3]),
        fixed.min + fixed.hit
    );
    assert_eq!(store.get([3 * 8, -2 * 8 + 1, 5 * 8 + 3]), fixed.min);
    assert_eq!(store.get([3 * 8, -2 * 8 + 1, 5 * 8 + 8]), UNKNOWN);
    store.assert_valid(fixed);
    assert_eq!(store.block_count(), 1);
}

/// Blocks that list an occupied value live in their own arena: a new block with a
/// hit, a palette updated in place that gains an occupied value (moved), a block
/// rewritten without one (moved back); a scan's blocks end where they should.
#[test]
fn blocks_that_list_an_occupied_value_move_to_their_own_arena() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut store = Store::default();
    let b = [2, -1, 0];
    let all = [u64::MAX; 8];
    let none = [0u64; 8];
    let mut one = [0u64; 8];
    one[0] = 1 << 5;
    // Every cell missed once: a 1-bit palette of one free value.
    store.update(b, &all, &none, fixed);
    store.assert_valid(fixed);
    assert_eq!(store.entry(b).map(|e| e.kind()), Some(Kind::Palette(1)));
    assert_eq!(store.in_occupied_arena(b), Some(false));
    // Cell 5 hit: updated in place (a second value fits), now occupied: moved.
    store.update(b, &none, &one, fixed);
    store.assert_valid(fixed);
    assert_eq!(store.entry(b).map(|e| e.kind()), Some(Kind::Palette(1)));
    assert!(store.get(cell_of(b, 5)) >= fixed.threshold);
    assert_eq!(store.in_occupied_arena(b), Some(true));
    // Cell 5 freed: the block rewritten lists no occupied value and moves back.
    store.set(cell_of(b, 5), fixed.miss, fixed);
    store.assert_valid(fixed);
    assert_eq!(store.in_occupied_arena(b), Some(false));
    // New blocks: a hit places the block with the occupied ones, misses alone not.
    let (c, d) = ([40, 0, 0], [41, 0, 0]);
    store.update(c, &none, &one, fixed);
    store.update(d, &one, &none, fixed);
    store.assert_valid(fixed);
    // One occupied cell and unknown: a surface, whose palette would take two bits
    // (9 units against 2, past the slack): sparse.
    assert_eq!(store.entry(c).map(|e| e.kind()), Some(Kind::Sparse));
    assert_eq!(store.in_occupied_arena(c), Some(true));
    assert_eq!(store.in_occupied_arena(d), Some(false));
    // Random updates: `assert_valid` checks every block's arena after each.
    let mut rng = Pcg64::seed_from_u64(11);
    for _ in 0..3000 {
        let b = BLOCKS[rng.random_range(0..BLOCKS.len())];
        let mut miss = [0u64; 8];
        let mut hit = [0u64; 8];
        for _ in 0..rng.random_range(1..40) {
            let i = rng.random_range(0..512);
            if rng.random_range(0..4) == 0 {
                hit[i >> 6] |= 1 << (i & 63);
            } else {
                miss[i >> 6] |= 1 << (i & 63);
            }
        }
        for w in 0..8 {
            miss[w] &= !hit[w];
        }
        store.update(b, &miss, &hit, fixed);
        store.assert_valid(fixed);
    }
    assert!(BLOCKS
        .iter()
        .any(|&b| store.in_occupied_arena(b) == Some(true)));
}

#[test]
fn tidy_compacts_an_arena_with_free_chunks_and_keeps_every_cell() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut rng = Pcg64::seed_from_u64(77);
    let mut store = Store::default();
    let blocks: Vec<[i64; 3]> = (0..400).map(|k| [k % 20, k / 20, -3]).collect();
    let mut model: HashMap<[i64; 3], i16> = HashMap::new();
    // Blocks of many values each (palettes of 8 bits: 33 units and more).
    for &b in &blocks {
        let cells: [i16; 512] = std::array::from_fn(|_| rng.random_range(fixed.min..=fixed.max));
        store.put(b, &cells, fixed);
        for (i, &v) in cells.iter().enumerate() {
            model.insert(cell_of(b, i), v);
        }
    }
    // A fifth of them clamped: their chunks freed, short of the quarter at which
    // an arena compacts itself.
    let before = store.compactions();
    for &b in blocks.iter().step_by(5) {
        store.put(b, &[fixed.min; 512], fixed);
        for i in 0..512 {
            model.insert(cell_of(b, i), fixed.min);
        }
    }
    assert_eq!(
        store.compactions(),
        before,
        "no compaction during the updates"
    );
    let bytes = store.bytes();
    store.tidy();
    store.assert_valid(fixed);
    assert_eq!(store.compactions(), before + 1, "tidy compacted the arena");
    assert!(
        store.bytes() * 5 < bytes * 4,
        "{} bytes of {bytes}",
        store.bytes()
    );
    for (&c, &v) in &model {
        assert_eq!(store.get(c), v, "cell {c:?}");
    }
    // Nothing left to tidy.
    store.tidy();
    assert_eq!(store.compactions(), before + 1, "a second tidy did nothing");
}

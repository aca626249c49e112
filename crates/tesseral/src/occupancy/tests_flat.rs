//! The read index (`store::flat`): mirrored writes, retirement by a block outside
//! its box, and rebuilds paid for by work, against a `HashMap` of cells.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::sensor::{Fixed, UNKNOWN};
use super::store::Store;
use super::tests_lookup::check_lookups;
use super::SensorModel;

/// The read index follows every write once it is built: blocks emptied, made
/// uniform, rewritten in another form, moved by the arena's compaction, and a block
/// made outside its box (which retires the index until the next `settle`). After
/// each step: `assert_valid` (the index against the tables) and every cell against
/// the model.
#[test]
fn the_read_index_mirrors_every_write_once_built() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut rng = Pcg64::seed_from_u64(50);
    let mut store = Store::default();
    let mut model: HashMap<[i64; 3], i16> = HashMap::new();
    let set = |store: &mut Store, model: &mut HashMap<[i64; 3], i16>, c: [i64; 3], v: i16| {
        store.set(c, v, fixed);
        if v == UNKNOWN {
            model.remove(&c);
        } else {
            model.insert(c, v);
        }
    };
    // 300 blocks of 1 to 40 cells over a 10 x 10 x 3 box of blocks.
    let blocks: Vec<[i64; 3]> = (0..300)
        .map(|k| [k % 10, k / 10 % 10, k / 100].map(|x| x - 4))
        .collect();
    for &b in &blocks {
        for _ in 0..rng.random_range(1..40) {
            let c = [0, 1, 2].map(|a| b[a] << 3 | rng.random_range(0..8));
            set(
                &mut store,
                &mut model,
                c,
                rng.random_range(fixed.min + 1..fixed.max),
            );
        }
    }
    store.settle();
    assert!(store.flat_live(), "a compact map gets a read index");
    let check = |store: &Store, model: &HashMap<[i64; 3], i16>, what: &str| {
        store.assert_valid(fixed);
        let cells: Vec<[i64; 3]> = blocks
            .iter()
            .flat_map(|&b| (0..512).map(move |i| super::store::join(b, i)))
            .collect();
        check_lookups(store, model, &cells, what);
    };
    check(&store, &model, "built");
    let compactions = store.compactions();
    // Empty two blocks in three: the arena compacts.
    for (k, &b) in blocks.iter().enumerate().filter(|(k, _)| k % 3 != 0) {
        let known: Vec<[i64; 3]> = (0..512)
            .map(|i| super::store::join(b, i))
            .filter(|c| model.contains_key(c))
            .collect();
        for c in known {
            set(&mut store, &mut model, c, UNKNOWN);
        }
        assert!(
            store.flat_live(),
            "block {k}: emptying keeps the index live"
        );
    }
    assert!(store.compactions() > compactions, "the arena compacted");
    check(&store, &model, "emptied and compacted");
    // One block clamped whole (uniform), one made dense.
    for i in 0..512 {
        set(
            &mut store,
            &mut model,
            super::store::join(blocks[0], i),
            fixed.min,
        );
        set(
            &mut store,
            &mut model,
            super::store::join(blocks[3], i),
            (i % 300) as i16,
        );
    }
    assert!(store.flat_live());
    check(&store, &model, "uniform and dense");
    // A block far outside the box: the index retires, lookups go on through the
    // directory, and `settle` builds it again over the new box.
    set(&mut store, &mut model, [200, 0, 0], fixed.hit);
    assert!(
        !store.flat_live(),
        "a block outside the box retires the index"
    );
    check(&store, &model, "retired");
    store.settle();
    assert!(store.flat_live(), "rebuilt over the new box");
    check(&store, &model, "rebuilt");
}

/// A rebuild waits for the work that pays for it: two cells set 14 blocks apart
/// make a box of 15³ = 3,375 blocks (within the budget every store has), which
/// needs twice as many cells updated; then a block outside the box retires the index
/// until as much work again was done.
#[test]
fn the_read_index_is_rebuilt_once_the_work_pays_for_it() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let mut store = Store::default();
    store.set([0; 3], fixed.hit, fixed);
    store.set([14 * 8; 3], fixed.hit, fixed);
    store.settle();
    assert!(
        !store.flat_live(),
        "2 cells updated do not pay for 3,375 blocks"
    );
    store.worked(2 * 3375 - 3);
    store.settle();
    assert!(!store.flat_live(), "one cell short");
    store.worked(1);
    store.settle();
    assert!(store.flat_live(), "rebuilt once paid for");
    store.assert_valid(fixed);
    store.set([8; 3], fixed.miss, fixed);
    assert!(store.flat_live(), "a block inside the box is mirrored");
    store.set([15 * 8, 0, 0], fixed.miss, fixed);
    assert!(!store.flat_live(), "a block outside retires it");
    store.settle();
    assert!(
        !store.flat_live(),
        "the work since the last rebuild does not pay"
    );
    for (c, v) in [
        ([0; 3], fixed.hit),
        ([8; 3], fixed.miss),
        ([15 * 8, 0, 0], fixed.miss),
        ([1; 3], UNKNOWN),
    ] {
        assert_eq!(store.get(c), v, "cell {c:?} through the directory");
    }
    store.worked(u64::MAX);
    store.settle();
    assert!(store.flat_live());
    store.assert_valid(fixed);
}

//! The census of a sorted cell list and the palette's packing, against the census of
//! all 512 cells and a cell-by-cell read of the packed words; the patched palette
//! against its cells.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::arena::UNIT;
use super::census::Census;
use super::forms::{bits_words, palette_index, width_for, write_palette};
use super::patched::{self, Patch};
use super::BLOCK_CELLS;
use crate::occupancy::sensor::UNKNOWN;

/// A random block: each cell known with probability `p`, its value one of `k`.
fn block(rng: &mut Pcg64, p: f64, k: i16) -> [i16; BLOCK_CELLS] {
    std::array::from_fn(|_| {
        if rng.random_bool(p) {
            rng.random_range(-k..k) * 7
        } else {
            UNKNOWN
        }
    })
}

#[test]
fn a_census_of_the_list_is_the_census_of_the_cells() {
    let mut rng = Pcg64::seed_from_u64(31);
    for round in 0..4000 {
        let p = [0.0, 0.002, 0.05, 0.3, 0.8, 0.99, 1.0][round % 7];
        let k = rng.random_range(1..12);
        let mut cells = block(&mut rng, p, k);
        // Some blocks known from cell 0, some unknown only at the end.
        match round % 5 {
            0 => cells[0] = 14,
            1 => cells[BLOCK_CELLS - 1] = UNKNOWN,
            _ => {}
        }
        let list: Vec<u32> = cells
            .iter()
            .enumerate()
            .filter(|(_, &v)| v != UNKNOWN)
            .map(|(i, &v)| (i as u32) << 16 | u32::from(v as u16))
            .collect();
        let want = Census::of(&cells);
        assert_eq!(Census::of_list(&list), want, "round {round}");
        // The palette packs each cell's number where a read finds it.
        let Some(w) = width_for(want.values.len()) else {
            continue;
        };
        let mut words = vec![0xABCDu16; bits_words(w) + 1 + (1 << w).max(want.values.len())];
        write_palette(&mut words, w, &want);
        for i in 0..BLOCK_CELLS {
            assert_eq!(
                palette_index(&words, w, i),
                usize::from(want.index[i]),
                "round {round}, width {w}, cell {i}"
            );
        }
        let at = bits_words(w);
        assert_eq!(usize::from(words[at]), want.values.len());
        let listed: Vec<i16> = words[at + 1..at + 1 + want.values.len()]
            .iter()
            .map(|&v| v as i16)
            .collect();
        assert_eq!(listed, want.values);
        assert!(words[at + 1 + want.values.len()..].iter().all(|&x| x == 0));
    }
}

/// A surface's block: each cell one of three common values with probability
/// `1 − p`, else one of `k` others.
fn surface(rng: &mut Pcg64, p: f64, k: i16) -> [i16; BLOCK_CELLS] {
    std::array::from_fn(|_| {
        if rng.random_bool(p) {
            100 + rng.random_range(0..k)
        } else {
            [UNKNOWN, -16000, 16000][rng.random_range(0..3)]
        }
    })
}

#[test]
fn a_patched_palette_reads_back_every_cell() {
    let mut rng = Pcg64::seed_from_u64(32);
    let mut sizes = [false; 4];
    for round in 0..3000 {
        let p = [0.0, 0.004, 0.05, 0.2, 0.6, 1.0][round % 6];
        let k = [2, 3, 4, 5, 12, 16, 17, 40, 256][rng.random_range(0..9)];
        let cells = surface(&mut rng, p, k);
        let census = Census::of(&cells);
        let Some(patch) = Patch::of(&census) else {
            assert!(!(5..=259).contains(&census.values.len()), "round {round}");
            continue;
        };
        let units = patch.units();
        // A chunk followed by another block's words, which must stay as they were.
        let mut words = vec![0xABCDu16; units * UNIT + UNIT];
        patched::write(&mut words[..units * UNIT], &census, &patch);
        assert!(
            words[units * UNIT..].iter().all(|&x| x == 0xABCD),
            "round {round}"
        );
        assert_eq!(patched::units_of(&words), units, "round {round}");
        patched::assert_valid(&words, units, &format!("round {round}"));
        let mut out = [0i16; BLOCK_CELLS];
        patched::decode(&words, &mut out);
        assert_eq!(out, cells, "round {round}: decode");
        // The lookup's two steps: the 2-bit number, then the patch for the escape.
        for (i, &v) in cells.iter().enumerate() {
            let got = match palette_index(&words, 2, i) {
                patched::ESCAPE => patched::escaped_value(|q| words[q], 0, i),
                j => words[patched::COMMON + j] as i16,
            };
            assert_eq!(got, v, "round {round}: cell {i}");
        }
        // Counts per number, against the cells.
        let mut n = [0u64; 256];
        let mut common = [0u64; 3];
        patched::numbers(&words, &mut n, &mut common);
        let (values, listed) = patched::values(&words);
        for (&x, &c) in values.iter().chain(listed).zip(common.iter().chain(&n)) {
            let want = cells.iter().filter(|&&v| v == x as i16).count() as u64;
            assert_eq!(c, want, "round {round}: value {}", x as i16);
        }
        // Each width of the patch's numbers.
        sizes[width_for(listed.len()).expect("a patch").trailing_zeros() as usize] = true;
    }
    assert_eq!(sizes, [true; 4]);
}

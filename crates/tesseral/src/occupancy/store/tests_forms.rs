//! The census of a sorted cell list and the palette's packing, against the census of
//! all 512 cells and a cell-by-cell read of the packed words.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::census::Census;
use super::forms::{bits_words, palette_index, width_for, write_palette};
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

//! Every fast path held against a naive model, and the papers' worked examples.
//!
//! The shared generator and reference encoders are here; the tests are in one file
//! per topic: `addressing.rs` (encode/decode), `arith.rs` (`Space` arithmetic),
//! `papers.rs` (the papers' tables and worked examples, P-adic subtraction),
//! `notation.rs` (octal strings).

use super::digits::{self, add_by_table, add_by_table_traced, ADD_TABLE, SUB_TABLE};
use super::notation::{format_padded, format_padic, parse_octal, parse_padic};
use super::padic::padic_sub;
use super::*;
use core::cmp::Ordering;
use proptest::prelude::*;

/// A tiny seeded generator (PCG-style LCG output mix), so failures name their seed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = self.0;
        (x ^ (x >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9) ^ (x >> 32)
    }
}

const SEED: u64 = 0x7e55_e4a1_2024_0001;

/// Bit-by-bit interleave: the obviously right reference.
fn naive_encode<W: CodeWord>(p: [u64; 3]) -> W {
    let mut c = W::ZERO;
    for i in 0..W::MAX_DEPTH {
        for (axis, &v) in p.iter().enumerate() {
            if (v >> i) & 1 == 1 {
                c = c | (W::from_digit(1) << (3 * i + axis as u32));
            }
        }
    }
    c
}

fn naive_decode<W: CodeWord>(c: W) -> [u64; 3] {
    let mut p = [0u64; 3];
    for i in 0..W::MAX_DEPTH {
        let d = (c >> (3 * i)).low_digit();
        for (axis, v) in p.iter_mut().enumerate() {
            *v |= u64::from((d >> axis) & 1) << i;
        }
    }
    p
}

fn random_point(rng: &mut Rng, depth: u32) -> [u64; 3] {
    let m = if depth >= 64 { !0 } else { (1u64 << depth) - 1 };
    [rng.next() & m, rng.next() & m, rng.next() & m]
}

mod addressing;
mod arith;
mod notation;
mod papers;

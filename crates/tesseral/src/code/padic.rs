//! Tesseral subtraction by the P-adic method (Harakal & Chmúrny §3, after Bell &
//! Mason), step by step.
//!
//! To find `T_x = T_b - T_a` solve `T_a + T_x = T_b` from the least significant digit:
//! Table 2 gives the digit `x` with `a + x` ending in `b` and the carry of that sum,
//! which is added to the remaining digits of `T_a`. Strip the solved digit from both
//! sides and repeat. The process stops when an equation comes back that was met
//! before; the digits found since then repeat forever to the left. A negative result
//! (the "tesseral hypercube") is exactly such an infinite string: two's complement per
//! axis, its sign digit repeating.

use serde::Serialize;

use super::digits::SUB_TABLE;
use super::{CodeWord, Space};

/// One equation `T_a + T_x = T_b` and the digit of `T_x` it yields.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PadicStep<W> {
    /// `T_a` of this equation (the subtrahend with earlier carries folded in).
    pub ta: W,
    /// `T_b` of this equation (the minuend's remaining digits).
    pub tb: W,
    /// The last digit of `T_a`: the row of Table 2.
    pub a: u8,
    /// The last digit of `T_b`: the column of Table 2.
    pub b: u8,
    /// Table 2's carry: added to the remaining digits of `T_a`.
    pub carry: u8,
    /// Table 2's digit: the next digit of `T_x`, from the right.
    pub x: u8,
    /// `T_a` of the next equation: the remaining digits of `T_a` plus `carry`.
    pub next_ta: W,
}

/// The whole P-adic subtraction `T_b - T_a`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PadicSubtraction<W> {
    /// The equations solved, least significant digit first.
    pub steps: Vec<PadicStep<W>>,
    /// The step whose equation came back after the last step: the digits of
    /// `steps[repeat_from..]` repeat forever to the left.
    pub repeat_from: usize,
    /// `T_x` reduced to the space's digits.
    pub result: W,
}

impl<W: CodeWord> PadicSubtraction<W> {
    /// The digits that repeat forever to the left, least significant first.
    #[must_use]
    pub fn repeating_digits(&self) -> Vec<u8> {
        self.steps[self.repeat_from..].iter().map(|s| s.x).collect()
    }
}

/// `tb - ta` by the P-adic method, step by step. With `signed`, codes are read as two's
/// complement in the space (their sign digit repeats to the left); otherwise they are
/// nonnegative (zeros to the left) and the result is reduced modulo `2^depth` per axis.
/// Takes O(depth) steps of O(1) each, plus O(depth²) to spot the repeating equation.
///
/// ```
/// use tesseral::code::{padic::padic_sub, Space};
/// let s = Space::<u64>::full();
/// // Harakal & Chmúrny §3: 642 + T_x = 6530 gives T_x = 752.
/// let p = padic_sub(&s, 0o6530, 0o642, true);
/// assert_eq!(p.result, 0o752);
/// assert_eq!(p.repeating_digits(), vec![0]);
/// ```
#[must_use]
pub fn padic_sub<W: CodeWord>(space: &Space<W>, tb: W, ta: W, signed: bool) -> PadicSubtraction<W> {
    let mut seen = vec![(ta & space.mask(), tb & space.mask())];
    let mut steps = Vec::new();
    let repeat_from = loop {
        let (ta, tb) = seen[seen.len() - 1];
        let (a, b) = (ta.low_digit(), tb.low_digit());
        let (carry, x) = SUB_TABLE[usize::from(a)][usize::from(b)];
        let next_ta = space.add(space.shr_digit(ta, signed), W::from_digit(carry));
        let next = (next_ta, space.shr_digit(tb, signed));
        steps.push(PadicStep {
            ta,
            tb,
            a,
            b,
            carry,
            x,
            next_ta,
        });
        if let Some(k) = seen.iter().position(|&s| s == next) {
            break k;
        }
        seen.push(next);
    };
    let cycle = steps.len() - repeat_from;
    let mut result = W::ZERO;
    for i in 0..space.depth() as usize {
        let x = if i < steps.len() {
            steps[i].x
        } else {
            steps[repeat_from + (i - repeat_from) % cycle].x
        };
        result = result | (W::from_digit(x) << (3 * i as u32));
    }
    PadicSubtraction {
        steps,
        repeat_from,
        result,
    }
}

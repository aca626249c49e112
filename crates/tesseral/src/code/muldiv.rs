//! Tesseral multiplication and division (Harakal & Chmúrny §3: "multiplication and
//! division of tesseral numbers simultaneously realise scaling and rotation").
//!
//! The paper's source (Bell & Mason 1990) is not available, so the operations are
//! defined here, on our codes, and documented in `docs/arithmetic.md`:
//!
//! - **Multiplication** `T_a * T_b` multiplies the two's-complement coordinates axis by
//!   axis. It runs on the dilated codes: for each digit `d` of `T_b`, the axes set in
//!   `d` receive a copy of `T_a` shifted by that digit's place, added with the
//!   tesseral adder. Nothing is decoded. `7` = (1, 1, 1) is the unit; `70` = (2, 2, 2)
//!   appends a digit, which doubles.
//! - **Division** `T_b / T_a` solves `T_a * T_x = T_b` by the P-adic method, digit by
//!   digit from the least significant, as subtraction does: on an axis whose divisor is
//!   odd, the next digit of `T_x` is the parity of what is left of `T_b`, and that
//!   many copies of `T_a` are taken away before the remainder moves one digit down.
//!   The remainders come back after finitely many steps; the digits found since then
//!   repeat forever to the left, so a quotient that is not an integer is a 2-adic
//!   number (1/3 on one axis is …0101011 in binary). An even divisor is halved with
//!   the dividend first, while both are even; one that does not divide (the dividend
//!   stays odd), or a zero, is an error that names the axis.

use serde::Serialize;

use super::{Axis, Carried, CodeWord, Space};

impl<W: CodeWord> Space<W> {
    /// The bits of the axes set in `digit` (bit 0 x, 1 y, 2 z), within the space.
    #[must_use]
    pub fn axes_mask(&self, digit: u8) -> W {
        Axis::ALL
            .iter()
            .filter(|a| digit & a.unit_digit() != 0)
            .fold(W::ZERO, |m, &a| m | self.axis_mask(a))
    }

    /// `a * b`, coordinates multiplied axis by axis as unsigned numbers, by shift and
    /// add on the codes, with the axes whose product left the space reported in
    /// `carry`. The low digits are those of the two's-complement product too.
    /// O(depth) tesseral additions.
    ///
    /// ```
    /// use tesseral::code::Space;
    /// let s = Space::<u64>::new(4).unwrap();
    /// // (3, 1, 2) * (2, 2, 2) = (6, 2, 4): 70 doubles.
    /// let a = s.encode_wrapping([3, 1, 2]);
    /// assert_eq!(s.overflowing_mul(a, 0o70).code, s.encode_wrapping([6, 2, 4]));
    /// ```
    #[must_use]
    pub fn overflowing_mul(&self, a: W, b: W) -> Carried<W> {
        let d = self.depth();
        let a = a & self.mask();
        let mut acc = W::ZERO;
        let mut carry = 0u8;
        for i in 0..d {
            let digit = (b >> (3 * i)).low_digit();
            if digit == 0 {
                continue;
            }
            let part = a & self.axes_mask(digit);
            // Bits of `part` shifted past the top digit are lost on their axes.
            let lost = if i == 0 {
                W::ZERO
            } else {
                part >> (3 * (d - i))
            };
            carry |= axes_of(self, lost);
            let r = self.overflowing_add(acc, (part << (3 * i)) & self.mask());
            acc = r.code;
            carry |= r.carry;
        }
        Carried { code: acc, carry }
    }

    /// `a * b` axis by axis, wrapping modulo `2^depth` (the same for unsigned and
    /// two's-complement readings). O(depth).
    #[must_use]
    pub fn mul(&self, a: W, b: W) -> W {
        self.overflowing_mul(a, b).code
    }

    /// `a * b` axis by axis as unsigned numbers, or `None` when a product leaves
    /// `[0, 2^depth)`. O(depth).
    #[must_use]
    pub fn checked_mul(&self, a: W, b: W) -> Option<W> {
        let r = self.overflowing_mul(a, b);
        (r.carry == 0).then_some(r.code)
    }

    /// `a * b` axis by axis reading coordinates as two's complement, or `None` when a
    /// product leaves `[-2^(depth-1), 2^(depth-1))`. The magnitudes are multiplied
    /// and the signs applied, all on codes. O(depth).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// let s = Space::<u64>::new(5).unwrap();
    /// let a = s.encode_signed([3, -2, 1]).unwrap();
    /// let b = s.encode_signed([-4, -3, 7]).unwrap();
    /// assert_eq!(s.decode_signed(s.checked_mul_signed(a, b).unwrap()), [-12, 6, 7]);
    /// assert_eq!(s.checked_mul_signed(a, s.encode_signed([8, 0, 0]).unwrap()), None);
    /// ```
    #[must_use]
    pub fn checked_mul_signed(&self, a: W, b: W) -> Option<W> {
        if self.depth() == 0 {
            return Some(W::ZERO);
        }
        let (sa, sb) = (self.sign_digit(a), self.sign_digit(b));
        let r = self.overflowing_mul(self.abs_axes(a, sa), self.abs_axes(b, sb));
        if r.carry != 0 {
            return None;
        }
        // A magnitude with the top bit set fits only as -2^(depth-1) exactly.
        let negative = sa ^ sb;
        let top = self.sign_digit(r.code);
        for axis in Axis::ALL {
            let u = axis.unit_digit();
            if top & u != 0 {
                let m = self.axis_mask(axis);
                let min = m & !(m >> 3);
                if negative & u == 0 || r.code & m != min {
                    return None;
                }
            }
        }
        Some(self.abs_axes(r.code, negative))
    }

    /// `a` with the axes in `digit` negated (two's complement). O(1).
    fn abs_axes(&self, a: W, digit: u8) -> W {
        let m = self.axes_mask(digit);
        (self.neg(a) & m) | (a & self.mask() & !m)
    }

    /// `a` with the axes in `digit` moved one digit down (halved), the sign repeated
    /// when `signed`; the other axes unchanged. O(1).
    fn halve_axes(&self, a: W, digit: u8, signed: bool) -> W {
        let m = self.axes_mask(digit);
        (self.shr_digit(a, signed) & m) | (a & self.mask() & !m)
    }
}

/// The digit with bit k set where `bits` has a bit of axis k.
fn axes_of<W: CodeWord>(space: &Space<W>, bits: W) -> u8 {
    Axis::ALL
        .iter()
        .filter(|&&a| bits & space.axis_mask(a) != W::ZERO)
        .fold(0, |d, a| d | a.unit_digit())
}

/// Why a division has no 2-adic quotient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DivisionError {
    /// The divisor is zero on this axis.
    #[error("division by zero along {}", .0.name())]
    ByZero(Axis),
    /// The divisor is even on this axis and does not divide the dividend: after
    /// halving both while they are even, the divisor is still even and the dividend
    /// odd.
    #[error(
        "along {}: the divisor is even and does not divide the dividend (no 2-adic quotient)",
        .0.name()
    )]
    NotDivisible(Axis),
}

/// One equation `T_a * T_x = T_b` of a division and the digit of `T_x` it yields.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct DivisionStep<W> {
    /// What is left of the dividend.
    pub tb: W,
    /// The next digit of `T_x`, from the right: the axes where `tb` is odd.
    pub x: u8,
    /// The next remainder: `tb` minus `x`'s copies of `T_a`, one digit down.
    pub next: W,
}

/// A whole division `T_b / T_a` by the P-adic method.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Division<W> {
    /// Each halving of an even divisor: the axis halved (as a digit), with the
    /// divisor and dividend after it.
    pub halvings: Vec<(u8, W, W)>,
    /// The odd divisor the steps use.
    pub divisor: W,
    /// The equations solved, least significant digit first.
    pub steps: Vec<DivisionStep<W>>,
    /// Per axis (x, y, z): the step whose remainder on that axis came back, and the
    /// period, so the axis's bits of `steps[start..start + period]` repeat forever to
    /// the left. `None` when it did not come back within the step budget.
    pub cycles: [Option<(usize, usize)>; 3],
    /// The quotient reduced to the space's digits.
    pub result: W,
}

impl<W: CodeWord> Division<W> {
    /// Digit `i` of the quotient (from the least significant), or `None` past the
    /// steps on an axis whose period was not found.
    #[must_use]
    pub fn digit(&self, i: usize) -> Option<u8> {
        (0..3).try_fold(0u8, |d, k| {
            let j = match self.cycles[k] {
                _ if i < self.steps.len() => i,
                Some((start, period)) => start + (i - start) % period,
                None => return None,
            };
            Some(d | (self.steps[j].x & (1 << k)))
        })
    }

    /// Where the digits of the whole code start to repeat and the period: the
    /// latest start and the least common multiple of the axes' periods. `None` when
    /// an axis's period was not found.
    #[must_use]
    pub fn cycle(&self) -> Option<(usize, usize)> {
        self.cycles.iter().try_fold((0, 1), |(s, p), c| {
            let (start, period) = (*c)?;
            let g = gcd(p, period);
            Some((s.max(start), (p / g).checked_mul(period)?))
        })
    }

    /// The digits that repeat forever to the left, least significant first, when the
    /// period is at most `max` digits.
    #[must_use]
    pub fn repeating_digits(&self, max: usize) -> Option<Vec<u8>> {
        let (start, period) = self.cycle()?;
        (period <= max).then(|| {
            (start..start + period)
                .filter_map(|i| self.digit(i))
                .collect()
        })
    }

    /// The digits before the repeating ones, least significant first (all the steps
    /// when the period is not known).
    #[must_use]
    pub fn leading_digits(&self) -> Vec<u8> {
        let end = self.cycle().map_or(self.steps.len(), |c| c.0);
        (0..end).filter_map(|i| self.digit(i)).collect()
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// `tb / ta` by the P-adic method, step by step. With `signed` the codes are two's
/// complement (sign digits repeat to the left); otherwise zeros are. Steps go on
/// until every axis's remainder has come back, or for `max(depth, max_steps)` steps,
/// so `result` holds every digit of the space. Each step is O(1) plus a hash lookup
/// per axis.
///
/// # Errors
/// [`DivisionError`] naming the first axis (x, y, z) where the divisor is zero, or
/// even without dividing.
///
/// ```
/// use tesseral::code::{muldiv::padic_div, Space};
/// let s = Space::<u64>::new(8).unwrap();
/// let (b, a) = (s.encode_signed([12, -9, 1]).unwrap(), s.encode_signed([3, 3, 3]).unwrap());
/// let q = padic_div(&s, b, a, true, 64).unwrap();
/// assert_eq!(s.decode_signed(q.result)[..2], [4, -3]);
/// // 1/3 along z: the digits repeat with period two.
/// assert_eq!(q.cycles[2].unwrap().1, 2);
/// ```
pub fn padic_div<W: CodeWord>(
    space: &Space<W>,
    tb: W,
    ta: W,
    signed: bool,
    max_steps: usize,
) -> Result<Division<W>, DivisionError> {
    let (mut ta, mut tb) = (ta & space.mask(), tb & space.mask());
    let mut halvings = Vec::new();
    for axis in Axis::ALL {
        if ta & space.axis_mask(axis) == W::ZERO {
            return Err(DivisionError::ByZero(axis));
        }
    }
    // Axis by axis (x, y, z), halve both while the divisor is even.
    for axis in Axis::ALL {
        let u = axis.unit_digit();
        while ta.low_digit() & u == 0 {
            if tb.low_digit() & u != 0 {
                return Err(DivisionError::NotDivisible(axis));
            }
            ta = space.halve_axes(ta, u, signed);
            tb = space.halve_axes(tb, u, signed);
            halvings.push((u, ta, tb));
        }
    }
    // The odd divisor's upper digits: subtracting x copies of ta from an odd
    // remainder and halving is halving both (odd - odd) and subtracting.
    let ta_up = space.shr_digit(ta, signed);
    let depth = space.depth() as usize;
    let masks = Axis::ALL.map(|a| space.axis_mask(a));
    let mut steps: Vec<DivisionStep<W>> = Vec::new();
    // Each axis evolves on its own: its remainder comes back with its own period.
    let mut seen: [std::collections::HashMap<W, usize>; 3] = Default::default();
    let mut cycles: [Option<(usize, usize)>; 3] = [None; 3];
    let mut rem = tb;
    while cycles.iter().any(Option::is_none) && steps.len() < depth.max(max_steps) {
        for k in 0..3 {
            if cycles[k].is_none() {
                let state = rem & masks[k];
                match seen[k].get(&state) {
                    Some(&start) => cycles[k] = Some((start, steps.len() - start)),
                    None => {
                        seen[k].insert(state, steps.len());
                    }
                }
            }
        }
        if cycles.iter().all(Option::is_some) {
            break;
        }
        let x = rem.low_digit();
        let next = space.sub(space.shr_digit(rem, signed), ta_up & space.axes_mask(x));
        steps.push(DivisionStep { tb: rem, x, next });
        rem = next;
    }
    let mut division = Division {
        halvings,
        divisor: ta,
        steps,
        cycles,
        result: W::ZERO,
    };
    division.result = (0..depth).fold(W::ZERO, |r, i| {
        r | (W::from_digit(division.digit(i).unwrap_or(0)) << (3 * i as u32))
    });
    Ok(division)
}
/// `q v q̄` for the integer quaternion `q = (a, b, c, d)`: the rotation by
/// `2·atan2(|(b, c, d)|, a)` about `(b, c, d)` scaled by `a² + b² + c² + d²`, which maps
/// the lattice into itself. Exact (`i128`). O(1).
///
/// ```
/// use tesseral::code::muldiv::quaternion_apply;
/// // q = 1 + k (norm 2): a quarter turn about z, scaled by 2.
/// assert_eq!(quaternion_apply([1, 0, 0, 1], [1, 0, 0]), [0, 2, 0]);
/// ```
#[must_use]
pub fn quaternion_apply(q: [i64; 4], v: [i64; 3]) -> [i128; 3] {
    let w = i128::from(q[0]);
    let u = [q[1], q[2], q[3]].map(i128::from);
    let v = v.map(i128::from);
    let uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    [0, 1, 2].map(|i| (w * w - uu) * v[i] + 2 * uv * u[i] + 2 * w * cross[i])
}

//! The two's complement reading of a [`Space`]'s codes (the "tesseral hypercube").

use core::cmp::Ordering;

use super::{Axis, Space};
use crate::code::CodeWord;

impl<W: CodeWord> Space<W> {
    /// The top digit: bit `a` set when axis `a` is negative in the two's complement
    /// reading. It is also the digit that repeats forever to the left in the P-adic
    /// (infinite) form of the code.
    #[inline]
    #[must_use]
    pub fn sign_digit(&self, a: W) -> u8 {
        if self.depth == 0 {
            0
        } else {
            (a >> (3 * (self.depth - 1))).low_digit()
        }
    }

    /// Compares the `axis` coordinates of `a` and `b` read as two's complement. O(1).
    #[inline]
    #[must_use]
    pub fn cmp_axis_signed(&self, a: W, b: W, axis: Axis) -> Ordering {
        let m = self.axis[axis as usize];
        // Flipping the sign bit maps two's complement order onto unsigned order.
        let top = m & !(m >> 3);
        ((a ^ top) & m).cmp(&((b ^ top) & m))
    }

    /// The digit of axes whose two's complement sum overflowed: same input signs,
    /// different result sign.
    #[inline]
    fn signed_overflow(&self, a: W, b: W, r: W) -> u8 {
        self.sign_digit(!(a ^ b) & (a ^ r))
    }

    /// `a + b` reading coordinates as two's complement in `depth` bits, or `None` on
    /// signed overflow. O(1).
    #[inline]
    #[must_use]
    pub fn checked_add_signed(&self, a: W, b: W) -> Option<W> {
        let r = self.add(a, b);
        (self.signed_overflow(a, b, r) == 0).then_some(r)
    }

    /// `a - b` reading coordinates as two's complement, or `None` on signed overflow.
    /// O(1).
    #[inline]
    #[must_use]
    pub fn checked_sub_signed(&self, a: W, b: W) -> Option<W> {
        let r = self.sub(a, b);
        // a - b overflows when a and b differ in sign and r's sign differs from a's.
        let ov = self.sign_digit((a ^ b) & (a ^ r));
        (ov == 0).then_some(r)
    }

    /// `-a` reading coordinates as two's complement, or `None` when a coordinate is
    /// the most negative value `-2^(depth-1)`. O(1).
    #[inline]
    #[must_use]
    pub fn checked_neg_signed(&self, a: W) -> Option<W> {
        self.checked_sub_signed(W::ZERO, a)
    }
}

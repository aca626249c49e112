//! Coordinates in a [`Space`]: encoding (wrapping, signed, unsigned) and decoding.

use super::Space;
use crate::code::CodeWord;

impl<W: CodeWord> Space<W> {
    /// The code of `p`, each coordinate taken modulo `2^depth` (negative coordinates in
    /// two's complement). O(1).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// let s = Space::<u64>::new(3).unwrap();
    /// assert_eq!(s.encode_wrapping([0, -5, 0]), 0o022);
    /// ```
    #[must_use]
    pub fn encode_wrapping(&self, p: [i64; 3]) -> W {
        W::encode(
            W::coord_from_u64(p[0] as u64),
            W::coord_from_u64(p[1] as u64),
            W::coord_from_u64(p[2] as u64),
        ) & self.all
    }

    /// The code of `p` read as two's complement, or `None` when a coordinate lies
    /// outside `[-2^(depth-1), 2^(depth-1))`. O(1).
    #[must_use]
    pub fn encode_signed(&self, p: [i64; 3]) -> Option<W> {
        let Some(half) = self.half() else {
            // Depth 0: one cell, coordinate 0.
            return (p == [0; 3]).then_some(W::ZERO);
        };
        p.iter()
            .all(|&c| (-half..half).contains(&i128::from(c)))
            .then(|| self.encode_wrapping(p))
    }

    /// The code of `p`, or `None` when a coordinate lies outside `[0, 2^depth)`.
    #[must_use]
    pub fn encode_unsigned(&self, p: [u64; 3]) -> Option<W> {
        let side = 1u128 << self.depth;
        p.iter().all(|&c| u128::from(c) < side).then(|| {
            W::encode(
                W::coord_from_u64(p[0]),
                W::coord_from_u64(p[1]),
                W::coord_from_u64(p[2]),
            )
        })
    }

    fn half(&self) -> Option<i128> {
        (self.depth > 0).then(|| 1i128 << (self.depth - 1))
    }

    /// The coordinates of `code` in `[0, 2^depth)`. O(1).
    #[must_use]
    pub fn decode_unsigned(&self, code: W) -> [u64; 3] {
        (code & self.all).decode().map(W::coord_to_u64)
    }

    /// The coordinates of `code` read as two's complement. O(1).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// let s = Space::<u64>::new(4).unwrap();
    /// // -5 along y is binary 1011, spread onto the y bits: 2022.
    /// assert_eq!(s.decode_signed(0o2022), [0, -5, 0]);
    /// // In 3 digits the same bits 011 read +3: -5 does not fit [-4, 4).
    /// assert_eq!(Space::<u64>::new(3).unwrap().decode_signed(0o022), [0, 3, 0]);
    /// ```
    #[must_use]
    pub fn decode_signed(&self, code: W) -> [i64; 3] {
        let u = self.decode_unsigned(code);
        let d = self.depth;
        u.map(|c| {
            if d == 0 {
                0
            } else {
                // Sign-extend from bit d - 1.
                let shift = 64 - d;
                ((c << shift) as i64) >> shift
            }
        })
    }

    /// `code` moved one digit towards the root (divided by 2 on each axis): a logical
    /// shift, or with `signed` an arithmetic one that repeats the sign digit. O(1).
    #[must_use]
    pub fn shr_digit(&self, code: W, signed: bool) -> W {
        let code = code & self.all;
        let shifted = code >> 3;
        if signed && self.depth > 0 {
            let top = W::from_digit(self.sign_digit(code)) << (3 * (self.depth - 1));
            shifted | top
        } else {
            shifted
        }
    }
}

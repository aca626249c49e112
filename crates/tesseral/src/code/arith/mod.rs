//! Tesseral arithmetic on codes: dilated-integer addition, subtraction, negation,
//! unit steps and per-axis comparison, without decoding.
//!
//! Each axis occupies every third bit of a code. Filling the *other* axes' bits of one
//! operand with ones makes an ordinary binary carry jump over them, so one machine
//! addition per axis adds all digits at once (the dilated-integer method). This is
//! Harakal & Chmúrny §3's tesseral addition (translation) and Ahuja & Nash §3.1's
//! label arithmetic, done in O(1) word operations instead of digit by digit;
//! [`crate::code::digits`] keeps the papers' digit-by-digit tables as the reference.
//!
//! A [`Space`] of depth `D` holds codes of `D` octal digits. Ahuja & Nash drop the
//! carry out of the top digit; the `overflowing_*` methods do so and report it, the
//! `checked_*` methods return `None` instead. Negative coordinates are two's complement
//! per axis (the "tesseral hypercube"); the `*_signed` methods read codes that way.
//!
//! `mod.rs` holds the types and the unsigned arithmetic; `signed.rs` the two's
//! complement reading; `coords.rs` encoding and decoding coordinates in a space.

use core::cmp::Ordering;

use super::{CodeError, CodeWord};

mod coords;
mod signed;

/// One of the three axes: x east, y north, z up. The lattice's one axis type (also
/// `tesseral::lattice::Axis` and `tesseral::linear::Axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Axis {
    /// x, east: bit 0 of each digit.
    X = 0,
    /// y, north: bit 1 of each digit.
    Y = 1,
    /// z, up: bit 2 of each digit.
    Z = 2,
}

impl Axis {
    /// The three axes in order x, y, z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// The bit of this axis within a digit: 0, 1 or 2.
    #[inline]
    #[must_use]
    pub const fn shift(self) -> u32 {
        self as u32
    }

    /// The digit that is a unit step along this axis: 1, 2 or 4 (Ahuja & Nash Table 1).
    ///
    /// ```
    /// use tesseral::code::Axis;
    /// assert_eq!(Axis::Y.unit_digit(), 2);
    /// ```
    #[inline]
    #[must_use]
    pub const fn unit_digit(self) -> u8 {
        1 << self as u32
    }

    /// Its index as an array subscript: 0, 1 or 2.
    ///
    /// ```
    /// assert_eq!(tesseral::code::Axis::Z.index(), 2);
    /// ```
    #[inline]
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The axis's lower-case name.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

/// A code with the carry lost out of the top digit of a bounded space.
///
/// `carry` is a digit: bit `a` is set when axis `a` carried (or, for subtraction,
/// borrowed) out of the top. Ahuja & Nash's "r1057" for r275 + 011 along y is
/// `Carried { code: 0o057, carry: 2 }`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Carried<W> {
    /// The result, reduced to the space.
    pub code: W,
    /// The lost carry digit: bit 0 for x, 1 for y, 2 for z; 0 when nothing was lost.
    pub carry: u8,
}

/// A bounded space of `depth` octal digits: `2^depth` cells per axis.
///
/// All operations ignore bits of their operands above the space and return codes
/// inside it. Every operation is O(1): a few word operations per axis.
///
/// ```
/// use tesseral::code::Space;
/// // Ahuja & Nash §3.1: r057 moved +5 along y (binary 101, spread to 202) is r275.
/// let s = Space::<u64>::new(3).unwrap();
/// assert_eq!(s.add(0o57, 0o202), 0o275);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Space<W> {
    depth: u32,
    axis: [W; 3],
    all: W,
}

impl<W: CodeWord> Space<W> {
    /// A space of `depth` digits, `0 <= depth <= W::MAX_DEPTH`.
    ///
    /// # Errors
    /// [`CodeError::DepthTooLarge`] when `depth > W::MAX_DEPTH`.
    pub fn new(depth: u32) -> Result<Self, CodeError> {
        if depth > W::MAX_DEPTH {
            return Err(CodeError::DepthTooLarge {
                depth,
                max: W::MAX_DEPTH,
            });
        }
        let x = W::X_MASK & W::low_bits(3 * depth);
        Ok(Space {
            depth,
            axis: [x, x << 1, x << 2],
            all: W::low_bits(3 * depth),
        })
    }

    /// The largest space this width holds (depth `W::MAX_DEPTH`).
    #[must_use]
    pub fn full() -> Self {
        match Self::new(W::MAX_DEPTH) {
            Ok(s) => s,
            Err(_) => unreachable!("MAX_DEPTH is always a valid depth"),
        }
    }

    /// The number of octal digits.
    #[inline]
    #[must_use]
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The bits of one axis within the space.
    #[inline]
    #[must_use]
    pub fn axis_mask(&self, axis: Axis) -> W {
        self.axis[axis as usize]
    }

    /// The bits of all digits of the space.
    #[inline]
    #[must_use]
    pub fn mask(&self) -> W {
        self.all
    }

    /// Whether `code` has no bits above the space.
    #[inline]
    #[must_use]
    pub fn contains(&self, code: W) -> bool {
        code & !self.all == W::ZERO
    }

    #[inline]
    fn add_axis(a: W, b: W, m: W) -> (W, bool) {
        // Ones in every bit outside this axis carry straight through them; the carry
        // out of the axis's top bit runs through the ones above and leaves the word.
        let (s, c) = (a | !m).overflowing_add(b & m);
        (s & m, c)
    }

    #[inline]
    fn sub_axis(a: W, b: W, m: W) -> (W, bool) {
        // Zeros outside the axis pass a borrow on (0 - 0 - 1 = 1, borrow 1).
        let (s, c) = (a & m).overflowing_sub(b & m);
        (s & m, c)
    }

    /// `op` (one of [`Self::add_axis`], [`Self::sub_axis`]) on every axis, with the
    /// carries out of the top collected into a digit.
    #[inline]
    fn overflowing_per_axis(&self, a: W, b: W, op: impl Fn(W, W, W) -> (W, bool)) -> Carried<W> {
        let mut code = W::ZERO;
        let mut carry = 0;
        for (i, &m) in self.axis.iter().enumerate() {
            let (s, c) = op(a, b, m);
            code = code | s;
            carry |= u8::from(c) << i;
        }
        Carried { code, carry }
    }

    /// `op` (one of [`Self::add_axis`], [`Self::sub_axis`]) of a unit along `axis`,
    /// the other axes unchanged; a depth-0 space has no unit, so the step is lost.
    #[inline]
    fn overflowing_step(&self, a: W, axis: Axis, op: impl Fn(W, W, W) -> (W, bool)) -> Carried<W> {
        let m = self.axis[axis as usize];
        let (s, c) = op(a, m & W::low_bits(3), m);
        let unit_missing = self.depth == 0;
        Carried {
            code: (a & self.all & !m) | s,
            carry: u8::from(c || unit_missing) << axis.shift(),
        }
    }

    /// `a + b`, the translation of `a` by the vector `0b`, with the carry out of the
    /// top digit dropped. O(1).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// // Harakal & Chmúrny §3: 642 + 752 = 6530.
    /// assert_eq!(Space::<u64>::full().add(0o642, 0o752), 0o6530);
    /// ```
    #[inline]
    #[must_use]
    pub fn add(&self, a: W, b: W) -> W {
        let [x, y, z] = self.axis;
        let sx = (a | !x).wrapping_add(b & x) & x;
        let sy = (a | !y).wrapping_add(b & y) & y;
        let sz = (a | !z).wrapping_add(b & z) & z;
        sx | sy | sz
    }

    /// `a + b` with the lost carry reported (Ahuja & Nash's "carry lost"). O(1).
    ///
    /// ```
    /// use tesseral::code::{Carried, Space};
    /// let s = Space::<u64>::new(3).unwrap();
    /// assert_eq!(s.overflowing_add(0o275, 0o022), Carried { code: 0o057, carry: 2 });
    /// ```
    #[inline]
    #[must_use]
    pub fn overflowing_add(&self, a: W, b: W) -> Carried<W> {
        self.overflowing_per_axis(a, b, Self::add_axis)
    }

    /// `a + b`, or `None` when a coordinate leaves `[0, 2^depth)`. O(1).
    #[inline]
    #[must_use]
    pub fn checked_add(&self, a: W, b: W) -> Option<W> {
        let r = self.overflowing_add(a, b);
        (r.carry == 0).then_some(r.code)
    }

    /// `a - b`, the translation of `a` by the vector `b0`, wrapping per axis. O(1).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// assert_eq!(Space::<u64>::full().sub(0o6530, 0o642), 0o752);
    /// ```
    #[inline]
    #[must_use]
    pub fn sub(&self, a: W, b: W) -> W {
        let [x, y, z] = self.axis;
        let dx = (a & x).wrapping_sub(b & x) & x;
        let dy = (a & y).wrapping_sub(b & y) & y;
        let dz = (a & z).wrapping_sub(b & z) & z;
        dx | dy | dz
    }

    /// `a - b` with the borrow out of the top digit reported in `carry`. O(1).
    #[inline]
    #[must_use]
    pub fn overflowing_sub(&self, a: W, b: W) -> Carried<W> {
        self.overflowing_per_axis(a, b, Self::sub_axis)
    }

    /// `a - b`, or `None` when a coordinate would go below 0. O(1).
    #[inline]
    #[must_use]
    pub fn checked_sub(&self, a: W, b: W) -> Option<W> {
        let r = self.overflowing_sub(a, b);
        (r.carry == 0).then_some(r.code)
    }

    /// The two's complement of every axis: the displacement `-a` (Ahuja & Nash §3.1).
    /// O(1).
    ///
    /// ```
    /// use tesseral::code::Space;
    /// // -5 along y in 3 digits: binary 011, spread to 022.
    /// assert_eq!(Space::<u64>::new(3).unwrap().neg(0o202), 0o022);
    /// ```
    #[inline]
    #[must_use]
    pub fn neg(&self, a: W) -> W {
        self.sub(W::ZERO, a)
    }

    /// One step in the positive direction of `axis`, wrapping, with the lost carry.
    /// O(1).
    #[inline]
    #[must_use]
    pub fn overflowing_inc(&self, a: W, axis: Axis) -> Carried<W> {
        self.overflowing_step(a, axis, Self::add_axis)
    }

    /// One step in the positive direction of `axis`, wrapping. O(1).
    ///
    /// ```
    /// use tesseral::code::{Axis, Space};
    /// // Ahuja & Nash §3.1: r057 moved +1 along y is r075.
    /// assert_eq!(Space::<u64>::new(3).unwrap().inc(0o57, Axis::Y), 0o75);
    /// ```
    #[inline]
    #[must_use]
    pub fn inc(&self, a: W, axis: Axis) -> W {
        self.overflowing_inc(a, axis).code
    }

    /// One step in the positive direction of `axis`, or `None` at the space's edge.
    #[inline]
    #[must_use]
    pub fn checked_inc(&self, a: W, axis: Axis) -> Option<W> {
        let r = self.overflowing_inc(a, axis);
        (r.carry == 0).then_some(r.code)
    }

    /// One step in the negative direction of `axis`, wrapping, with the lost borrow.
    /// O(1).
    #[inline]
    #[must_use]
    pub fn overflowing_dec(&self, a: W, axis: Axis) -> Carried<W> {
        self.overflowing_step(a, axis, Self::sub_axis)
    }

    /// One step in the negative direction of `axis`, wrapping. O(1).
    ///
    /// ```
    /// use tesseral::code::{Axis, Space};
    /// assert_eq!(Space::<u64>::new(3).unwrap().dec(0o75, Axis::Y), 0o57);
    /// ```
    #[inline]
    #[must_use]
    pub fn dec(&self, a: W, axis: Axis) -> W {
        self.overflowing_dec(a, axis).code
    }

    /// One step in the negative direction of `axis`, or `None` at the space's edge.
    #[inline]
    #[must_use]
    pub fn checked_dec(&self, a: W, axis: Axis) -> Option<W> {
        let r = self.overflowing_dec(a, axis);
        (r.carry == 0).then_some(r.code)
    }

    /// Compares the `axis` coordinates of `a` and `b` as unsigned integers, without
    /// decoding: masking keeps the axis's bits in their order of significance. O(1).
    ///
    /// ```
    /// use tesseral::code::{Axis, Space};
    /// use core::cmp::Ordering;
    /// let s = Space::<u64>::full();
    /// // 0o45 is (1, 0, 3) and 0o6 is (0, 1, 1).
    /// assert_eq!(s.cmp_axis(0o45, 0o6, Axis::X), Ordering::Greater);
    /// assert_eq!(s.cmp_axis(0o45, 0o6, Axis::Y), Ordering::Less);
    /// ```
    #[inline]
    #[must_use]
    pub fn cmp_axis(&self, a: W, b: W, axis: Axis) -> Ordering {
        let m = self.axis[axis as usize];
        (a & m).cmp(&(b & m))
    }
}

//! The two code widths, `u64` (depth 21) and `u128` (depth 42), behind one sealed trait.
//!
//! Every algorithm in [`crate::code`] is written once, generically over [`CodeWord`];
//! a macro instantiates the trait for both widths from one template, so the magic-bits
//! masks, the BMI2 kernels and the arithmetic are never copied by hand.

use core::fmt::Debug;
use core::hash::Hash;
use core::ops::{BitAnd, BitOr, BitXor, Not, Shl, Shr};

mod sealed {
    pub trait Sealed {}
    impl Sealed for u64 {}
    impl Sealed for u128 {}
}

/// An unsigned integer that holds a tesseral code: `u64` (depth up to 21) or `u128`
/// (depth up to 42).
///
/// Bit `3i` of a code is bit `i` of x, bit `3i + 1` is bit `i` of y and bit `3i + 2`
/// is bit `i` of z (docs/conventions.md). The trait is sealed: only `u64` and `u128` implement it.
///
/// ```
/// use tesseral::code::CodeWord;
/// assert_eq!(<u64 as CodeWord>::encode(1, 0, 3), 0o45);
/// assert_eq!(<u128 as CodeWord>::decode(0o45), [1, 0, 3]);
/// ```
pub trait CodeWord:
    sealed::Sealed
    + Copy
    + Eq
    + Ord
    + Hash
    + Debug
    + Default
    + Send
    + Sync
    + 'static
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
    + Shl<u32, Output = Self>
    + Shr<u32, Output = Self>
{
    /// One coordinate: `u32` for `u64` codes, `u64` for `u128` codes.
    type Coord: Copy + Eq + Ord + Hash + Debug + Default + Send + Sync + 'static;
    /// The most octal digits (tree depth) a code of this width holds.
    const MAX_DEPTH: u32;
    /// Width of the word in bits.
    const BITS: u32;
    /// The code 0.
    const ZERO: Self;
    /// Bits `3i` for `i < MAX_DEPTH`: the x bits of every digit.
    const X_MASK: Self;

    /// Spreads the low `MAX_DEPTH` bits of `v` so that bit `i` moves to bit `3i`
    /// (portable magic bits, O(log MAX_DEPTH) shifts and masks).
    fn dilate(v: Self::Coord) -> Self;
    /// Gathers bits `3i` into bit `i`: the inverse of [`CodeWord::dilate`].
    fn undilate(self) -> Self::Coord;
    /// The code of `(x, y, z)`, portable magic bits. Bits above `MAX_DEPTH` are dropped.
    #[inline]
    fn encode(x: Self::Coord, y: Self::Coord, z: Self::Coord) -> Self {
        Self::dilate(x) | (Self::dilate(y) << 1) | (Self::dilate(z) << 2)
    }
    /// The coordinates `[x, y, z]` of a code, portable magic bits.
    #[inline]
    fn decode(self) -> [Self::Coord; 3] {
        [
            self.undilate(),
            (self >> 1).undilate(),
            (self >> 2).undilate(),
        ]
    }
    /// `self + rhs` modulo 2^BITS, with the carry out of the top bit.
    fn overflowing_add(self, rhs: Self) -> (Self, bool);
    /// `self - rhs` modulo 2^BITS, with the borrow out of the top bit.
    fn overflowing_sub(self, rhs: Self) -> (Self, bool);
    /// `self + rhs` modulo 2^BITS.
    fn wrapping_add(self, rhs: Self) -> Self;
    /// `self - rhs` modulo 2^BITS.
    fn wrapping_sub(self, rhs: Self) -> Self;
    /// The code whose lowest digit is `d & 7` and whose other digits are 0.
    fn from_digit(d: u8) -> Self;
    /// The lowest octal digit (bits 0..3).
    fn low_digit(self) -> u8;
    /// A coordinate widened to `u64`.
    fn coord_to_u64(c: Self::Coord) -> u64;
    /// The low bits of `v` as a coordinate (truncating).
    fn coord_from_u64(v: u64) -> Self::Coord;
    /// A mask of the low `bits` bits (`bits <= BITS`).
    fn low_bits(bits: u32) -> Self;

    /// [`CodeWord::encode`] with BMI2 `pdep`.
    ///
    /// # Safety
    /// The CPU must support BMI2 (see [`crate::code::Backend::detect`]). On targets other
    /// than x86-64 this is the portable encoder.
    unsafe fn encode_bmi2(x: Self::Coord, y: Self::Coord, z: Self::Coord) -> Self;
    /// [`CodeWord::decode`] with BMI2 `pext`.
    ///
    /// # Safety
    /// As for [`CodeWord::encode_bmi2`].
    unsafe fn decode_bmi2(self) -> [Self::Coord; 3];
    /// Encodes `src[i]` into `dst[i]` with `pdep`, for `i < min(len)`; O(n).
    ///
    /// # Safety
    /// As for [`CodeWord::encode_bmi2`].
    unsafe fn encode_slice_bmi2(src: &[[Self::Coord; 3]], dst: &mut [Self]);
    /// Decodes `src[i]` into `dst[i]` with `pext`, for `i < min(len)`; O(n).
    ///
    /// # Safety
    /// As for [`CodeWord::encode_bmi2`].
    unsafe fn decode_slice_bmi2(src: &[Self], dst: &mut [[Self::Coord; 3]]);
}

/// Bit `(i / g) * 3g + i % g` for each `i < n`: the layout after the magic-bits step
/// that leaves groups of `g` input bits spaced `3g` apart.
const fn group_mask_u128(g: u32, n: u32) -> u128 {
    let mut m = 0u128;
    let mut i = 0;
    while i < n {
        m |= 1u128 << ((i / g) * 3 * g + i % g);
        i += 1;
    }
    m
}

macro_rules! impl_code_word {
    ($w:ty, $coord:ty, $depth:expr, magic: $dil:ident, $undil:ident, $encm:ident, $decm:ident,
     bmi2: $enc:ident, $dec:ident, $encs:ident, $decs:ident) => {
        impl CodeWord for $w {
            type Coord = $coord;
            const MAX_DEPTH: u32 = $depth;
            const BITS: u32 = <$w>::BITS;
            const ZERO: Self = 0;
            const X_MASK: Self = group_mask_u128(1, $depth) as $w;

            #[inline]
            fn dilate(v: $coord) -> $w {
                $dil(v)
            }

            #[inline]
            fn undilate(self) -> $coord {
                $undil(self)
            }

            #[inline]
            fn encode(x: $coord, y: $coord, z: $coord) -> Self {
                $encm(x, y, z)
            }

            #[inline]
            fn decode(self) -> [$coord; 3] {
                $decm(self)
            }

            #[inline]
            fn overflowing_add(self, rhs: Self) -> (Self, bool) {
                <$w>::overflowing_add(self, rhs)
            }
            #[inline]
            fn overflowing_sub(self, rhs: Self) -> (Self, bool) {
                <$w>::overflowing_sub(self, rhs)
            }
            #[inline]
            fn wrapping_add(self, rhs: Self) -> Self {
                <$w>::wrapping_add(self, rhs)
            }
            #[inline]
            fn wrapping_sub(self, rhs: Self) -> Self {
                <$w>::wrapping_sub(self, rhs)
            }
            #[inline]
            fn from_digit(d: u8) -> Self {
                <$w>::from(d & 7)
            }
            #[inline]
            fn low_digit(self) -> u8 {
                (self & 7) as u8
            }
            #[inline]
            fn coord_to_u64(c: $coord) -> u64 {
                c as u64
            }
            #[inline]
            fn coord_from_u64(v: u64) -> $coord {
                v as $coord
            }
            #[inline]
            fn low_bits(bits: u32) -> Self {
                if bits >= <$w>::BITS {
                    !0
                } else {
                    (1 << bits) - 1
                }
            }

            #[inline]
            unsafe fn encode_bmi2(x: $coord, y: $coord, z: $coord) -> Self {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the caller guarantees BMI2 (this method's contract).
                return unsafe { bmi2::$enc(x, y, z) };
                #[cfg(not(target_arch = "x86_64"))]
                return Self::encode(x, y, z);
            }

            #[inline]
            unsafe fn decode_bmi2(self) -> [$coord; 3] {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the caller guarantees BMI2 (this method's contract).
                return unsafe { bmi2::$dec(self) };
                #[cfg(not(target_arch = "x86_64"))]
                return self.decode();
            }

            unsafe fn encode_slice_bmi2(src: &[[$coord; 3]], dst: &mut [Self]) {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the caller guarantees BMI2 (this method's contract).
                unsafe {
                    bmi2::$encs(src, dst)
                };
                #[cfg(not(target_arch = "x86_64"))]
                for (d, &[x, y, z]) in dst.iter_mut().zip(src) {
                    *d = Self::encode(x, y, z);
                }
            }

            unsafe fn decode_slice_bmi2(src: &[Self], dst: &mut [[$coord; 3]]) {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the caller guarantees BMI2 (this method's contract).
                unsafe {
                    bmi2::$decs(src, dst)
                };
                #[cfg(not(target_arch = "x86_64"))]
                for (d, &c) in dst.iter_mut().zip(src) {
                    *d = c.decode();
                }
            }
        }
    };
}

/// Magic bits for 21 bits: each step halves the groups of input bits and spreads them
/// three times as far apart (groups of 16 bits 48 apart, then 8 bits 24 apart, …).
#[inline]
fn dilate_u64(v: u32) -> u64 {
    let mut x = u64::from(v) & const { group_mask_u128(32, 21) as u64 };
    x = (x | (x << 32)) & const { group_mask_u128(16, 21) as u64 };
    x = (x | (x << 16)) & const { group_mask_u128(8, 21) as u64 };
    x = (x | (x << 8)) & const { group_mask_u128(4, 21) as u64 };
    x = (x | (x << 4)) & const { group_mask_u128(2, 21) as u64 };
    x = (x | (x << 2)) & const { group_mask_u128(1, 21) as u64 };
    x
}

/// The steps of [`dilate_u64`] in reverse.
#[inline]
fn undilate_u64(c: u64) -> u32 {
    let mut x = c & const { group_mask_u128(1, 21) as u64 };
    x = (x | (x >> 2)) & const { group_mask_u128(2, 21) as u64 };
    x = (x | (x >> 4)) & const { group_mask_u128(4, 21) as u64 };
    x = (x | (x >> 8)) & const { group_mask_u128(8, 21) as u64 };
    x = (x | (x >> 16)) & const { group_mask_u128(16, 21) as u64 };
    x = (x | (x >> 32)) & const { group_mask_u128(32, 21) as u64 };
    x as u32
}

const LOW21: u64 = (1 << 21) - 1;
const LOW63: u64 = (1 << 63) - 1;

/// A `u128` code is two `u64` codes: digits 0..21 in bits 0..63, digits 21..42 in bits
/// 63..126. Reusing the `u64` kernel on each half avoids slow two-register shifts.
#[inline]
fn dilate_u128(v: u64) -> u128 {
    let lo = dilate_u64((v & LOW21) as u32);
    let hi = dilate_u64(((v >> 21) & LOW21) as u32);
    u128::from(lo) | (u128::from(hi) << 63)
}

/// The inverse of [`dilate_u128`].
#[inline]
fn undilate_u128(c: u128) -> u64 {
    let lo = undilate_u64(c as u64 & LOW63);
    let hi = undilate_u64((c >> 63) as u64 & LOW63);
    u64::from(lo) | (u64::from(hi) << 21)
}

#[inline]
fn encode_u64(x: u32, y: u32, z: u32) -> u64 {
    dilate_u64(x) | (dilate_u64(y) << 1) | (dilate_u64(z) << 2)
}

#[inline]
fn decode_u64(c: u64) -> [u32; 3] {
    [undilate_u64(c), undilate_u64(c >> 1), undilate_u64(c >> 2)]
}

/// Two `u64` codes side by side (see [`dilate_u128`]).
#[inline]
fn encode_u128(x: u64, y: u64, z: u64) -> u128 {
    let half = |s: u32| {
        encode_u64(
            ((x >> s) & LOW21) as u32,
            ((y >> s) & LOW21) as u32,
            ((z >> s) & LOW21) as u32,
        )
    };
    u128::from(half(0)) | (u128::from(half(21)) << 63)
}

#[inline]
fn decode_u128(c: u128) -> [u64; 3] {
    let lo = decode_u64(c as u64 & LOW63);
    let hi = decode_u64((c >> 63) as u64 & LOW63);
    [0, 1, 2].map(|k| u64::from(lo[k]) | (u64::from(hi[k]) << 21))
}

impl_code_word!(u64, u32, 21, magic: dilate_u64, undilate_u64, encode_u64, decode_u64,
    bmi2: encode_u64, decode_u64, encode_slice_u64, decode_slice_u64);
impl_code_word!(u128, u64, 42, magic: dilate_u128, undilate_u128, encode_u128, decode_u128,
    bmi2: encode_u128, decode_u128, encode_slice_u128, decode_slice_u128);

/// BMI2 kernels (`pdep`/`pext`), x86-64 only. Callers must have checked that the CPU
/// supports BMI2 (`is_x86_feature_detected!("bmi2")`).
#[cfg(target_arch = "x86_64")]
pub(crate) mod bmi2 {
    use core::arch::x86_64::{_pdep_u64, _pext_u64};

    /// x bits of the 21 digits that fit in 63 bits.
    const X64: u64 = 0x1249_2492_4924_9249;
    const LOW21: u64 = 0x1f_ffff;
    const LOW63: u64 = (1 << 63) - 1;

    /// Encodes with `pdep`: one instruction per axis.
    #[inline]
    #[target_feature(enable = "bmi2")]
    pub(crate) fn encode_u64(x: u32, y: u32, z: u32) -> u64 {
        _pdep_u64(u64::from(x), X64)
            | _pdep_u64(u64::from(y), X64 << 1)
            | _pdep_u64(u64::from(z), X64 << 2)
    }

    /// Decodes with `pext`: one instruction per axis.
    #[inline]
    #[target_feature(enable = "bmi2")]
    pub(crate) fn decode_u64(c: u64) -> [u32; 3] {
        [
            _pext_u64(c, X64) as u32,
            _pext_u64(c, X64 << 1) as u32,
            _pext_u64(c, X64 << 2) as u32,
        ]
    }

    /// Encodes a `u128` code: digits 0..21 in bits 0..63, digits 21..42 in bits 63..126.
    #[inline]
    #[target_feature(enable = "bmi2")]
    pub(crate) fn encode_u128(x: u64, y: u64, z: u64) -> u128 {
        let lo = encode_u64((x & LOW21) as u32, (y & LOW21) as u32, (z & LOW21) as u32);
        let hi = encode_u64(
            ((x >> 21) & LOW21) as u32,
            ((y >> 21) & LOW21) as u32,
            ((z >> 21) & LOW21) as u32,
        );
        u128::from(lo) | (u128::from(hi) << 63)
    }

    /// Decodes a `u128` code.
    #[inline]
    #[target_feature(enable = "bmi2")]
    pub(crate) fn decode_u128(c: u128) -> [u64; 3] {
        let lo = decode_u64(c as u64 & LOW63);
        let hi = decode_u64((c >> 63) as u64 & LOW63);
        [
            u64::from(lo[0]) | (u64::from(hi[0]) << 21),
            u64::from(lo[1]) | (u64::from(hi[1]) << 21),
            u64::from(lo[2]) | (u64::from(hi[2]) << 21),
        ]
    }

    macro_rules! slice_kernels {
        ($encs:ident, $decs:ident, $enc:ident, $dec:ident, $w:ty, $coord:ty) => {
            /// The `pdep` encoder over a slice; the loop is compiled with BMI2 enabled so
            /// that `pdep` inlines.
            #[target_feature(enable = "bmi2")]
            pub(crate) fn $encs(src: &[[$coord; 3]], dst: &mut [$w]) {
                for (d, &[x, y, z]) in dst.iter_mut().zip(src) {
                    *d = $enc(x, y, z);
                }
            }

            /// The `pext` decoder over a slice.
            #[target_feature(enable = "bmi2")]
            pub(crate) fn $decs(src: &[$w], dst: &mut [[$coord; 3]]) {
                for (d, &c) in dst.iter_mut().zip(src) {
                    *d = $dec(c);
                }
            }
        };
    }
    slice_kernels!(
        encode_slice_u64,
        decode_slice_u64,
        encode_u64,
        decode_u64,
        u64,
        u32
    );
    slice_kernels!(
        encode_slice_u128,
        decode_slice_u128,
        encode_u128,
        decode_u128,
        u128,
        u64
    );
}

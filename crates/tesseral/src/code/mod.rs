//! Tesseral addressing and arithmetic: (x, y, z) to and from tesseral (Morton) codes,
//! and translation by arithmetic on the codes themselves.
//!
//! A code interleaves the coordinate bits: bit `3i` is bit `i` of x, bit `3i+1` is
//! bit `i` of y and bit `3i+2` is bit `i` of z. Read in octal, its digits are the
//! child labels `x + 2y + 4z` on the path from the root, most significant first
//! (Harakal & Chmúrny §3 "tesseral addressing"; Ahuja & Nash §3.1 labels).
//!
//! * Widths: `u64` codes cover depth up to [`MAX_DEPTH_U64`] (21), `u128` codes up to
//!   [`MAX_DEPTH_U128`] (42). Both implement [`CodeWord`]; everything else is generic
//!   and written once.
//! * Addressing: [`encode`]/[`decode`] (portable magic bits, inlined), and the slice
//!   kernels in [`batch`] that pick BMI2 `pdep`/`pext` at run time ([`Backend`]).
//!   Single codes use magic bits: a run-time CPU check per call, and a call that
//!   cannot be inlined, would cost more than `pdep` saves; slices pay the check once.
//! * Arithmetic: [`Space`] (a bounded space of `D` digits) adds, subtracts, negates,
//!   steps and compares codes without decoding them; carries out of the top are
//!   dropped and reported ([`Carried`]), or refused (`checked_*`).
//! * The papers: [`digits`] computes their tables and keeps the digit-by-digit adder
//!   as the reference; [`padic`] does the P-adic subtraction step by step;
//!   [`notation`] reads and writes octal strings, including `...6062` for negative
//!   (repeating) codes.

mod arith;
pub mod batch;
pub mod digits;
mod error;
pub mod muldiv;
pub mod notation;
pub mod padic;
mod word;

pub use arith::{Axis, Carried, Space};
pub use batch::Backend;
pub use error::{CodeError, ParseCodeError};
pub use word::CodeWord;

/// The deepest tree whose codes fit a `u64`: 21 octal digits, 63 bits.
pub const MAX_DEPTH_U64: u32 = 21;

/// The deepest tree whose codes fit a `u128`: 42 octal digits, 126 bits.
pub const MAX_DEPTH_U128: u32 = 42;

/// Spreads the low 21 bits of `v` so that bit `i` moves to bit `3i`.
///
/// ```
/// assert_eq!(tesseral::code::dilate3(0b101), 0o101);
/// ```
#[inline]
#[must_use]
pub fn dilate3(v: u32) -> u64 {
    <u64 as CodeWord>::dilate(v)
}

/// Gathers bits `3i` of `d` into bit `i`: the inverse of [`dilate3`].
///
/// ```
/// assert_eq!(tesseral::code::undilate3(0o101), 0b101);
/// ```
#[inline]
#[must_use]
pub fn undilate3(d: u64) -> u32 {
    d.undilate()
}

/// The tesseral code of `(x, y, z)`; each coordinate keeps its low 21 bits.
///
/// ```
/// // docs/conventions.md: (1, 0, 3) has the octal code 45.
/// assert_eq!(tesseral::code::encode(1, 0, 3), 0o45);
/// ```
#[inline]
#[must_use]
pub fn encode(x: u32, y: u32, z: u32) -> u64 {
    <u64 as CodeWord>::encode(x, y, z)
}

/// The coordinates `[x, y, z]` of a tesseral code.
///
/// ```
/// assert_eq!(tesseral::code::decode(0o45), [1, 0, 3]);
/// ```
#[inline]
#[must_use]
pub fn decode(code: u64) -> [u32; 3] {
    code.decode()
}

/// The `u128` tesseral code of `(x, y, z)`; each coordinate keeps its low 42 bits.
///
/// ```
/// let c = tesseral::code::encode_wide(1 << 41, 0, 3);
/// assert_eq!(tesseral::code::decode_wide(c), [1 << 41, 0, 3]);
/// ```
#[inline]
#[must_use]
pub fn encode_wide(x: u64, y: u64, z: u64) -> u128 {
    <u128 as CodeWord>::encode(x, y, z)
}

/// The coordinates `[x, y, z]` of a `u128` tesseral code.
#[inline]
#[must_use]
pub fn decode_wide(code: u128) -> [u64; 3] {
    code.decode()
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_muldiv;

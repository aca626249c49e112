//! Errors of the `code` module.

use thiserror::Error;

/// What can go wrong with tesseral codes.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum CodeError {
    /// A space was asked for more digits than the code width holds.
    #[error("depth {depth} exceeds the maximum {max} for this code width")]
    DepthTooLarge {
        /// The depth asked for.
        depth: u32,
        /// The most the width holds.
        max: u32,
    },
    /// A batch kernel was asked for a backend this CPU lacks.
    #[error("the {0:?} backend is not available on this CPU")]
    BackendUnavailable(super::Backend),
    /// Source and destination slices of a batch operation differ in length.
    #[error("slice lengths differ: {src} codes in, room for {dst}")]
    LengthMismatch {
        /// Length of the input slice.
        src: usize,
        /// Length of the output slice.
        dst: usize,
    },
}

/// Why a string is not a tesseral code.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum ParseCodeError {
    /// The string holds no digits.
    #[error("empty code: expected octal digits 0-7")]
    Empty,
    /// A character is not an octal digit.
    #[error("{found:?} at position {position} is not an octal digit (0-7)")]
    InvalidDigit {
        /// The offending character.
        found: char,
        /// Its position, counted in characters from 1.
        position: usize,
    },
    /// More digits than the space holds.
    #[error("{digits} digits, but the space holds at most {max}")]
    TooManyDigits {
        /// Digits in the string.
        digits: usize,
        /// The most the space holds.
        max: usize,
    },
}

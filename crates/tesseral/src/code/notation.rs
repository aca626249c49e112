//! Codes written as octal digit strings, most significant digit first.
//!
//! A bounded space of `D` digits writes every code with exactly `D` digits
//! ([`format_padded`]). The signed (P-adic) notation writes a code whose sign digit is
//! not 0 with its repeating digit after `...`: `...6062` stands for `…666062`, the code
//! of `(0, -5, -6)` ([`format_padic`], [`parse_padic`]).

use super::{CodeWord, ParseCodeError, Space};

/// Parses the octal digits of `s` (at most `max_digits` of them, leading zeros
/// counted). O(len).
///
/// # Errors
/// [`ParseCodeError`] for an empty string, a character other than `0`-`7`, or more
/// than `max_digits` digits.
///
/// ```
/// use tesseral::code::notation::parse_octal;
/// assert_eq!(parse_octal::<u64>("057", 3), Ok(0o57));
/// assert!(parse_octal::<u64>("0578", 4).is_err());
/// ```
pub fn parse_octal<W: CodeWord>(s: &str, max_digits: u32) -> Result<W, ParseCodeError> {
    parse_digits(s, 0, max_digits as usize)
}

fn parse_digits<W: CodeWord>(s: &str, offset: usize, max: usize) -> Result<W, ParseCodeError> {
    if s.is_empty() {
        return Err(ParseCodeError::Empty);
    }
    let mut code = W::ZERO;
    let mut n = 0;
    for (i, ch) in s.chars().enumerate() {
        let d = match ch {
            '0'..='7' => ch as u8 - b'0',
            _ => {
                return Err(ParseCodeError::InvalidDigit {
                    found: ch,
                    position: offset + i + 1,
                })
            }
        };
        n += 1;
        if n <= max {
            code = (code << 3) | W::from_digit(d);
        }
    }
    if n > max {
        return Err(ParseCodeError::TooManyDigits { digits: n, max });
    }
    Ok(code)
}

/// Parses a code in the signed notation of `space`: plain digits for a code whose
/// coordinates are nonnegative, or `...r` followed by digits, where `r` repeats to the
/// left up to the top of the space. Plain digits may fill at most `depth - 1`
/// positions, so that the sign digit stays 0. O(len).
///
/// # Errors
/// [`ParseCodeError`] as for [`parse_octal`].
///
/// ```
/// use tesseral::code::{notation::parse_padic, Space};
/// let s = Space::<u64>::new(6).unwrap();
/// assert_eq!(parse_padic::<u64>("...6062", &s), Ok(0o666062));
/// assert_eq!(parse_padic::<u64>("752", &s), Ok(0o752));
/// ```
pub fn parse_padic<W: CodeWord>(s: &str, space: &Space<W>) -> Result<W, ParseCodeError> {
    let finite_max = space.depth().saturating_sub(1) as usize;
    let rest = s.strip_prefix("...").or_else(|| s.strip_prefix('…'));
    let Some(rest) = rest else {
        return parse_digits(s, 0, finite_max);
    };
    let offset = s.chars().count() - rest.chars().count();
    let mut chars = rest.chars();
    let r = match chars.next() {
        None => return Err(ParseCodeError::Empty),
        Some(ch @ '0'..='7') => ch as u8 - b'0',
        Some(ch) => {
            return Err(ParseCodeError::InvalidDigit {
                found: ch,
                position: offset + 1,
            })
        }
    };
    let finite_str = chars.as_str();
    let finite: W = if finite_str.is_empty() {
        W::ZERO
    } else {
        parse_digits(finite_str, offset + 1, finite_max).map_err(|e| match e {
            ParseCodeError::TooManyDigits { digits, max } => ParseCodeError::TooManyDigits {
                digits: digits + 1,
                max: max + 1,
            },
            e => e,
        })?
    };
    let n = finite_str.chars().count() as u32;
    let mut code = finite;
    for i in n..space.depth() {
        code = code | (W::from_digit(r) << (3 * i));
    }
    Ok(code & space.mask())
}

/// The digits of `code` in a space of `depth` digits, all of them, leading zeros
/// included. O(depth).
///
/// ```
/// use tesseral::code::notation::format_padded;
/// assert_eq!(format_padded(0o57u64, 3), "057");
/// ```
#[must_use]
pub fn format_padded<W: CodeWord>(code: W, depth: u32) -> String {
    (0..depth)
        .rev()
        .map(|i| char::from(b'0' + (code >> (3 * i)).low_digit()))
        .collect()
}

/// The shortest signed notation of `code` in `space`: plain digits without leading
/// zeros when the sign digit is 0, else `...r` and the digits below the highest digit
/// that differs from `r`. O(depth).
///
/// ```
/// use tesseral::code::{notation::format_padic, Space};
/// let s = Space::<u64>::new(6).unwrap();
/// assert_eq!(format_padic(0o666062u64, &s), "...6062");
/// assert_eq!(format_padic(0o000752u64, &s), "752");
/// assert_eq!(format_padic(0o111111u64, &s), "...1");
/// ```
#[must_use]
pub fn format_padic<W: CodeWord>(code: W, space: &Space<W>) -> String {
    let depth = space.depth();
    let r = space.sign_digit(code);
    let digit = |i: u32| (code >> (3 * i)).low_digit();
    let top = (0..depth).rev().find(|&i| digit(i) != r);
    let finite: String = match top {
        Some(t) => (0..=t).rev().map(|i| char::from(b'0' + digit(i))).collect(),
        None => String::new(),
    };
    if r == 0 {
        if finite.is_empty() {
            "0".to_owned()
        } else {
            finite
        }
    } else {
        format!("...{r}{finite}")
    }
}

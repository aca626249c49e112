//! Tesseral addressing: (x, y, z) to and from tesseral (Morton) codes.
//!
//! A code interleaves the coordinate bits: bit `3i` is bit `i` of x, bit `3i+1` is
//! bit `i` of y and bit `3i+2` is bit `i` of z. Read in octal, its digits are the
//! child labels `x + 2y + 4z` on the path from the root, most significant first.
//!
//! `u64` codes cover depth up to [`MAX_DEPTH_U64`] (21).

/// The deepest tree whose codes fit a `u64`: 21 octal digits, 63 bits.
pub const MAX_DEPTH_U64: u32 = 21;

/// Spreads the low 21 bits of `v` so that bit `i` moves to bit `3i`.
#[inline]
#[must_use]
pub fn dilate3(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// Gathers bits `3i` of `d` into bit `i`: the inverse of [`dilate3`].
#[inline]
#[must_use]
pub fn undilate3(d: u64) -> u32 {
    let mut x = d & 0x1249_2492_4924_9249;
    x = (x | (x >> 2)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x >> 4)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x >> 8)) & 0x001f_0000_ff00_00ff;
    x = (x | (x >> 16)) & 0x001f_0000_0000_ffff;
    x = (x | (x >> 32)) & 0x1f_ffff;
    x as u32
}

/// The tesseral code of `(x, y, z)`; each coordinate keeps its low 21 bits.
///
/// ```
/// // DESIGN.md: (1, 0, 3) has the octal code 45.
/// assert_eq!(tesseral::code::encode(1, 0, 3), 0o45);
/// ```
#[inline]
#[must_use]
pub fn encode(x: u32, y: u32, z: u32) -> u64 {
    dilate3(x) | (dilate3(y) << 1) | (dilate3(z) << 2)
}

/// The coordinates `[x, y, z]` of a tesseral code.
///
/// ```
/// assert_eq!(tesseral::code::decode(0o45), [1, 0, 3]);
/// ```
#[inline]
#[must_use]
pub fn decode(code: u64) -> [u32; 3] {
    [undilate3(code), undilate3(code >> 1), undilate3(code >> 2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive_encode(x: u32, y: u32, z: u32) -> u64 {
        (0..21).fold(0, |c, i| {
            c | (u64::from(x >> i & 1) << (3 * i))
                | (u64::from(y >> i & 1) << (3 * i + 1))
                | (u64::from(z >> i & 1) << (3 * i + 2))
        })
    }

    #[test]
    fn encode_matches_bit_by_bit_reference() {
        let mut s = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..10_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let (x, y, z) = (
                (s >> 1) as u32 & 0x1f_ffff,
                (s >> 22) as u32 & 0x1f_ffff,
                (s >> 43) as u32 & 0x1f_ffff,
            );
            let c = encode(x, y, z);
            assert_eq!(c, naive_encode(x, y, z));
            assert_eq!(decode(c), [x, y, z]);
        }
    }
}

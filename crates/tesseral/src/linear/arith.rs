//! Tesseral (dilated-integer) arithmetic on codes, private to the octree modules.
//!
//! These few lines duplicate what `crate::code` is growing (tesseral add and
//! subtract); they live here so that translation does not wait on it. Each axis of a
//! code is a dilated integer (its bits every third position); adding two of them is
//! an ordinary addition once the other axes' bits are filled with ones, so that
//! carries jump over them: `((a | !mask) + (b & mask)) & mask`.

/// The x bits of a code: bit `3i` for every digit `i`.
pub(crate) const MASK_X: u64 = 0x9249_2492_4924_9249 & ((1 << 63) - 1);

/// The bits of axis `axis` (0 = x, 1 = y, 2 = z).
#[inline]
pub(crate) const fn axis_mask(axis: usize) -> u64 {
    (MASK_X << axis) & ((1 << 63) - 1)
}

/// Tesseral addition of two codes, every axis modulo `2^21` (carries out of the top
/// digit are dropped, as in Ahuja & Nash §3.1).
#[inline]
pub(crate) fn add(a: u64, b: u64) -> u64 {
    let mut sum = 0;
    for axis in 0..3 {
        let m = axis_mask(axis);
        sum |= ((a | !m).wrapping_add(b & m)) & m;
    }
    sum
}

/// The code of a displacement whose components are taken modulo `2^21` (two's
/// complement for negative components, the "tesseral hypercube").
#[inline]
pub(crate) fn displacement_code(t: [i64; 3]) -> u64 {
    let c = |v: i64| (v & 0x1f_ffff) as u32;
    crate::code::encode(c(t[0]), c(t[1]), c(t[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::code::{decode, encode};

    #[test]
    fn addition_is_per_axis_modular_addition() {
        let mut s = 0x1234_5678_9abc_def1_u64;
        for _ in 0..10_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let a = [
                s as u32 & 0x1f_ffff,
                (s >> 21) as u32 & 0x1f_ffff,
                (s >> 42) as u32 & 0x1f_ffff,
            ];
            let t = [
                (s >> 3) as i64 % 5000 - 2500,
                (s >> 17) as i64 % 70,
                -((s >> 29) as i64 % 1000),
            ];
            let sum = add(encode(a[0], a[1], a[2]), displacement_code(t));
            let want: [u32; 3] =
                std::array::from_fn(|i| ((i64::from(a[i]) + t[i]).rem_euclid(1 << 21)) as u32);
            assert_eq!(decode(sum), want, "seed-free xorshift, a={a:?} t={t:?}");
        }
    }

    #[test]
    fn harakal_chmurny_sum() {
        // 642 + 752 = 6530 (octal), DESIGN.md; it holds in both digit conventions.
        assert_eq!(add(0o642, 0o752), 0o6530);
    }
}

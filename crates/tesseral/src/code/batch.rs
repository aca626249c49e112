//! Encoding and decoding whole slices, with the fastest kernel this CPU has.
//!
//! The BMI2 instructions `pdep`/`pext` scatter and gather bits under a mask in one
//! instruction each, so a code costs three of them. Whether the CPU has them is
//! checked at run time (once per slice, the answer is cached by `std`); elsewhere the
//! portable magic-bits kernel runs. Both are tested against a bit-by-bit reference.

use super::{CodeError, CodeWord, Space};

/// Which kernel encodes and decodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Portable shifts and masks (O(log depth) steps per coordinate).
    MagicBits,
    /// x86-64 BMI2 `pdep`/`pext`, one instruction per coordinate.
    Bmi2,
}

impl Backend {
    /// The fastest backend this CPU supports.
    ///
    /// ```
    /// use tesseral::code::Backend;
    /// assert!(Backend::detect().is_available());
    /// ```
    #[must_use]
    pub fn detect() -> Backend {
        if Backend::Bmi2.is_available() {
            Backend::Bmi2
        } else {
            Backend::MagicBits
        }
    }

    /// Whether this CPU can run the backend.
    #[must_use]
    pub fn is_available(self) -> bool {
        match self {
            Backend::MagicBits => true,
            #[cfg(target_arch = "x86_64")]
            Backend::Bmi2 => std::arch::is_x86_feature_detected!("bmi2"),
            #[cfg(not(target_arch = "x86_64"))]
            Backend::Bmi2 => false,
        }
    }
}

#[inline(always)]
fn encode_magic<W: CodeWord>(src: &[[W::Coord; 3]], dst: &mut [W]) {
    for (d, &[x, y, z]) in dst.iter_mut().zip(src) {
        *d = W::encode(x, y, z);
    }
}

#[inline(always)]
fn decode_magic<W: CodeWord>(src: &[W], dst: &mut [[W::Coord; 3]]) {
    for (d, &c) in dst.iter_mut().zip(src) {
        *d = c.decode();
    }
}

/// The same magic-bits loops compiled with AVX2 enabled, so that the compiler can run
/// four codes per instruction. Same algorithm, same results; chosen at run time.
#[cfg(target_arch = "x86_64")]
mod wide {
    use super::{add_loop, decode_magic, encode_magic, translate_loop, CodeWord, Space};

    #[target_feature(enable = "avx2")]
    pub(super) fn translate_avx2<W: CodeWord>(space: &Space<W>, codes: &mut [W], by: W) {
        translate_loop(space, codes, by);
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn add_avx2<W: CodeWord>(space: &Space<W>, a: &[W], b: &[W], out: &mut [W]) {
        add_loop(space, a, b, out);
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn encode_magic_avx2<W: CodeWord>(src: &[[W::Coord; 3]], dst: &mut [W]) {
        encode_magic(src, dst);
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn decode_magic_avx2<W: CodeWord>(src: &[W], dst: &mut [[W::Coord; 3]]) {
        decode_magic(src, dst);
    }
}

fn check_len(src: usize, dst: usize) -> Result<(), CodeError> {
    if src == dst {
        Ok(())
    } else {
        Err(CodeError::LengthMismatch { src, dst })
    }
}

/// Encodes `src[i]` into `dst[i]` with the fastest backend. O(n).
///
/// # Errors
/// [`CodeError::LengthMismatch`] when the slices differ in length.
///
/// ```
/// use tesseral::code::batch::encode_slice;
/// let mut out = [0u64; 2];
/// encode_slice(&[[1, 0, 3], [0, 0, 1]], &mut out).unwrap();
/// assert_eq!(out, [0o45, 0o4]);
/// ```
pub fn encode_slice<W: CodeWord>(src: &[[W::Coord; 3]], dst: &mut [W]) -> Result<(), CodeError> {
    encode_slice_with(Backend::detect(), src, dst)
}

/// Encodes `src[i]` into `dst[i]` with the given backend. O(n).
///
/// # Errors
/// [`CodeError::LengthMismatch`] when the slices differ in length,
/// [`CodeError::BackendUnavailable`] when the CPU lacks the backend.
pub fn encode_slice_with<W: CodeWord>(
    backend: Backend,
    src: &[[W::Coord; 3]],
    dst: &mut [W],
) -> Result<(), CodeError> {
    check_len(src.len(), dst.len())?;
    match backend {
        Backend::MagicBits => {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: AVX2 support was checked just above.
                unsafe { wide::encode_magic_avx2(src, dst) };
                return Ok(());
            }
            encode_magic(src, dst);
        }
        Backend::Bmi2 => {
            if !backend.is_available() {
                return Err(CodeError::BackendUnavailable(backend));
            }
            // SAFETY: BMI2 support was checked just above.
            unsafe { W::encode_slice_bmi2(src, dst) };
        }
    }
    Ok(())
}

/// Decodes `src[i]` into `dst[i]` with the fastest backend. O(n).
///
/// # Errors
/// [`CodeError::LengthMismatch`] when the slices differ in length.
pub fn decode_slice<W: CodeWord>(src: &[W], dst: &mut [[W::Coord; 3]]) -> Result<(), CodeError> {
    decode_slice_with(Backend::detect(), src, dst)
}

/// Decodes `src[i]` into `dst[i]` with the given backend. O(n).
///
/// # Errors
/// [`CodeError::LengthMismatch`] when the slices differ in length,
/// [`CodeError::BackendUnavailable`] when the CPU lacks the backend.
pub fn decode_slice_with<W: CodeWord>(
    backend: Backend,
    src: &[W],
    dst: &mut [[W::Coord; 3]],
) -> Result<(), CodeError> {
    check_len(src.len(), dst.len())?;
    match backend {
        Backend::MagicBits => {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: AVX2 support was checked just above.
                unsafe { wide::decode_magic_avx2(src, dst) };
                return Ok(());
            }
            decode_magic(src, dst);
        }
        Backend::Bmi2 => {
            if !backend.is_available() {
                return Err(CodeError::BackendUnavailable(backend));
            }
            // SAFETY: BMI2 support was checked just above.
            unsafe { W::decode_slice_bmi2(src, dst) };
        }
    }
    Ok(())
}

/// Translates every code by `by` in place (tesseral addition, carries out of the
/// space dropped). O(n), a dozen word operations per code, no decoding.
///
/// ```
/// use tesseral::code::{batch::translate_slice, Space};
/// let mut codes = [0o57u64, 0o75];
/// translate_slice(&Space::new(3).unwrap(), &mut codes, 0o2);
/// assert_eq!(codes, [0o75, 0o77]);
/// ```
pub fn translate_slice<W: CodeWord>(space: &Space<W>, codes: &mut [W], by: W) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 support was checked just above.
        unsafe { wide::translate_avx2(space, codes, by) };
        return;
    }
    translate_loop(space, codes, by);
}

/// `out[i] = a[i] + b[i]` in `space` (carries out of the space dropped). O(n), no
/// decoding; the loop runs with AVX2 where the CPU has it.
///
/// # Errors
/// [`CodeError::LengthMismatch`] when the three slices differ in length.
///
/// ```
/// use tesseral::code::{batch::add_slices, Space};
/// let mut out = [0u64; 2];
/// add_slices(&Space::full(), &[0o642, 0o57], &[0o752, 0o2], &mut out).unwrap();
/// assert_eq!(out, [0o6530, 0o75]);
/// ```
pub fn add_slices<W: CodeWord>(
    space: &Space<W>,
    a: &[W],
    b: &[W],
    out: &mut [W],
) -> Result<(), CodeError> {
    check_len(a.len(), out.len())?;
    check_len(b.len(), out.len())?;
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 support was checked just above.
        unsafe { wide::add_avx2(space, a, b, out) };
        return Ok(());
    }
    add_loop(space, a, b, out);
    Ok(())
}

#[inline(always)]
fn translate_loop<W: CodeWord>(space: &Space<W>, codes: &mut [W], by: W) {
    for c in codes {
        *c = space.add(*c, by);
    }
}

#[inline(always)]
fn add_loop<W: CodeWord>(space: &Space<W>, a: &[W], b: &[W], out: &mut [W]) {
    for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
        *o = space.add(x, y);
    }
}

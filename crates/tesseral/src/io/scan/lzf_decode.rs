//! LZF decompression (liblzf's format, as PCL's `binary_compressed` uses it), streamed
//! through a window of the last 8 KiB, bounds-checked, every error naming the byte
//! offset of the control byte at fault.
//!
//! The stream is a sequence of runs, each starting with a control byte `c`:
//! - `c < 32`: a literal, the next `c + 1` bytes copied as they are;
//! - else a back reference of `(c >> 5) + 2` bytes (when `c >> 5` is 7, the next byte
//!   is added to it), copied from `((c & 31) << 8 | next byte) + 1` bytes back from
//!   the end of the output (overlapping copies repeat the bytes).
//!
//! We do not use the `lzf` crate here: its `decompress` keeps the output position in
//! an `i32`, so an output of 2 GiB or more panics (an index out of bounds), and it
//! needs the whole output in memory. A back reference reaches at most 8 KiB back, so
//! a window of that much, handed on in pieces, is all a reader needs to hold.

use crate::io::FormatError;

/// How far back a reference may reach.
const WINDOW: usize = 8192;
/// How many new bytes the window gathers before they are handed on.
const PIECE: usize = 256 * 1024;

/// Decompresses `input` (which starts at byte `at` of the file), which must give
/// exactly `size` bytes. The output is handed to `sink` in pieces as
/// `sink(start, bytes, new)`: `bytes` are the output from offset `start`, of which
/// those from offset `new` on have not been handed on before; the bytes before
/// `new` (up to 8 KiB of them) are the ones handed on last, kept so that a value cut
/// between two pieces can be read whole.
///
/// # Errors
/// [`FormatError::Corrupt`] naming the byte offset of a run that is cut short,
/// refers back before the start of the output or past `size`, or a stream that
/// ends short of `size`.
pub(crate) fn decompress(
    input: &[u8],
    at: usize,
    size: usize,
    mut sink: impl FnMut(usize, &[u8], usize),
) -> Result<(), FormatError> {
    let corrupt = |i: usize, m: &str| FormatError::corrupt(format!("byte {}: {m}", at + i));
    // The window: output bytes from offset `start`; those from `start + handed` on
    // are new.
    let mut buf: Vec<u8> = Vec::with_capacity(WINDOW + PIECE + 300);
    let (mut start, mut handed) = (0usize, 0usize);
    let mut i = 0;
    while i < input.len() {
        let ctrl = usize::from(input[i]);
        let out = start + buf.len();
        if ctrl < 32 {
            let n = ctrl + 1;
            let lit = input
                .get(i + 1..i + 1 + n)
                .ok_or_else(|| corrupt(i, "the compressed data ends inside a literal run"))?;
            if n > size - out {
                return Err(corrupt(
                    i,
                    "the compressed data gives more than the declared size",
                ));
            }
            buf.extend_from_slice(lit);
            i += 1 + n;
        } else {
            let mut len = ctrl >> 5;
            let mut j = i + 1;
            if len == 7 {
                len += usize::from(*input.get(j).ok_or_else(|| {
                    corrupt(i, "the compressed data ends inside a back reference")
                })?);
                j += 1;
            }
            let low = *input
                .get(j)
                .ok_or_else(|| corrupt(i, "the compressed data ends inside a back reference"))?;
            let back = ((ctrl & 31) << 8 | usize::from(low)) + 1;
            let len = len + 2;
            if back > buf.len() {
                // The window holds all of the last 8 KiB, so only a reference before
                // the start of the output reaches past it.
                return Err(corrupt(i, "a back reference before the start of the data"));
            }
            if len > size - out {
                return Err(corrupt(
                    i,
                    "the compressed data gives more than the declared size",
                ));
            }
            let from = buf.len() - back;
            // The bytes from `from` repeat with period `back`; copy as many as there
            // are each time, doubling.
            let mut done = 0;
            while done < len {
                let k = (len - done).min(back + done);
                buf.extend_from_within(from..from + k);
                done += k;
            }
            i = j + 1;
        }
        if buf.len() - handed >= PIECE {
            sink(start, &buf, start + handed);
            let drop = buf.len() - WINDOW;
            buf.drain(..drop);
            start += drop;
            handed = buf.len();
        }
    }
    let out = start + buf.len();
    if out != size {
        return Err(corrupt(
            input.len(),
            &format!("the compressed data ends after {out} of {size} bytes"),
        ));
    }
    if buf.len() > handed {
        sink(start, &buf, start + handed);
    }
    Ok(())
}

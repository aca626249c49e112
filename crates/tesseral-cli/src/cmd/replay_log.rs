//! The operations log of `tesseral replay`: one operation per line. Plain `std`
//! code with no CLI dependencies, so that the fuzz target `replay` (in `fuzz/`)
//! includes this very file and fuzzes the parser the binary uses.

use std::io::{BufRead, Read};

/// The longest line accepted, in bytes; a longer one is an error (so a hostile file
/// without newlines cannot make us buffer it whole).
pub const MAX_LINE: usize = 4096;

/// What a line asks for.
pub enum Op {
    /// `+ x y z`.
    Insert([i64; 3]),
    /// `- x y z`.
    Remove([i64; 3]),
    /// `? x y z`.
    Query([i64; 3]),
    /// A blank line or a comment.
    Skip,
}

/// Parses one line (without its newline).
///
/// # Errors
/// A message naming what is wrong.
pub fn parse_line(line: &str) -> Result<Op, String> {
    let line = line.trim();
    if line.is_empty() || line.starts_with('#') {
        return Ok(Op::Skip);
    }
    let mut words = line.split_whitespace();
    let op = words.next().unwrap_or_default();
    let make: fn([i64; 3]) -> Op = match op {
        "+" => Op::Insert,
        "-" => Op::Remove,
        "?" => Op::Query,
        _ => {
            return Err(format!(
                "unknown operation '{op}' (expected '+', '-', '?' or '#')"
            ))
        }
    };
    let coords: Vec<&str> = words.collect();
    if coords.len() != 3 {
        return Err(format!(
            "'{op}' needs 3 coordinates x y z, found {}",
            coords.len()
        ));
    }
    let mut v = [0i64; 3];
    for (a, w) in coords.iter().enumerate() {
        v[a] = w.parse().map_err(|_| {
            format!(
                "coordinate {} '{w}' is not an integer in [-2^63, 2^63)",
                ["x", "y", "z"][a]
            )
        })?;
    }
    Ok(make(v))
}

/// Reads one line into `buf` (without the newline); `Ok(false)` at end of input.
/// Fails on a line longer than [`MAX_LINE`] bytes or one that is not UTF-8.
pub fn read_line<R: BufRead>(r: &mut R, buf: &mut Vec<u8>) -> Result<bool, String> {
    buf.clear();
    let n = r
        .take(MAX_LINE as u64 + 1)
        .read_until(b'\n', buf)
        .map_err(|e| format!("read error: {e}"))?;
    if n == 0 {
        return Ok(false);
    }
    if buf.last() == Some(&b'\n') {
        buf.pop();
        if buf.last() == Some(&b'\r') {
            buf.pop();
        }
    } else if buf.len() > MAX_LINE {
        return Err(format!("line longer than {MAX_LINE} bytes"));
    }
    Ok(true)
}

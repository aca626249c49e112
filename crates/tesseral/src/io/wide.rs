//! The frame shared by the `.tess` files of what a model cannot hold (2^21 voxels
//! on an axis): an occupancy map's own (`occupancy/tess_map.rs`) and a dynamic
//! octree's own (`dynamic/tess_dyn.rs`). Each starts with its magic number, the
//! version (1), flags (0) and a zero word, goes on with its kind's header and
//! blocks, and ends with a CRC-32 of all bytes before.

use std::path::Path;

use super::leafstream::{crc_checked, Reader};
use super::FormatError;

/// The version both kinds write and read.
const VERSION: u16 = 1;

/// Starts a file of `magic`: the magic, version, flags and zero word (16 bytes).
pub(crate) fn start(out: &mut Vec<u8>, magic: &[u8; 8]) {
    out.extend_from_slice(magic);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&[0; 6]);
}

/// Ends a file: the CRC-32 of all its bytes.
pub(crate) fn seal(out: &mut Vec<u8>) {
    let crc = crc32fast::hash(out);
    out.extend_from_slice(&crc.to_le_bytes());
}

/// Opens the bytes of a file of `magic` (`what` names the kind in errors: "occupancy
/// map") whose header takes `header_len` bytes: checks the magic, the length, the
/// checksum, then the version, flags and zero word. Gives a reader over the bytes
/// before the checksum, at byte 16.
///
/// # Errors
/// [`FormatError::Corrupt`] for another magic, a file shorter than its header and
/// checksum, or a checksum that does not match; [`FormatError::Unsupported`] for
/// another version, or flags.
pub(crate) fn open<'a>(
    bytes: &'a [u8],
    magic: &[u8; 8],
    what: &str,
    header_len: usize,
) -> Result<Reader<'a>, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    if !bytes.starts_with(magic) {
        return Err(bad(format!("not a tesseral {what} (bad magic number)")));
    }
    if bytes.len() < header_len + 4 {
        return Err(bad(format!(
            "truncated: {} bytes, a {what}'s header and checksum take {}",
            bytes.len(),
            header_len + 4
        )));
    }
    let mut r = Reader {
        bytes: crc_checked(bytes).map_err(bad)?,
        pos: 8,
    };
    let version = r.u16().map_err(bad)?;
    let flags = r.u16().map_err(bad)?;
    let zero = r.u32().map_err(bad)?;
    if version != VERSION || flags != 0 || zero != 0 {
        return Err(FormatError::unsupported(format!(
            "{what} format version {version}, flags {flags:#x}; this build reads version \
             {VERSION} with no flags"
        )));
    }
    Ok(r)
}

/// The bytes of the file `path` (read whole, up to 4 GiB) when it starts with
/// `magic`; `None` for any other file, which the caller reads as a model.
///
/// # Errors
/// [`FormatError::Io`] naming the path when it cannot be read.
pub(crate) fn read_if(path: &Path, magic: &[u8; 8]) -> Result<Option<Vec<u8>>, FormatError> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut f = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
    let n = f.read(&mut head).unwrap_or(0);
    if head[..n] != *magic {
        return Ok(None);
    }
    super::read_limited(path, super::MAX_FILE_BYTES).map(Some)
}

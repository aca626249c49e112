//! Reading and writing octrees in the formats people use, chosen by file extension.
//!
//! Every command that reads an octree goes through [`read_octree`], and every one that
//! writes goes through [`write_octree`], so each format added here works everywhere.
//! Files are written to a temporary name in the same folder and renamed into place
//! ([`write_atomic`]), so a crash never leaves a half-written file where a good one
//! stood.

pub mod xyz;

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::linear::{LinearOctree, OctreeError};

/// What can go wrong reading or writing a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// The operating system refused to read or write the file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// The file's content is malformed at a given line and column (1-based).
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The line, from 1.
        line: usize,
        /// The column, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The file is malformed at a byte offset or in a named field.
    #[error("{path}: {message}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the field or offset.
        message: String,
    },
    /// The extension names no format we know.
    #[error("{path}: unknown file format (known extensions: {known})")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// The extensions we know, comma-separated.
        known: &'static str,
    },
    /// The content does not fit an octree (too deep, out of bounds).
    #[error("{path}: {source}")]
    Octree {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: OctreeError,
    },
}

/// The extensions [`read_octree`] and [`write_octree`] understand.
pub const KNOWN_EXTENSIONS: &str = "xyz";

/// Reads an octree from `path`, choosing the format by its extension.
///
/// # Errors
/// [`FormatError`] naming the file, and the line and column or field at fault.
pub fn read_octree(path: &Path) -> Result<LinearOctree, FormatError> {
    match extension(path).as_str() {
        "xyz" => xyz::read(path),
        _ => Err(FormatError::UnknownFormat {
            path: path.to_owned(),
            known: KNOWN_EXTENSIONS,
        }),
    }
}

/// Writes `tree` to `path` atomically, choosing the format by its extension.
///
/// # Errors
/// [`FormatError`] naming the file.
pub fn write_octree(path: &Path, tree: &LinearOctree) -> Result<(), FormatError> {
    match extension(path).as_str() {
        "xyz" => write_atomic(path, |w| xyz::write(w, tree)),
        _ => Err(FormatError::UnknownFormat {
            path: path.to_owned(),
            known: KNOWN_EXTENSIONS,
        }),
    }
}

/// The lower-case extension of `path`, or "".
#[must_use]
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Writes a file through `body` to a temporary name beside `path`, then renames it
/// into place. On any error the temporary file is removed and `path` is untouched.
///
/// # Errors
/// [`FormatError::Io`] naming `path`.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), FormatError> {
    let wrap = |source| FormatError::Io {
        path: path.to_owned(),
        source,
    };
    let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
    tmp_name.push(format!(".{}.tmp", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let result = (|| {
        let mut w = BufWriter::new(fs::File::create(&tmp)?);
        body(&mut w)?;
        w.into_inner()
            .map_err(io::IntoInnerError::into_error)?
            .sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(wrap)
}

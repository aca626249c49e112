//! `FormatError`: what goes wrong reading or writing a file.
//!
//! Byte decoders know no path: they return errors that say *where in the bytes*
//! (line and column, field, byte offset). The path is attached once, where the file
//! is opened, with [`FormatError::with_path`], as ripgrep's `Error::with_path` does,
//! so no variant carries its own path and no message names a file twice.

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

use crate::linear::OctreeError;

/// What can go wrong reading or writing a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// The operating system refused to read or write the file.
    #[error("{0}")]
    Io(#[source] io::Error),
    /// The content is malformed at a given line and column (1-based).
    #[error("{line}:{column}: {message}")]
    Syntax {
        /// The line, from 1.
        line: usize,
        /// The column, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The content is malformed at a byte offset or in a named field (the message
    /// names it).
    #[error("{0}")]
    Corrupt(String),
    /// The extension names no format we know.
    #[error("unknown file format (known extensions: {known})")]
    UnknownFormat {
        /// The extensions we know, comma-separated.
        known: &'static str,
    },
    /// The content does not fit an octree (too deep, out of bounds).
    #[error("{0}")]
    Octree(#[source] OctreeError),
    /// The content is well formed but exceeds a limit that protects memory and time
    /// (grid size, voxel count, element count); the message names the limit.
    #[error("{0}")]
    TooLarge(String),
    /// The octree cannot be expressed in the target format (too big for its grid,
    /// too many colours), or the content uses a feature we do not read.
    #[error("{0}")]
    Unsupported(String),
    /// A mesh that should bound a solid has open edges, so inside and outside are not
    /// defined. Voxelize its surface only, or repair it.
    #[error("mesh is not watertight: {open_edges} edge(s) are not shared by an even number of triangles (first near {example:?}); use --surface-only to voxelize the surface")]
    NotWatertight {
        /// How many edges have an odd number of triangles.
        open_edges: usize,
        /// The coordinates of one end of one open edge.
        example: [f64; 3],
    },
    /// An error in a named file.
    #[error("{}", InFile(path, source))]
    WithPath {
        /// The file.
        path: PathBuf,
        /// What went wrong in it.
        source: Box<FormatError>,
    },
}

/// Shows `path:line:column: message` for syntax errors, `path: message` otherwise.
struct InFile<'a>(&'a Path, &'a FormatError);

impl fmt::Display for InFile<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sep = if matches!(self.1, FormatError::Syntax { .. }) {
            ":"
        } else {
            ": "
        };
        write!(f, "{}{sep}{}", self.0.display(), self.1)
    }
}

impl FormatError {
    /// The error attached to the file `path` (once: an error that already names a
    /// file is returned as it is).
    ///
    /// ```
    /// use tesseral::io::FormatError;
    /// let e = FormatError::Syntax { line: 3, column: 5, message: "bad".into() };
    /// assert_eq!(e.with_path("a.obj").to_string(), "a.obj:3:5: bad");
    /// ```
    #[must_use]
    pub fn with_path(self, path: impl AsRef<Path>) -> Self {
        match self {
            e @ Self::WithPath { .. } => e,
            e => Self::WithPath {
                path: path.as_ref().to_owned(),
                source: Box::new(e),
            },
        }
    }

    /// The error itself, without the file it names.
    #[must_use]
    pub fn kind(&self) -> &FormatError {
        match self {
            Self::WithPath { source, .. } => source.kind(),
            e => e,
        }
    }

    /// The file the error names, if any.
    #[must_use]
    pub fn path(&self) -> Option<&Path> {
        match self {
            Self::WithPath { path, .. } => Some(path),
            _ => None,
        }
    }

    pub(crate) fn corrupt(message: impl Into<String>) -> Self {
        Self::Corrupt(message.into())
    }
    pub(crate) fn too_large(message: impl Into<String>) -> Self {
        Self::TooLarge(message.into())
    }
    pub(crate) fn unsupported(message: impl Into<String>) -> Self {
        Self::Unsupported(message.into())
    }
    pub(crate) fn io(source: io::Error) -> Self {
        Self::Io(source)
    }
    pub(crate) fn octree(source: OctreeError) -> Self {
        Self::Octree(source)
    }
}

//! Located diagnostics and the errors of reading a scene.

use std::fmt;
use std::path::PathBuf;

use crate::csg::CsgError;

/// How many characters of a source line a diagnostic shows, and how many of them
/// come before the fault.
const SHOWN_CHARS: usize = 120;
const SHOWN_BEFORE: usize = 40;

/// A located error in a scene file: `file:line:column`, the line itself with a caret
/// under the fault, and a hint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file.
    pub path: PathBuf,
    /// The line, from 1.
    pub line: usize,
    /// The column, from 1 (in characters).
    pub column: usize,
    /// The width of the fault, in characters (at least 1).
    pub width: usize,
    /// What is wrong.
    pub message: String,
    /// How to fix it, when we can tell (for a misspelled name: the closest known one).
    pub hint: Option<String>,
    /// The text of the line at fault.
    pub source_line: String,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        )?;
        let num = self.line.to_string();
        let pad = " ".repeat(num.len());
        // A hostile line can be megabytes long: show a window of it around the fault.
        let skip = self.column.saturating_sub(1 + SHOWN_BEFORE);
        let shown: String = self
            .source_line
            .chars()
            .skip(skip)
            .take(SHOWN_CHARS)
            .collect();
        let (cut, under_cut) = if skip > 0 { ("…", " ") } else { ("", "") };
        write!(f, "\n{pad} |\n{num} | {cut}{shown}\n{pad} | {under_cut}")?;
        let col = self.column.saturating_sub(1) - skip;
        write!(
            f,
            "{}{}",
            " ".repeat(col),
            "^".repeat(self.width.clamp(1, SHOWN_CHARS.saturating_sub(col).max(1)))
        )?;
        if let Some(h) = &self.hint {
            write!(f, "\n{pad} = hint: {h}")?;
        }
        Ok(())
    }
}

/// What can go wrong reading a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: {source}", path = .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The text is malformed or meaningless at a located place.
    #[error("{0}")]
    Parse(Box<Diagnostic>),
    /// The scene parsed but its octree cannot be built (too many leaves).
    #[error("{path}: {source}", path = .path.display())]
    Build {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: CsgError,
    },
}

impl SceneError {
    /// The diagnostic, for a parse error.
    #[must_use]
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        match self {
            SceneError::Parse(d) => Some(d),
            _ => None,
        }
    }
}

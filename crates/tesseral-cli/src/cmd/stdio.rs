//! `-` as a file name: standard input for octree inputs, standard output for octree
//! and PNG outputs.
//!
//! Standard input is read whole (at most [`MAX_STDIN_BYTES`]), its format told from
//! its first bytes (`tesseral::io::sniff_format`), and parsed like a file; errors say
//! `<stdin>`. An octree sent to standard output needs `--format EXT`, since there is
//! no extension to name it. Both go through a private temporary folder because the
//! readers and writers work on files; the folder is removed when done.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The most bytes read from standard input (4 GiB, the file readers' own cap).
pub const MAX_STDIN_BYTES: u64 = 4 << 30;

/// Standard input saved to a temporary file named by its sniffed format.
pub struct Stdin {
    _dir: tempfile::TempDir,
    /// The temporary file.
    pub path: PathBuf,
}

impl Stdin {
    /// Reads standard input and tells its format.
    ///
    /// # Errors
    /// When stdin is unreadable, too large, or in no format we know.
    pub fn read() -> Result<Stdin> {
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .take(MAX_STDIN_BYTES + 1)
            .read_to_end(&mut bytes)
            .context("<stdin>")?;
        if bytes.len() as u64 > MAX_STDIN_BYTES {
            bail!("<stdin>: more than {MAX_STDIN_BYTES} bytes; give a file instead");
        }
        let Some(ext) = tesseral::io::sniff_format(&bytes) else {
            bail!(
                "<stdin>: cannot tell the format from the first bytes \
                 (known: .tess, .binvox, .vox, .bt, .ot, .ply, .stl, .obj, .xyz); give a file with an extension"
            );
        };
        let dir = tempfile::tempdir().context("a temporary folder for <stdin>")?;
        let path = dir.path().join(format!("stdin.{ext}"));
        std::fs::write(&path, &bytes).context("saving <stdin>")?;
        Ok(Stdin { _dir: dir, path })
    }

    /// An error about the temporary file, told about `<stdin>` instead.
    pub fn rename(&self, err: &anyhow::Error) -> anyhow::Error {
        let text = format!("{err:#}");
        anyhow::anyhow!(
            "{}",
            text.replace(&self.path.display().to_string(), "<stdin>")
        )
    }
}

/// Runs `write` on a temporary file named `out.EXT` and copies the result to
/// standard output.
///
/// # Errors
/// The writer's error, or the copy's (a closed pipe ends the program quietly).
pub fn to_stdout(ext: &str, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = tempfile::tempdir().context("a temporary folder for <stdout>")?;
    let path = dir.path().join(format!("out.{ext}"));
    write(&path).map_err(|e| {
        let text = format!("{e:#}");
        anyhow::anyhow!("{}", text.replace(&path.display().to_string(), "<stdout>"))
    })?;
    let mut file = std::fs::File::open(&path).context("<stdout>")?;
    let mut out = std::io::stdout().lock();
    std::io::copy(&mut file, &mut out).context("<stdout>: writing the output")?;
    out.flush().context("<stdout>: writing the output")?;
    Ok(())
}

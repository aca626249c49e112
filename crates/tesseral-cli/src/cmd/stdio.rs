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

/// Standard output that a reader may close early (`tesseral replay ops -o F | head`).
///
/// The first broken pipe marks it [`closed`](Self::closed) and every later write is
/// dropped, so that a command with files still to write goes on and writes them; a
/// command with nothing else to do asks `closed` and stops. Other errors pass through.
pub struct Detachable<W: Write> {
    inner: W,
    closed: bool,
}

impl<W: Write> Detachable<W> {
    pub fn new(inner: W) -> Self {
        Self {
            inner,
            closed: false,
        }
    }

    /// Whether the reader has gone (a write or flush met a broken pipe).
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// `Ok` for a broken pipe, which marks the writer closed.
    fn detach<T>(&mut self, r: std::io::Result<T>, dropped: T) -> std::io::Result<T> {
        match r {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
                self.closed = true;
                Ok(dropped)
            }
            r => r,
        }
    }
}

impl<W: Write> Write for Detachable<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.closed {
            return Ok(buf.len());
        }
        let r = self.inner.write(buf);
        self.detach(r, buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.closed {
            return Ok(());
        }
        let r = self.inner.flush();
        self.detach(r, ())
    }
}

#[cfg(test)]
mod tests {
    use super::Detachable;
    use std::io::{self, Write};

    /// A pipe whose reader leaves after `keep` bytes.
    struct Pipe {
        keep: usize,
        got: Vec<u8>,
    }

    impl Write for Pipe {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.got.len() >= self.keep {
                return Err(io::ErrorKind::BrokenPipe.into());
            }
            let n = buf.len().min(self.keep - self.got.len());
            self.got.extend_from_slice(&buf[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_broken_pipe_closes_it_and_later_writes_are_dropped() {
        let mut out = Detachable::new(Pipe {
            keep: 4,
            got: Vec::new(),
        });
        out.write_all(b"1\n0\n").unwrap();
        assert!(!out.closed());
        out.write_all(b"1\n").unwrap();
        assert!(out.closed());
        out.write_all(b"more\n").unwrap();
        out.flush().unwrap();
        assert_eq!(out.inner.got, b"1\n0\n");
    }

    #[test]
    fn other_errors_pass_through() {
        struct Full;
        impl Write for Full {
            fn write(&mut self, _: &[u8]) -> io::Result<usize> {
                Err(io::Error::from_raw_os_error(28))
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let mut out = Detachable::new(Full);
        assert!(out.write_all(b"x").is_err());
        assert!(!out.closed());
    }
}

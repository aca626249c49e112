//! Atomic, link-safe file output, and the registry of temporaries a signal handler
//! removes.
//!
//! Every file the library writes goes through [`write_atomic`]: the bytes go to a new
//! temporary file in the target's folder, which is then renamed over the target.
//!
//! - The temporary is created with `O_CREAT | O_EXCL` under a random name (the
//!   `tempfile` crate), so a file or symbolic link planted under a guessed name is
//!   never opened, let alone followed: the victim of a planted link is untouched.
//! - The rename replaces the target's directory entry. If the target was a symbolic
//!   link, the link itself is replaced by a regular file; what it pointed to is not
//!   written.
//! - On any error the temporary is removed and the target is untouched.
//! - While a temporary exists its path is listed in a process-wide registry, so that
//!   a program's SIGINT/SIGTERM handler can call [`remove_pending_temporaries`] before
//!   it exits. The library installs no handler itself (it has no business owning a
//!   process's signals); the `tesseral` binary does. A `kill -9` (SIGKILL) cannot be
//!   caught by any process: a temporary named `.NAME.*.tmp` may then be left beside
//!   the target.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::FormatError;

/// The temporaries that exist right now. A global because a signal handler has no
/// other way to reach them; it holds paths only, and is locked for a push, a removal
/// or a sweep, never across I/O of the file itself.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic while the lock was held cannot leave the list inconsistent (pushes and
    // removals are single operations), so a poisoned lock is still usable.
    PENDING
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Removes every temporary file that a [`write_atomic`] in progress has created and
/// not yet renamed into place (and every directory a [`StagedDir`](super::StagedDir)
/// is filling), and returns how many were removed.
///
/// Meant for a signal handler that is about to end the process (the write in
/// progress then fails or is never finished). Safe to call from any thread at any
/// time; a write whose temporary was removed fails with an I/O error at its rename.
///
/// # Runtime
/// O(number of writes in progress).
///
/// # Example
/// ```
/// // Nothing is being written: nothing to remove.
/// assert_eq!(tesseral::io::remove_pending_temporaries(), 0);
/// ```
pub fn remove_pending_temporaries() -> usize {
    let mut list = pending();
    let mut removed = 0;
    for path in list.drain(..) {
        // A staged dataset directory (`StagedDir`) goes with its contents.
        let gone = if path.is_dir() {
            fs::remove_dir_all(&path)
        } else {
            fs::remove_file(&path)
        };
        if gone.is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The temporaries of writes in progress (for tests, diagnostics and progress
/// display: a caller may watch their sizes grow).
///
/// # Runtime
/// O(number of writes in progress).
///
/// # Example
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.txt");
/// tesseral::io::write_atomic(&path, |w| {
///     // While the body runs, its temporary is listed, beside the target.
///     let pending = tesseral::io::pending_temporaries();
///     assert!(pending.iter().any(|p| p.parent() == Some(dir.path())));
///     w.write_all(b"x")
/// })
/// .unwrap();
/// assert!(tesseral::io::pending_temporaries().iter().all(|p| p.parent() != Some(dir.path())));
/// ```
#[must_use]
pub fn pending_temporaries() -> Vec<PathBuf> {
    pending().clone()
}

/// Keeps a temporary's path in the registry for as long as it lives.
#[derive(Debug)]
pub(super) struct Registered(PathBuf);

impl Registered {
    pub(super) fn new(path: PathBuf) -> Self {
        pending().push(path.clone());
        Self(path)
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        let mut list = pending();
        if let Some(i) = list.iter().position(|p| *p == self.0) {
            list.swap_remove(i);
        }
    }
}

/// Writes a file through `body` to a new temporary file beside `path`, then renames
/// it into place. On any error the temporary file is removed and `path` is untouched.
///
/// The temporary is created exclusively under a random name, so no planted file or
/// link is ever opened, and the result at `path` is always a regular file (a link at
/// `path` is replaced, not followed). New files get the usual `0666 & !umask` mode.
///
/// # Runtime
/// O(bytes written), plus one `fsync` of the new file.
///
/// # Errors
/// [`FormatError::Io`] naming `path`.
///
/// # Example
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("hello.txt");
/// tesseral::io::write_atomic(&path, |w| w.write_all(b"hello")).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// ```
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), FormatError> {
    write_atomic_inner(path, body).map_err(|source| FormatError::Io(source).with_path(path))
}

/// The error of making a temporary file or folder in `dir`, without the temporary
/// name (which the user never asked for): `cannot create a file in DIR: REASON`.
pub(crate) fn in_folder(e: io::Error, dir: &Path) -> io::Error {
    // tempfile's message ends with the temporary path: ` at path "…"`.
    let text = e.to_string();
    let reason = text.rfind(" at path ").map_or(&*text, |k| &text[..k]);
    io::Error::new(
        e.kind(),
        format!("cannot create a file in {}: {reason}", dir.display()),
    )
}

fn write_atomic_inner(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(path.file_name().unwrap_or_default());
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // tempfile's default is 0600; an output file should get the mode any new
        // file gets (the umask still applies at creation).
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(dir).map_err(|e| in_folder(e, dir))?;
    // Registered right after creation, before any byte is written; the guard is
    // dropped (unregistered) after the rename or after `tmp` removed the file.
    let registered = Registered::new(tmp.path().to_owned());
    let mut w = BufWriter::new(tmp);
    body(&mut w)?;
    let tmp = w.into_inner().map_err(io::IntoInnerError::into_error)?;
    tmp.as_file().sync_all()?;
    let result = tmp.persist(path).map(drop).map_err(|e| e.error);
    drop(registered);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        write_atomic(&path, |w| w.write_all(b"one")).unwrap();
        write_atomic(&path, |w| w.write_all(b"two")).unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"two");
        assert_eq!(names(dir.path()), ["a.txt"]);
    }

    #[test]
    fn error_leaves_target_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        fs::write(&path, b"old").unwrap();
        let err = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("boom"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("a.txt"), "{err}");
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["a.txt"]);
    }

    #[test]
    fn a_missing_folder_is_named_not_the_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no").join("a.txt");
        let err = write_atomic(&path, |w| w.write_all(b"x")).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("a.txt"), "{text}");
        assert!(text.contains("cannot create a file in"), "{text}");
        assert!(!text.contains(".a.txt."), "{text}");
        let err = crate::io::StagedDir::beside(&path).unwrap_err().to_string();
        assert!(
            err.contains("cannot create a file in") && !err.contains(".a.txt."),
            "{err}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn symlink_at_target_is_replaced_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        fs::write(&victim, b"precious").unwrap();
        let path = dir.path().join("out.xyz");
        std::os::unix::fs::symlink(&victim, &path).unwrap();
        // Plant links under the names the old writer used, too.
        let planted = dir
            .path()
            .join(format!("out.xyz.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_atomic(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert!(!fs::symlink_metadata(&path)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&path).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn new_files_get_the_umask_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m");
        write_atomic(&path, |w| w.write_all(b"x")).unwrap();
        // A file made the ordinary way gets 0666 & !umask; ours must match it.
        let reference = dir.path().join("reference");
        fs::File::create(&reference).unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&path), mode(&reference));
    }
}

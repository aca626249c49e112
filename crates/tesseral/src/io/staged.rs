//! A directory output (a partitioned dataset) written as a whole or not at all.
//!
//! The contents go into a new hidden directory beside the target (`.NAME.*.tmp`,
//! created exclusively under a random name), listed in the registry of temporaries
//! so that a signal handler's [`remove_pending_temporaries`] removes it with what it
//! holds. [`StagedDir::commit`] renames it into place; an old directory there is
//! renamed aside first and removed after, so a reader sees the old dataset or the
//! new one, never a mixture. Dropped without a commit, the staged directory is
//! removed.
//!
//! A SIGKILL cannot be caught, so a killed writer leaves its staged directory.
//! Each one therefore holds a marker file ([`MARKER`]) naming its writer: the
//! process id, the process's start time, the boot, the pid namespace and the host.
//! [`sweep_stale_staged`] (called by the next writer of the same target) removes
//! the staged directories of that target whose marker names a writer that is
//! provably gone: same host and pid namespace, and another boot, or no such
//! process, or a process of that id started at another time (the id reused). A
//! directory without a readable marker, of another host or namespace, of another
//! user, or of a live writer is kept, and so is an old dataset renamed aside
//! (`.tmp.old`: a kill between the two renames of a commit leaves the only copy
//! there). Liveness is read from `/proc`, so on systems without it nothing is
//! swept. The marker is removed just before the rename into place, so a
//! committed dataset holds only its own files.
//!
//! [`stage_dir`] and [`commit_staged`] are the same steps without the guard, for a
//! writer whose directory outlives one process (`tesseral.dask`: the client makes
//! it, workers fill it, a task commits it).
//!
//! [`remove_pending_temporaries`]: super::remove_pending_temporaries

use std::fs;
use std::path::{Path, PathBuf};

use super::atomic::Registered;
use super::FormatError;

/// The marker file in a staged directory, naming its writer.
pub const MARKER: &str = ".tesseral-staged";

/// The first line of a marker.
const MARKER_HEAD: &str = "tesseral staged dataset directory";

/// A new hidden directory beside a target directory, to be renamed into place.
#[derive(Debug)]
pub struct StagedDir {
    dir: Option<PathBuf>,
    _registered: Registered,
}

/// The folder beside `target` and the staged directories' name prefix.
fn parent_and_prefix(target: &Path) -> (&Path, String) {
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    (parent, format!(".{name}."))
}

/// Makes a new staged directory beside `target` (`.NAME.XXXXXX.tmp`, created
/// exclusively, mode `0777` less the umask as `mkdir` gives), holding a marker
/// that names this process; returns its path. Nothing removes it: commit it with
/// [`commit_staged`] or remove it. [`StagedDir::beside`] is this with a guard.
///
/// # Errors
/// [`FormatError::Io`] naming `target` when the directory or its marker cannot be
/// made.
pub fn stage_dir(target: &Path) -> Result<PathBuf, FormatError> {
    let (parent, prefix) = parent_and_prefix(target);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o777));
    }
    let dir = builder
        .tempdir_in(parent)
        .map_err(|e| FormatError::io(super::atomic::in_folder(e, parent)).with_path(target))?;
    fs::write(dir.path().join(MARKER), marker_text(&Writer::this()))
        .map_err(|e| FormatError::io(e).with_path(target))?;
    Ok(dir.keep())
}

/// Renames the staged directory `staged` to `target` (its marker removed
/// first). An old directory at `target` is renamed aside first (and put back if
/// the second rename fails), then removed.
///
/// # Errors
/// [`FormatError::Io`] naming `target`.
pub fn commit_staged(staged: &Path, target: &Path) -> Result<(), FormatError> {
    let io = |e: std::io::Error| FormatError::io(e).with_path(target);
    match fs::remove_file(staged.join(MARKER)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(e)),
        _ => {}
    }
    if !target.exists() {
        return fs::rename(staged, target).map_err(io);
    }
    let mut old = staged.to_path_buf().into_os_string();
    old.push(".old");
    let old = PathBuf::from(old);
    fs::rename(target, &old).map_err(io)?;
    if let Err(e) = fs::rename(staged, target) {
        let _ = fs::rename(&old, target);
        return Err(io(e));
    }
    fs::remove_dir_all(&old).map_err(|e| FormatError::io(e).with_path(&old))
}

impl StagedDir {
    /// Makes the staging directory beside `target` (in its parent folder), with
    /// its marker ([`stage_dir`]).
    ///
    /// # Errors
    /// [`FormatError::Io`] naming `target` when the directory cannot be made.
    ///
    /// # Example
    /// ```
    /// let dir = tempfile::tempdir().unwrap();
    /// let target = dir.path().join("parts");
    /// let staged = tesseral::io::StagedDir::beside(&target).unwrap();
    /// std::fs::write(staged.path().join("manifest.json"), b"{}").unwrap();
    /// assert!(tesseral::io::pending_temporaries().contains(&staged.path().to_path_buf()));
    /// staged.commit(&target).unwrap();
    /// assert!(target.join("manifest.json").is_file());
    /// ```
    pub fn beside(target: &Path) -> Result<Self, FormatError> {
        let dir = stage_dir(target)?;
        let registered = Registered::new(dir.clone());
        Ok(Self {
            dir: Some(dir),
            _registered: registered,
        })
    }

    /// The staging directory, to write into.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.dir.as_deref().unwrap_or(Path::new(""))
    }

    /// Renames the staged directory to `target` ([`commit_staged`]).
    ///
    /// # Errors
    /// [`FormatError::Io`] naming `target`; the staged directory is then removed.
    pub fn commit(mut self, target: &Path) -> Result<(), FormatError> {
        let staged = self
            .dir
            .take()
            .expect("a staged directory is committed once");
        let done = commit_staged(&staged, target);
        if done.is_err() && staged.exists() {
            let _ = fs::remove_dir_all(&staged);
        }
        done
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if let Some(dir) = self.dir.take() {
            let _ = fs::remove_dir_all(dir);
        }
    }
}

/// Removes the staged directories beside `target` (`.NAME.*.tmp` with a marker)
/// whose writers are provably gone (see the module docs), and returns them. Best
/// effort: a directory that cannot be read or removed is left as it is.
///
/// # Runtime
/// O(entries of `target`'s folder), plus the removals.
pub fn sweep_stale_staged(target: &Path) -> Vec<PathBuf> {
    let (parent, prefix) = parent_and_prefix(target);
    let Ok(entries) = fs::read_dir(parent) else {
        return Vec::new();
    };
    let me = Writer::this();
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !(name.starts_with(&prefix) && name.ends_with(".tmp")) {
            continue;
        }
        let path = e.path();
        let stale = read_marker(&path).is_some_and(|w| w.is_gone(&me));
        if stale && fs::remove_dir_all(&path).is_ok() {
            removed.push(path);
        }
    }
    removed
}

/// Who wrote a staged directory. Fields read from `/proc` are `None` where it
/// cannot be read.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Writer {
    pid: u32,
    /// The process's start time, in clock ticks after boot (`/proc/PID/stat`).
    start: Option<u64>,
    boot: Option<String>,
    pid_ns: Option<String>,
    host: Option<String>,
}

fn proc_line(path: &str) -> Option<String> {
    let s = fs::read_to_string(path).ok()?;
    let s = s.trim();
    (!s.is_empty()).then(|| s.to_owned())
}

/// Field 22 of `/proc/PID/stat` (after the command's closing parenthesis, which
/// may itself hold spaces and parentheses).
fn start_time(pid: &str) -> Option<u64> {
    let stat = fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(19)?.parse().ok()
}

impl Writer {
    fn this() -> Self {
        Self {
            pid: std::process::id(),
            start: start_time("self"),
            boot: proc_line("/proc/sys/kernel/random/boot_id"),
            pid_ns: fs::read_link("/proc/self/ns/pid")
                .ok()
                .map(|p| p.to_string_lossy().into_owned()),
            host: proc_line("/proc/sys/kernel/hostname"),
        }
    }

    /// Whether the writer is provably not running (seen from `me`): same host and
    /// pid namespace, and another boot, or no process of its id, or one that
    /// started at another time. Unknown fields never prove it gone.
    fn is_gone(&self, me: &Writer) -> bool {
        let same = |a: &Option<String>, b: &Option<String>| a.is_some() && a == b;
        if !(same(&self.host, &me.host) && same(&self.pid_ns, &me.pid_ns)) {
            return false;
        }
        if me.boot.is_some() && self.boot.is_some() && self.boot != me.boot {
            return true;
        }
        if self.pid == me.pid {
            return me.start.is_some() && self.start.is_some() && self.start != me.start;
        }
        let proc = Path::new("/proc");
        if !proc.join("self").exists() {
            return false;
        }
        if !proc.join(self.pid.to_string()).exists() {
            return true;
        }
        match (self.start, start_time(&self.pid.to_string())) {
            (Some(a), Some(b)) => a != b,
            _ => false,
        }
    }
}

fn marker_text(w: &Writer) -> String {
    let opt = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
    format!(
        "{MARKER_HEAD}\npid {}\nstart {}\nboot {}\npidns {}\nhost {}\n",
        w.pid,
        w.start.map_or_else(|| "-".into(), |s| s.to_string()),
        opt(&w.boot),
        opt(&w.pid_ns),
        opt(&w.host)
    )
}

/// The writer named by the marker of `dir`, when `dir` is a real directory (not a
/// link) of this user holding a well-formed marker.
fn read_marker(dir: &Path) -> Option<Writer> {
    let meta = fs::symlink_metadata(dir).ok()?;
    if !meta.is_dir() {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if meta.uid() != fs::metadata("/proc/self").ok()?.uid() {
            return None;
        }
    }
    let m = dir.join(MARKER);
    if !fs::symlink_metadata(&m).ok()?.is_file() || fs::metadata(&m).ok()?.len() > 4096 {
        return None;
    }
    let text = fs::read_to_string(m).ok()?;
    let mut lines = text.lines();
    if lines.next()? != MARKER_HEAD {
        return None;
    }
    let mut field = |key: &str| -> Option<Option<String>> {
        let v = lines.next()?.strip_prefix(key)?.strip_prefix(' ')?;
        Some((v != "-").then(|| v.to_owned()))
    };
    let pid = field("pid")??.parse().ok()?;
    let start = match field("start")? {
        Some(s) => Some(s.parse().ok()?),
        None => None,
    };
    Some(Writer {
        pid,
        start,
        boot: field("boot")?,
        pid_ns: field("pidns")?,
        host: field("host")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_staged_directory_replaces_the_old_one_whole_or_goes_away() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("ds");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("old.tess"), b"old").unwrap();
        // Dropped without a commit: removed, the old directory untouched.
        let staged = StagedDir::beside(&target).unwrap();
        let path = staged.path().to_path_buf();
        fs::write(path.join("new.tess"), b"new").unwrap();
        drop(staged);
        assert!(!path.exists());
        assert!(!super::super::pending_temporaries().contains(&path));
        assert_eq!(fs::read(target.join("old.tess")).unwrap(), b"old");
        // Committed: the new contents only, nothing left beside.
        let staged = StagedDir::beside(&target).unwrap();
        fs::write(staged.path().join("new.tess"), b"new").unwrap();
        staged.commit(&target).unwrap();
        assert!(!target.join("old.tess").exists());
        assert_eq!(fs::read(target.join("new.tess")).unwrap(), b"new");
        let names: Vec<_> = fs::read_dir(root.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }

    /// Writes a staged directory beside `target` whose marker names `w`.
    fn planted(target: &Path, w: &Writer) -> PathBuf {
        let dir = stage_dir(target).unwrap();
        fs::write(dir.join(MARKER), marker_text(w)).unwrap();
        fs::write(dir.join("part-0000.tess"), b"part").unwrap();
        dir
    }

    /// The staged directories of dead writers are swept, and only those: a live
    /// writer's (another process, and this one), one without a marker or with a
    /// damaged one, another host's or namespace's, another target's, a link and
    /// an aside `.old` are kept; a reused pid (same id, another start time) and
    /// another boot count as gone.
    #[test]
    #[cfg(target_os = "linux")]
    fn only_the_staged_directories_of_dead_writers_are_swept() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("ds");
        let me = Writer::this();
        assert!(me.start.is_some() && me.boot.is_some() && me.host.is_some());
        let mut dead = std::process::Command::new("true").spawn().unwrap();
        dead.wait().unwrap();
        let dead_pid = dead.id();
        let mut live = std::process::Command::new("sleep")
            .arg("60")
            .spawn()
            .unwrap();
        let live_pid = live.id().to_string();
        let live_start = (0..100)
            .find_map(|_| {
                std::thread::sleep(std::time::Duration::from_millis(10));
                start_time(&live_pid)
            })
            .unwrap();
        let with = |pid: u32, start: Option<u64>| Writer {
            pid,
            start,
            ..me.clone()
        };
        let gone = [
            planted(&target, &with(dead_pid, None)),
            planted(&target, &with(dead_pid, Some(5))),
            planted(&target, &with(live.id(), Some(live_start + 1))),
            planted(
                &target,
                &Writer {
                    boot: Some("another-boot".into()),
                    ..with(live.id(), Some(live_start))
                },
            ),
        ];
        let kept = [
            planted(&target, &with(live.id(), Some(live_start))),
            planted(&target, &with(live.id(), None)),
            stage_dir(&target).unwrap(),
            planted(
                &target,
                &Writer {
                    host: Some("elsewhere".into()),
                    ..with(dead_pid, None)
                },
            ),
            planted(
                &target,
                &Writer {
                    pid_ns: None,
                    ..with(dead_pid, None)
                },
            ),
            planted(&root.path().join("other"), &with(dead_pid, None)),
        ];
        // No marker, a damaged marker, an aside directory, a link to a dead
        // writer's directory elsewhere.
        let bare = root.path().join(".ds.bare01.tmp");
        fs::create_dir(&bare).unwrap();
        let bad = planted(&target, &with(dead_pid, None));
        fs::write(
            bad.join(MARKER),
            "tesseral staged dataset directory\npid x\n",
        )
        .unwrap();
        let old = root.path().join(".ds.aside1.tmp.old");
        fs::create_dir(&old).unwrap();
        fs::write(old.join(MARKER), marker_text(&with(dead_pid, None))).unwrap();
        let elsewhere = tempfile::tempdir().unwrap();
        let victim = planted(&elsewhere.path().join("x"), &with(dead_pid, None));
        let link = root.path().join(".ds.link01.tmp");
        std::os::unix::fs::symlink(&victim, &link).unwrap();

        let mut removed = sweep_stale_staged(&target);
        removed.sort();
        let mut want = gone.to_vec();
        want.sort();
        assert_eq!(removed, want);
        for p in &gone {
            assert!(!p.exists(), "{p:?}");
        }
        for p in kept.iter().chain([&bare, &bad, &old, &victim, &link]) {
            assert!(p.exists(), "{p:?}");
        }
        live.kill().unwrap();
        live.wait().unwrap();
        // Now gone: the sweep takes the live writer's two directories too.
        assert_eq!(sweep_stale_staged(&target).len(), 2);
        assert!(!kept[0].exists() && kept[2].exists());
    }

    /// A committed dataset holds no marker; a marker parses back to its writer.
    #[test]
    fn the_marker_names_the_writer_and_leaves_with_the_commit() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("ds");
        let staged = StagedDir::beside(&target).unwrap();
        let read = read_marker(staged.path());
        #[cfg(target_os = "linux")]
        assert_eq!(read, Some(Writer::this()));
        let _ = read;
        staged.commit(&target).unwrap();
        assert!(!target.join(MARKER).exists());
        assert!(fs::read_dir(&target).unwrap().next().is_none());
    }
}

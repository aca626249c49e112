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
//! [`remove_pending_temporaries`]: super::remove_pending_temporaries

use std::fs;
use std::path::{Path, PathBuf};

use super::atomic::Registered;
use super::FormatError;

/// A new hidden directory beside a target directory, to be renamed into place.
#[derive(Debug)]
pub struct StagedDir {
    dir: Option<tempfile::TempDir>,
    _registered: Registered,
}

impl StagedDir {
    /// Makes the staging directory beside `target` (in its parent folder).
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
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let name = target.file_name().unwrap_or_default().to_string_lossy();
        let dir = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .tempdir_in(parent)
            .map_err(|e| FormatError::io(e).with_path(target))?;
        let registered = Registered::new(dir.path().to_path_buf());
        Ok(Self {
            dir: Some(dir),
            _registered: registered,
        })
    }

    /// The staging directory, to write into.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.dir
            .as_ref()
            .map_or(Path::new(""), tempfile::TempDir::path)
    }

    /// Renames the staged directory to `target`. An old directory at `target` is
    /// renamed aside first (and put back if the second rename fails), then removed.
    ///
    /// # Errors
    /// [`FormatError::Io`] naming `target`; the staged directory is then removed.
    pub fn commit(mut self, target: &Path) -> Result<(), FormatError> {
        let dir = self
            .dir
            .take()
            .expect("a staged directory is committed once");
        let staged = dir.path().to_path_buf();
        let io = |e: std::io::Error| FormatError::io(e).with_path(target);
        if !target.exists() {
            fs::rename(&staged, target).map_err(io)?;
            let _ = dir.keep();
            return Ok(());
        }
        let mut old = staged.clone().into_os_string();
        old.push(".old");
        let old = PathBuf::from(old);
        fs::rename(target, &old).map_err(io)?;
        if let Err(e) = fs::rename(&staged, target) {
            let _ = fs::rename(&old, target);
            return Err(io(e));
        }
        let _ = dir.keep();
        fs::remove_dir_all(&old).map_err(|e| FormatError::io(e).with_path(&old))
    }
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
}

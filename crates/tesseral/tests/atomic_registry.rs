//! The registry of pending temporaries, in a process of its own: sweeping it removes
//! every temporary of the process, which would break other tests' writes if they ran
//! beside it in one test binary.

use std::fs;

use tesseral::io::{pending_temporaries, remove_pending_temporaries, write_atomic};

#[test]
fn registry_lists_the_temporary_while_writing_and_a_sweep_removes_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.bin");
    fs::write(&path, b"old").unwrap();
    let mut seen = Vec::new();
    let result = write_atomic(&path, |w| {
        w.write_all(b"abc")?;
        seen = pending_temporaries();
        assert_eq!(seen.len(), 1, "{seen:?}");
        assert!(seen[0].starts_with(dir.path()));
        assert!(seen[0].exists());
        // What a signal handler does: the temporary disappears under the writer.
        assert_eq!(remove_pending_temporaries(), 1);
        Ok(())
    });
    assert!(!seen[0].exists());
    assert!(result.is_err(), "the rename of a removed temporary fails");
    assert_eq!(fs::read(&path).unwrap(), b"old", "the target is untouched");
    let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1);
    assert!(pending_temporaries().is_empty());
    assert_eq!(remove_pending_temporaries(), 0);
}

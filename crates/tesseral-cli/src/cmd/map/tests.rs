//! `tesseral map`: files read again, and `--memory`.

use clap::Parser;

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: super::Args,
}

/// 400 points of a helix 2 m around the z axis, turned by `phase` radians, as
/// `.xyz` text.
fn helix(phase: f64) -> String {
    (0..400)
        .map(|i| {
            let a = f64::from(i) * 0.37 + phase;
            format!(
                "{:.3} {:.3} {:.3}\n",
                2.0 * a.cos(),
                2.0 * a.sin(),
                0.01 * f64::from(i % 50)
            )
        })
        .collect()
}

/// Files read again for the insertion (none kept but the last) give the map
/// that files kept give, byte for byte; a bad file is refused either way.
#[test]
fn files_read_again_give_the_same_map() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for k in 0..3 {
        let path = dir.path().join(format!("c{k}.xyz"));
        std::fs::write(&path, helix(f64::from(k))).unwrap();
        files.push(path.display().to_string());
    }
    let map = |budget: usize, out: &str, files: &[String]| {
        let out = dir.path().join(out);
        let mut argv = vec!["map".to_string()];
        argv.extend(files.iter().cloned());
        argv.extend(
            [
                "-o",
                out.to_str().unwrap(),
                "--resolution",
                "0.1",
                "--origin",
                "0,0,1",
            ]
            .map(String::from),
        );
        super::run_holding(Cli::parse_from(argv).args, budget).map(|()| std::fs::read(out).unwrap())
    };
    let kept = map(usize::MAX, "kept.ot", &files).unwrap();
    let again = map(0, "again.ot", &files).unwrap();
    assert!(kept.len() > 1000);
    assert_eq!(kept, again);
    let bad = dir.path().join("bad.xyz");
    std::fs::write(&bad, "1 2 3\n4 5 x\n").unwrap();
    let mut with_bad = files.clone();
    with_bad.insert(1, bad.display().to_string());
    for budget in [0, usize::MAX] {
        let e = map(budget, "bad.ot", &with_bad).unwrap_err().to_string();
        assert!(e.contains("bad.xyz:2:5"), "{e}");
        assert!(!dir.path().join("bad.ot").exists());
    }
}

/// `--memory`: a file whose points alone are over it is refused before any scan
/// is cast; a map that grows over it is refused after the scan that took it over,
/// naming the file and the scan; nothing is written either way.
#[test]
fn memory_bounds_the_scans_and_the_map() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.xyz");
    // 400 points: 9,600 bytes held.
    std::fs::write(&path, helix(0.0)).unwrap();
    let out = dir.path().join("m.tess");
    let map = |memory: &str| {
        let argv = ["map", path.to_str().unwrap(), "-o", out.to_str().unwrap()]
            .into_iter()
            .chain([
                "--resolution",
                "0.05",
                "--origin",
                "0,0,1",
                "--memory",
                memory,
            ]);
        super::run(Cli::parse_from(argv).args).map_err(|e| format!("{e:#}"))
    };
    let e = map("9K").unwrap_err();
    assert!(
        e.contains("c.xyz: its points take 9.4 KiB, more than --memory 9.0 KiB"),
        "{e}"
    );
    assert!(!out.exists());
    let e = map("20K").unwrap_err();
    assert!(e.contains("c.xyz: scan 1 of 1: the map ("), "{e}");
    assert!(
        e.contains("and the scans read for it (9.4 KiB) take more than --memory 20.0 KiB"),
        "{e}"
    );
    assert!(!out.exists());
    map("64M").unwrap();
    assert!(out.exists());
}

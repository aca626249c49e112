//! The output-safety layer every command goes through, in this order:
//!
//! 1. [`guard`], before any work: the output's extension must name a format the
//!    command writes (`render -o x.jpg` is refused, not PNG bytes under a JPEG name),
//!    and the output must not be one of the inputs (canonical paths and
//!    device/inode compared, so symbolic and hard links are seen through).
//! 2. [`check_size`], once the size is known and before a byte is written: the
//!    library's estimate against `--max-output`.
//! 3. The write itself, through `tesseral::io::write_atomic` (a random `O_EXCL`
//!    temporary renamed into place); [`install_signal_handler`] removes pending
//!    temporaries on SIGINT/SIGTERM and exits with 130/143.
//!
//! Standard output goes through [`outln!`](crate::outln), which returns the write's
//! error instead of panicking, so a closed pipe (`tesseral tables | head -1`) ends the
//! program quietly with status 0 (see `main`).

use std::path::Path;

use anyhow::{bail, Result};

/// `writeln!` to standard output, returning `std::io::Result<()>` (use it with `?`).
/// `println!` panics when the reader has gone; this lets the error reach `main`,
/// which ends quietly on a broken pipe.
#[macro_export]
macro_rules! outln {
    () => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock())
    }};
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

/// `write!` to standard output, returning `std::io::Result<()>`; see [`outln!`].
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*)
    }};
}

/// The budget flag of every command that writes a file.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Limits {
    /// Refuse to write an output file estimated larger than this, checked before
    /// writing: bytes, or a number with K, M, G or T (powers of 1024).
    #[arg(long, value_name = "SIZE", default_value = "4G", value_parser = parse_bytes)]
    pub max_output: u64,
}

/// Parses a byte count: `123`, `64K`, `1.5G`, `50G`, `2T` (binary units; a trailing
/// `B` or `iB` is allowed).
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let upper = t.to_ascii_uppercase();
    let body = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, shift) = match body.chars().last() {
        Some('K') => (&body[..body.len() - 1], 10),
        Some('M') => (&body[..body.len() - 1], 20),
        Some('G') => (&body[..body.len() - 1], 30),
        Some('T') => (&body[..body.len() - 1], 40),
        _ => (body, 0),
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{t}` is not a size (write bytes, or e.g. 512M, 4G, 1T)"))?;
    if !(value.is_finite() && value >= 0.0) {
        return Err(format!(
            "`{t}`: a size must be a finite, non-negative number"
        ));
    }
    let bytes = value * (1u64 << shift) as f64;
    if bytes >= u64::MAX as f64 {
        return Err(format!("`{t}`: too large"));
    }
    Ok(bytes as u64)
}

/// A byte count for people: `3.2 GiB`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

/// A count and its noun for people: `1 leaf`, `2 leaves`.
pub fn plural(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The extensions of every octree format `tesseral::io` writes.
pub fn octree_formats() -> Vec<&'static str> {
    tesseral::io::KNOWN_WRITE_EXTENSIONS.split(", ").collect()
}

/// The largest image side any command draws.
pub const MAX_SIDE: usize = 8192;
/// The most pixels in one picture (a contact sheet has four).
pub const MAX_PIXELS: usize = 16 << 20;

/// An image size on the command line, `WIDTHxHEIGHT` (`--size` everywhere).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Pixels across.
    pub width: usize,
    /// Pixels down.
    pub height: usize,
}

/// Parses `WIDTHxHEIGHT` (each side 1 to [`MAX_SIDE`], at most [`MAX_PIXELS`]).
pub fn parse_size(s: &str) -> Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}`: expected WIDTHxHEIGHT, e.g. 800x600"))?;
    let side = |t: &str, what: &str| -> Result<usize, String> {
        t.trim()
            .parse()
            .map_err(|_| format!("`{s}`: the {what} `{t}` is not a whole number"))
    };
    let (width, height) = (side(w, "width")?, side(h, "height")?);
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(format!("`{s}`: each side must be from 1 to {MAX_SIDE}"));
    }
    if width * height > MAX_PIXELS {
        return Err(format!("`{s}`: more than {MAX_PIXELS} pixels"));
    }
    Ok(Size { width, height })
}

/// A step rate for people: three significant figures, with k or M.
pub fn rate_text(per_second: f64) -> String {
    let (value, unit) = if per_second >= 1e6 {
        (per_second / 1e6, "M ")
    } else if per_second >= 1e3 {
        (per_second / 1e3, "k ")
    } else {
        (per_second, "")
    };
    let decimals = if value >= 100.0 {
        0
    } else if value >= 10.0 {
        1
    } else {
        2
    };
    format!("{value:.decimals$} {unit}steps/s")
}

/// Where an output goes, for the checks: `-` is standard output.
pub fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Checks an output path before any work: its extension must be one of `formats`
/// (lower case, no dot), it must not be, or link to, one of `inputs`, and its
/// folder must exist. `flag` names the option in errors (`--output`).
///
/// # Errors
/// An error naming the flag and the path.
pub fn guard(flag: &str, output: &Path, formats: &[&str], inputs: &[&Path]) -> Result<()> {
    if is_stdio(output) {
        return Ok(());
    }
    let ext = tesseral::io::extension(output);
    if !formats.contains(&ext.as_str()) {
        let known = formats
            .iter()
            .map(|f| format!(".{f}"))
            .collect::<Vec<_>>()
            .join(", ");
        if ext.is_empty() {
            bail!(
                "{flag} {}: the name has no extension; this command writes {known}",
                output.display()
            );
        }
        bail!(
            "{flag} {}: this command does not write .{ext} files (it writes {known})",
            output.display()
        );
    }
    for input in inputs {
        if same_file(input, output) {
            bail!(
                "{flag} {}: this is the input {}; refusing to overwrite an input (write to another name)",
                output.display(),
                input.display()
            );
        }
    }
    // Checked here, before the work, rather than when the file is made after it.
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        let why = if folder.exists() {
            "not a folder"
        } else {
            "no such folder"
        };
        bail!(
            "{flag} {}: cannot create a file in {}: {why}",
            output.display(),
            folder.display()
        );
    }
    Ok(())
}

/// Whether `a` and `b` name the same file: the same canonical path, or the same
/// device and inode (hard links; symbolic links are followed by both).
pub fn same_file(a: &Path, b: &Path) -> bool {
    if is_stdio(a) || is_stdio(b) {
        return false;
    }
    if let (Ok(ca), Ok(cb)) = (a.canonicalize(), b.canonicalize()) {
        if ca == cb {
            return true;
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    false
}

/// Refuses an output whose estimated size exceeds `limit`, naming `--max-output`.
///
/// # Errors
/// An error naming the output, the estimate, the limit and the flag.
pub fn check_size(output: &Path, estimate: u64, limit: u64) -> Result<()> {
    if estimate > limit {
        // `.tess` is the most compact format: suggest it only for another one.
        let tess = output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("tess"));
        let compact = if tess {
            ""
        } else {
            ", or choose a more compact format such as .tess"
        };
        // The exact count only where the rounded one hides it.
        let exact = if estimate < 1024 {
            String::new()
        } else {
            format!(" ({estimate} bytes)")
        };
        bail!(
            "{}: the output would be about {}{exact}, more than the limit of {}; \
             raise it with --max-output (e.g. --max-output {}){compact}",
            output.display(),
            human_bytes(estimate),
            human_bytes(limit),
            suggest(estimate)
        );
    }
    Ok(())
}

/// A `--max-output` value just above `bytes`, in whole MiB, GiB or TiB.
fn suggest(bytes: u64) -> String {
    let mib = bytes.div_ceil(1 << 20);
    if mib < 1024 {
        return format!("{mib}M");
    }
    let gib = bytes.div_ceil(1 << 30);
    if gib < 1024 {
        format!("{gib}G")
    } else {
        format!("{}T", gib.div_ceil(1024))
    }
}

/// Outputs smaller than this are written without a progress bar.
const PROGRESS_MIN_BYTES: u64 = 64 << 20;

/// Runs `write`, and while it runs shows on standard error (on a terminal only) how
/// far the temporary file of the write in progress has grown towards `estimate`. The
/// library prints nothing, so the bar watches the file from a second thread.
pub fn with_progress<T>(estimate: u64, write: impl FnOnce() -> T) -> T {
    use std::io::IsTerminal;
    if estimate < PROGRESS_MIN_BYTES || !std::io::stderr().is_terminal() {
        return write();
    }
    let bar = indicatif::ProgressBar::new(estimate);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "writing {bar:40} {bytes}/~{total_bytes} {bytes_per_sec}, eta {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    watch(&bar, || written_bytes().min(estimate), write)
}

/// Runs `write` while a second thread sets `bar` to `position()` five times a
/// second, then clears the bar: the library reports no progress for these writes,
/// so the bar watches what they leave on disk.
pub fn watch<T>(
    bar: &indicatif::ProgressBar,
    position: impl Fn() -> u64 + Sync,
    write: impl FnOnce() -> T,
) -> T {
    let done = std::sync::atomic::AtomicBool::new(false);
    let result = std::thread::scope(|scope| {
        scope.spawn(|| {
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                bar.set_position(position());
                std::thread::sleep(std::time::Duration::from_millis(200));
            }
        });
        let result = write();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        result
    });
    bar.finish_and_clear();
    result
}

/// Installs the SIGINT/SIGTERM/SIGHUP handler: remove the temporaries of writes in
/// progress and exit with 128 + the signal (130 for Ctrl-C, 143 for SIGTERM, 129 when
/// the terminal goes away), as a shell reports a process killed by it. SIGKILL cannot be caught: a `kill -9` may leave a
/// `.NAME.*.tmp` file beside the output.
pub fn install_signal_handler() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // If the handler cannot be installed, the default action (die at once, possibly
    // leaving a temporary) still stops the program; that is no reason to refuse work.
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            tesseral::io::remove_pending_temporaries();
            std::process::exit(128 + signal);
        }
    });
}

/// Bytes written so far by the writes in progress: each temporary file's size,
/// and the files in each staged dataset directory.
pub fn written_bytes() -> u64 {
    let len = |p: &Path| std::fs::symlink_metadata(p).map_or(0, |m| m.len());
    tesseral::io::pending_temporaries()
        .iter()
        .map(|p| {
            if p.is_dir() {
                std::fs::read_dir(p).map_or(0, |d| d.flatten().map(|e| len(&e.path())).sum())
            } else {
                len(p)
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_size_suggests_tess_only_for_other_formats() {
        let err = |name: &str| check_size(Path::new(name), 10, 5).unwrap_err().to_string();
        assert!(err("big.xyz")
            .contains("--max-output 1M), or choose a more compact format such as .tess"));
        assert!(
            err("big.tess").ends_with("--max-output 1M)"),
            "{}",
            err("big.tess")
        );
        // Small sizes once; large ones with the exact count; the suggestion in
        // the unit that fits.
        assert!(err("big.tess").contains("about 10 bytes, more"));
        let big = check_size(Path::new("a.tess"), 3 << 30, 1 << 30)
            .unwrap_err()
            .to_string();
        assert!(
            big.contains("about 3.0 GiB (3221225472 bytes)") && big.ends_with("--max-output 3G)"),
            "{big}"
        );
        assert!(check_size(Path::new("big.tess"), 5, 5).is_ok());
    }

    #[test]
    fn byte_sizes() {
        assert_eq!(parse_bytes("123"), Ok(123));
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("4g"), Ok(4 << 30));
        assert_eq!(parse_bytes("50GiB"), Ok(50 << 30));
        assert_eq!(parse_bytes("1.5K"), Ok(1536));
        assert_eq!(parse_bytes("2T"), Ok(2 << 40));
        assert_eq!(parse_bytes("512MB"), Ok(512 << 20));
        assert!(parse_bytes("").is_err());
        assert!(parse_bytes("-1G").is_err());
        assert!(parse_bytes("nanG").is_err());
        assert!(parse_bytes("4X").is_err());
        assert!(parse_bytes("99999999999T").is_err());
    }

    #[test]
    fn image_sizes() {
        assert_eq!(
            parse_size("800x600"),
            Ok(Size {
                width: 800,
                height: 600
            })
        );
        assert_eq!(
            parse_size("16X9"),
            Ok(Size {
                width: 16,
                height: 9
            })
        );
        for bad in [
            "800",
            "0x10",
            "10x0",
            "x",
            "8193x10",
            "-1x5",
            "4096x4097",
            "axb",
        ] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn human() {
        assert_eq!(human_bytes(10), "10 bytes");
        assert_eq!(human_bytes(1536), "1.5 KiB");
        assert_eq!(human_bytes(44 << 30), "44.0 GiB");
        assert_eq!(suggest(44 << 30), "44G");
        assert_eq!(suggest((44 << 30) + 1), "45G");
        assert_eq!(suggest(3 << 40), "3T");
        assert_eq!(plural(1, "leaf", "leaves"), "1 leaf");
        assert_eq!(plural(0, "leaf", "leaves"), "0 leaves");
        assert_eq!(plural(2, "scan", "scans"), "2 scans");
    }

    #[test]
    fn rates_read_well() {
        assert_eq!(rate_text(1_234_567.891), "1.23 M steps/s");
        assert_eq!(rate_text(45_678.9), "45.7 k steps/s");
        assert_eq!(rate_text(999.4), "999 steps/s");
        assert_eq!(rate_text(2.71), "2.71 steps/s");
        assert_eq!(rate_text(0.0), "0.00 steps/s");
    }
}

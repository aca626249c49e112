//! What the streamed paths of `op`, `translate` and `convert` share: opening an
//! operand (a `.tess` file or a dataset directory) as a list of `.tess` files read
//! in code order, the output-size estimate checked against `--max-output` before
//! the work, and where the temporary spools go.

use std::path::{Path, PathBuf};

use anyhow::Result;
use tesseral::io::TessFile;
use tesseral::model::Frame;

use super::budget::Budget;

/// Memory per byte of a version-1 `.tess` file decoded whole: a leaf takes at
/// least one byte there and about 24 bytes in memory (the leaf, its colour
/// region's copy, and the decoder's buffers).
const V1_BYTES_PER_FILE_BYTE: u64 = 24;

/// An operand opened for streaming: its files in code order (one file, or a
/// dataset's parts), its frame, and their size in bytes on disk.
pub struct Operand {
    /// The files whose leaves follow each other in code order.
    pub files: Vec<TessFile>,
    /// The frame (a dataset's from its manifest).
    pub frame: Frame,
    /// The files' bytes on disk.
    pub bytes: u64,
}

impl Operand {
    /// Whether every file's only layer (if any) is colours, so that it streams.
    pub fn colours_only(&self) -> Result<bool> {
        for f in &self.files {
            if f.has_layers() && f.colour_leaves()?.is_none() {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// The space of the first file.
    pub fn space(&self) -> (u8, [i64; 3]) {
        self.files
            .first()
            .map_or((0, [0; 3]), |f| (f.depth(), f.origin()))
    }
}

fn file_len(path: &Path) -> Result<u64> {
    Ok(std::fs::metadata(path)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
        .len())
}

/// Whether `path` is a `.tess` file of version 1 (one payload, no chunks).
pub fn is_version_1(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 10];
    let mut f =
        std::fs::File::open(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    if f.read_exact(&mut head).is_err() {
        return Ok(false);
    }
    Ok(u16::from_le_bytes([head[8], head[9]]) == 1)
}

/// The leaves of a `.tess` file or a dataset, from its header or manifest without
/// reading the leaves (a version-1 file: its length, since a leaf takes at least one
/// byte of it); `None` for other inputs.
pub fn leaves_on_disk(path: &Path) -> Result<Option<u64>> {
    if super::output::is_stdio(path) {
        return Ok(None);
    }
    Ok(Some(if tesseral::partition::is_dataset(path) {
        let m = tesseral::partition::read_manifest(path)?;
        m.parts.iter().map(|p| p.leaves).sum::<u64>()
    } else if path.is_file() && tesseral::io::extension(path) == "tess" {
        if is_version_1(path)? {
            file_len(path)?
        } else {
            TessFile::open(path)?.leaf_count()
        }
    } else {
        return Ok(None);
    }))
}

/// Before a version-1 `.tess` file is read whole (the in-memory paths, taken
/// when it has layers that do not stream or the command cannot stream): its
/// memory, at most 24 bytes a byte of the file, against `--memory`. Nothing for
/// other inputs.
pub fn check_version_1_in_memory(path: &Path, budget: &Budget) -> Result<()> {
    if super::output::is_stdio(path)
        || !(path.is_file() && tesseral::io::extension(path) == "tess")
        || !is_version_1(path)?
    {
        return Ok(());
    }
    budget.check_memory(
        &format!("{} (a version-1 .tess file, read whole)", path.display()),
        file_len(path)?.saturating_mul(V1_BYTES_PER_FILE_BYTE),
        "",
    )
}

/// Opens `path` for streaming: a dataset directory (its parts, checked against
/// the manifest) or a `.tess` file of either version (a version-1 file's payload
/// is indexed in one pass, `TessFile::open_streaming`, and then streams as a
/// version-2 file does). `None` for anything else (read it in memory).
pub fn open_operand(path: &Path) -> Result<Option<Operand>> {
    use tesseral::partition::{is_dataset, open_part, read_manifest};
    if super::output::is_stdio(path) {
        return Ok(None);
    }
    if is_dataset(path) {
        let m = read_manifest(path)?;
        let mut files = Vec::with_capacity(m.parts.len());
        let mut bytes = 0u64;
        for (i, p) in m.parts.iter().enumerate() {
            bytes += file_len(&path.join(&p.file))?;
            files.push(open_part(path, &m, i)?);
        }
        let frame = Frame::new(m.frame.voxel_size, m.frame.translate);
        return Ok(Some(Operand {
            files,
            frame,
            bytes,
        }));
    }
    if !(path.is_file() && tesseral::io::extension(path) == "tess") {
        return Ok(None);
    }
    let bytes = file_len(path)?;
    let f = TessFile::open_streaming(path)?;
    let frame = f.frame();
    Ok(Some(Operand {
        files: vec![f],
        frame,
        bytes,
    }))
}

/// Makes the staged directory a dataset is written into beside `dir`, after
/// removing the staged directories of writers of `dir` that were killed
/// (`io::sweep_stale_staged`: only those whose marker names a process that is
/// provably gone), each named in a note on standard error.
pub fn stage_dataset(dir: &Path) -> Result<tesseral::io::StagedDir> {
    for gone in tesseral::io::sweep_stale_staged(dir) {
        eprintln!(
            "note: removed {}, left by a writer of {} that was killed",
            gone.display(),
            dir.display()
        );
    }
    Ok(tesseral::io::StagedDir::beside(dir)?)
}

/// The folder for temporary files beside `out`.
pub fn spool_dir(out: &Path) -> PathBuf {
    match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// Whether `out` is a `.tess` file (not standard output).
pub fn is_tess_output(out: &Path) -> bool {
    !super::output::is_stdio(out) && tesseral::io::extension(out) == "tess"
}

/// Streamed writes of fewer input leaves than this show no progress bar.
const PROGRESS_MIN_LEAVES: u64 = 1 << 20;

/// The bytes the chunks of `f` take: the leaves' share of the file, which a
/// streamed copy, cut, merge or translation writes as it goes (the colour
/// regions are spooled and copied at the end).
fn chunk_bytes(f: &TessFile) -> u64 {
    let c = f.chunks();
    match (c.first(), c.last()) {
        (Some(a), Some(b)) if c.len() > 1 => {
            let span = b.offset - a.offset;
            span + span / (c.len() as u64 - 1)
        }
        _ => f.leaf_count() + f.leaf_count() / 10,
    }
}

/// Runs `write`, a streamed write of the leaves of the files `inputs` (`what`: "cutting",
/// "translating"...), and while it runs shows on standard error, on a terminal
/// only and for inputs of at least 2^20 leaves, a bar of the input's leaves with
/// the time left. The library prints nothing and reports no progress here, so
/// the bar watches the output grow from a second thread (the temporary file, or
/// a staged dataset's files) against the bytes of the input's chunks: the leaves
/// shown are that share of the input's leaves, an estimate (an operation that
/// drops most leaves, such as an intersection, ends early).
pub fn with_leaf_progress<T>(what: &str, inputs: &[&[TessFile]], write: impl FnOnce() -> T) -> T {
    use std::io::IsTerminal;
    let files = || inputs.iter().flat_map(|f| f.iter());
    let leaves: u64 = files().map(TessFile::leaf_count).sum();
    if leaves < PROGRESS_MIN_LEAVES || !std::io::stderr().is_terminal() {
        return write();
    }
    let bytes = files().map(chunk_bytes).sum::<u64>().max(1);
    let bar = indicatif::ProgressBar::new(leaves);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{what} {{bar:40}} ~{{pos}}/{{len}} leaves, eta {{eta}}"
        ))
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    super::output::watch(
        &bar,
        || {
            let share = super::output::written_bytes().min(bytes) as f64 / bytes as f64;
            (share * leaves as f64) as u64
        },
        write,
    )
}

//! The dataset steps of `tesseral.dask`, one call each: the parts and manifest of
//! a dataset on disk (the library's dataset code, so a dataset written here is the
//! one `tesseral build --parts` writes), and the staged directory it is written in.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::linear::LinearOctree;
use tesseral::partition::{self as part, Manifest, ManifestPart, Partition};

use crate::args::Int;
use crate::errors;
use crate::octree::Octree;
use crate::partition::{depth_of, frame_of, v3, Vec3};

fn entry<'py>(py: Python<'py>, e: &ManifestPart) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("file", &e.file)?;
    d.set_item("lo", e.lo)?;
    d.set_item("hi", e.hi)?;
    d.set_item("leaves", e.leaves)?;
    d.set_item("voxels", e.voxels)?;
    d.set_item("crc32", e.crc32)?;
    Ok(d)
}

/// A manifest entry as Python hands it back.
#[derive(FromPyObject)]
pub struct Entry {
    #[pyo3(item)]
    file: String,
    #[pyo3(item)]
    lo: u64,
    #[pyo3(item)]
    hi: u64,
    #[pyo3(item)]
    leaves: u64,
    #[pyo3(item)]
    voxels: u64,
    #[pyo3(item)]
    crc32: u32,
}

/// Writes part `i` (range `[lo, hi)`) of a dataset in `dir`, which must exist (the
/// staged folder the client made: a task still running after the write was
/// abandoned and its folder removed must not make it again), with its frame and
/// colours; returns its manifest entry as a dict.
#[pyfunction]
pub fn partition_write_part<'py>(
    py: Python<'py>,
    dir: PathBuf,
    i: usize,
    lo: u64,
    hi: u64,
    tree: &Octree,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &tree.model;
    if !dir.is_dir() {
        let gone = std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "the dataset's staged folder is gone (its write was abandoned)",
        );
        return Err(errors::io(&gone, Some(&dir)));
    }
    let e = py
        .allow_threads(|| part::write_model_part(&dir, i, Partition { lo, hi }, m))
        .map_err(partition_error)?;
    entry(py, &e)
}

/// Writes the manifest of a dataset whose parts are written: the space
/// (`depth`, `origin`), the frame (`voxel_size`, `translate`) and the entries.
#[pyfunction]
pub fn partition_write_manifest(
    py: Python<'_>,
    dir: PathBuf,
    depth: Int,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    entries: Vec<Entry>,
) -> PyResult<()> {
    let depth = depth_of(&depth, "depth")?;
    let parts: Vec<ManifestPart> = entries.into_iter().map(ManifestPart::from).collect();
    LinearOctree::empty(depth, v3(origin)).map_err(errors::octree)?;
    let frame = frame_of(voxel_size, translate)?;
    let origin = [origin.0, origin.1, origin.2];
    py.allow_threads(|| part::write_manifest(&dir, depth, origin, frame, &parts))
        .map_err(partition_error)
}

/// A dataset's manifest, checked: {"depth", "origin", "voxel_size", "translate",
/// "parts": [entry, …]}.
#[pyfunction]
pub fn partition_read_manifest(py: Python<'_>, dir: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let m = part::read_manifest(&dir).map_err(partition_error)?;
    let d = PyDict::new(py);
    d.set_item("depth", m.depth)?;
    d.set_item("origin", (m.origin[0], m.origin[1], m.origin[2]))?;
    d.set_item("voxel_size", m.frame.voxel_size)?;
    let t = m.frame.translate;
    d.set_item("translate", (t[0], t[1], t[2]))?;
    let parts = m
        .parts
        .iter()
        .map(|e| entry(py, e))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("parts", parts)?;
    Ok(d)
}

/// A part of the dataset in `dir` as the client's manifest describes it (space
/// `(depth, origin)`, frame, and the part's entry): read and checked against that
/// description (CRC-32, space, range, leaf and voxel counts) where it is loaded,
/// so a part changed since the manifest was read is an error naming it.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn partition_read_part(
    py: Python<'_>,
    dir: PathBuf,
    depth: Int,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    entry: Entry,
) -> PyResult<Octree> {
    let depth = depth_of(&depth, "depth")?;
    let frame = frame_of(voxel_size, translate)?;
    let m = Manifest::new(depth, v3(origin), frame, vec![entry.into()]);
    py.allow_threads(|| part::read_part(&dir, &m, 0))
        .map(Octree::new)
        .map_err(partition_error)
}

/// File errors as `FormatError`/`OSError`, the rest as `FormatError` too (they name
/// the manifest or part at fault).
pub fn partition_error(e: part::PartitionError) -> PyErr {
    match e {
        part::PartitionError::Format(f) => errors::format(f),
        other => errors::FormatError::new_err(other.to_string()),
    }
}

impl From<Entry> for ManifestPart {
    fn from(e: Entry) -> Self {
        ManifestPart {
            file: e.file,
            lo: e.lo,
            hi: e.hi,
            leaves: e.leaves,
            voxels: e.voxels,
            crc32: e.crc32,
        }
    }
}

/// Makes a staged dataset directory beside `target` (`.NAME.XXXXXX.tmp`, with
/// the marker naming this process, as `tesseral build --parts` makes it) and
/// returns its path; nothing removes it but [`staged_commit`] or the caller.
#[pyfunction]
pub fn staged_create(target: PathBuf) -> PyResult<PathBuf> {
    tesseral::io::stage_dir(&target).map_err(errors::format)
}

/// Renames the staged directory `staged` to `target` (its marker removed; an old
/// directory at `target` renamed aside first, then removed), as the CLI does.
#[pyfunction]
pub fn staged_commit(py: Python<'_>, staged: PathBuf, target: PathBuf) -> PyResult<()> {
    py.allow_threads(|| tesseral::io::commit_staged(&staged, &target))
        .map_err(errors::format)
}

/// Removes the staged directories beside `target` whose writers are provably
/// gone (killed), as the CLI's `--parts` writers do; returns their paths.
#[pyfunction]
pub fn staged_sweep(py: Python<'_>, target: PathBuf) -> Vec<PathBuf> {
    py.allow_threads(|| tesseral::io::sweep_stale_staged(&target))
}

/// Registers the functions above.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(partition_write_part, m)?)?;
    m.add_function(wrap_pyfunction!(partition_write_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(partition_read_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(partition_read_part, m)?)?;
    m.add_function(wrap_pyfunction!(staged_create, m)?)?;
    m.add_function(wrap_pyfunction!(staged_commit, m)?)?;
    m.add_function(wrap_pyfunction!(staged_sweep, m)?)?;
    Ok(())
}

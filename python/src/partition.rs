//! The steps of a partitioned run, one call each, for `tesseral.dask`'s tasks:
//! balanced ranges of a scene, building one code range (with the scene's colours),
//! a set operation of two parts, cutting, joining, the reach and the two halves of a
//! shuffle, and the parts and manifest of a dataset on disk (the library's dataset
//! code, so a dataset written here is the one `tesseral build --parts` writes).
//!
//! Ranges cross as lists of `(lo, hi)` pairs; parts as `Octree`s (models: tree,
//! frame, colours), each in the whole space with its leaves inside its range.

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::linear::{LinearOctree, SetOp};
use tesseral::model::{Frame, Model};
use tesseral::partition::{self as part, Manifest, ManifestPart, Partition};

use crate::errors;
use crate::octree::Octree;
use crate::scene::Scene;

type Vec3 = (i64, i64, i64);
type Bbox = Option<(Vec3, Vec3)>;

fn ranges_in(ranges: &[(u64, u64)]) -> Vec<Partition> {
    ranges
        .iter()
        .map(|&(lo, hi)| Partition { lo, hi })
        .collect()
}

fn ranges_out(ranges: &[Partition]) -> Vec<(u64, u64)> {
    ranges.iter().map(|p| (p.lo, p.hi)).collect()
}

fn set_op(name: &str) -> PyResult<SetOp> {
    match name {
        "union" => Ok(SetOp::Union),
        "intersection" => Ok(SetOp::Intersection),
        "difference" => Ok(SetOp::Difference),
        "xor" | "symmetric_difference" => Ok(SetOp::SymmetricDifference),
        _ => Err(PyValueError::new_err(format!(
            "operation {name:?}: expected 'union', 'intersection', 'difference' or 'xor'"
        ))),
    }
}

fn frame_of(voxel_size: f64, translate: (f64, f64, f64)) -> PyResult<Frame> {
    if !(voxel_size.is_finite() && voxel_size > 0.0) {
        return Err(PyValueError::new_err(
            "voxel_size must be positive and finite",
        ));
    }
    Ok(Frame::new(
        voxel_size,
        [translate.0, translate.1, translate.2],
    ))
}

fn v3(v: Vec3) -> [i64; 3] {
    [v.0, v.1, v.2]
}

fn octrees(models: Vec<Model>) -> Vec<Octree> {
    models.into_iter().map(Octree::new).collect()
}

/// About `k` ranges of equal work for building `scene` at `depth` (those of
/// `tesseral build --parts k`).
#[pyfunction]
pub fn partition_scene_ranges(
    py: Python<'_>,
    scene: &Scene,
    depth: Option<u8>,
    k: usize,
) -> PyResult<Vec<(u64, u64)>> {
    let s = scene.at_depth(depth)?;
    let r = py
        .allow_threads(|| part::scene_ranges(&s, k))
        .map_err(errors::octree)?;
    Ok(ranges_out(&r))
}

/// The part of `scene` at `depth` in the codes `[lo, hi)`, with the scene's frame
/// and colours (those `tesseral build --parts` writes for the range).
#[pyfunction]
pub fn partition_build_range(
    py: Python<'_>,
    scene: &Scene,
    depth: Option<u8>,
    lo: u64,
    hi: u64,
) -> PyResult<Octree> {
    let s = scene.at_depth(depth)?;
    let window = tesseral::csg::StreamPlan::default_window();
    py.allow_threads(|| part::build_scene_range(&s, Partition { lo, hi }, window))
        .map(Octree::new)
        .map_err(errors::octree)
}

/// The set operation `op` of two parts cut to the same range (the first operand's
/// colour wins).
#[pyfunction]
pub fn partition_set_op(py: Python<'_>, a: &Octree, b: &Octree, op: &str) -> PyResult<Octree> {
    let op = set_op(op)?;
    let (ma, mb) = (&a.model, &b.model);
    py.allow_threads(|| part::set_op_models(ma, mb, op))
        .map(Octree::new)
        .map_err(errors::octree)
}

/// The part cut into `ranges` (sorted and disjoint; every leaf must lie in one),
/// one Octree per range, colours cut with it.
#[pyfunction]
pub fn partition_split(
    py: Python<'_>,
    tree: &Octree,
    ranges: Vec<(u64, u64)>,
) -> PyResult<Vec<Octree>> {
    let m = &tree.model;
    let ranges = ranges_in(&ranges);
    py.allow_threads(|| part::split_model(m, &ranges))
        .map(octrees)
        .map_err(errors::octree)
}

/// The union of disjoint pieces (with their colours) in the space `(depth,
/// origin)` with the frame `(voxel_size, translate)`; an empty part when there are
/// none.
#[pyfunction]
pub fn partition_join(
    py: Python<'_>,
    depth: u8,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    pieces: Vec<Octree>,
) -> PyResult<Octree> {
    let frame = frame_of(voxel_size, translate)?;
    let models: Vec<Model> = pieces.into_iter().map(|p| p.model).collect();
    py.allow_threads(|| part::join_models(depth, v3(origin), frame, models))
        .map(Octree::new)
        .map_err(errors::octree)
}

/// For each source range (of the space `(src_depth, src_origin)`), the indices of
/// the target ranges (of `(dst_depth, dst_origin)`) that its voxels moved by `by`
/// can land in, from the ranges alone.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn partition_reach(
    py: Python<'_>,
    src_depth: u8,
    src_origin: Vec3,
    src_ranges: Vec<(u64, u64)>,
    by: Vec3,
    dst_depth: u8,
    dst_origin: Vec3,
    dst_ranges: Vec<(u64, u64)>,
) -> PyResult<Vec<Vec<usize>>> {
    let (src, dst) = (ranges_in(&src_ranges), ranges_in(&dst_ranges));
    py.allow_threads(|| {
        part::reach(
            (src_depth, v3(src_origin)),
            &src,
            v3(by),
            (dst_depth, v3(dst_origin)),
            &dst,
        )
    })
    .map_err(errors::octree)
}

/// The ranges of the space `(depth, origin)` re-expressed in a space grown from it
/// (`(new_depth, new_origin)`), tiling it.
#[pyfunction]
pub fn partition_embedded_ranges(
    depth: u8,
    origin: Vec3,
    ranges: Vec<(u64, u64)>,
    new_depth: u8,
    new_origin: Vec3,
) -> PyResult<Vec<(u64, u64)>> {
    let r = part::embedded_ranges(
        depth,
        v3(origin),
        &ranges_in(&ranges),
        new_depth,
        v3(new_origin),
    )
    .map_err(errors::octree)?;
    Ok(ranges_out(&r))
}

/// The space of the whole tree (of space `depth`, `origin`, whose parts have the
/// bounding boxes `bboxes`) translated by `by`: `(depth, origin)`.
#[pyfunction]
pub fn partition_translated_space(
    depth: u8,
    origin: Vec3,
    bboxes: Vec<Bbox>,
    by: Vec3,
) -> PyResult<(u8, Vec3)> {
    let v = |p: Vec3| [p.0, p.1, p.2];
    let bbox = part::union_bbox(bboxes.into_iter().map(|b| b.map(|(lo, hi)| (v(lo), v(hi)))));
    let (d, o) = part::translated_space(depth, v(origin), bbox, v(by)).map_err(errors::octree)?;
    Ok((d, (o[0], o[1], o[2])))
}

/// Sorted codes, in the space `(depth, origin)`, of about `max` leaves of `tree`
/// moved by `by` (a sample for balancing the ranges of a translation).
#[pyfunction]
pub fn partition_translated_sample<'py>(
    py: Python<'py>,
    tree: &Octree,
    by: Vec3,
    depth: u8,
    origin: Vec3,
    max: usize,
) -> Bound<'py, PyArray1<u64>> {
    let t = &tree.model.tree;
    let codes = py.allow_threads(|| {
        part::translated_sample(
            t,
            [by.0, by.1, by.2],
            depth,
            [origin.0, origin.1, origin.2],
            max,
        )
    });
    codes.into_pyarray(py)
}

/// Exactly `k` ranges of the depth-`depth` space (fewer only when it has fewer
/// codes), balanced on the sorted sample `codes`.
#[pyfunction]
pub fn partition_balanced_ranges(
    depth: u8,
    k: usize,
    codes: PyReadonlyArray1<'_, u64>,
) -> PyResult<Vec<(u64, u64)>> {
    LinearOctree::empty(depth, [0; 3]).map_err(errors::octree)?;
    let mut c = codes.as_array().to_vec();
    c.sort_unstable();
    Ok(ranges_out(&part::balanced_ranges_exact(depth, k, &c)))
}

/// `tree` moved by `by` into the space `(depth, origin)` and cut into `ranges` of
/// it (sorted, disjoint: those `partition_reach` gives), colours with it; voxels
/// landing outside the space are dropped when `drop_outside`, else an error.
#[pyfunction]
pub fn partition_move_split(
    py: Python<'_>,
    tree: &Octree,
    by: Vec3,
    depth: u8,
    origin: Vec3,
    ranges: Vec<(u64, u64)>,
    drop_outside: bool,
) -> PyResult<Vec<Octree>> {
    let m = &tree.model;
    let ranges = ranges_in(&ranges);
    py.allow_threads(|| part::move_and_split(m, v3(by), depth, v3(origin), &ranges, drop_outside))
        .map(octrees)
        .map_err(errors::octree)
}

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
    depth: u8,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    entries: Vec<Entry>,
) -> PyResult<()> {
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
    depth: u8,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    entry: Entry,
) -> PyResult<Octree> {
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
    m.add_function(wrap_pyfunction!(partition_scene_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(partition_build_range, m)?)?;
    m.add_function(wrap_pyfunction!(partition_set_op, m)?)?;
    m.add_function(wrap_pyfunction!(partition_split, m)?)?;
    m.add_function(wrap_pyfunction!(partition_join, m)?)?;
    m.add_function(wrap_pyfunction!(partition_translated_space, m)?)?;
    m.add_function(wrap_pyfunction!(partition_translated_sample, m)?)?;
    m.add_function(wrap_pyfunction!(partition_balanced_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(partition_reach, m)?)?;
    m.add_function(wrap_pyfunction!(partition_embedded_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(partition_move_split, m)?)?;
    m.add_function(wrap_pyfunction!(partition_write_part, m)?)?;
    m.add_function(wrap_pyfunction!(partition_write_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(partition_read_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(partition_read_part, m)?)?;
    m.add_function(wrap_pyfunction!(staged_create, m)?)?;
    m.add_function(wrap_pyfunction!(staged_commit, m)?)?;
    m.add_function(wrap_pyfunction!(staged_sweep, m)?)?;
    Ok(())
}

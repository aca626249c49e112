//! The steps of a partitioned run, one call each, for `tesseral.dask`'s tasks:
//! balanced ranges of a scene, building one code range (with the scene's colours),
//! a set operation of two parts, cutting, joining, the reach and the two halves of a
//! shuffle (the parts and manifest of a dataset on disk are in `dataset.rs`).
//!
//! Ranges cross as lists of `(lo, hi)` pairs; parts as `Octree`s (models: tree,
//! frame, colours), each in the whole space with its leaves inside its range.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tesseral::linear::{LinearOctree, SetOp, MAX_DEPTH};
use tesseral::model::{Frame, Model};
use tesseral::partition::{self as part, Partition};

use crate::args::Int;
use crate::errors;
use crate::octree::Octree;
use crate::scene::{scene_depth, Scene};

pub(crate) type Vec3 = (i64, i64, i64);
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

pub(crate) fn frame_of(voxel_size: f64, translate: (f64, f64, f64)) -> PyResult<Frame> {
    if !(voxel_size.is_finite() && voxel_size > 0.0) {
        return Err(PyValueError::new_err(
            "voxel_size must be positive and finite",
        ));
    }
    let t = [translate.0, translate.1, translate.2];
    if !t.iter().all(|x| x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "translate {translate:?}: each of x, y, z must be finite"
        )));
    }
    Ok(Frame::new(voxel_size, t))
}

/// The depth of a space, 0 to 21 (the lattice's): ValueError naming `name`
/// outside, however far (not pyo3's OverflowError past u8).
pub(crate) fn depth_of(d: &Int, name: &str) -> PyResult<u8> {
    d.within(name, 0..=i128::from(MAX_DEPTH), "expected 0 to 21")
}

/// A count of ranges, 0 to 2**64 - 1.
fn count_of(k: &Int) -> PyResult<usize> {
    k.within("k", crate::args::U64, "expected 0 to 2**64 - 1")
}

pub(crate) fn v3(v: Vec3) -> [i64; 3] {
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
    depth: Option<Int>,
    k: Int,
) -> PyResult<Vec<(u64, u64)>> {
    let s = scene.at_depth(scene_depth(depth.as_ref())?)?;
    let k = count_of(&k)?;
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
    depth: Option<Int>,
    lo: u64,
    hi: u64,
) -> PyResult<Octree> {
    let s = scene.at_depth(scene_depth(depth.as_ref())?)?;
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
    depth: Int,
    origin: Vec3,
    voxel_size: f64,
    translate: (f64, f64, f64),
    pieces: Vec<Octree>,
) -> PyResult<Octree> {
    let depth = depth_of(&depth, "depth")?;
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
    src_depth: Int,
    src_origin: Vec3,
    src_ranges: Vec<(u64, u64)>,
    by: Vec3,
    dst_depth: Int,
    dst_origin: Vec3,
    dst_ranges: Vec<(u64, u64)>,
) -> PyResult<Vec<Vec<usize>>> {
    let src_depth = depth_of(&src_depth, "src_depth")?;
    let dst_depth = depth_of(&dst_depth, "dst_depth")?;
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
    depth: Int,
    origin: Vec3,
    ranges: Vec<(u64, u64)>,
    new_depth: Int,
    new_origin: Vec3,
) -> PyResult<Vec<(u64, u64)>> {
    let depth = depth_of(&depth, "depth")?;
    let new_depth = depth_of(&new_depth, "new_depth")?;
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
    depth: Int,
    origin: Vec3,
    bboxes: Vec<Bbox>,
    by: Vec3,
) -> PyResult<(u8, Vec3)> {
    let depth = depth_of(&depth, "depth")?;
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
    depth: Int,
    origin: Vec3,
    max: usize,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    let depth = depth_of(&depth, "depth")?;
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
    Ok(codes.into_pyarray(py))
}

/// Exactly `k` ranges of the depth-`depth` space (fewer only when it has fewer
/// codes), balanced on the sorted sample `codes`.
#[pyfunction]
pub fn partition_balanced_ranges(
    depth: Int,
    k: Int,
    codes: PyReadonlyArray1<'_, u64>,
) -> PyResult<Vec<(u64, u64)>> {
    let (depth, k) = (depth_of(&depth, "depth")?, count_of(&k)?);
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
    depth: Int,
    origin: Vec3,
    ranges: Vec<(u64, u64)>,
    drop_outside: bool,
) -> PyResult<Vec<Octree>> {
    let depth = depth_of(&depth, "depth")?;
    let m = &tree.model;
    let ranges = ranges_in(&ranges);
    py.allow_threads(|| part::move_and_split(m, v3(by), depth, v3(origin), &ranges, drop_outside))
        .map(octrees)
        .map_err(errors::octree)
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
    crate::dataset::register(m)?;
    Ok(())
}

//! What the scan-taking calls share: their arguments checked (origins, `max_range`,
//! the work budget), their counts as dicts, and `tesseral.read_scans`.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::occupancy::{OccupancyMap as Map, ScanStats};

use crate::args::{Int, U64};

/// The default of `max_cells`: as the CLI's `--max-cells`.
pub(crate) const DEFAULT_MAX_CELLS: Int = Int::Fits(10_000_000_000);

/// `n` finite numbers from any sequence of them (a tuple, a list, an array), named
/// `name` in errors: TypeError when it is not `n` numbers, ValueError when one is NaN
/// or infinite (as the CLI's `--origin` and `--pose`).
pub(crate) fn finite<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; N]> {
    let v: [f64; N] = obj.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected {N} numbers, got {}",
            obj.repr()
                .map_or_else(|_| "?".to_owned(), |r| r.to_string())
        ))
    })?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}: {v:?} is not finite (every coordinate must be a finite number)"
        )));
    }
    Ok(v)
}

/// A sensor origin (x, y, z): three finite numbers.
pub(crate) fn origin(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    finite::<3>(obj, "origin")
}

/// `max_range` checked as the CLI checks `--max-range`: None (no limit) or a positive
/// finite number. (The library reads a negative range as no limit, as OctoMap does;
/// Python refuses it, and NaN, rather than guess.)
pub(crate) fn max_range(r: Option<f64>) -> PyResult<Option<f64>> {
    match r {
        Some(m) if !(m.is_finite() && m > 0.0) => Err(PyValueError::new_err(format!(
            "max_range {m}: expected a positive finite number, or None for no limit"
        ))),
        _ => Ok(r),
    }
}

/// `max_cells` checked: 0 to 2**64 - 1 (ValueError naming it outside, however
/// large, not pyo3's OverflowError).
pub(crate) fn max_cells(m: &Int) -> PyResult<u64> {
    m.within("max_cells", U64, "expected 0 to 2**64 - 1 cells")
}

/// Refuses a scan whose rays may cross more than `max_cells` cells, before any is
/// cast (a far point with no `max_range` would be walked for hours).
pub(crate) fn check_work(
    map: &Map,
    origin: [f64; 3],
    points: &[[f64; 3]],
    max_range: Option<f64>,
    max_cells: u64,
) -> PyResult<()> {
    let w = map.scan_work(origin, points, max_range);
    if w.cells > max_cells {
        return Err(PyValueError::new_err(format!(
            "the scan's {} rays may cross {} cells (the longest is {:.6e} units), past \
             max_cells={max_cells}: cut long rays with max_range, or raise max_cells",
            w.rays, w.cells, w.longest
        )));
    }
    Ok(())
}

/// A scan's counts as a dict: points, rays, skipped, hits, misses.
pub(crate) fn stats_dict<'py>(py: Python<'py>, s: &ScanStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("points", s.points)?;
    d.set_item("rays", s.rays)?;
    d.set_item("skipped", s.skipped)?;
    d.set_item("hits", s.hits)?;
    d.set_item("misses", s.misses)?;
    Ok(d)
}

/// An error about scan `i` of a list: its message prefixed by the scan, its type
/// kept (TypeError or ValueError).
pub(crate) fn at_scan(py: Python<'_>, i: usize, e: PyErr) -> PyErr {
    PyErr::from_type(e.get_type(py), format!("scan {i}: {}", e.value(py)))
}

/// One item of `insert_scans`' iterable: an `(origin, points)` pair as any
/// two-item iterable (a tuple, a list).
pub(crate) fn scan_pair<'py>(item: &Bound<'py, PyAny>) -> PyResult<([f64; 3], Vec<[f64; 3]>)> {
    let parts = item
        .try_iter()
        .and_then(|it| it.take(3).collect::<PyResult<Vec<_>>>())
        .ok()
        .filter(|p| p.len() == 2 && !item.is_instance_of::<pyo3::types::PyString>());
    let Some(parts) = parts else {
        return Err(PyTypeError::new_err(format!(
            "expected an (origin, points) pair, got {}",
            item.get_type()
                .name()
                .map_or_else(|_| "?".to_owned(), |n| n.to_string())
        )));
    };
    Ok((
        origin(&parts[0])?,
        crate::arrays::points(&parts[1], "points")?,
    ))
}

/// A scan as `read_scans` gives it: the sensor origin and N×3 world points.
type PlacedScan<'py> = ((f64, f64, f64), Bound<'py, numpy::PyArray2<f64>>);

/// Reads a scan file (`.graph`, `.log`, `.xyz`, `.ply`, `.pcd`, as `tesseral map`
/// does) as a list of `(origin, points)` pairs, the points an N×3 float array in
/// world coordinates: what `OccupancyMap.insert_scans` takes. A graph's or log's
/// poses are applied, a PCD's `VIEWPOINT` is its origin. For a cloud, `origin`
/// gives the sensor position (the points are world coordinates) or `pose` (x, y, z,
/// roll, pitch, yaw) moves points given in the sensor frame; both are refused for
/// `.graph` and `.log`, which carry their own poses, and both must be finite. NaN
/// points are kept, for `insert_scans` to skip and count.
#[pyfunction]
#[pyo3(signature = (path, origin = None, pose = None))]
pub fn read_scans<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    origin: Option<&Bound<'py, PyAny>>,
    pose: Option<&Bound<'py, PyAny>>,
) -> PyResult<Vec<PlacedScan<'py>>> {
    use tesseral::io::scan::{self, Placement, ScanFormat};
    let origin = origin.map(self::origin).transpose()?;
    let pose = pose.map(|p| finite::<6>(p, "pose")).transpose()?;
    let placement = Placement::of(origin, pose)
        .ok_or_else(|| PyValueError::new_err("give origin or pose, not both"))?;
    // The extension decides, as in `scan::read`, which names the file when unknown.
    let format = ScanFormat::from_extension(&tesseral::io::extension(&path));
    if placement.overrides() && format.is_some_and(ScanFormat::has_poses) {
        return Err(PyValueError::new_err(format!(
            "{}: a scan graph or log carries its own poses; origin and pose place clouds",
            path.display()
        )));
    }
    let scans = py
        .allow_threads(|| scan::read(&path))
        .map_err(crate::errors::format)?;
    scans
        .into_iter()
        .map(|mut s| {
            s.place(placement);
            let [x, y, z] = s.translation;
            let points = py.allow_threads(|| s.into_world_points());
            Ok(((x, y, z), crate::arrays::to_array(py, points)?))
        })
        .collect()
}

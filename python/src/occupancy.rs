//! `tesseral.OccupancyMap`: an occupancy map fed whole scans (N×3 float arrays).

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::occupancy::{CellState, OccupancyMap as Map, ScanStats, SensorModel};

use crate::arrays::rows;
use crate::octree::Octree;

/// An unbounded occupancy map (unknown / free / occupied cells with log-odds), built
/// from range scans with OctoMap's `insertPointCloud` semantics and sensor model.
#[pyclass(module = "tesseral")]
pub struct OccupancyMap {
    map: Map,
}

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The sensor model of the constructors' probabilities (ValueError when they do not
/// make one).
fn sensor_model(
    prob_hit: f64,
    prob_miss: f64,
    clamp: (f64, f64),
    threshold: f64,
) -> PyResult<SensorModel> {
    SensorModel::from_probabilities(prob_hit, prob_miss, clamp, threshold).map_err(value_error)
}

/// The default of `max_cells`: as the CLI's `--max-cells`.
pub(crate) const DEFAULT_MAX_CELLS: u64 = 10_000_000_000;

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

/// An error about scan `i` of a list, with its message prefixed by the scan.
fn at_scan(py: Python<'_>, i: usize, e: PyErr) -> PyErr {
    PyValueError::new_err(format!("scan {i}: {}", e.value(py)))
}

#[pymethods]
impl OccupancyMap {
    #[new]
    #[pyo3(signature = (resolution, prob_hit = 0.7, prob_miss = 0.4, clamp = (0.1192, 0.971), threshold = 0.5))]
    fn new(
        resolution: f64,
        prob_hit: f64,
        prob_miss: f64,
        clamp: (f64, f64),
        threshold: f64,
    ) -> PyResult<Self> {
        let sensor = sensor_model(prob_hit, prob_miss, clamp, threshold)?;
        Ok(Self {
            map: Map::new(resolution, sensor).map_err(value_error)?,
        })
    }

    /// Inserts one scan: `points` is N×3 (world units), `origin` the sensor position.
    /// Returns the scan's counts: points, rays, skipped (NaN/inf), hits, misses
    /// (cells missed, not counting those of blocks already clamped free, which a
    /// miss leaves unchanged). A scan whose rays may cross more than `max_cells`
    /// cells in all is refused (ValueError) before any is cast.
    #[pyo3(signature = (origin, points, max_range = None, max_cells = DEFAULT_MAX_CELLS))]
    fn insert_scan<'py>(
        &mut self,
        py: Python<'py>,
        origin: [f64; 3],
        points: PyReadonlyArray2<'_, f64>,
        max_range: Option<f64>,
        max_cells: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pts = rows(&points)?;
        check_work(&self.map, origin, &pts, max_range, max_cells)?;
        let m = &mut self.map;
        let s = py.allow_threads(|| m.insert_scan(origin, &pts, max_range));
        m.check_capacity().map_err(value_error)?;
        stats_dict(py, &s)
    }

    /// Inserts scans in order, as a loop of `insert_scan` would, each given as an
    /// `(origin, points)` pair: each scan is cast while the one before it is written
    /// into the map, so several threads are kept busy. Returns one dict of counts per
    /// scan. At the end the map's storage is packed as `shrink_to_fit` packs it
    /// (patched palettes where smaller, arenas compacted where an eighth holds
    /// nothing), so it may take fewer bytes than after the loop. Every scan's work
    /// is checked against `max_cells` before any is cast (ValueError naming the
    /// scan).
    #[pyo3(signature = (scans, max_range = None, max_cells = DEFAULT_MAX_CELLS))]
    fn insert_scans<'py>(
        &mut self,
        py: Python<'py>,
        scans: Vec<([f64; 3], PyReadonlyArray2<'_, f64>)>,
        max_range: Option<f64>,
        max_cells: u64,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut placed = Vec::with_capacity(scans.len());
        for (i, (origin, points)) in scans.iter().enumerate() {
            let pts = rows(points).map_err(|e| at_scan(py, i, e))?;
            check_work(&self.map, *origin, &pts, max_range, max_cells)
                .map_err(|e| at_scan(py, i, e))?;
            placed.push((*origin, pts));
        }
        let m = &mut self.map;
        let mut counts = Vec::with_capacity(placed.len());
        py.allow_threads(|| {
            m.insert_scans_each(
                placed.iter().map(|(o, p)| (*o, p.as_slice())),
                max_range,
                |m, s| {
                    m.check_capacity()
                        .map_err(|e| format!("scan {}: {e}", counts.len()))?;
                    counts.push(s);
                    Ok::<(), String>(())
                },
            )
        })
        .map_err(PyValueError::new_err)?;
        counts.iter().map(|s| stats_dict(py, s)).collect()
    }

    /// The state of each cell of an N×3 int64 array: 0 unknown, 1 free, 2 occupied.
    fn state<'py>(
        &self,
        py: Python<'py>,
        cells: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let c = rows(&cells)?;
        let m = &self.map;
        let out: Vec<u8> = py.allow_threads(|| {
            c.iter()
                .map(|&v| match m.state(v) {
                    CellState::Unknown => 0,
                    CellState::Free => 1,
                    CellState::Occupied => 2,
                })
                .collect()
        });
        Ok(out.into_pyarray(py))
    }

    /// The log-odds of each cell of an N×3 int64 array (NaN where unknown), looked
    /// up in batches whose memory accesses overlap (`log_odds_many`).
    fn log_odds<'py>(
        &self,
        py: Python<'py>,
        cells: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let c = rows(&cells)?;
        let m = &self.map;
        let out: Vec<f32> = py.allow_threads(|| {
            let mut v = vec![None; c.len()];
            m.log_odds_many(&c, &mut v);
            v.into_iter().map(|l| l.unwrap_or(f32::NAN)).collect()
        });
        Ok(out.into_pyarray(py))
    }

    /// The cell holding each point of an N×3 float array, N×3 int64.
    fn cells_of<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<i64>>> {
        let p = rows(&points)?;
        crate::arrays::to_array(py, p.iter().map(|&q| self.map.cell_of(q)).collect())
    }

    /// The side of a cell, in world units.
    #[getter]
    fn resolution(&self) -> f64 {
        self.map.resolution()
    }

    /// The map as an `Octree`, as `tesseral map` writes it: occupied cells as the
    /// voxels, frame of voxel size `resolution` at the world origin, free cells and
    /// every known cell's log-odds beside them. `write("map.bt")` or `.ot` gives
    /// OctoMap's files; `render`, `collide` and `info` take it as any octree.
    fn to_octree(&self, py: Python<'_>) -> PyResult<Octree> {
        let m = &self.map;
        py.allow_threads(|| m.to_model())
            .map(Octree::new)
            .map_err(crate::errors::octree)
    }

    /// Writes the map, atomically, in the format named by the extension: `.bt`
    /// and `.ot` straight from its cells (the bytes of `to_octree().write(path)`,
    /// without building the octree), any other format through `to_octree()`.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let m = &self.map;
        py.allow_threads(|| m.write_file(&path))
            .map_err(crate::errors::format)
    }

    /// A map from an `Octree` (as `tesseral.Octree.read("map.ot")` gives one): the
    /// frame's voxel size is the resolution (voxel (0, 0, 0) must sit at the world
    /// origin); known cells take their log-odds when the octree has them, else the
    /// upper clamp (occupied) or the lower clamp (free), as OctoMap reads a `.bt`.
    #[staticmethod]
    #[pyo3(signature = (octree, prob_hit = 0.7, prob_miss = 0.4, clamp = (0.1192, 0.971), threshold = 0.5))]
    fn from_octree(
        py: Python<'_>,
        octree: &Octree,
        prob_hit: f64,
        prob_miss: f64,
        clamp: (f64, f64),
        threshold: f64,
    ) -> PyResult<Self> {
        let sensor = sensor_model(prob_hit, prob_miss, clamp, threshold)?;
        let model = &octree.model;
        py.allow_threads(|| Map::from_model_with(model, sensor))
            .map(|map| Self { map })
            .map_err(value_error)
    }

    /// Packs the map's storage as the end of `insert_scans` does (for a map built
    /// by a loop of `insert_scan`): the cells are unchanged, the bytes fewer.
    fn shrink_to_fit(&mut self, py: Python<'_>) {
        let m = &mut self.map;
        py.allow_threads(|| m.shrink_to_fit());
    }

    /// Counts: occupied, free, leaves, blocks, bytes.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let n = self.map.counts();
        d.set_item("occupied", n.occupied)?;
        d.set_item("free", n.free)?;
        d.set_item("leaves", n.leaves)?;
        d.set_item("blocks", self.map.block_count())?;
        d.set_item("bytes", self.map.bytes())?;
        Ok(d)
    }
}

/// A scan as `read_scans` gives it: the sensor origin and N×3 world points.
type PlacedScan<'py> = ((f64, f64, f64), Bound<'py, numpy::PyArray2<f64>>);

/// Reads a scan file (`.graph`, `.log`, `.xyz`, `.ply`, `.pcd`, as `tesseral map`
/// does) as a list of `(origin, points)` pairs, the points an N×3 float array in
/// world coordinates: what `OccupancyMap.insert_scans` takes. A graph's or log's
/// poses are applied, a PCD's `VIEWPOINT` is its origin. For a cloud, `origin`
/// gives the sensor position (the points are world coordinates) or `pose` (x, y, z,
/// roll, pitch, yaw) moves points given in the sensor frame; both are refused for
/// `.graph` and `.log`, which carry their own poses. NaN points are kept, for
/// `insert_scans` to skip and count.
#[pyfunction]
#[pyo3(signature = (path, origin = None, pose = None))]
pub fn read_scans(
    py: Python<'_>,
    path: std::path::PathBuf,
    origin: Option<[f64; 3]>,
    pose: Option<[f64; 6]>,
) -> PyResult<Vec<PlacedScan<'_>>> {
    use tesseral::io::scan::{self, Placement, ScanFormat};
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

//! `tesseral.OccupancyMap`: an occupancy map fed whole scans (N×3 float arrays).

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::occupancy::{CellState, OccupancyMap as Map, SensorModel};

use crate::args::Int;
use crate::arrays::{cells, check_cell, points};
use crate::errors::{borrow, borrow_mut};
use crate::octree::Octree;
use crate::scans::DEFAULT_MAX_CELLS;
use crate::scans::{at_scan, check_work, max_cells, max_range, origin, scan_pair, stats_dict};

/// An unbounded occupancy map (unknown / free / occupied cells with log-odds), built
/// from range scans with OctoMap's `insertPointCloud` semantics and sensor model.
#[pyclass(module = "tesseral")]
pub struct OccupancyMap {
    pub(crate) map: Map,
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

/// What the class's borrows are called in their errors.
const WHAT: &str = "OccupancyMap";

#[pymethods]
impl OccupancyMap {
    #[new]
    #[pyo3(signature = (resolution, prob_hit = 0.7, prob_miss = 0.4, clamp = (0.1192, 0.971), threshold = 0.5),
           text_signature = "(resolution, prob_hit=0.7, prob_miss=0.4, clamp=(0.1192, 0.971), threshold=0.5)")]
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

    /// Inserts one scan: `points` is N×3 (world units; any numeric dtype, or a list
    /// of rows), `origin` the sensor position (finite). Returns the scan's counts:
    /// points, rays, skipped (NaN/inf), hits, misses (cells missed, not counting
    /// those of blocks already clamped free, which a miss leaves unchanged).
    /// `max_range` is None (no limit) or a positive number. A scan whose rays may
    /// cross more than `max_cells` cells in all is refused (ValueError) before any
    /// is cast.
    #[pyo3(signature = (origin, points, max_range = None, max_cells = DEFAULT_MAX_CELLS),
           text_signature = "(self, origin, points, max_range=None, max_cells=10000000000)")]
    fn insert_scan<'py>(
        slf: &Bound<'py, Self>,
        origin: &Bound<'py, PyAny>,
        points: &Bound<'py, PyAny>,
        max_range: Option<f64>,
        max_cells: Int,
    ) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let (o, pts) = (self::origin(origin)?, self::points(points, "points")?);
        let max_range = self::max_range(max_range)?;
        let max_cells = self::max_cells(&max_cells)?;
        let mut this = borrow_mut(slf, WHAT)?;
        check_work(&this.map, o, &pts, max_range, max_cells)?;
        let m = &mut this.map;
        let s = py.allow_threads(|| m.insert_scan(o, &pts, max_range));
        m.check_capacity().map_err(value_error)?;
        stats_dict(py, &s)
    }

    /// Inserts scans in order, as a loop of `insert_scan` would, from any iterable of
    /// `(origin, points)` pairs (tuples, lists, a generator): each scan is cast while
    /// the one before it is written into the map, so several threads are kept busy.
    /// Returns one dict of counts per scan. At the end the map's storage is packed as
    /// `shrink_to_fit` packs it (patched palettes where smaller, arenas compacted
    /// where an eighth holds nothing), so it may take fewer bytes than after the
    /// loop. Every scan is read and its work checked against `max_cells` before any
    /// is cast (errors name the scan: "scan 3: ...").
    #[pyo3(signature = (scans, max_range = None, max_cells = DEFAULT_MAX_CELLS),
           text_signature = "(self, scans, max_range=None, max_cells=10000000000)")]
    fn insert_scans<'py>(
        slf: &Bound<'py, Self>,
        scans: &Bound<'py, PyAny>,
        max_range: Option<f64>,
        max_cells: Int,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let py = slf.py();
        let max_range = self::max_range(max_range)?;
        let max_cells = self::max_cells(&max_cells)?;
        let items = scans.try_iter().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "scans: expected an iterable of (origin, points) pairs, got {}",
                scans.get_type()
            ))
        })?;
        let mut placed = Vec::new();
        for (i, item) in items.enumerate() {
            placed.push(
                item.and_then(|s| scan_pair(&s))
                    .map_err(|e| at_scan(py, i, e))?,
            );
        }
        let mut this = borrow_mut(slf, WHAT)?;
        for (i, (o, pts)) in placed.iter().enumerate() {
            check_work(&this.map, *o, pts, max_range, max_cells).map_err(|e| at_scan(py, i, e))?;
        }
        let m = &mut this.map;
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

    /// The state of each cell of an N×3 integer array: 0 unknown, 1 free, 2 occupied.
    fn state<'py>(
        slf: &Bound<'py, Self>,
        cells: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let py = slf.py();
        let c = self::cells(cells, "cells")?;
        let this = borrow(slf, WHAT)?;
        let m = &this.map;
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

    /// The log-odds of each cell of an N×3 integer array (NaN where unknown), looked
    /// up in batches whose memory accesses overlap (`log_odds_many`).
    fn log_odds<'py>(
        slf: &Bound<'py, Self>,
        cells: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let py = slf.py();
        let c = self::cells(cells, "cells")?;
        let this = borrow(slf, WHAT)?;
        let m = &this.map;
        let out: Vec<f32> = py.allow_threads(|| {
            let mut v = vec![None; c.len()];
            m.log_odds_many(&c, &mut v);
            v.into_iter().map(|l| l.unwrap_or(f32::NAN)).collect()
        });
        Ok(out.into_pyarray(py))
    }

    /// The cell holding each point of an N×3 array of numbers, N×3 int64. A point
    /// with a coordinate NaN or infinite, or in a cell past the range of int64, is
    /// refused (ValueError naming its row), not clamped.
    fn cells_of<'py>(
        slf: &Bound<'py, Self>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<i64>>> {
        let p = self::points(points, "points")?;
        let this = borrow(slf, WHAT)?;
        let m = &this.map;
        // The position in cells as `cell_of` computes it (p × (1 / res)), checked.
        let inv = 1.0 / m.resolution();
        let cells = p
            .iter()
            .enumerate()
            .map(|(i, &q)| {
                check_cell("points", "cell", i, q, q.map(|c| c * inv))?;
                Ok(m.cell_of(q))
            })
            .collect::<Result<Vec<_>, String>>()
            .map_err(PyValueError::new_err)?;
        crate::arrays::to_array(slf.py(), cells)
    }

    /// The side of a cell, in world units.
    #[getter]
    fn resolution(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(borrow(slf, WHAT)?.map.resolution())
    }

    /// The map as an `Octree`, as `tesseral map` writes it: occupied cells as the
    /// voxels, frame of voxel size `resolution` at the world origin, free cells and
    /// every known cell's log-odds beside them. `write("map.bt")` or `.ot` gives
    /// OctoMap's files; `render`, `collide` and `info` take it as any octree.
    fn to_octree(slf: &Bound<'_, Self>) -> PyResult<Octree> {
        let this = borrow(slf, WHAT)?;
        let m = &this.map;
        slf.py()
            .allow_threads(|| m.to_model())
            .map(Octree::new)
            .map_err(crate::errors::octree)
    }

    /// Writes the map, atomically, in the format named by the extension: `.bt`
    /// and `.ot` straight from its cells (the bytes of `to_octree().write(path)`,
    /// without building the octree), any other format through `to_octree()`. A
    /// map wider than an octree holds (2^21 cells on an axis) is written to `.tess`
    /// as the map's own file, which keeps the full range: `OccupancyMap.read`
    /// reads it back.
    fn write(slf: &Bound<'_, Self>, path: PathBuf) -> PyResult<()> {
        let this = borrow(slf, WHAT)?;
        let m = &this.map;
        slf.py()
            .allow_threads(|| m.write_file(&path))
            .map_err(crate::errors::format)
    }

    /// A map from an `Octree` (as `tesseral.Octree.read("map.ot")` gives one): the
    /// frame's voxel size is the resolution (voxel (0, 0, 0) must sit at the world
    /// origin); known cells take their log-odds when the octree has them, else the
    /// upper clamp (occupied) or the lower clamp (free), as OctoMap reads a `.bt`.
    #[staticmethod]
    #[pyo3(signature = (octree, prob_hit = 0.7, prob_miss = 0.4, clamp = (0.1192, 0.971), threshold = 0.5),
           text_signature = "(octree, prob_hit=0.7, prob_miss=0.4, clamp=(0.1192, 0.971), threshold=0.5)")]
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

    /// Reads a map from a file: a map's own `.tess` (a map wider than an octree,
    /// with its sensor model), or any octree file as `from_octree` reads it
    /// (OctoMap's sensor model).
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        py.allow_threads(|| Map::read_file(&path))
            .map(|map| Self { map })
            .map_err(crate::errors::format)
    }

    /// Packs the map's storage as the end of `insert_scans` does (for a map built
    /// by a loop of `insert_scan`): the cells are unchanged, the bytes fewer.
    fn shrink_to_fit(slf: &Bound<'_, Self>) -> PyResult<()> {
        let mut this = borrow_mut(slf, WHAT)?;
        let m = &mut this.map;
        slf.py().allow_threads(|| m.shrink_to_fit());
        Ok(())
    }

    /// Counts: occupied, free, leaves, blocks, bytes.
    fn stats<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let this = borrow(slf, WHAT)?;
        let d = PyDict::new(slf.py());
        let n = this.map.counts();
        d.set_item("occupied", n.occupied)?;
        d.set_item("free", n.free)?;
        d.set_item("leaves", n.leaves)?;
        d.set_item("blocks", this.map.block_count())?;
        d.set_item("bytes", this.map.bytes())?;
        Ok(d)
    }
}

//! `tesseral.DynamicOctree`: Libes' unbounded octree, fed whole arrays at a time.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::dynamic::DynamicOctree as Tree;
use tesseral::occupancy::{OccupancyMap, SensorModel};

use crate::arrays::{rows, to_array};
use crate::occupancy::{check_work, DEFAULT_MAX_CELLS};

/// An unbounded dynamic octree of voxels (i64 coordinates), with the surface-face
/// list of the random-surface simulations.
#[pyclass(module = "tesseral")]
pub struct DynamicOctree {
    tree: Tree,
}

#[pymethods]
impl DynamicOctree {
    #[new]
    fn new() -> Self {
        DynamicOctree {
            tree: Tree::with_faces(),
        }
    }

    /// Inserts the voxels of an N×3 int64 array; returns how many were new.
    fn insert(&mut self, py: Python<'_>, voxels: PyReadonlyArray2<'_, i64>) -> PyResult<u64> {
        let v = rows(&voxels)?;
        let t = &mut self.tree;
        Ok(py.allow_threads(|| v.iter().map(|&p| u64::from(t.insert(p))).sum()))
    }

    /// Removes the voxels of an N×3 int64 array; returns how many were present.
    fn remove(&mut self, py: Python<'_>, voxels: PyReadonlyArray2<'_, i64>) -> PyResult<u64> {
        let v = rows(&voxels)?;
        let t = &mut self.tree;
        Ok(py.allow_threads(|| v.iter().map(|&p| u64::from(t.remove(p))).sum()))
    }

    /// Whether each voxel of an N×3 int64 array is present: a bool array.
    fn contains<'py>(
        &self,
        py: Python<'py>,
        voxels: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let v = rows(&voxels)?;
        let t = &self.tree;
        let out: Vec<bool> = py.allow_threads(|| v.iter().map(|&p| t.contains(p)).collect());
        Ok(out.into_pyarray(py))
    }

    /// Inserts one range scan, as a binary map: the cells the ray from `origin` to each
    /// point crosses are cleared and each point's own cell is set (a cell both hit and
    /// crossed in one scan is set), with OctoMap's `insertPointCloud` ray rules (see
    /// `OccupancyMap.insert_scan`). Coordinates are in voxels: voxel i spans [i, i+1).
    /// A point beyond `max_range` clears its ray up to `max_range` and sets nothing.
    /// Returns the scan's counts plus `inserted` and `removed` (voxels that changed).
    /// A scan whose rays may cross more than `max_cells` voxels in all is refused
    /// (ValueError) before any is cast.
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
        // One scan in a fresh map at unit resolution: hit cells end with a positive
        // log-odds and crossed ones with a negative one.
        let mut map = OccupancyMap::new(1.0, SensorModel::octomap())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        check_work(&map, origin, &pts, max_range, max_cells)?;
        let t = &mut self.tree;
        let (s, inserted, removed) = py.allow_threads(|| {
            let s = map.insert_scan(origin, &pts, max_range);
            let (mut inserted, mut removed) = (0u64, 0u64);
            for (cell, l) in map.cells() {
                if l > 0.0 {
                    inserted += u64::from(t.insert(cell));
                } else {
                    removed += u64::from(t.remove(cell));
                }
            }
            (s, inserted, removed)
        });
        let d = crate::occupancy::stats_dict(py, &s)?;
        d.set_item("inserted", inserted)?;
        d.set_item("removed", removed)?;
        Ok(d)
    }

    /// Every voxel, N×3 int64.
    fn voxels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let t = &self.tree;
        let v = py.allow_threads(|| t.voxels());
        to_array(py, v)
    }

    /// The number of exposed voxel faces (the surface).
    #[getter]
    fn face_count(&self) -> usize {
        self.tree.face_count()
    }

    fn __len__(&self) -> usize {
        self.tree.voxel_count() as usize
    }

    /// Counts and memory: voxels, faces, nodes, bytes, expansions, contractions.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = &self.tree;
        let d = PyDict::new(py);
        d.set_item("voxels", t.voxel_count())?;
        d.set_item("faces", t.face_count())?;
        d.set_item("nodes", t.node_count())?;
        d.set_item("bytes", t.bytes())?;
        d.set_item("expansions", t.expansions())?;
        d.set_item("contractions", t.contractions())?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "DynamicOctree({} voxels, {} faces)",
            self.tree.voxel_count(),
            self.tree.face_count()
        )
    }
}

//! `tesseral.DynamicOctree`: Libes' unbounded octree, fed whole arrays at a time.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::dynamic::DynamicOctree as Tree;

use crate::arrays::{rows, to_array};

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

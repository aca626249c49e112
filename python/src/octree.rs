//! `tesseral.Octree`: a model (linear octree, frame, colours, free space).

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use tesseral::linear::{Axis, LinearOctree, SetOp};
use tesseral::model::{Frame, Model};

use crate::args::{int_within, within3, Int, I64, I64_RULE, ZERO3};
use crate::arrays::{cells, check_cell, mask3, points, to_array};
use crate::errors;

/// A voxel as Python sees it.
type Vec3 = (i64, i64, i64);
/// `(vertices, faces)` of a mesh.
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);
/// `(voxels, rgba)` of the coloured voxels.
type ColourArrays<'py> = (Bound<'py, PyArray2<i64>>, Bound<'py, PyArray2<u8>>);

/// A solid as a linear octree with its frame (voxel size and placement in world
/// units) and optional per-voxel colours and known-free space.
#[pyclass(module = "tesseral", frozen)]
#[derive(Clone)]
pub struct Octree {
    pub model: Model,
}

pub fn axis(name: &str) -> PyResult<Axis> {
    match name {
        "x" | "X" => Ok(Axis::X),
        "y" | "Y" => Ok(Axis::Y),
        "z" | "Z" => Ok(Axis::Z),
        _ => Err(PyValueError::new_err(format!(
            "axis {name:?}: expected 'x', 'y' or 'z'"
        ))),
    }
}

impl Octree {
    pub fn new(model: Model) -> Self {
        Self { model }
    }

    fn op(&self, py: Python<'_>, other: &Octree, op: SetOp) -> PyResult<Octree> {
        let (a, b) = (&self.model, &other.model);
        py.allow_threads(|| a.set_op(b, op))
            .map(Octree::new)
            .map_err(errors::octree)
    }
}

#[pymethods]
impl Octree {
    /// An octree of the voxels in an N×3 integer array (duplicates allowed; floats
    /// only when whole numbers), in the smallest space that holds them; unit frame.
    #[staticmethod]
    fn from_voxels(py: Python<'_>, voxels: &Bound<'_, PyAny>) -> PyResult<Octree> {
        let v = cells(voxels, "voxels")?;
        let tree = py
            .allow_threads(|| LinearOctree::from_voxels_fitted(&v))
            .map_err(errors::octree)?;
        Ok(Octree::new(Model::new(tree)))
    }

    /// The voxels of size `voxel_size` holding the points of an N×3 array of numbers
    /// (world units; voxel i spans [i·h, (i+1)·h)). A point with a coordinate NaN or
    /// infinite, or in a voxel past the range of int64, is refused (OctreeError
    /// naming its row), not clamped.
    #[staticmethod]
    fn from_points(py: Python<'_>, points: &Bound<'_, PyAny>, voxel_size: f64) -> PyResult<Octree> {
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(PyValueError::new_err(
                "voxel_size must be positive and finite",
            ));
        }
        let p = self::points(points, "points")?;
        let frame = Frame::new(voxel_size, [0.0; 3]);
        let tree = py.allow_threads(|| {
            let mut v = Vec::with_capacity(p.len());
            for (i, &q) in p.iter().enumerate() {
                check_cell("points", "voxel", i, q, frame.to_lattice(q))?;
                v.push(frame.voxel_of_point(q));
            }
            LinearOctree::from_voxels_fitted(&v).map_err(|e| e.to_string())
        });
        let tree = tree.map_err(errors::octree)?;
        Ok(Octree::new(Model::new(tree).with_frame(frame)))
    }

    /// The voxels where a 3-D boolean array (indexed [x, y, z]) is true, the array's
    /// element [0, 0, 0] at voxel `origin`. Another dtype (integers too) is a
    /// TypeError, another number of dimensions a ValueError.
    #[staticmethod]
    #[pyo3(signature = (mask, origin = ZERO3), text_signature = "(mask, origin=(0, 0, 0))")]
    fn from_dense(
        py: Python<'_>,
        mask: &Bound<'_, PyAny>,
        origin: (Int, Int, Int),
    ) -> PyResult<Octree> {
        let o: [i64; 3] = within3(&origin, "origin", I64, I64_RULE)?;
        let mask = mask3(mask, "mask")?;
        let a = mask.as_array();
        // A voxel past int64 (origin near its end) is refused, not wrapped round.
        let at = |o: i64, i: usize| i64::try_from(i).ok().and_then(|i| o.checked_add(i));
        let v: Vec<[i64; 3]> = a
            .indexed_iter()
            .filter(|(_, &b)| b)
            .map(
                |((x, y, z), _)| match (at(o[0], x), at(o[1], y), at(o[2], z)) {
                    (Some(x), Some(y), Some(z)) => Ok([x, y, z]),
                    _ => Err(PyValueError::new_err(format!(
                        "origin ({}, {}, {}): the true element [{x}, {y}, {z}] lies past int64 \
                     from it",
                        o[0], o[1], o[2]
                    ))),
                },
            )
            .collect::<PyResult<_>>()?;
        let tree = py
            .allow_threads(|| LinearOctree::from_voxels_fitted(&v))
            .map_err(errors::octree)?;
        Ok(Octree::new(Model::new(tree)))
    }

    /// Reads an octree file (every format the CLI reads, chosen by extension), or a
    /// partitioned dataset directory (`tesseral build --parts`, `tesseral.dask.write`)
    /// as one model, its parts checked against the manifest.
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Octree> {
        if tesseral::partition::is_dataset(&path) {
            return py
                .allow_threads(|| tesseral::partition::read_dataset_model(&path))
                .map(Octree::new)
                .map_err(crate::dataset::partition_error);
        }
        py.allow_threads(|| tesseral::io::read_model(&path))
            .map(Octree::new)
            .map_err(errors::format)
    }

    /// The octree as `.tess` bytes (the native format, with the frame, colours and
    /// free space): what pickling sends.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let m = &self.model;
        let bytes = py.allow_threads(|| tesseral::io::native::encode(m));
        PyBytes::new(py, &bytes)
    }

    /// An octree from `.tess` bytes (as `to_bytes` gives).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Octree> {
        py.allow_threads(|| tesseral::io::native::decode(data))
            .map(Octree::new)
            .map_err(errors::format)
    }

    /// Pickling: the `.tess` bytes, read back by `Octree.from_bytes`.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let f = py.get_type::<Octree>().getattr("from_bytes")?;
        Ok((f, (self.to_bytes(py),)))
    }

    /// Writes the octree, atomically, in the format named by the extension.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let m = &self.model;
        py.allow_threads(|| tesseral::io::write_model(&path, m))
            .map_err(errors::format)
    }

    /// The black voxels as an N×3 int64 array, in tesseral order.
    fn voxels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let t = &self.model.tree;
        let v: Vec<[i64; 3]> = py.allow_threads(|| {
            let mut v = Vec::new();
            t.voxels_into(&mut v);
            v
        });
        to_array(py, v)
    }

    /// The coloured voxels and their colours: (voxels N×3 int64, colours N×4 uint8
    /// RGBA), sorted by voxel (x, then y, then z); empty arrays when there are no
    /// colours.
    fn colors<'py>(&self, py: Python<'py>) -> PyResult<ColourArrays<'py>> {
        let l = &self.model.colors;
        let (v, c): (Vec<[i64; 3]>, Vec<[u8; 4]>) = py.allow_threads(|| {
            l.as_ref().map_or((Vec::new(), Vec::new()), |l| {
                l.to_voxels().into_iter().map(|(v, _, c)| (v, c)).unzip()
            })
        });
        let n = c.len();
        let rgba: Vec<u8> = c.into_iter().flatten().collect();
        Ok((to_array(py, v)?, rgba.into_pyarray(py).reshape([n, 4])?))
    }

    /// The voxel centres in world units, N×3 float64.
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (t, f) = (&self.model.tree, self.model.frame);
        let p: Vec<[f64; 3]> = py.allow_threads(|| {
            t.voxels()
                .map(|v| f.to_world(v.map(|c| c as f64 + 0.5)))
                .collect()
        });
        to_array(py, p)
    }

    /// The leaves: (codes uint64, sizes uint8), each leaf the block of side 2**size
    /// whose lowest voxel has the code (relative to the origin).
    fn leaves<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<u64>>, Bound<'py, PyArray1<u8>>) {
        let l = self.model.tree.leaves();
        let codes: Vec<u64> = l.iter().map(|x| x.code()).collect();
        let sizes: Vec<u8> = l.iter().map(|x| x.size_log2()).collect();
        (codes.into_pyarray(py), sizes.into_pyarray(py))
    }

    fn __len__(&self) -> usize {
        self.model.tree.voxel_count() as usize
    }

    /// Black voxels.
    #[getter]
    fn voxel_count(&self) -> u64 {
        self.model.tree.voxel_count()
    }

    /// Leaves (maximal blocks).
    #[getter]
    fn leaf_count(&self) -> usize {
        self.model.tree.leaf_count()
    }

    /// Depth of the space: 2**depth voxels per axis.
    #[getter]
    fn depth(&self) -> u8 {
        self.model.tree.depth()
    }

    /// The space's lowest voxel.
    #[getter]
    fn origin(&self) -> (i64, i64, i64) {
        let o = self.model.tree.origin();
        (o[0], o[1], o[2])
    }

    /// The frame: {"voxel_size": h, "translate": (x, y, z)}.
    #[getter]
    fn frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("voxel_size", self.model.frame.voxel_size)?;
        let t = self.model.frame.translate;
        d.set_item("translate", (t[0], t[1], t[2]))?;
        Ok(d)
    }

    /// ((x0, y0, z0), (x1, y1, z1)), the lowest and highest black voxels, or None.
    #[getter]
    fn bbox(&self) -> Option<(Vec3, Vec3)> {
        self.model
            .tree
            .bbox()
            .map(|(a, b)| ((a[0], a[1], a[2]), (b[0], b[1], b[2])))
    }

    /// What `tesseral info --json` prints, as a dict.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (m, t) = (&self.model, &self.model.tree);
        let d = PyDict::new(py);
        d.set_item("voxels", t.voxel_count())?;
        d.set_item("leaves", t.leaf_count())?;
        d.set_item("depth", t.depth())?;
        d.set_item("origin", self.origin())?;
        d.set_item("bbox_min", self.bbox().map(|b| b.0))?;
        d.set_item("bbox_max", self.bbox().map(|b| b.1))?;
        d.set_item("leaves_by_depth", t.leaves_by_depth())?;
        d.set_item("bytes", 8 * t.leaf_count())?;
        d.set_item("voxel_size", m.frame.voxel_size)?;
        let tr = m.frame.translate;
        d.set_item("translate", (tr[0], tr[1], tr[2]))?;
        d.set_item("colors", m.colors.as_ref().map(|c| c.region_count()))?;
        d.set_item(
            "colored_voxels",
            m.colors.as_ref().map_or(0, |c| c.voxel_count()),
        )?;
        d.set_item("free_voxels", m.free.as_ref().map(|f| f.voxel_count()))?;
        d.set_item("log_odds", m.log_odds.is_some())?;
        Ok(d)
    }

    fn union(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.op(py, other, SetOp::Union)
    }
    fn intersection(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.op(py, other, SetOp::Intersection)
    }
    fn difference(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.op(py, other, SetOp::Difference)
    }
    fn symmetric_difference(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.op(py, other, SetOp::SymmetricDifference)
    }
    fn __or__(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.union(py, other)
    }
    fn __and__(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.intersection(py, other)
    }
    fn __sub__(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.difference(py, other)
    }
    fn __xor__(&self, py: Python<'_>, other: &Octree) -> PyResult<Octree> {
        self.symmetric_difference(py, other)
    }

    /// The white voxels of the space (colours and free space do not carry over).
    fn complement(&self) -> Octree {
        Octree::new(self.model.complement())
    }

    /// Moved by a whole number of voxels (x, y, z); the frame is kept.
    fn translate(&self, py: Python<'_>, v: (Int, Int, Int)) -> PyResult<Octree> {
        let v: [i64; 3] = within3(&v, "v", I64, I64_RULE)?;
        let m = &self.model;
        py.allow_threads(|| m.translate(v))
            .map(Octree::new)
            .map_err(errors::octree)
    }

    /// Quarter turns about 'x', 'y' or 'z' within the space (as `tesseral rotate`):
    /// any integer, taken modulo 4.
    fn rotate(&self, axis_name: &str, turns: &Bound<'_, PyAny>) -> PyResult<Octree> {
        // Modulo 4 here, as the library takes it, so that a count of any size is the
        // rotation it names (was pyo3's OverflowError past i32).
        let turns = match int_within(turns, "turns", i64::MIN..=i64::MAX)? {
            Some(n) => n.rem_euclid(4),
            None => turns.rem(4)?.extract::<i64>()?,
        } as i32;
        self.model
            .rotate_in_space(axis(axis_name)?, turns)
            .map(Octree::new)
            .map_err(errors::octree)
    }

    /// Mirrored within the space along 'x', 'y' or 'z'.
    fn mirror(&self, axis_name: &str) -> PyResult<Octree> {
        self.model
            .mirror_in_space(axis(axis_name)?)
            .map(Octree::new)
            .map_err(errors::octree)
    }

    /// Scaled by an integer, or by one integer per axis (kx, ky, kz); a negative
    /// factor mirrors. Exact.
    fn scale(&self, py: Python<'_>, k: &Bound<'_, PyAny>) -> PyResult<Octree> {
        let f: [i64; 3] = if let Ok(n) = k.extract::<Int>() {
            [n.within(
                "k",
                I64,
                "the factor must lie in int64 (-2**63 to 2**63 - 1)",
            )?; 3]
        } else {
            within3(&k.extract()?, "k", I64, I64_RULE)?
        };
        let m = &self.model;
        py.allow_threads(|| m.scale_axes(f))
            .map(Octree::new)
            .map_err(errors::octree)
    }

    /// Whether each voxel of an N×3 integer array is black: a bool array.
    fn contains<'py>(
        &self,
        py: Python<'py>,
        voxels: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let v = cells(voxels, "voxels")?;
        let t = &self.model.tree;
        let out: Vec<bool> = py.allow_threads(|| v.iter().map(|&p| t.contains(p)).collect());
        Ok(out.into_pyarray(py))
    }

    /// Equal when the black voxels are the same.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .downcast::<Octree>()
            .ok()
            .and_then(|o| self.model.tree.same_voxels(&o.get().model.tree).ok())
            .unwrap_or(false)
    }

    /// The exact boundary as a triangle mesh in world units: (vertices N×3 float64,
    /// faces M×3 int64).
    fn mesh<'py>(&self, py: Python<'py>) -> PyResult<MeshArrays<'py>> {
        let (t, f) = (&self.model.tree, self.model.frame);
        let mesh = py.allow_threads(|| tesseral::mesh::boundary_mesh(t));
        let v: Vec<[f64; 3]> = mesh.positions.iter().map(|&p| f.to_world(p)).collect();
        let faces: Vec<[i64; 3]> = mesh.triangles.iter().map(|t| t.map(i64::from)).collect();
        Ok((to_array(py, v)?, to_array(py, faces)?))
    }

    fn __repr__(&self) -> String {
        let t = &self.model.tree;
        format!(
            "Octree({}, {}, depth {}, voxel size {})",
            crate::count(t.voxel_count(), "voxel", "voxels"),
            crate::count(t.leaf_count() as u64, "leaf", "leaves"),
            t.depth(),
            self.model.frame.voxel_size
        )
    }

    /// A PNG picture, for Jupyter.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let img = crate::scene::render_model(py, &self.model, &crate::scene::Options::default())?;
        crate::scene::png(py, &img)
    }
}

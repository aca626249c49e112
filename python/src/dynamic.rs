//! `tesseral.DynamicOctree`: Libes' unbounded octree, fed whole arrays at a time.

use std::path::{Path, PathBuf};

use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::dynamic::DynamicOctree as Tree;
use tesseral::io::FormatError;
use tesseral::occupancy::{OccupancyMap, SensorModel};

use crate::args::Int;
use crate::arrays::{cells, points, to_array};
use crate::errors::{borrow, borrow_mut};
use crate::scans::{check_work, max_cells, max_range, origin, DEFAULT_MAX_CELLS};

/// An unbounded dynamic octree of voxels (i64 coordinates), with its count of
/// exposed faces (the surface area) kept as voxels come and go.
#[pyclass(module = "tesseral")]
pub struct DynamicOctree {
    tree: Tree,
    /// The exposed faces: each voxel's faces with no voxel beyond them.
    faces: u64,
}

/// What the class's borrows are called in their errors.
const WHAT: &str = "DynamicOctree";

/// The most lookups `read` spends counting faces (2^28, some ten seconds): one for
/// each voxel on a positive face of a stored block or full octant. A model file
/// holds a solid of up to 2^63 voxels in a few bytes, and a cube of 2^21 a side
/// would take 3 · 2^42.
const MAX_FACE_WORK: u64 = 1 << 28;

impl DynamicOctree {
    /// An octree read from `path` and its face count, refused (before the count)
    /// past [`MAX_FACE_WORK`].
    fn of(tree: Tree, path: &Path) -> Result<Self, FormatError> {
        let work = tree.exposed_faces_work();
        if work > MAX_FACE_WORK {
            return Err(FormatError::TooLarge(format!(
                "{} voxels whose faces would take {work} lookups to count, past the 2^28 \
                 that DynamicOctree.read spends",
                tree.voxel_count()
            ))
            .with_path(path));
        }
        let faces = tree.exposed_faces();
        Ok(DynamicOctree { tree, faces })
    }

    /// Inserts `v`, and counts its faces: each of its six is exposed but where a
    /// neighbour is, and hides that neighbour's face too. Whether it was new.
    fn put(&mut self, v: [i64; 3]) -> bool {
        let new = self.tree.insert(v);
        if new {
            let hidden = u64::from(self.tree.face_neighbours(v).len());
            self.faces = self.faces + 6 - 2 * hidden;
        }
        new
    }

    /// Removes `v`, undoing what [`put`](Self::put) counted. Whether it was there.
    fn take(&mut self, v: [i64; 3]) -> bool {
        let gone = self.tree.remove(v);
        if gone {
            let hidden = u64::from(self.tree.face_neighbours(v).len());
            self.faces = self.faces + 2 * hidden - 6;
        }
        gone
    }
}

#[pymethods]
impl DynamicOctree {
    #[new]
    fn new() -> Self {
        let mut tree = Tree::new();
        // Bitmap blocks from the start: the face count reads every new voxel's
        // neighbourhood, faster from bitmaps (as `Tree::with_faces` chooses).
        tree.set_small_blocks(false);
        DynamicOctree { tree, faces: 0 }
    }

    /// Inserts the voxels of an N×3 integer array; returns how many were new.
    fn insert(slf: &Bound<'_, Self>, voxels: &Bound<'_, PyAny>) -> PyResult<u64> {
        let v = cells(voxels, "voxels")?;
        let mut this = borrow_mut(slf, WHAT)?;
        let d = &mut *this;
        Ok(slf
            .py()
            .allow_threads(|| v.iter().map(|&p| u64::from(d.put(p))).sum()))
    }

    /// Removes the voxels of an N×3 integer array; returns how many were present.
    fn remove(slf: &Bound<'_, Self>, voxels: &Bound<'_, PyAny>) -> PyResult<u64> {
        let v = cells(voxels, "voxels")?;
        let mut this = borrow_mut(slf, WHAT)?;
        let d = &mut *this;
        Ok(slf
            .py()
            .allow_threads(|| v.iter().map(|&p| u64::from(d.take(p))).sum()))
    }

    /// Whether each voxel of an N×3 integer array is present: a bool array.
    fn contains<'py>(
        slf: &Bound<'py, Self>,
        voxels: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let v = cells(voxels, "voxels")?;
        let this = borrow(slf, WHAT)?;
        let t = &this.tree;
        let out: Vec<bool> = slf
            .py()
            .allow_threads(|| v.iter().map(|&p| t.contains(p)).collect());
        Ok(out.into_pyarray(slf.py()))
    }

    /// Inserts one range scan, as a binary map: the cells the ray from `origin` to each
    /// point crosses are cleared and each point's own cell is set (a cell both hit and
    /// crossed in one scan is set), with OctoMap's `insertPointCloud` ray rules (see
    /// `OccupancyMap.insert_scan`). Coordinates are in voxels: voxel i spans [i, i+1).
    /// A point beyond `max_range` (None, or a positive number) clears its ray up to
    /// `max_range` and sets nothing. Returns the scan's counts plus `inserted` and
    /// `removed` (voxels that changed). A scan whose rays may cross more than
    /// `max_cells` voxels in all is refused (ValueError) before any is cast.
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
        // One scan in a fresh map at unit resolution: hit cells end with a positive
        // log-odds and crossed ones with a negative one.
        let mut map = OccupancyMap::new(1.0, SensorModel::octomap())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        check_work(&map, o, &pts, max_range, max_cells)?;
        let mut this = borrow_mut(slf, WHAT)?;
        let d = &mut *this;
        let (s, inserted, removed) = py.allow_threads(|| {
            let s = map.insert_scan(o, &pts, max_range);
            let (mut inserted, mut removed) = (0u64, 0u64);
            for (cell, l) in map.cells() {
                if l > 0.0 {
                    inserted += u64::from(d.put(cell));
                } else {
                    removed += u64::from(d.take(cell));
                }
            }
            (s, inserted, removed)
        });
        let d = crate::scans::stats_dict(py, &s)?;
        d.set_item("inserted", inserted)?;
        d.set_item("removed", removed)?;
        Ok(d)
    }

    /// Writes the octree, atomically, in the format named by the extension: as a
    /// model (voxel size 1, the root's corner at its origin) when it fits one (2^21
    /// voxels on an axis), else to `.tess` as the octree's own file, which keeps its
    /// full `i64` range (any other format refuses it: FormatError). The face count is
    /// not written; `DynamicOctree.read` reads either back and counts them.
    fn write(slf: &Bound<'_, Self>, path: PathBuf) -> PyResult<()> {
        let this = borrow(slf, WHAT)?;
        let t = &this.tree;
        slf.py()
            .allow_threads(|| t.write_file(&path))
            .map_err(crate::errors::format)
    }

    /// Reads an octree from a file: an octree's own `.tess` (one wider than a
    /// model), or any model file (its voxels; the frame is dropped). The faces are
    /// counted as it is read, in time that follows the surface of its blocks and
    /// full octants; a file whose count would take more than 2^28 lookups is
    /// refused (FormatError).
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        py.allow_threads(|| Tree::read_file(&path).and_then(|t| Self::of(t, &path)))
            .map_err(crate::errors::format)
    }

    /// Every voxel, N×3 int64.
    fn voxels<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let this = borrow(slf, WHAT)?;
        let t = &this.tree;
        let v = slf.py().allow_threads(|| t.voxels());
        to_array(slf.py(), v)
    }

    /// The number of exposed voxel faces (the surface).
    #[getter]
    fn face_count(slf: &Bound<'_, Self>) -> PyResult<u64> {
        Ok(borrow(slf, WHAT)?.faces)
    }

    fn __len__(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(borrow(slf, WHAT)?.tree.voxel_count() as usize)
    }

    /// Counts and memory: voxels, faces, nodes, bytes, expansions, contractions.
    fn stats<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let this = borrow(slf, WHAT)?;
        let t = &this.tree;
        let d = PyDict::new(slf.py());
        d.set_item("voxels", t.voxel_count())?;
        d.set_item("faces", this.faces)?;
        d.set_item("nodes", t.node_count())?;
        d.set_item("bytes", t.bytes())?;
        d.set_item("expansions", t.expansions())?;
        d.set_item("contractions", t.contractions())?;
        Ok(d)
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let this = borrow(slf, WHAT)?;
        Ok(format!(
            "DynamicOctree({}, {})",
            crate::count(this.tree.voxel_count(), "voxel", "voxels"),
            crate::count(this.faces, "face", "faces")
        ))
    }
}

//! Voxelizing a triangle mesh into a solid linear octree, top-down.
//!
//! Everything after reading is exact. Vertices are snapped to a fixed-point lattice of
//! `2^-20` voxel, and every predicate runs in `i128`:
//!
//! - **Inside/outside** by ray parity along +z through voxel centres. Each triangle is
//!   rasterized onto the columns whose centre its xy-projection covers; ties on a
//!   shared edge or vertex are broken by symbolic perturbation of the column
//!   (Edelsbrunner & Mücke's simulation of simplicity, with the point moved by
//!   `(ε, ε²)`), so every column crosses a closed surface an even number of times and
//!   nothing is counted twice. The crossing height is an exact rational; it becomes
//!   the index of the first voxel whose centre lies above it (a "flip").
//! - **Watertightness** first: after welding vertices on the lattice, every edge must
//!   belong to an even number of triangles, else [`VoxelizeError::NotWatertight`]
//!   (use `surface_only`).
//! - **Surface cells** by the exact triangle/box separating-axis test of
//!   Akenine-Möller (2001) on integers, over a uniform grid of triangle bins with a
//!   summed-volume table, so a cell far from the surface is answered in O(1).
//!
//! The octree is built by [`LinearOctree::from_classifier`]: a cell whose hull of
//! voxel centres meets no triangle is uniform and costs one parity lookup; only cells
//! near the surface are split, so the cost follows the surface.

mod bins;
mod coincident;
mod columns;
#[cfg(test)]
mod tests;

use std::collections::HashMap;

use self::bins::{tri_box_overlap, Bins};
use self::coincident::fold_coincident;
use self::columns::{crossing_bound, surface_area, Columns};
use super::TriMesh;
use crate::linear::{CellClass, Classifier, LinearOctree};
use crate::model::{Frame, Model};
use crate::Voxel;

/// What can go wrong voxelizing a mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VoxelizeError {
    /// The mesh itself is malformed (a triangle names a missing vertex).
    #[error("{0}")]
    BadMesh(String),
    /// The grid would exceed a limit (depth, extent, ray crossings); the message
    /// names it.
    #[error("{0}")]
    TooLarge(String),
    /// An option cannot be used (a voxel size that is not positive).
    #[error("{0}")]
    Unsupported(String),
    /// A mesh that should bound a solid has open edges, so inside and outside are not
    /// defined.
    #[error("mesh is not watertight: {open_edges} edge(s) are not shared by an even number of triangles (first near {example:?}); use --surface-only to voxelize the surface")]
    NotWatertight {
        /// How many edges have an odd number of triangles.
        open_edges: usize,
        /// The coordinates of one end of one open edge.
        example: [f64; 3],
    },
    /// The octree could not be built.
    #[error(transparent)]
    Octree(#[from] crate::linear::OctreeError),
}

impl VoxelizeError {
    fn corrupt(m: impl Into<String>) -> Self {
        Self::BadMesh(m.into())
    }
    fn too_large(m: impl Into<String>) -> Self {
        Self::TooLarge(m.into())
    }
    fn unsupported(m: impl Into<String>) -> Self {
        Self::Unsupported(m.into())
    }
}

/// The deepest voxelization we attempt (16384 voxels per axis).
pub const MAX_VOXELIZE_DEPTH: u8 = 14;
/// Fixed-point bits below one voxel.
const FRAC_BITS: u32 = 20;
const ONE: i64 = 1 << FRAC_BITS;
const HALF: i64 = ONE / 2;
/// The default budget of column crossings held in memory (8 bytes each, 1 GiB).
pub const MAX_CROSSINGS: usize = 1 << 27;
/// The most triangle references held by the bin grid.
const MAX_BIN_ENTRIES: u64 = 1 << 25;

/// The resolution of a voxelization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Resolution {
    /// `2^depth` voxels along the longest side of the mesh's bounding box; the grid
    /// starts at the box's lowest corner.
    Depth(u8),
    /// Voxels of this side in mesh units, on a grid aligned to the mesh's origin
    /// (voxel `i` spans `[i·size, (i+1)·size)`).
    VoxelSize(f64),
}

/// How a mesh is voxelized.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelizeOptions {
    /// The grid.
    pub resolution: Resolution,
    /// Keep only voxels whose closed cube meets a triangle (no inside test, so the
    /// mesh need not be watertight).
    pub surface_only: bool,
    /// The most ray crossings (8 bytes each) a solid voxelization may hold; bounded
    /// from the triangles before any work.
    pub max_crossings: usize,
    /// The most leaves the octree may have, estimated from the surface area before
    /// any work (a surface leaf per unit of area: the leaves of a voxelized surface
    /// are about 1–1.4 times its area in voxels).
    pub max_leaves: usize,
}

impl Default for VoxelizeOptions {
    fn default() -> Self {
        Self {
            resolution: Resolution::Depth(8),
            surface_only: false,
            max_crossings: MAX_CROSSINGS,
            max_leaves: crate::csg::DEFAULT_MAX_LEAVES,
        }
    }
}

type Tri = [[i64; 3]; 3];

/// Voxelizes `mesh` into a solid (a voxel is black when its centre is inside) or,
/// with `surface_only`, into the voxels the surface touches. The result carries a [`Frame`] mapping voxels back to mesh units.
///
/// # Runtime
/// O(T + C log C + S) for T triangles, C column crossings (about twice the projected
/// area in voxels) and S cells near the surface.
///
/// # Errors
/// [`VoxelizeError::NotWatertight`]; [`VoxelizeError::TooLarge`] for a grid deeper than
/// [`MAX_VOXELIZE_DEPTH`] or too many crossings; [`VoxelizeError::BadMesh`] for a bad
/// vertex index.
///
/// ```
/// use tesseral::mesh::{voxelize, Resolution, TriMesh, VoxelizeOptions};
/// // A closed tetrahedron-free box: read one from OBJ text.
/// let obj = "v 0 0 0\nv 4 0 0\nv 0 4 0\nv 4 4 0\nv 0 0 4\nv 4 0 4\nv 0 4 4\nv 4 4 4\n\
///            f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
/// let mesh = tesseral::io::mesh::parse_obj(obj.as_bytes()).unwrap();
/// let opts = VoxelizeOptions { resolution: Resolution::VoxelSize(0.5), ..Default::default() };
/// let model = voxelize(&mesh, &opts).unwrap();
/// assert_eq!(model.tree.voxel_count(), 8 * 8 * 8);
/// ```
pub fn voxelize(mesh: &TriMesh, options: &VoxelizeOptions) -> Result<Model, VoxelizeError> {
    let n = mesh.positions.len();
    if let Some(t) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(VoxelizeError::corrupt(format!(
            "triangle {t} names a missing vertex"
        )));
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &mesh.triangles {
        for &i in t {
            let p = mesh.positions[i as usize];
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    if mesh.triangles.is_empty() {
        return Ok(Model::new(LinearOctree::empty(0, [0; 3]).expect("depth 0")));
    }
    let (depth, origin, h, translate) = match options.resolution {
        Resolution::Depth(d) => {
            if d > MAX_VOXELIZE_DEPTH {
                return Err(VoxelizeError::too_large(format!(
                    "depth {d} exceeds the voxelization limit {MAX_VOXELIZE_DEPTH}"
                )));
            }
            let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
            if !ext.is_finite() {
                return Err(VoxelizeError::too_large("the mesh's extent overflows"));
            }
            let h = if ext > 0.0 {
                ext / f64::from(1u32 << d)
            } else {
                1.0
            };
            (d, [0i64; 3], h, lo)
        }
        Resolution::VoxelSize(h) => {
            if !(h.is_finite() && h > 0.0) {
                return Err(VoxelizeError::unsupported(format!(
                    "voxel size {h} must be positive"
                )));
            }
            let mut origin = [0i64; 3];
            let mut extent = 1i64;
            for a in 0..3 {
                let (l, u) = ((lo[a] / h).floor(), (hi[a] / h).floor());
                if !(l.abs() < 1e15 && u.abs() < 1e15) {
                    return Err(VoxelizeError::too_large(format!(
                        "voxel size {h} gives a grid too large"
                    )));
                }
                origin[a] = l as i64;
                extent = extent.max(u as i64 - l as i64 + 1);
            }
            let d = (extent as u64).next_power_of_two().trailing_zeros();
            if d > u32::from(MAX_VOXELIZE_DEPTH) {
                return Err(VoxelizeError::too_large(format!(
                    "voxel size {h} needs {extent} voxels per axis, beyond the limit of {}",
                    1u32 << MAX_VOXELIZE_DEPTH
                )));
            }
            (d as u8, origin, h, [0.0; 3])
        }
    };
    let side = 1i64 << depth;
    let quant = |p: [f64; 3]| -> [i64; 3] {
        [0, 1, 2].map(|a| {
            let q = (((p[a] - translate[a]) / h - origin[a] as f64) * ONE as f64).round();
            q.clamp(-(ONE as f64), ((side + 1) * ONE) as f64) as i64
        })
    };
    let q: Vec<[i64; 3]> = mesh.positions.iter().map(|&p| quant(p)).collect();
    let tris: Vec<Tri> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| q[i as usize]))
        .collect();
    // Repeated triangles would each be rasterized onto the same columns; fold them
    // first, exactly (see `coincident`).
    let tris = fold_coincident(tris, options.surface_only);
    if !options.surface_only {
        check_watertight(&tris, |p| {
            [0, 1, 2].map(|a| translate[a] + h * (origin[a] as f64 + p[a] as f64 / ONE as f64))
        })?;
    }
    let area = surface_area(&tris);
    if area > options.max_leaves as f64 {
        return Err(VoxelizeError::TooLarge(format!(
            "the surface at depth {depth} is about {area:.0} voxels in area, so the octree would have about that many leaves, more than the budget of {} (raise --max-leaves or --memory, or lower --depth)",
            options.max_leaves
        )));
    }
    if !options.surface_only {
        // The budget is checked before any work, from the triangles alone.
        let bound = crossing_bound(&tris);
        if bound > options.max_crossings as u64 {
            return Err(VoxelizeError::TooLarge(format!(
                "a solid voxelization at depth {depth} needs up to {bound} ray crossings ({} MiB at 8 bytes each), more than the budget of {} (raise --memory, lower --depth, or use --surface-only)",
                bound.saturating_mul(8) >> 20,
                options.max_crossings
            )));
        }
    }
    let bins = Bins::new(&tris, depth);
    let columns = if options.surface_only {
        Columns::default()
    } else {
        Columns::new(&tris, depth, options.max_crossings).map_err(VoxelizeError::too_large)?
    };
    let classifier = MeshClassifier {
        tris,
        bins,
        columns,
        origin,
        side,
        surface_only: options.surface_only,
    };
    let tree =
        LinearOctree::from_classifier(depth, origin, &classifier).map_err(VoxelizeError::Octree)?;
    Ok(Model::new(tree).with_frame(Frame::new(h, translate)))
}

fn check_watertight(
    tris: &[Tri],
    world: impl Fn([i64; 3]) -> [f64; 3],
) -> Result<(), VoxelizeError> {
    let mut ids: HashMap<[i64; 3], u32> = HashMap::with_capacity(tris.len());
    let mut odd: HashMap<(u32, u32), bool> = HashMap::with_capacity(tris.len() * 3 / 2);
    let mut points: Vec<[i64; 3]> = Vec::new();
    for t in tris {
        let w = t.map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p).or_insert_with(|| {
                points.push(p);
                next
            })
        });
        for e in 0..3 {
            let (a, b) = (w[e], w[(e + 1) % 3]);
            if a != b {
                let key = (a.min(b), a.max(b));
                let v = odd.entry(key).or_insert(false);
                *v = !*v;
            }
        }
    }
    let open: Vec<(u32, u32)> = odd.into_iter().filter(|e| e.1).map(|e| e.0).collect();
    if let Some(&(a, _)) = open.iter().min() {
        return Err(VoxelizeError::NotWatertight {
            open_edges: open.len(),
            example: world(points[a as usize]),
        });
    }
    Ok(())
}

struct MeshClassifier {
    tris: Vec<Tri>,
    bins: Bins,
    columns: Columns,
    origin: Voxel,
    side: i64,
    surface_only: bool,
}

impl Classifier for MeshClassifier {
    fn classify(&self, min: Voxel, k: u8) -> CellClass {
        let rel = [0, 1, 2].map(|a| min[a] - self.origin[a]);
        let s = 1i64 << k;
        let last = rel.map(|r| (r + s - 1).min(self.side - 1));
        let state = |inside: bool| {
            if inside {
                CellClass::Inside
            } else {
                CellClass::Outside
            }
        };
        if self.surface_only {
            // Triangle bin ranges carry a one-unit margin, so a triangle that only
            // touches the cell's faces is still among the cell's own bins.
            let lo = rel.map(|r| r * ONE);
            let hi = rel.map(|r| (r + s) * ONE);
            let hit = self.bins.query(rel, last).is_some_and(|r| {
                self.bins
                    .any(r, |t| tri_box_overlap(lo, hi, &self.tris[t as usize]))
            });
            return match (hit, k) {
                (false, _) => CellClass::Outside,
                (true, 0) => CellClass::Inside,
                (true, _) => CellClass::Partial,
            };
        }
        if k == 0 {
            return state(self.columns.inside(rel));
        }
        let Some(r) = self.bins.query(rel, last) else {
            return state(self.columns.inside(rel));
        };
        if k <= 3 {
            return self
                .columns
                .uniform(rel, k)
                .map_or(CellClass::Partial, state);
        }
        // The hull of the cell's voxel centres, padded by one lattice unit.
        let lo = rel.map(|r| r * ONE + HALF - 1);
        let hi = rel.map(|r| (r + s - 1) * ONE + HALF + 1);
        if self
            .bins
            .any(r, |t| tri_box_overlap(lo, hi, &self.tris[t as usize]))
        {
            CellClass::Partial
        } else {
            state(self.columns.inside(rel))
        }
    }
}

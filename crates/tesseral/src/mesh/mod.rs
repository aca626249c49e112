//! Meshes in and out.
//!
//! - **Out** ([`boundary_mesh`], [`smooth_mesh`]): the boundary of a solid as a
//!   watertight, manifold triangle mesh. Coplanar faces are merged greedily, vertices
//!   are split where voxels touch only along an edge or at a corner, and T-junctions
//!   are closed, so every edge is shared by exactly two triangles.
//! - **In** ([`voxelize()`]): a triangle mesh becomes a solid octree at a chosen depth
//!   or voxel size, top-down through a
//!   [`crate::linear::Classifier`], with exact integer triangle/box overlap tests and
//!   exact ray parity for inside/outside.

mod boundary;
mod voxelize;

pub use boundary::{boundary_mesh, smooth_mesh};
pub use voxelize::{voxelize, Resolution, VoxelizeError, VoxelizeOptions, MAX_VOXELIZE_DEPTH};

/// An indexed triangle mesh. Triangles are counter-clockwise seen from outside.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// A colour per triangle, or empty when the mesh has none.
    pub colors: Vec<[u8; 3]>,
}

impl TriMesh {
    /// The signed volume enclosed (positive for outward-facing triangles), by the
    /// divergence theorem.
    ///
    /// # Runtime
    /// O(triangles).
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    /// The number of directed edges that do not have exactly one opposite partner and
    /// no twin, i.e. the violations of "every edge is shared by exactly two triangles,
    /// in opposite directions". Zero for a closed, oriented, manifold-edged mesh.
    ///
    /// # Runtime
    /// O(triangles) expected (hashing).
    #[must_use]
    pub fn edge_defects(&self) -> usize {
        use std::collections::HashMap;
        let mut count: HashMap<(u32, u32), i32> = HashMap::with_capacity(self.triangles.len() * 3);
        for t in &self.triangles {
            for e in 0..3 {
                *count.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        count
            .iter()
            .filter(|(&(a, b), &n)| n != 1 || count.get(&(b, a)) != Some(&1))
            .count()
    }

    /// Maps every position through `f` (for example voxel to world coordinates).
    pub fn transform(&mut self, f: impl Fn([f64; 3]) -> [f64; 3]) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }
}

/// How an octree becomes a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshOptions {
    /// A smooth surface (surface nets over the voxel centres) instead of the exact,
    /// greedily merged blocky boundary.
    pub smooth: bool,
}

// The mesh file formats (STL, OBJ, PLY, glTF) live with the other formats in
// `crate::io::mesh`; this module is geometry only and depends on no file code.

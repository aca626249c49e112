//! The boundary of a linear octree as a watertight, manifold triangle mesh.
//!
//! 1. **Boundary squares.** For each face of each black block, the aligned cube across
//!    it is classified against the tree (one binary search): black, white, or mixed;
//!    mixed cubes are split into the four quarters touching the face. White squares
//!    are boundary. The cost follows the boundary, not the volume.
//! 2. **Greedy merging.** Squares are cut into rows per plane and orientation, runs
//!    in a row are joined, and identical runs in consecutive rows are stacked into
//!    rectangles, so a flat side of any size costs two triangles.
//! 3. **Split vertices.** At a lattice point, the (up to 12) boundary unit faces are
//!    grouped by which faces continue into which across the 6 edges at the point: an
//!    edge with two boundary faces joins them; an edge with four (voxels touching only
//!    along that edge) joins the two faces of the same black voxel. Each group is one
//!    vertex, so voxels meeting at an edge or a corner get separate vertices and the
//!    surface is a manifold (black is 6-connected).
//! 4. **No T-junctions.** A rectangle includes, along its sides, every vertex that is
//!    a corner of another rectangle in the same group, and is then fanned from its
//!    centre, so the two sides of every edge are cut at the same points and every
//!    edge has exactly two triangles.
//!
//! One file per step: `squares.rs` (1), `rects.rs` (2), `groups.rs` (the table of
//! step 3) and `vertices.rs` (its use), `triangulate.rs` (4); `tests.rs`.

mod groups;
mod lattice;
mod rects;
mod squares;
mod triangulate;
mod vertices;

use super::TriMesh;
use crate::linear::LinearOctree;
use triangulate::build;

/// The boundary of `tree` as a watertight, manifold mesh in voxel coordinates
/// (voxel `(i, j, k)` is the unit cube at that corner), with coplanar faces merged.
///
/// Every edge is shared by exactly two triangles, in opposite directions, and the
/// enclosed volume equals the voxel count. Voxels that touch only along an edge or at
/// a corner get separate vertices there.
///
/// # Runtime
/// O(B log n) for B boundary squares found top-down and n leaves, plus hashing per
/// output vertex.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::mesh::boundary_mesh;
/// let cube = LinearOctree::full(5, [0, 0, 0]).unwrap(); // 32³ voxels
/// let mesh = boundary_mesh(&cube);
/// assert_eq!(mesh.triangles.len(), 12); // six sides, two triangles each
/// assert!((mesh.volume() - 32.0 * 32.0 * 32.0).abs() < 1e-6);
/// assert_eq!(mesh.edge_defects(), 0);
/// ```
#[must_use]
pub fn boundary_mesh(tree: &LinearOctree) -> TriMesh {
    build(tree, true).0
}

/// A smooth surface: the unit-face boundary with each vertex moved to the mean of the
/// centres of its faces (surface nets over the voxel centres). The topology is that of
/// the blocky boundary (watertight, manifold, split at edge and corner contacts).
///
/// # Runtime
/// O(unit boundary faces · log n).
///
/// ```
/// use tesseral::linear::LinearOctree;
/// let cube = LinearOctree::full(2, [0, 0, 0]).unwrap();
/// let mesh = tesseral::mesh::smooth_mesh(&cube);
/// assert_eq!(mesh.edge_defects(), 0);
/// assert!(mesh.volume() > 0.0 && mesh.volume() < 64.0);
/// ```
#[must_use]
pub fn smooth_mesh(tree: &LinearOctree) -> TriMesh {
    let (mut mesh, keys, rows) = build(tree, false);
    for (i, ((p, g), row)) in keys.iter().zip(&rows).enumerate() {
        let mut sum = [0.0f64; 3];
        let mut n = 0.0;
        for (f, _) in row.iter().enumerate().filter(|e| e.1 == g) {
            {
                let a = f / 4;
                let mut c = p.map(|x| x as f64);
                c[(a + 1) % 3] += (f & 1) as f64 - 0.5;
                c[(a + 2) % 3] += ((f >> 1) & 1) as f64 - 0.5;
                for (s, c) in sum.iter_mut().zip(c) {
                    *s += c;
                }
                n += 1.0;
            }
        }
        mesh.positions[i] = sum.map(|s| s / n);
    }
    mesh
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_lattice;

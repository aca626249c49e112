//! Mesh files: STL (ASCII and binary), Wavefront OBJ, PLY (ASCII and binary) and
//! glTF binary (write only). Reading parses a [`crate::mesh::TriMesh`] and voxelizes it
//! ([`crate::mesh::voxelize`]); writing meshes the octree
//! ([`crate::mesh::boundary_mesh`] or [`crate::mesh::smooth_mesh`]) in world units.

mod read;
mod write;

pub(crate) use read::parse_ply_points;
pub use read::{parse, parse_obj, parse_ply, parse_stl, read, MAX_MESH_ELEMENTS};
pub use write::{write_file, write_glb, write_obj, write_ply, write_stl, MESH_EXTENSIONS};

use std::path::Path;

use super::FormatError;
use crate::mesh::{
    boundary_mesh, smooth_mesh, voxelize, MeshOptions, VoxelizeError, VoxelizeOptions,
};
use crate::model::Model;

impl From<VoxelizeError> for FormatError {
    fn from(e: VoxelizeError) -> Self {
        match e {
            VoxelizeError::BadMesh(m) => Self::Corrupt(m),
            VoxelizeError::TooLarge(m) => Self::TooLarge(m),
            VoxelizeError::NotWatertight {
                open_edges,
                example,
            } => Self::NotWatertight {
                open_edges,
                example,
            },
            VoxelizeError::Octree(e) => Self::Octree(e),
            other => Self::Unsupported(other.to_string()),
        }
    }
}

/// Voxelizes the mesh at `path` (by extension: `.stl`, `.obj`, `.ply`).
///
/// # Errors
/// Parser errors naming the file and line; [`FormatError::NotWatertight`] for a
/// solid voxelization of an open mesh; [`FormatError::TooLarge`] past
/// [`crate::mesh::MAX_VOXELIZE_DEPTH`].
pub fn read_voxelized(path: &Path, options: &VoxelizeOptions) -> Result<Model, FormatError> {
    let mesh = read(path)?;
    if mesh.triangles.is_empty() {
        return Err(
            FormatError::corrupt("the mesh has no triangles: nothing to voxelize").with_path(path),
        );
    }
    voxelize(&mesh, options).map_err(|e| FormatError::from(e).with_path(path))
}

/// Meshes `model` (blocky or smooth) and writes it by extension (`.stl`, `.obj`,
/// `.ply`, `.glb`), in world units (the model's frame applied). PLY (face colours)
/// and glTF (`COLOR_0`) carry the model's colours; STL and OBJ have no standard
/// place for them.
///
/// # Errors
/// [`FormatError::Io`]; [`FormatError::UnknownFormat`] for another extension.
pub fn write_meshed(path: &Path, model: &Model, options: &MeshOptions) -> Result<(), FormatError> {
    let mut mesh = if options.smooth {
        smooth_mesh(&model.tree)
    } else {
        boundary_mesh(&model.tree)
    };
    if let Some(colors) = &model.colors {
        mesh.colors = face_colors(&mesh, colors);
    }
    let f = model.frame;
    mesh.transform(|p| f.to_world(p));
    write_file(path, &mesh)
}

/// The colour of each triangle: that of the voxel half a voxel inside the surface at
/// its centroid (voxel units), or the default colour where the voxel has none.
fn face_colors(
    mesh: &crate::mesh::TriMesh,
    colors: &crate::model::Layer<crate::model::Rgba>,
) -> Vec<[u8; 3]> {
    use rayon::prelude::*;
    let default = super::vox::DEFAULT_COLOR;
    // A triangle's neighbours in the list are mostly its neighbours on the surface:
    // each run of them starts its search where the last one's ended.
    mesh.triangles
        .par_iter()
        .map_init(
            || 0usize,
            |near, t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let u = [0, 1, 2].map(|k| b[k] - a[k]);
                let v = [0, 1, 2].map(|k| c[k] - a[k]);
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
                    .sqrt()
                    .max(f64::MIN_POSITIVE);
                // Triangles wind counter-clockwise seen from outside: n points out.
                let p = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0 - 0.5 * n[k] / len);
                let col = colors
                    .get_near(p.map(|x| x.floor() as i64), near)
                    .unwrap_or(default);
                [col[0], col[1], col[2]]
            },
        )
        .collect()
}

//! Mesh files: STL (ASCII and binary), Wavefront OBJ, PLY (ASCII and binary) and
//! glTF binary (write only). Reading parses a [`crate::mesh::TriMesh`] and voxelizes it
//! ([`crate::mesh::voxelize`]); writing meshes the octree
//! ([`crate::mesh::boundary_mesh`] or [`crate::mesh::smooth_mesh`]) in world units.

mod read;
mod write;

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
/// `.ply`, `.glb`), in world units (the model's frame applied).
///
/// # Errors
/// [`FormatError::Io`]; [`FormatError::UnknownFormat`] for another extension.
pub fn write_meshed(path: &Path, model: &Model, options: &MeshOptions) -> Result<(), FormatError> {
    let mut mesh = if options.smooth {
        smooth_mesh(&model.tree)
    } else {
        boundary_mesh(&model.tree)
    };
    let f = model.frame;
    mesh.transform(|p| f.to_world(p));
    write_file(path, &mesh)
}

//! Reading and writing octrees in the formats people use, chosen by file extension.
//!
//! Every command that reads an octree goes through [`read_octree`] (or
//! [`read_model`], which also keeps the voxel size, placement and colours a format
//! carries), and every one that writes goes through [`write_octree`] /
//! [`write_model`], so each format added here works everywhere.
//! Files are written to a temporary name in the same folder and renamed into place
//! ([`write_atomic`]), so a crash never leaves a half-written file where a good one
//! stood.
//!
//! | extension | format | module |
//! |---|---|---|
//! | `.tess` | tesseral's native binary linear octree | [`native`] |
//! | `.xyz` | plain voxel list | [`xyz`] |
//! | `.binvox` | binvox run-length voxel grid | [`binvox`] |
//! | `.vox` | MagicaVoxel, with palette colours | [`vox`] |
//! | `.bt`, `.ot` | OctoMap binary and full occupancy trees | [`octomap`] |
//! | `.stl`, `.obj`, `.ply` | meshes, voxelized on read, meshed on write | [`crate::mesh`] |
//! | `.glb` | glTF binary mesh (write only) | [`crate::mesh`] |
//!
//! Range scans for occupancy mapping (`.graph`, `.log`, `.xyz`, `.ply`, `.pcd`, with
//! sensor poses) are read by [`scan`].

mod atomic;
pub mod binvox;
mod chunked;
pub(crate) mod colour_index;
mod estimate;
pub(crate) mod leafstream;
pub mod mesh;
pub mod native;
pub mod octomap;
mod reframe;
pub mod scan;
pub(crate) mod sections;
mod sniff;
mod spool;
pub(crate) mod tess_colours;
pub(crate) mod text_number;

mod tess_file;
mod tess_file_colours;
mod tess_v1;
#[cfg(all(test, target_os = "linux"))]
mod tests_release;
pub mod vox;
pub(crate) mod wide;
pub mod xyz;

mod error;
mod staged;
pub use atomic::{pending_temporaries, remove_pending_temporaries, write_atomic};
pub use chunked::{ChunkInfo, TessWriter, DEFAULT_CHUNK_LEAVES};
pub use error::FormatError;
pub use estimate::{
    estimate_image_bytes, estimate_model_bytes, estimate_output_bytes, estimate_xyz_bytes,
};
pub use reframe::reframe;
pub use sniff::sniff_format;
pub use spool::LeafSpool;
pub use staged::{commit_staged, stage_dir, sweep_stale_staged, StagedDir, MARKER};
pub use tess_colours::RegionLeaves;
pub use tess_file::{LeafIter, TessFile};

use std::fs;
use std::path::Path;

use crate::linear::LinearOctree;
#[cfg(test)]
use crate::Voxel;

pub use crate::model::{Frame, Model};

/// How to read formats that need a choice (meshes need a resolution).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadOptions {
    /// How meshes are voxelized.
    pub mesh: crate::mesh::VoxelizeOptions,
}

/// How to write formats that need a choice (meshes can be blocky or smooth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriteOptions {
    /// How meshes are made from the octree.
    pub mesh: crate::mesh::MeshOptions,
}

/// The extensions [`read_octree`] understands.
pub const KNOWN_EXTENSIONS: &str = "tess, xyz, binvox, vox, bt, ot, stl, obj, ply";

/// The extensions [`write_octree`] understands.
pub const KNOWN_WRITE_EXTENSIONS: &str = "tess, xyz, binvox, vox, bt, ot, stl, obj, ply, glb";

/// Reads an octree from `path`, choosing the format by its extension. Meshes are
/// voxelized with [`ReadOptions::default`].
///
/// # Errors
/// [`FormatError`] naming the file, and the line and column or field at fault.
pub fn read_octree(path: &Path) -> Result<LinearOctree, FormatError> {
    Ok(read_model(path)?.tree)
}

/// Reads an octree with its frame and colours, with default options.
///
/// # Errors
/// [`FormatError`] naming the file, and the line and column or field at fault.
pub fn read_model(path: &Path) -> Result<Model, FormatError> {
    read_model_with(path, &ReadOptions::default())
}

/// Reads an octree with its frame and colours, choosing the format by extension.
///
/// # Errors
/// [`FormatError`] naming the file, and the line and column or field at fault.
pub fn read_model_with(path: &Path, options: &ReadOptions) -> Result<Model, FormatError> {
    match extension(path).as_str() {
        "tess" => native::read(path),
        "xyz" => xyz::read(path).map(Model::new),
        "binvox" => binvox::read(path),
        "vox" => vox::read(path),
        "bt" | "ot" => octomap::read(path),
        "stl" | "obj" | "ply" => mesh::read_voxelized(path, &options.mesh),
        // A name with no known extension: say first when there is no such file, or
        // a folder, rather than that the format is unknown.
        _ => Err(match std::fs::metadata(path) {
            Err(e) => FormatError::io(e),
            Ok(m) if m.is_dir() => FormatError::unsupported(
                "a folder, not an octree file (a dataset's folder holds a manifest.json)",
            ),
            Ok(_) => FormatError::UnknownFormat {
                known: KNOWN_EXTENSIONS,
            },
        }),
    }
    .map_err(|e| e.with_path(path))
}

/// Writes `tree` to `path` atomically, choosing the format by its extension.
///
/// # Errors
/// [`FormatError`] naming the file.
pub fn write_octree(path: &Path, tree: &LinearOctree) -> Result<(), FormatError> {
    write_model(path, &Model::new(tree.clone()))
}

/// Writes a model with its frame and colours, with default options.
///
/// # Errors
/// [`FormatError`] naming the file.
pub fn write_model(path: &Path, model: &Model) -> Result<(), FormatError> {
    write_model_with(path, model, &WriteOptions::default())
}

/// Writes a model to `path` atomically, choosing the format by its extension.
/// Formats without colour or frame drop them.
///
/// # Errors
/// [`FormatError`] naming the file; [`FormatError::Unsupported`] when the octree
/// does not fit the format (for example a `.vox` wider than 256 voxels).
pub fn write_model_with(
    path: &Path,
    model: &Model,
    options: &WriteOptions,
) -> Result<(), FormatError> {
    match extension(path).as_str() {
        "tess" => write_atomic(path, |w| native::write(w, model)),
        "xyz" => write_atomic(path, |w| xyz::write(w, &model.tree)),
        "binvox" => binvox::write_file(path, model),
        "vox" => vox::write_file(path, model),
        "bt" | "ot" => octomap::write_file(path, model),
        "stl" | "obj" | "ply" | "glb" => mesh::write_meshed(path, model, &options.mesh),
        _ => Err(FormatError::UnknownFormat {
            known: KNOWN_WRITE_EXTENSIONS,
        }),
    }
    .map_err(|e| e.with_path(path))
}

/// The lower-case extension of `path`, or "".
#[must_use]
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// The bytes after a UTF-8 byte order mark, if they start with one: text readers
/// skip it (editors on Windows write one), and count columns after it.
pub fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes)
}

/// A text file's bytes after a UTF-8 byte order mark ([`strip_bom`]); a UTF-16 or
/// UTF-32 one is refused at line 1, column 1, naming the encoding, rather than read
/// as bytes that fail somewhere further on.
pub(crate) fn text_start(bytes: &[u8]) -> Result<&[u8], FormatError> {
    const WIDE: [(&[u8], &str); 4] = [
        (
            b"\xff\xfe\x00\x00",
            "UTF-32 little-endian (byte order mark FF FE 00 00)",
        ),
        (
            b"\x00\x00\xfe\xff",
            "UTF-32 big-endian (byte order mark 00 00 FE FF)",
        ),
        (b"\xff\xfe", "UTF-16 little-endian (byte order mark FF FE)"),
        (b"\xfe\xff", "UTF-16 big-endian (byte order mark FE FF)"),
    ];
    match WIDE.iter().find(|(mark, _)| bytes.starts_with(mark)) {
        Some((_, encoding)) => Err(FormatError::Syntax {
            line: 1,
            column: 1,
            message: format!("the text is {encoding}: save it as UTF-8"),
        }),
        None => Ok(strip_bom(bytes)),
    }
}

/// Reads a whole file, refusing files larger than `limit` bytes.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, FormatError> {
    let attach = |e: FormatError| e.with_path(path);
    let meta = fs::metadata(path).map_err(|e| attach(FormatError::io(e)))?;
    if meta.len() > limit {
        return Err(attach(FormatError::too_large(format!(
            "file is {} bytes; the limit is {limit}",
            meta.len()
        ))));
    }
    fs::read(path).map_err(|e| attach(FormatError::io(e)))
}

/// The largest file the whole-file readers load (4 GiB).
pub(crate) const MAX_FILE_BYTES: u64 = 4 << 30;

/// The most voxels a dense format (binvox, `.vox`) may expand to before we refuse.
pub const MAX_DENSE_VOXELS: u64 = 1 << 26;

/// The most per-voxel colours a reader expands (a colour map entry takes about 40
/// bytes).
pub const MAX_COLORED_VOXELS: u64 = 1 << 24;

/// Random test solids: an origin in `[-spread, spread)^3` and up to `max_count - 1`
/// voxels drawn uniformly from the cube of side `side` above it (repeats possible).
#[cfg(test)]
pub(crate) fn random_voxels(
    rng: &mut impl rand::Rng,
    spread: i64,
    side: i64,
    max_count: i32,
) -> (Voxel, Vec<Voxel>) {
    let origin = [
        rng.random_range(-spread..spread),
        rng.random_range(-spread..spread),
        rng.random_range(-spread..spread),
    ];
    let voxels = (0..rng.random_range(0..max_count))
        .map(|_| {
            [
                origin[0] + rng.random_range(0..side),
                origin[1] + rng.random_range(0..side),
                origin[2] + rng.random_range(0..side),
            ]
        })
        .collect();
    (origin, voxels)
}

//! A partitioned dataset on disk: a directory of `.tess` parts (`part-00000.tess`,
//! …) and `manifest.json`:
//!
//! ```json
//! {"format": "tesseral-partitioned", "version": 1, "depth": 12, "origin": [0, 0, 0],
//!  "frame": {"voxel_size": 0.25, "translate": [0, 0, 0]},
//!  "parts": [{"file": "part-00000.tess", "lo": 0, "hi": 8589934592,
//!             "leaves": 1234, "voxels": 56789, "crc32": 305419896}, …]}
//! ```
//!
//! `lo` and `hi` are the part's code range, `crc32` the CRC-32 of the part file's
//! bytes. The reader checks that the ranges tile the space, that each part file
//! matches its CRC, space, range and counts.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{Partition, PartitionError, PartitionedOctree};
use crate::io::{FormatError, TessFile};
use crate::linear::LinearOctree;
use crate::model::{Frame, Model};
use crate::Voxel;

/// The manifest's file name.
pub const MANIFEST: &str = "manifest.json";
const FORMAT: &str = "tesseral-partitioned";

/// The manifest of a dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always `tesseral-partitioned`.
    pub format: String,
    /// Always 1.
    pub version: u32,
    /// The depth of the space.
    pub depth: u8,
    /// The lowest voxel of the space.
    pub origin: Voxel,
    /// Voxel size and placement.
    pub frame: ManifestFrame,
    /// The parts in code order.
    pub parts: Vec<ManifestPart>,
}

/// The frame as the manifest spells it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestFrame {
    /// The side of a voxel in world units.
    pub voxel_size: f64,
    /// The world position of voxel (0, 0, 0)'s corner.
    pub translate: [f64; 3],
}

/// One part of a dataset.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestPart {
    /// The part's file name, in the dataset's directory.
    pub file: String,
    /// The first code of its range.
    pub lo: u64,
    /// One past the last code.
    pub hi: u64,
    /// Its leaf count.
    pub leaves: u64,
    /// Its voxel count.
    pub voxels: u64,
    /// The CRC-32 of the file's bytes.
    pub crc32: u32,
}

impl Manifest {
    /// The manifest of a dataset of the space `(depth, origin)` with `frame` and
    /// `parts` (unchecked: [`read_manifest`] checks what it reads).
    #[must_use]
    pub fn new(depth: u8, origin: Voxel, frame: Frame, parts: Vec<ManifestPart>) -> Self {
        Self {
            format: FORMAT.into(),
            version: 1,
            depth,
            origin,
            frame: ManifestFrame {
                voxel_size: frame.voxel_size,
                translate: frame.translate,
            },
            parts,
        }
    }
}

pub(crate) fn part_name(i: usize) -> String {
    format!("part-{i:05}.tess")
}

fn file_crc(path: &Path) -> Result<u32, FormatError> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
    let mut h = crc32fast::Hasher::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f
            .read(&mut buf)
            .map_err(|e| FormatError::io(e).with_path(path))?;
        if n == 0 {
            return Ok(h.finalize());
        }
        h.update(&buf[..n]);
    }
}

impl ManifestPart {
    /// The entry of a part file just written in `dir`.
    ///
    /// # Errors
    /// [`PartitionError::Format`] when the file cannot be read.
    pub fn of_file(
        dir: &Path,
        file: String,
        range: Partition,
        leaves: u64,
        voxels: u64,
    ) -> Result<Self, PartitionError> {
        let crc32 = file_crc(&dir.join(&file))?;
        Ok(Self {
            file,
            lo: range.lo,
            hi: range.hi,
            leaves,
            voxels,
            crc32,
        })
    }
}

/// Writes the manifest of a dataset whose parts are written (atomically; write it
/// last, so that no manifest names a missing part).
///
/// # Errors
/// [`PartitionError::Format`] when the file cannot be written.
pub fn write_manifest(
    dir: &Path,
    depth: u8,
    origin: Voxel,
    frame: Frame,
    parts: &[ManifestPart],
) -> Result<(), PartitionError> {
    let m = Manifest::new(depth, origin, frame, parts.to_vec());
    let text = serde_json::to_string_pretty(&m).expect("a manifest serializes");
    crate::io::write_atomic(&dir.join(MANIFEST), |w| {
        w.write_all(text.as_bytes())?;
        w.write_all(b"\n")
    })?;
    Ok(())
}

/// Writes a partitioned octree as a dataset in `dir` (created if missing): one
/// `.tess` per part, then the manifest.
///
/// # Errors
/// [`PartitionError::Format`] for a file that cannot be written.
pub fn write_dataset(
    dir: &Path,
    tree: &PartitionedOctree,
    frame: Frame,
) -> Result<(), PartitionError> {
    std::fs::create_dir_all(dir).map_err(|e| FormatError::io(e).with_path(dir))?;
    let mut parts = Vec::new();
    for (i, (p, t)) in tree.parts().iter().enumerate() {
        parts.push(write_part(dir, i, *p, t, frame)?);
    }
    write_manifest(dir, tree.depth(), tree.origin(), frame, &parts)
}

/// Writes part `i` of a dataset (`part-0000i.tess` in `dir`, atomically) and
/// returns its manifest entry. The leaves must lie in `range`.
///
/// # Errors
/// [`PartitionError::Ranges`] for leaves outside the range;
/// [`PartitionError::Format`] for a file that cannot be written.
pub fn write_part(
    dir: &Path,
    i: usize,
    range: Partition,
    tree: &LinearOctree,
    frame: Frame,
) -> Result<ManifestPart, PartitionError> {
    write_model_part(dir, i, range, &Model::new(tree.clone()).with_frame(frame))
}

/// As [`write_part`], for a model: its frame and colours are written with it.
///
/// # Errors
/// As [`write_part`].
pub fn write_model_part(
    dir: &Path,
    i: usize,
    range: Partition,
    model: &Model,
) -> Result<ManifestPart, PartitionError> {
    let tree = &model.tree;
    if tree.leaves().first().is_some_and(|l| l.code() < range.lo)
        || tree.leaves().last().is_some_and(|l| l.end() > range.hi)
    {
        return Err(PartitionError::Ranges(format!(
            "part {i} has leaves outside its range [{}, {})",
            range.lo, range.hi
        )));
    }
    let name = part_name(i);
    crate::io::write_model(&dir.join(&name), model)?;
    ManifestPart::of_file(
        dir,
        name,
        range,
        tree.leaf_count() as u64,
        tree.voxel_count(),
    )
}

/// Whether `path` is a dataset directory (holds a manifest).
#[must_use]
pub fn is_dataset(path: &Path) -> bool {
    path.is_dir() && path.join(MANIFEST).is_file()
}

/// Reads and checks a dataset's manifest.
///
/// # Errors
/// [`PartitionError::Manifest`] naming the field at fault.
pub fn read_manifest(dir: &Path) -> Result<Manifest, PartitionError> {
    let path = dir.join(MANIFEST);
    let bad = |message: String| PartitionError::Manifest {
        path: path.clone(),
        message,
    };
    let text = crate::io::read_limited(&path, 64 << 20).map_err(PartitionError::Format)?;
    let m: Manifest = serde_json::from_slice(&text)
        .map_err(|e| bad(format!("line {}, column {}: {e}", e.line(), e.column())))?;
    if m.format != FORMAT || m.version != 1 {
        return Err(bad(format!(
            "format {:?} version {}: expected {FORMAT:?} version 1",
            m.format, m.version
        )));
    }
    crate::linear::LinearOctree::empty(m.depth, m.origin).map_err(|e| bad(e.to_string()))?;
    if !(m.frame.voxel_size.is_normal() && m.frame.voxel_size > 0.0)
        || m.frame.translate.iter().any(|t| !t.is_finite())
    {
        return Err(bad(
            "frame: voxel_size must be positive and translate finite".into(),
        ));
    }
    let ranges: Vec<Partition> = m
        .parts
        .iter()
        .map(|p| Partition { lo: p.lo, hi: p.hi })
        .collect();
    super::check_tiling(m.depth, &ranges).map_err(|e| bad(e.to_string()))?;
    for (i, p) in m.parts.iter().enumerate() {
        let plain = Path::new(&p.file);
        if plain.components().count() != 1
            || plain.file_name().is_none()
            || !p.file.ends_with(".tess")
        {
            return Err(bad(format!(
                "parts[{i}].file {:?} is not a .tess file name in the directory",
                p.file
            )));
        }
    }
    Ok(m)
}

/// Opens part `i` of a dataset and checks it against the manifest (CRC, space,
/// range, leaf count). A part of version 1 (our writers write version 2, but a
/// manifest may name older files) is opened by [`TessFile::open_streaming`], so
/// that it streams as a version-2 part does.
///
/// # Errors
/// [`PartitionError`] naming the part file.
pub fn open_part(dir: &Path, m: &Manifest, i: usize) -> Result<TessFile, PartitionError> {
    let p = &m.parts[i];
    let path: PathBuf = dir.join(&p.file);
    let bad = |message: String| PartitionError::Manifest {
        path: path.clone(),
        message,
    };
    let crc = file_crc(&path)?;
    if crc != p.crc32 {
        return Err(bad(format!(
            "CRC-32 {crc} differs from the manifest's {}: the part is corrupted or was replaced",
            p.crc32
        )));
    }
    let f = TessFile::open_streaming(&path)?;
    if (f.depth(), f.origin()) != (m.depth, m.origin) {
        return Err(bad(
            "the part is in another space than the manifest's".into()
        ));
    }
    if f.leaf_count() != p.leaves {
        return Err(bad(format!(
            "{} leaves where the manifest says {}",
            f.leaf_count(),
            p.leaves
        )));
    }
    if let (Some(first), Some(last)) = (f.chunks().first(), f.chunks().last()) {
        if first.lo < p.lo || last.hi > p.hi {
            return Err(bad(format!(
                "leaves outside the range [{}, {})",
                p.lo, p.hi
            )));
        }
    }
    Ok(f)
}

/// Reads part `i` of a dataset, checked against the manifest (CRC, space, range,
/// leaf and voxel counts), with the manifest's frame.
///
/// # Errors
/// [`PartitionError`] naming the part file.
pub fn read_part(dir: &Path, m: &Manifest, i: usize) -> Result<Model, PartitionError> {
    let p = m.parts.get(i).ok_or_else(|| PartitionError::Manifest {
        path: dir.join(MANIFEST),
        message: format!("no part {i} (the manifest has {})", m.parts.len()),
    })?;
    let f = open_part(dir, m, i)?;
    let model = f.to_model()?;
    if model.tree.voxel_count() != p.voxels {
        return Err(PartitionError::Manifest {
            path: dir.join(&p.file),
            message: format!(
                "{} voxels where the manifest says {}",
                model.tree.voxel_count(),
                p.voxels
            ),
        });
    }
    let frame = Frame::new(m.frame.voxel_size, m.frame.translate);
    Ok(model.with_frame(frame))
}

/// Reads a whole dataset: the partitioned octree and its frame.
///
/// # Errors
/// [`PartitionError`] naming the manifest or part at fault.
pub fn read_dataset(dir: &Path) -> Result<(PartitionedOctree, Frame), PartitionError> {
    let (p, frame, _) = read_dataset_parts(dir)?;
    Ok((p, frame))
}

/// The parts, the frame and the parts' colour regions (all parts' regions, in
/// order; several may hold one colour).
type DatasetParts = (
    PartitionedOctree,
    Frame,
    Vec<(crate::model::Rgba, LinearOctree)>,
);

fn read_dataset_parts(dir: &Path) -> Result<DatasetParts, PartitionError> {
    let m = read_manifest(dir)?;
    let mut colours = Vec::new();
    let mut parts = Vec::with_capacity(m.parts.len());
    for (i, p) in m.parts.iter().enumerate() {
        let model = read_part(dir, &m, i)?;
        if let Some(layer) = &model.colors {
            colours.extend(layer.regions().iter().cloned());
        }
        parts.push((Partition { lo: p.lo, hi: p.hi }, model.tree));
    }
    let frame = Frame::new(m.frame.voxel_size, m.frame.translate);
    Ok((
        PartitionedOctree::from_parts(m.depth, m.origin, parts)?,
        frame,
        colours,
    ))
}

/// Reads a dataset as one model: the parts joined, with their colours.
///
/// # Errors
/// As [`read_dataset`].
pub fn read_dataset_model(dir: &Path) -> Result<Model, PartitionError> {
    let (p, frame, colours) = read_dataset_parts(dir)?;
    let (depth, origin) = (p.depth(), p.origin());
    let colors = if colours.is_empty() {
        None
    } else {
        // Layer::from_regions joins the parts' regions of one colour.
        let layer = crate::model::Layer::from_regions(depth, origin, colours)
            .map_err(|e| PartitionError::Ranges(e.to_string()))?;
        Some(layer)
    };
    Ok(Model {
        colors,
        ..Model::new(p.concat()).with_frame(frame)
    })
}

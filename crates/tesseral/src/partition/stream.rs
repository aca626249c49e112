//! Streaming a scene's build to files: one `.tess` ([`write_plan_tess`]) or a
//! partitioned dataset ([`build_scene_dataset`]), holding a window of work cells.

use std::io::{self, Write};
use std::path::Path;

use super::dataset::{write_manifest, ManifestPart};
use super::{balanced_ranges, Partition, PartitionError};
use crate::csg::{Csg, Scene, StreamPlan, StreamProgress};
use crate::io::TessWriter;
use crate::model::Frame;

/// What a streaming build wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StreamSummary {
    /// Leaves in the file (merged).
    pub leaves: u64,
    /// Black voxels.
    pub voxels: u64,
}

/// Runs `plan` into a `.tess` file (version 2) written to `w`, with `frame`:
/// [`StreamPlan::run`] feeding a [`TessWriter`]; `window` cells are held at once.
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_plan_tess(
    plan: &StreamPlan,
    csg: &Csg,
    frame: Frame,
    w: &mut dyn Write,
    window: usize,
    progress: &mut dyn FnMut(StreamProgress),
) -> io::Result<StreamSummary> {
    let mut tw = TessWriter::new(w, plan.depth(), plan.origin())?;
    let mut voxels = 0u64;
    plan.run::<io::Error>(
        csg,
        window,
        &mut |ls| {
            for &l in ls {
                voxels += l.voxel_count();
                tw.push(l)?;
            }
            Ok(())
        },
        progress,
    )?;
    let leaves = tw.leaf_count();
    tw.finish(frame)?;
    Ok(StreamSummary { leaves, voxels })
}

/// The `k` (or fewer) ranges of about equal work into which `build_scene_dataset`
/// cuts `scene`: the work cells of a streaming plan with about 64 k cells or more
/// (4 + log4(k) levels below the root), cut evenly.
///
/// # Errors
/// [`PartitionError::Ranges`] for a scene that does not compile.
pub fn scene_ranges(scene: &Scene, k: usize) -> Result<Vec<Partition>, PartitionError> {
    let csg = scene
        .csg()
        .map_err(|e| PartitionError::Ranges(e.to_string()))?;
    csg_ranges(&csg, scene.depth, k)
}

fn csg_ranges(csg: &Csg, depth: u8, k: usize) -> Result<Vec<Partition>, PartitionError> {
    let levels = (4 + (usize::BITS - k.max(1).leading_zeros()).div_ceil(2)) as u8;
    let sample = csg
        .stream_plan_cells(depth, [0, 0, 0], 0..u64::MAX, depth.saturating_sub(levels))
        .map_err(|e| PartitionError::Ranges(e.to_string()))?;
    Ok(balanced_ranges(depth, k, &sample.cell_ranges()))
}

/// Builds `scene` into the directory `dir` as `k` parts of about equal work (the
/// ranges cut the work cells of the streaming plan evenly), each streamed to its
/// own `.tess` file, then the manifest. Each part is written atomically and the
/// manifest last, so a crash leaves no manifest naming a missing part.
///
/// # Errors
/// [`PartitionError`] for the scene, the files or the manifest.
pub fn build_scene_dataset(
    scene: &Scene,
    dir: &Path,
    k: usize,
    window: usize,
    progress: &mut dyn FnMut(usize, StreamProgress),
) -> Result<Vec<ManifestPart>, PartitionError> {
    let scene_err = |e: crate::csg::SceneError| PartitionError::Ranges(e.to_string());
    let csg = scene.csg().map_err(scene_err)?;
    let ranges = csg_ranges(&csg, scene.depth, k)?;
    std::fs::create_dir_all(dir).map_err(|e| crate::io::FormatError::io(e).with_path(dir))?;
    let mut parts = Vec::with_capacity(ranges.len());
    for (i, p) in ranges.iter().enumerate() {
        let plan = csg
            .stream_plan(scene.depth, [0, 0, 0], p.range())
            .map_err(|e| PartitionError::Ranges(e.to_string()))?;
        let name = super::dataset::part_name(i);
        let path = dir.join(&name);
        let mut summary = StreamSummary::default();
        crate::io::write_atomic(&path, |w| {
            summary = write_plan_tess(&plan, &csg, scene.frame(), w, window, &mut |s| {
                progress(i, s);
            })?;
            Ok(())
        })?;
        parts.push(ManifestPart::of_file(
            dir,
            name,
            *p,
            summary.leaves,
            summary.voxels,
        )?);
    }
    write_manifest(dir, scene.depth, [0, 0, 0], scene.frame(), &parts)?;
    Ok(parts)
}

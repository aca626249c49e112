//! Streaming a scene's build to files: one `.tess` ([`write_plan_tess`]) or a
//! partitioned dataset ([`build_scene_dataset`]), holding a window of work cells.

use std::io::{self, Write};
use std::path::Path;

use super::dataset::{write_manifest, ManifestPart};
use super::{balanced_ranges, Partition, PartitionError};
use crate::csg::{Csg, Scene, StreamPlan, StreamProgress};
use crate::io::{LeafSpool, TessWriter};
use crate::model::{Frame, Rgba};

/// What a streaming build wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StreamSummary {
    /// Leaves in the file (merged).
    pub leaves: u64,
    /// Black voxels.
    pub voxels: u64,
    /// Colour regions written (colours with at least one voxel).
    pub colours: u64,
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
    write_plan_tess_coloured(plan, csg, &[], frame, w, window, Path::new("."), progress)
}

/// As [`write_plan_tess`], with the colour parts `colours` (see
/// [`crate::csg::Scene::colour_csgs`]) built in the same cells
/// ([`StreamPlan::run_coloured`]) and written as the file's colour section, through
/// one [`LeafSpool`] per colour: temporary files in `spool_dir`.
///
/// # Errors
/// Any I/O error of `w` or of the spools.
#[allow(clippy::too_many_arguments)]
pub fn write_plan_tess_coloured(
    plan: &StreamPlan,
    csg: &Csg,
    colours: &[(Rgba, Csg)],
    frame: Frame,
    w: &mut dyn Write,
    window: usize,
    spool_dir: &Path,
    progress: &mut dyn FnMut(StreamProgress),
) -> io::Result<StreamSummary> {
    let mut tw = TessWriter::new(w, plan.depth(), plan.origin())?;
    let mut spools = Vec::with_capacity(colours.len());
    for (c, _) in colours {
        spools.push((*c, LeafSpool::new_in(spool_dir)?));
    }
    let csgs: Vec<Csg> = colours.iter().map(|(_, c)| c.clone()).collect();
    let mut voxels = 0u64;
    plan.run_coloured::<io::Error>(
        csg,
        &csgs,
        window,
        &mut |ls, coloured| {
            for &l in ls {
                voxels += l.voxel_count();
                tw.push(l)?;
            }
            for ((_, spool), leaves) in spools.iter_mut().zip(coloured) {
                for &l in leaves {
                    spool.push(l)?;
                }
            }
            Ok(())
        },
        progress,
    )?;
    let leaves = tw.leaf_count();
    let colours = spools.iter().filter(|(_, s)| s.leaf_count() > 0).count() as u64;
    tw.finish_spooled(frame, spools)?;
    Ok(StreamSummary {
        leaves,
        voxels,
        colours,
    })
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
/// own `.tess` file with its colours, then the manifest. Each part is written atomically and the
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
    let colours = scene.colour_csgs().map_err(scene_err)?;
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
            summary = write_plan_tess_coloured(
                &plan,
                &csg,
                &colours,
                scene.frame(),
                w,
                window,
                dir,
                &mut |s| progress(i, s),
            )?;
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

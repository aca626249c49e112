//! Streaming builds: a scene's leaves produced in tesseral order, a few cells at a
//! time, so that a build to a file holds one cell's leaves per worker, never the tree.
//!
//! The code space is cut into aligned cells of `2^STREAM_CELL_LOG2` voxels per axis.
//! A plan ([`Csg::stream_plan`]) classifies top-down down to that size: cells found
//! inside above it become leaves at once, cells found outside are dropped, and the
//! others are listed as work. [`StreamPlan::run`] then builds the listed cells in
//! windows, in parallel (rayon), each on one thread, and hands their leaves to a sink
//! in order. A plan may cover only a code range `[lo, hi)` (a partition): cells
//! straddling its ends are built and their leaves clipped to it.

use std::ops::Range;

use super::{Csg, CsgError};
use crate::linear::{push_merging, CellClass, Leaf, LinearOctree};
use crate::Voxel;

/// The side of a work cell, as a power of two: 512 voxels, whose surface leaves fit
/// in a few megabytes.
pub const STREAM_CELL_LOG2: u8 = 9;

/// How far a streaming build has got.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StreamProgress {
    /// Work cells built so far.
    pub cells_done: u64,
    /// Work cells in the plan.
    pub cells_total: u64,
    /// Leaves handed to the sink so far (before the sink merges any).
    pub leaves: u64,
}

#[derive(Debug, Clone, Copy)]
pub(super) enum Item {
    /// A block decided inside from above, with its lowest voxel.
    Leaf { leaf: Leaf, min: Voxel },
    Cell {
        code: u64,
        min: Voxel,
        k: u8,
        clip: bool,
    },
}

/// The work of a streaming build: leaves decided from above and cells to build, in
/// tesseral order (see the module docs).
#[derive(Debug, Clone)]
pub struct StreamPlan {
    pub(super) items: Vec<Item>,
    pub(super) range: Range<u64>,
    pub(super) cells: u64,
    depth: u8,
    origin: Voxel,
    pub(super) cell_log2: u8,
}

impl Csg {
    /// Plans the streaming build of the solid in the space of `2^depth` voxels per
    /// axis from `origin`, restricted to the codes `range`.
    ///
    /// # Runtime
    /// One classification per cell above the work cells that the surface may cross.
    ///
    /// # Errors
    /// [`CsgError::Octree`] for a bad space.
    pub fn stream_plan(
        &self,
        depth: u8,
        origin: Voxel,
        range: Range<u64>,
    ) -> Result<StreamPlan, CsgError> {
        self.stream_plan_cells(depth, origin, range, STREAM_CELL_LOG2)
    }

    /// As [`Csg::stream_plan`], with work cells of `2^cell_log2` voxels per axis
    /// (finer cells sample where the surface lies more finely).
    ///
    /// # Errors
    /// As [`Csg::stream_plan`].
    pub fn stream_plan_cells(
        &self,
        depth: u8,
        origin: Voxel,
        range: Range<u64>,
        cell_log2: u8,
    ) -> Result<StreamPlan, CsgError> {
        LinearOctree::empty(depth, origin)?;
        let mut plan = StreamPlan {
            items: Vec::new(),
            range,
            cells: 0,
            depth,
            origin,
            cell_log2,
        };
        self.plan_cell(0, origin, depth, &mut plan);
        Ok(plan)
    }

    fn plan_cell(&self, code: u64, min: Voxel, k: u8, plan: &mut StreamPlan) {
        let end = code + (1u64 << (3 * u32::from(k)));
        let (lo, hi) = (plan.range.start, plan.range.end);
        if end <= lo || code >= hi {
            return;
        }
        let contained = lo <= code && end <= hi;
        if k <= plan.cell_log2 {
            plan.items.push(Item::Cell {
                code,
                min,
                k,
                clip: !contained,
            });
            plan.cells += 1;
            return;
        }
        match self.classify_cell(min, k) {
            CellClass::Outside => {}
            CellClass::Inside if contained => plan.items.push(Item::Leaf {
                leaf: Leaf::new(code, k),
                min,
            }),
            _ => {
                let half = 1i64 << (k - 1);
                let child = 1u64 << (3 * u32::from(k - 1));
                for d in 0..8u64 {
                    let m = [
                        min[0] + half * (d & 1) as i64,
                        min[1] + half * ((d >> 1) & 1) as i64,
                        min[2] + half * ((d >> 2) & 1) as i64,
                    ];
                    self.plan_cell(code + d * child, m, k - 1, plan);
                }
            }
        }
    }

    /// Builds the solid's leaves in the codes `range` as one tree (the leaves of
    /// [`Csg::build`] clipped to the range), through the streaming plan.
    ///
    /// # Errors
    /// [`CsgError::Octree`] for a bad space.
    pub fn build_range(
        &self,
        depth: u8,
        origin: Voxel,
        range: Range<u64>,
    ) -> Result<LinearOctree, CsgError> {
        let plan = self.stream_plan(depth, origin, range)?;
        let mut leaves = Vec::new();
        plan.run::<std::convert::Infallible>(
            self,
            rayon::current_num_threads() * 2,
            &mut |ls| {
                for &l in ls {
                    push_merging(&mut leaves, l);
                }
                Ok(())
            },
            &mut |_| {},
        )
        .unwrap_or_else(|e| match e {});
        Ok(LinearOctree::from_parts(depth, origin, leaves))
    }
}

impl super::Scene {
    /// The same scene at another depth: the same cube of space, with voxels
    /// `2^(self.depth - depth)` times the size.
    ///
    /// # Errors
    /// [`super::SceneError::Build`] for a depth outside 1 to the scene limit (16).
    pub fn with_depth(mut self, depth: u8) -> Result<Self, super::SceneError> {
        let max = super::scene::MAX_SCENE_DEPTH;
        if depth == 0 || depth > max {
            return Err(super::SceneError::Build {
                path: self.path.clone(),
                source: CsgError::Octree(crate::linear::OctreeError::InvalidArgument(format!(
                    "depth {depth}: a scene's depth is 1 to {max}"
                ))),
            });
        }
        self.voxel *= 2f64.powi(i32::from(self.depth) - i32::from(depth));
        self.depth = depth;
        Ok(self)
    }

    /// The scene's solid in voxel coordinates and the plan of its streaming build
    /// over the codes `range` (all of them: `0..u64::MAX`).
    ///
    /// # Errors
    /// [`super::SceneError::Build`].
    pub fn stream_plan(&self, range: Range<u64>) -> Result<(Csg, StreamPlan), super::SceneError> {
        let csg = self.csg()?;
        let plan = csg
            .stream_plan(self.depth, [0, 0, 0], range)
            .map_err(|source| super::SceneError::Build {
                path: self.path.clone(),
                source,
            })?;
        Ok((csg, plan))
    }

    /// Estimates the leaves of the scene's build as [`super::Scene::estimate_leaves`]
    /// does (a build three levels coarser, times 4³), but streamed and counted, so
    /// that it holds no tree.
    ///
    /// # Errors
    /// [`super::SceneError::Build`].
    pub fn estimate_leaves_streamed(&self) -> Result<u64, super::SceneError> {
        const COARSER: u8 = 3;
        let wrap = |source| super::SceneError::Build {
            path: self.path.clone(),
            source,
        };
        let (csg, depth, factor) = if self.depth < 2 * COARSER {
            (self.csg()?, self.depth, 1)
        } else {
            let s = 1.0 / (self.voxel * f64::from(1u32 << COARSER));
            let to_coarse = super::Transform {
                scale: s,
                at: self.bounds_min.map(|b| -b * s),
                ..super::Transform::IDENTITY
            };
            let csg = self
                .solid
                .clone()
                .transform(to_coarse)
                .compile()
                .map_err(wrap)?;
            (csg, self.depth - COARSER, 64)
        };
        let plan = csg
            .stream_plan(depth, [0, 0, 0], 0..u64::MAX)
            .map_err(wrap)?;
        let mut n = 0u64;
        plan.run::<std::convert::Infallible>(
            &csg,
            rayon::current_num_threads() * 2,
            &mut |ls| {
                n += ls.len() as u64;
                Ok(())
            },
            &mut |_| {},
        )
        .unwrap_or_else(|e| match e {});
        Ok(n.saturating_mul(factor))
    }
}

impl StreamPlan {
    /// The window [`StreamPlan::run`] is best given: two cells per rayon thread.
    #[must_use]
    pub fn default_window() -> usize {
        rayon::current_num_threads() * 2
    }

    /// The depth of the plan's space.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The lowest voxel of the plan's space.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The code range the plan covers.
    #[must_use]
    pub fn range(&self) -> Range<u64> {
        self.range.clone()
    }

    /// The code ranges of the work cells, in order: a sample of where the surface
    /// lies, used to cut the space into balanced partitions.
    #[must_use]
    pub fn cell_ranges(&self) -> Vec<Range<u64>> {
        self.items
            .iter()
            .filter_map(|i| match *i {
                Item::Cell { code, k, .. } => Some(code..code + (1u64 << (3 * u32::from(k)))),
                Item::Leaf { .. } => None,
            })
            .collect()
    }

    /// The number of work cells.
    #[must_use]
    pub fn cell_count(&self) -> u64 {
        self.cells
    }

    /// Runs the plan: builds `window` cells at a time in parallel and hands each
    /// cell's leaves, and the leaves decided from above, to `sink` in tesseral order;
    /// calls `progress` after each window. The leaves are sorted and disjoint but
    /// not merged across cells (eight full cells may make a bigger block): the sink
    /// merges (as [`crate::io::TessWriter`] does).
    ///
    /// # Errors
    /// The first error of `sink`; the build stops there.
    pub fn run<E>(
        &self,
        csg: &Csg,
        window: usize,
        sink: &mut dyn FnMut(&[Leaf]) -> Result<(), E>,
        progress: &mut dyn FnMut(StreamProgress),
    ) -> Result<(), E> {
        self.run_coloured(csg, &[], window, &mut |ls, _| sink(ls), progress)
    }
}

/// Appends the parts of `leaf` inside `range`, as aligned blocks in order.
pub(crate) fn clip_leaf(leaf: Leaf, range: &Range<u64>, out: &mut Vec<Leaf>) {
    if leaf.end() <= range.start || leaf.code() >= range.end {
        return;
    }
    if range.start <= leaf.code() && leaf.end() <= range.end {
        out.push(leaf);
        return;
    }
    let k = leaf.size_log2() - 1; // a straddling leaf has more than one voxel
    let child = 1u64 << (3 * u32::from(k));
    for d in 0..8 {
        clip_leaf(Leaf::new(leaf.code() + d * child, k), range, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csg::Scene;
    use rand::{Rng, SeedableRng};
    use std::path::Path;

    const SCENE: &str = "depth 11\nbounds [0, 0, 0] [2048, 2048, 2048]\n\
        difference { sphere(r = 700) sphere(r = 300) } at [1024, 1024, 1024]\n\
        box(size = [1500, 1500, 100]) rotate [10, 20, 0] at [1024, 1024, 400]\n";

    /// The streamed leaves, merged, equal the in-memory build; every range's tree
    /// equals the whole tree clipped to it (tested against a voxel-set model on a
    /// small scene, and leaf lists on a big one).
    #[test]
    fn streamed_and_ranged_builds_equal_the_whole_build() {
        let scene = Scene::parse(SCENE, Path::new("s.tss")).unwrap();
        let csg = scene.csg().unwrap();
        let whole = scene.build().unwrap();
        let streamed = csg.build_range(11, [0, 0, 0], 0..1 << 33).unwrap();
        streamed.assert_valid();
        assert_eq!(streamed, whole);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(15);
        let end = 1u64 << 33;
        let mut cuts: Vec<u64> = (0..5).map(|_| rng.random_range(0..end)).collect();
        cuts.extend([0, end]);
        cuts.sort_unstable();
        let mut joined = Vec::new();
        for w in cuts.windows(2) {
            let part = csg.build_range(11, [0, 0, 0], w[0]..w[1]).unwrap();
            part.assert_valid();
            assert!(part
                .leaves()
                .iter()
                .all(|l| l.code() >= w[0] && l.end() <= w[1]));
            for &l in part.leaves() {
                push_merging(&mut joined, l);
            }
        }
        assert_eq!(joined, whole.leaves());
    }

    #[test]
    fn small_scenes_voxel_for_voxel() {
        use std::collections::HashSet;
        let scene = Scene::parse(
            "depth 5\nsphere(r = 11) at [16, 14, 15]\nbox(size = [30, 4, 4]) at [16, 3, 20]\n",
            Path::new("s.tss"),
        )
        .unwrap();
        let csg = scene.csg().unwrap();
        let whole: HashSet<_> = scene.build().unwrap().voxels().collect();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for _ in 0..30 {
            let a = rng.random_range(0..1u64 << 15);
            let b = rng.random_range(a..=1u64 << 15);
            let part = csg.build_range(5, [0, 0, 0], a..b).unwrap();
            part.assert_valid();
            let got: HashSet<_> = part.voxels().collect();
            let want: HashSet<_> = whole
                .iter()
                .copied()
                .filter(|&v| {
                    let c = part.code_of(v).unwrap();
                    a <= c && c < b
                })
                .collect();
            assert_eq!(got, want, "[{a}, {b})");
        }
    }

    #[test]
    fn progress_counts_every_cell() {
        let scene = Scene::parse(SCENE, Path::new("s.tss")).unwrap();
        let csg = scene.csg().unwrap();
        let plan = csg.stream_plan(11, [0, 0, 0], 0..1 << 33).unwrap();
        let mut last = StreamProgress::default();
        let mut n = 0u64;
        plan.run::<()>(
            &csg,
            3,
            &mut |ls| {
                n += ls.len() as u64;
                Ok(())
            },
            &mut |p| last = p,
        )
        .unwrap();
        assert_eq!(last.cells_done, plan.cell_count());
        assert_eq!(last.leaves, n);
        assert!(plan.cell_count() > 8);
        // A sink's error stops the run.
        let mut calls = 0;
        let r = plan.run(
            &csg,
            1,
            &mut |_| {
                calls += 1;
                if calls == 3 {
                    Err("stop")
                } else {
                    Ok(())
                }
            },
            &mut |_| {},
        );
        assert_eq!(r, Err("stop"));
        assert_eq!(calls, 3);
    }
}

//! Streaming builds with colours: each work cell's leaves and, for each colour, the
//! leaves of that colour among them (the colour's part, see [`super::colour_parts`],
//! built in the same cell and cut to the cell's leaves). So a streamed build writes
//! the colour layer that [`super::Scene::colour_layer`] builds in memory, voxel for
//! voxel, while holding one window of cells.

use rayon::prelude::*;

use super::stream::{clip_leaf, Item, StreamPlan, StreamProgress};
use super::Csg;
use crate::linear::{push_merging, CellClass, Leaf};

/// What [`StreamPlan::run_coloured`] hands its leaves to: an item's leaves and, per
/// colour, its leaves of that colour.
pub type ColouredSink<'a, E> = dyn FnMut(&[Leaf], &[Vec<Leaf>]) -> Result<(), E> + 'a;

/// One piece of work: a plan item, and whether it counts against the window (a cell
/// to build, or a block whose colours must be built).
#[derive(Clone, Copy)]
struct Work {
    item: Item,
    heavy: bool,
    plan_cell: bool,
}

impl StreamPlan {
    /// Runs the plan as [`StreamPlan::run`] does, and builds each of `colours` in the
    /// same cells: `sink` gets each item's leaves and, per colour, that colour's
    /// leaves among them (sorted, disjoint, merged within the item but not across
    /// items). A block decided inside from above that a colour's boundary crosses is
    /// cut into blocks of at most one work cell first, so no item holds more than a
    /// cell's leaves.
    ///
    /// # Errors
    /// The first error of `sink`; the build stops there.
    pub fn run_coloured<E>(
        &self,
        csg: &Csg,
        colours: &[Csg],
        window: usize,
        sink: &mut ColouredSink<'_, E>,
        progress: &mut dyn FnMut(StreamProgress),
    ) -> Result<(), E> {
        let window = window.max(1);
        let mut state = StreamProgress {
            cells_total: self.cells,
            ..StreamProgress::default()
        };
        let mut next = 0usize;
        // Sub-blocks of a split block, the next one last.
        let mut split: Vec<Item> = Vec::new();
        loop {
            let mut batch: Vec<Work> = Vec::new();
            let mut heavy = 0;
            while heavy < window {
                let item = if let Some(i) = split.pop() {
                    i
                } else if next < self.items.len() {
                    next += 1;
                    self.items[next - 1]
                } else {
                    break;
                };
                let work = match item {
                    Item::Cell { .. } => Work {
                        item,
                        heavy: true,
                        plan_cell: true,
                    },
                    Item::Leaf { leaf, min } => {
                        let k = leaf.size_log2();
                        let crossed = colours
                            .iter()
                            .any(|c| matches!(c.classify_cell(min, k), CellClass::Partial));
                        if crossed && k > self.cell_log2 {
                            push_children(leaf, min, &mut split);
                            continue;
                        }
                        Work {
                            item,
                            heavy: crossed,
                            plan_cell: false,
                        }
                    }
                };
                heavy += usize::from(work.heavy);
                batch.push(work);
            }
            if batch.is_empty() {
                return Ok(());
            }
            let built: Vec<(Vec<Leaf>, Vec<Vec<Leaf>>)> = batch
                .par_iter()
                .with_max_len(1)
                .map(|w| self.build_item(csg, colours, w.item))
                .collect();
            for (leaves, coloured) in built {
                state.leaves += leaves.len() as u64;
                sink(&leaves, &coloured)?;
            }
            state.cells_done += batch.iter().filter(|w| w.plan_cell).count() as u64;
            progress(state);
        }
    }

    /// The leaves of one item and, per colour, its leaves of that colour.
    fn build_item(&self, csg: &Csg, colours: &[Csg], item: Item) -> (Vec<Leaf>, Vec<Vec<Leaf>>) {
        match item {
            Item::Leaf { leaf, min } => {
                // The block is black throughout: a colour's leaves in it are all kept.
                let coloured = colours
                    .iter()
                    .map(|c| {
                        let mut out = Vec::new();
                        c.build_subtree(leaf.code(), min, leaf.size_log2(), &mut out);
                        out
                    })
                    .collect();
                (vec![leaf], coloured)
            }
            Item::Cell { code, min, k, clip } => {
                let build = |c: &Csg| {
                    let mut out = Vec::new();
                    c.build_subtree(code, min, k, &mut out);
                    if clip {
                        let mut kept = Vec::with_capacity(out.len());
                        for l in out {
                            clip_leaf(l, &self.range, &mut kept);
                        }
                        kept
                    } else {
                        out
                    }
                };
                let leaves = build(csg);
                let coloured = colours
                    .iter()
                    .map(|c| intersect_leaves(&build(c), &leaves))
                    .collect();
                (leaves, coloured)
            }
        }
    }
}

/// Pushes the eight children of `leaf` (lowest voxel `min`) so that the first is
/// popped first.
fn push_children(leaf: Leaf, min: crate::Voxel, out: &mut Vec<Item>) {
    let k = leaf.size_log2() - 1;
    let half = 1i64 << k;
    let child = 1u64 << (3 * u32::from(k));
    for d in (0..8u64).rev() {
        let m = [
            min[0] + half * (d & 1) as i64,
            min[1] + half * ((d >> 1) & 1) as i64,
            min[2] + half * ((d >> 2) & 1) as i64,
        ];
        out.push(Item::Leaf {
            leaf: Leaf::new(leaf.code() + d * child, k),
            min: m,
        });
    }
}

/// The voxels in both of two sorted lists of disjoint leaves, as merged leaves in
/// order. Two aligned blocks are nested or disjoint, so each overlap is the smaller.
pub(crate) fn intersect_leaves(a: &[Leaf], b: &[Leaf]) -> Vec<Leaf> {
    let (mut i, mut j) = (0, 0);
    let mut out = Vec::new();
    while i < a.len() && j < b.len() {
        let (x, y) = (a[i], b[j]);
        if x.code().max(y.code()) < x.end().min(y.end()) {
            push_merging(&mut out, if x.size_log2() <= y.size_log2() { x } else { y });
        }
        if x.end() <= y.end() {
            i += 1;
        } else {
            j += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csg::Scene;
    use std::collections::HashSet;
    use std::path::Path;

    /// A red ball set in a blue box (a colour boundary inside a block decided inside
    /// from above), a green ring crossing both: the streamed colours equal the
    /// in-memory colour layer voxel for voxel, on whole builds and code ranges.
    #[test]
    fn streamed_colours_equal_the_colour_layer() {
        let scene = Scene::parse(
            "depth 7\nbounds [0, 0, 0] [128, 128, 128]\n\
             box(size = 100) at [64, 64, 64] colour \"blue\"\n\
             sphere(r = 19) at [62, 69, 56] colour \"red\"\n\
             torus(major = 44, minor = 6) at [64, 64, 64] colour \"green\"\n\
             sphere(r = 6) at [12, 12, 12]\n",
            Path::new("c.tss"),
        )
        .unwrap();
        let tree = scene.build().unwrap();
        let layer = scene.colour_layer(&tree, usize::MAX).unwrap().unwrap();
        layer.assert_valid();
        let colours = scene.colour_csgs().unwrap();
        let csgs: Vec<Csg> = colours.iter().map(|(_, c)| c.clone()).collect();
        let csg = scene.csg().unwrap();
        let end = 1u64 << 21;
        // Work cells of 4 voxels: blocks decided inside from above hold the red
        // ball's boundary and must be cut.
        for range in [0..end, 12_345..end / 2 + 999] {
            let plan = csg
                .stream_plan_cells(7, [0, 0, 0], range.clone(), 2)
                .unwrap();
            let mut leaves = Vec::new();
            let mut by_colour = vec![Vec::new(); csgs.len()];
            plan.run_coloured::<()>(
                &csg,
                &csgs,
                3,
                &mut |ls, cs| {
                    for &l in ls {
                        push_merging(&mut leaves, l);
                    }
                    for (acc, c) in by_colour.iter_mut().zip(cs) {
                        for &l in c {
                            push_merging(acc, l);
                        }
                    }
                    Ok(())
                },
                &mut |_| {},
            )
            .unwrap();
            let in_range = |code: u64| range.contains(&code);
            let want: Vec<Leaf> = tree
                .leaves()
                .iter()
                .flat_map(|&l| {
                    let mut v = Vec::new();
                    clip_leaf(l, &range, &mut v);
                    v
                })
                .collect();
            let got_set: HashSet<u64> = leaves.iter().flat_map(|l| l.code()..l.end()).collect();
            let want_set: HashSet<u64> = want.iter().flat_map(|l| l.code()..l.end()).collect();
            assert_eq!(got_set.len(), want_set.len());
            assert!(got_set == want_set);
            for ((rgba, _), got) in colours.iter().zip(&by_colour) {
                let region = layer
                    .regions()
                    .iter()
                    .find(|(x, _)| x == rgba)
                    .map(|(_, t)| t.leaves().to_vec())
                    .unwrap_or_default();
                let want: HashSet<u64> = region
                    .iter()
                    .flat_map(|l| l.code()..l.end())
                    .filter(|&c| in_range(c))
                    .collect();
                let got_codes: HashSet<u64> = got.iter().flat_map(|l| l.code()..l.end()).collect();
                assert!(got_codes == want, "colour {rgba:?} in {range:?}");
                // Canonical: no eight siblings left unmerged.
                let t = crate::linear::LinearOctree::from_sorted_leaves(7, [0, 0, 0], got.clone())
                    .unwrap();
                t.assert_valid();
                assert_eq!(t.leaves(), &got[..]);
            }
        }
    }

    #[test]
    fn intersect_leaves_matches_a_set_model() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for _ in 0..200 {
            let mut sets = Vec::new();
            for _ in 0..2 {
                let voxels: Vec<[i64; 3]> = (0..rng.random_range(0..300))
                    .map(|_| [0; 3].map(|_: i64| rng.random_range(0..16)))
                    .collect();
                sets.push(crate::linear::LinearOctree::from_voxels(4, [0, 0, 0], voxels).unwrap());
            }
            let got = intersect_leaves(sets[0].leaves(), sets[1].leaves());
            let t =
                crate::linear::LinearOctree::from_sorted_leaves(4, [0, 0, 0], got.clone()).unwrap();
            t.assert_valid();
            assert_eq!(t.leaves(), &got[..]);
            let a: HashSet<_> = sets[0].voxels().collect();
            let want: HashSet<_> = sets[1].voxels().filter(|v| a.contains(v)).collect();
            assert_eq!(t.voxels().collect::<HashSet<_>>(), want);
        }
    }
}

//! The memory [`plan`](fn@super::plan) will need, estimated before it starts, so that
//! a huge region (`--margin 1000000`) is refused at once instead of growing for
//! minutes.

use super::plan::{plan_bounds, NoPath, PlanOptions};
use crate::linear::LinearOctree;
use crate::Voxel;

/// Bytes per free cell while planning: its leaf (8), its block in the cell list (32),
/// and the search's share of states, costs and links (about 88).
pub const PLAN_BYTES_PER_CELL: u64 = 128;

/// What [`estimate_plan`] foresees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanEstimate {
    /// Free cells: the leaves of the region's box, plus the cells that the
    /// configuration obstacles split off (estimated as 8 per obstacle leaf).
    pub free_cells: u64,
    /// Working memory in bytes, [`PLAN_BYTES_PER_CELL`] per free cell.
    pub bytes: u64,
}

/// Estimates the free cells and memory of [`plan`](fn@super::plan) with the same
/// arguments, without building anything. For an empty environment the cell count
/// is exact: it is the number of maximal blocks of the region's box.
///
/// # Runtime
/// O(depth) plus the bounding boxes of the two trees.
///
/// # Errors
/// The [`NoPath`] that `plan` would return for an empty object or an object larger
/// than the region.
///
/// # Example
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{estimate_plan, PlanOptions};
/// let env = LinearOctree::from_voxels(3, [0, 0, 0], [[4, 4, 4]]).unwrap();
/// let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
/// let small = estimate_plan(&env, &dot, [0, 0, 0], [7, 0, 0], &PlanOptions::default()).unwrap();
/// let wide = PlanOptions { margin: 1_000_000, ..PlanOptions::default() };
/// let huge = estimate_plan(&env, &dot, [0, 0, 0], [7, 0, 0], &wide).unwrap();
/// assert!(small.bytes < 1 << 20 && huge.bytes > 1 << 40);
/// ```
pub fn estimate_plan(
    environment: &LinearOctree,
    object: &LinearOctree,
    from: Voxel,
    to: Voxel,
    options: &PlanOptions,
) -> Result<PlanEstimate, NoPath> {
    let bounds = plan_bounds(environment, object, from, to, options)?;
    let extent = [0, 1, 2].map(|a| u128::from(bounds.max[a].abs_diff(bounds.min[a])) + 1);
    let obstacles = (environment.leaf_count() as u64).saturating_mul(8);
    let free_cells = box_leaves(extent).saturating_add(obstacles.saturating_mul(8));
    Ok(PlanEstimate {
        free_cells,
        bytes: free_cells.saturating_mul(PLAN_BYTES_PER_CELL),
    })
}

/// The maximal aligned blocks of the box `[0, e)` on each axis: with `F(k)` the
/// aligned blocks of side `2^k` inside the box (`Π ⌊e_a / 2^k⌋`), each full block
/// whose parent is full is not maximal, so there are `Σ_k F(k) − 8 F(k+1)`.
fn box_leaves(extent: [u128; 3]) -> u64 {
    let full = |k: u32| -> u128 {
        extent
            .iter()
            .map(|&e| e.checked_shr(k).unwrap_or(0))
            .fold(1u128, u128::saturating_mul)
    };
    let mut total = 0u128;
    for k in 0..128 {
        let here = full(k);
        if here == 0 {
            break;
        }
        total = total.saturating_add(here - 8 * full(k + 1).min(here / 8));
    }
    u64::try_from(total).unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::motion::plan;

    /// The formula against a direct count: the leaves of a tree built from the box's
    /// voxels.
    #[test]
    fn box_leaves_against_a_built_tree() {
        let seed = 0xb0c5;
        println!("seed {seed:#x}");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        for _ in 0..60 {
            let e = [0, 1, 2].map(|_| rng.random_range(1..=20i64));
            let voxels = (0..e[0])
                .flat_map(|x| (0..e[1]).flat_map(move |y| (0..e[2]).map(move |z| [x, y, z])));
            let tree = LinearOctree::from_voxels(5, [0, 0, 0], voxels).unwrap();
            assert_eq!(
                box_leaves(e.map(|c| c as u128)),
                tree.leaf_count() as u64,
                "{e:?}"
            );
        }
        assert_eq!(box_leaves([1 << 21; 3]), 1);
        assert_eq!(box_leaves([u128::MAX; 3]), u64::MAX);
    }

    /// With an empty environment, the estimate is exactly the free cells `plan`
    /// uses; with obstacles, it is not below them.
    #[test]
    fn estimate_against_plan() {
        let seed = 0x91a4;
        println!("seed {seed:#x}");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let dot = LinearOctree::from_voxels(1, [0, 0, 0], [[0, 0, 0], [1, 0, 0]]).unwrap();
        let mut compared = [0; 2];
        for case in 0..30 {
            let n = if case % 2 == 0 {
                0
            } else {
                rng.random_range(1..30)
            };
            let walls: Vec<Voxel> = (0..n)
                .map(|_| [0, 1, 2].map(|_| rng.random_range(3..12)))
                .collect();
            let env = LinearOctree::from_voxels(4, [0, 0, 0], walls).unwrap();
            let options = PlanOptions {
                margin: rng.random_range(0..6),
                ..PlanOptions::default()
            };
            let (from, to) = ([0, 0, 0], [14, 13, 12]);
            let Ok(p) = plan(&env, &dot, from, to, &options) else {
                continue;
            };
            let e = estimate_plan(&env, &dot, from, to, &options).unwrap();
            if n == 0 {
                assert_eq!(e.free_cells, p.free_cells as u64, "case {case}");
            } else {
                assert!(e.free_cells >= p.free_cells as u64, "case {case}");
            }
            assert_eq!(e.bytes, e.free_cells * PLAN_BYTES_PER_CELL);
            compared[usize::from(n > 0)] += 1;
        }
        assert!(compared[0] >= 10 && compared[1] >= 5, "{compared:?}");
    }
}

//! Exact enumeration of sphere-topology surfaces of small area, for the detailed
//! balance test of the chain.
//!
//! The surfaces are counted up to translation: `c[A]` is the number of finite voxel
//! sets, modulo translation, bounded by one sphere of area `A`. The enumerator lists
//! every fixed polycube (face-connected voxel set modulo translation) by adding one
//! voxel at a time, deduplicating normalized sets, and keeps those that pass
//! [`super::topology::check_sphere`]. It is independent of the chain's local rules.
//!
//! A set of `n` voxels has area at least `6·n^(2/3)` (Loomis–Whitney: `n² ≤
//! |Pₓ|·|P_y|·|P_z|` for the three projections, and the area is at least twice their
//! sum), so polycubes up to `n = ⌊(A_max/6)^(3/2)⌋` voxels cover every area up to
//! `A_max`.
//!
//! ```
//! let c = tesseral::rsmc::enumerate::sphere_counts(18).unwrap();
//! // One cube, 3 dominoes, 15 trominoes, 3 squares of four, 83 other tetracubes.
//! assert_eq!((c[6], c[10], c[14], c[16], c[18]), (1, 3, 15, 3, 83));
//! ```

use std::collections::HashSet;

use super::{topology, Direction, RsmcError};
use crate::Voxel;

/// The largest `A_max` accepted by [`sphere_counts`] (polycubes of up to 9 voxels,
/// about 1.3 million sets).
pub const MAX_ENUMERATED_AREA: u64 = 26;

type Cells = Vec<[i8; 3]>;

fn normalize(mut cells: Cells) -> Cells {
    let mut lo = [i8::MAX; 3];
    for c in &cells {
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
        }
    }
    for c in &mut cells {
        for a in 0..3 {
            c[a] -= lo[a];
        }
    }
    cells.sort_unstable();
    cells
}

/// Every fixed polycube with one voxel more than those of `level`, normalized.
fn grow_level(level: &[Cells]) -> Vec<Cells> {
    let mut next: HashSet<Cells> = HashSet::new();
    for cells in level {
        let set: HashSet<[i8; 3]> = cells.iter().copied().collect();
        for c in cells {
            for d in Direction::ALL.map(Direction::unit) {
                let q = [c[0] + d[0] as i8, c[1] + d[1] as i8, c[2] + d[2] as i8];
                if !set.contains(&q) {
                    let mut grown = cells.clone();
                    grown.push(q);
                    next.insert(normalize(grown));
                }
            }
        }
    }
    let mut out: Vec<Cells> = next.into_iter().collect();
    out.sort_unstable();
    out
}

/// The largest voxel count that can have area `max_area` or less.
#[must_use]
pub fn max_volume_for_area(max_area: u64) -> usize {
    let mut n = 1usize;
    while 6.0 * ((n + 1) as f64).powf(2.0 / 3.0) <= max_area as f64 + 1e-9 {
        n += 1;
    }
    n
}

/// Every voxel set bounded by one sphere with area at most `max_area`, one per
/// translation class (normalized so each axis starts at 0).
///
/// # Errors
/// [`RsmcError::TooLarge`] above [`MAX_ENUMERATED_AREA`].
pub fn sphere_surfaces(max_area: u64) -> Result<Vec<Vec<Voxel>>, RsmcError> {
    if max_area > MAX_ENUMERATED_AREA {
        return Err(RsmcError::TooLarge(format!(
            "enumeration up to area {max_area} (limit {MAX_ENUMERATED_AREA})"
        )));
    }
    let n_max = max_volume_for_area(max_area);
    let mut out = Vec::new();
    let mut level: Vec<Cells> = vec![vec![[0, 0, 0]]];
    for n in 1..=n_max {
        for cells in &level {
            let set: HashSet<[i8; 3]> = cells.iter().copied().collect();
            let mut adj = 0u64;
            for c in cells {
                for d in Direction::ALL.map(Direction::unit) {
                    if set.contains(&[c[0] + d[0] as i8, c[1] + d[1] as i8, c[2] + d[2] as i8]) {
                        adj += 1;
                    }
                }
            }
            let area = 6 * n as u64 - adj; // each adjacency hides two faces, counted twice
            if area <= max_area {
                let voxels: Vec<Voxel> = cells
                    .iter()
                    .map(|c| [i64::from(c[0]), i64::from(c[1]), i64::from(c[2])])
                    .collect();
                if topology::check_sphere(&voxels).is_ok() {
                    out.push(voxels);
                }
            }
        }
        if n == n_max {
            break;
        }
        level = grow_level(&level);
    }
    Ok(out)
}

/// `c[A]` for `A` in `0..=max_area`: the number of sphere-bounded voxel sets of area
/// `A`, up to translation.
///
/// # Errors
/// [`RsmcError::TooLarge`] above [`MAX_ENUMERATED_AREA`].
pub fn sphere_counts(max_area: u64) -> Result<Vec<u64>, RsmcError> {
    let mut c = vec![0u64; max_area as usize + 1];
    for s in sphere_surfaces(max_area)? {
        let set: HashSet<Voxel> = s.iter().copied().collect();
        let mut area = 0;
        for v in &s {
            for d in Direction::ALL {
                if !set.contains(&d.step(*v)) {
                    area += 1;
                }
            }
        }
        c[area] += 1;
    }
    Ok(c)
}

/// The exact stationary distribution of the area, `P(A) ∝ c[A]·exp(−βA)`.
#[must_use]
pub fn area_distribution(counts: &[u64], beta: f64) -> Vec<f64> {
    let a0 = counts.iter().position(|&c| c > 0).unwrap_or(0) as f64;
    let w: Vec<f64> = counts
        .iter()
        .enumerate()
        .map(|(a, &c)| c as f64 * (-beta * (a as f64 - a0)).exp())
        .collect();
    let z: f64 = w.iter().sum();
    w.iter().map(|x| x / z).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_polycube_counts_match_oeis_a001931() {
        let mut level: Vec<Cells> = vec![vec![[0, 0, 0]]];
        let mut sizes = vec![level.len()];
        for _ in 2..=6 {
            level = grow_level(&level);
            sizes.push(level.len());
        }
        assert_eq!(sizes, vec![1, 3, 15, 86, 534, 3481]);
    }

    #[test]
    fn polycube_totals_match_known_counts() {
        // Fixed polycubes (OEIS A001931): 1, 3, 15, 86, 534, 3481.
        let all = sphere_surfaces(22).unwrap();
        let mut by_n = [0usize; 8];
        for s in &all {
            by_n[s.len()] += 1;
        }
        // Every polycube of up to 4 voxels is a ball.
        assert_eq!(&by_n[1..5], &[1, 3, 15, 86]);
        // Known: c[20] and c[22] include five- and six-voxel sets; some six-voxel sets
        // of area 22 are not balls (two voxels sharing only an edge).
        let c = sphere_counts(22).unwrap();
        assert_eq!(c.iter().sum::<u64>() as usize, all.len());
        assert!(c[22] > 0 && c[20] > 0);
    }

    #[test]
    fn non_ball_polycubes_are_excluded() {
        // The five-voxel set with an edge-only contact has area 22 and is not counted.
        let bad = vec![[0, 0, 0], [0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 1, 0]];
        assert!(topology::check_sphere(&bad).is_err());
        let all = sphere_surfaces(22).unwrap();
        let mut b = bad.clone();
        b.sort_unstable();
        assert!(!all.iter().any(|s| {
            let mut s = s.clone();
            s.sort_unstable();
            s == b
        }));
    }

    #[test]
    #[ignore = "prints the table for docs/rsmc.md"]
    fn print_counts() {
        let c = sphere_counts(24).unwrap();
        for (a, n) in c.iter().enumerate() {
            if *n > 0 {
                println!("c[{a}] = {n}");
            }
        }
    }

    #[test]
    fn limit_is_enforced() {
        assert!(matches!(sphere_counts(100), Err(RsmcError::TooLarge(_))));
    }
}

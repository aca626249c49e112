//! The occupancy map against a naive model: a `HashMap` from cell to log-odds whose
//! rays are found by a brute-force segment–box test over each ray's bounding box
//! (not the DDA).

use std::collections::{HashMap, HashSet};

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::dda::walk;
use super::sensor::Fixed;
use super::*;

pub(super) type Cell = [i64; 3];

/// Whether the segment `o → e` meets the box `[lo, lo + s)` (half-open) or, with
/// `closed`, `[lo, lo + s]`. Bounds on the segment parameter `t` are compared as
/// fractions by cross-multiplication, so on dyadic inputs (multiples of 1/64 here)
/// the test is exact.
fn meets(o: [f64; 3], e: [f64; 3], lo: [f64; 3], s: f64, closed: bool) -> bool {
    // Bounds as (numerator, denominator > 0, inclusive).
    let mut lower = (0.0, 1.0, true);
    let mut upper = (1.0, 1.0, true);
    let tighter_lower = |a: (f64, f64, bool), b: (f64, f64, bool)| {
        let (x, y) = (a.0 * b.1, b.0 * a.1);
        if x > y || (x == y && !a.2) {
            a
        } else {
            b
        }
    };
    let tighter_upper = |a: (f64, f64, bool), b: (f64, f64, bool)| {
        let (x, y) = (a.0 * b.1, b.0 * a.1);
        if x < y || (x == y && !a.2) {
            a
        } else {
            b
        }
    };
    for a in 0..3 {
        let d = e[a] - o[a];
        let (l, h) = (lo[a], lo[a] + s);
        if d == 0.0 {
            if !(l <= o[a] && (o[a] < h || (closed && o[a] == h))) {
                return false;
            }
        } else if d > 0.0 {
            lower = tighter_lower(lower, (l - o[a], d, true));
            upper = tighter_upper(upper, (h - o[a], d, closed));
        } else {
            upper = tighter_upper(upper, (o[a] - l, -d, true));
            lower = tighter_lower(lower, (o[a] - h, -d, closed));
        }
    }
    let (x, y) = (lower.0 * upper.1, upper.0 * lower.1);
    x < y || (x == y && lower.2 && upper.2)
}

fn key(p: [f64; 3], res: f64) -> Cell {
    let inv = 1.0 / res;
    p.map(|c| (c * inv).floor() as i64)
}

/// The cells of `o → e` other than `e`'s: half-open (what an exact DDA visits) and
/// closed (what a DDA may visit when the segment runs through an edge or corner).
fn naive_ray(o: [f64; 3], e: [f64; 3], res: f64) -> (HashSet<Cell>, HashSet<Cell>) {
    let (ko, ke) = (key(o, res), key(e, res));
    let (mut open, mut closed) = (HashSet::new(), HashSet::new());
    if ko == ke {
        return (open, closed);
    }
    let lo: [i64; 3] = std::array::from_fn(|a| ko[a].min(ke[a]) - 1);
    let hi: [i64; 3] = std::array::from_fn(|a| ko[a].max(ke[a]) + 1);
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                let c = [x, y, z];
                if c == ke {
                    continue;
                }
                let corner = c.map(|k| k as f64 * res);
                if meets(o, e, corner, res, false) {
                    open.insert(c);
                }
                if meets(o, e, corner, res, true) {
                    closed.insert(c);
                }
            }
        }
    }
    (open, closed)
}

fn dda(o: [f64; 3], e: [f64; 3], res: f64) -> Vec<Cell> {
    let mut out = Vec::new();
    walk(o, e, key(o, res), key(e, res), res, |c| out.push(c));
    out
}

/// The naive map: cell → fixed-point log-odds, updated with OctoMap's rules written
/// out with plain integers.
pub(super) struct Naive {
    pub(super) cells: HashMap<Cell, i32>,
    pub(super) f: Fixed,
    pub(super) res: f64,
}

impl Naive {
    pub(super) fn scan(
        &mut self,
        origin: [f64; 3],
        points: &[[f64; 3]],
        max_range: Option<f64>,
    ) -> ScanStats {
        let mut hits = HashSet::new();
        let mut misses = HashSet::new();
        let mut skipped = 0;
        for p in points {
            if !p.iter().all(|c| c.is_finite()) {
                skipped += 1;
                continue;
            }
            let d = [0, 1, 2].map(|i| p[i] - origin[i]);
            let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            match max_range {
                Some(r) if norm > r => {
                    let end = [0, 1, 2].map(|i| origin[i] + d[i] / norm * r);
                    misses.extend(naive_ray(origin, end, self.res).0);
                }
                _ => {
                    misses.extend(naive_ray(origin, *p, self.res).0);
                    hits.insert(key(*p, self.res));
                }
            }
        }
        let (lo, hi) = (i32::from(self.f.min), i32::from(self.f.max));
        // Blocks whose 512 cells were all at the lower clamp: misses not counted.
        let clamped = |c: &Cell| {
            let b = c.map(|k| k >> 3);
            (0..512).all(|i: i64| {
                let cell = [
                    b[0] << 3 | i & 7,
                    b[1] << 3 | i >> 3 & 7,
                    b[2] << 3 | i >> 6,
                ];
                self.cells.get(&cell) == Some(&lo)
            })
        };
        let counted = misses
            .iter()
            .filter(|c| !hits.contains(*c) && !clamped(c))
            .count() as u64;
        for c in &misses {
            if !hits.contains(c) {
                let v = self.cells.entry(*c).or_insert(0);
                *v = (*v + i32::from(self.f.miss)).clamp(lo, hi);
            }
        }
        for c in &hits {
            let v = self.cells.entry(*c).or_insert(0);
            *v = (*v + i32::from(self.f.hit)).clamp(lo, hi);
        }
        ScanStats {
            points: points.len() as u64,
            rays: (points.len() - skipped) as u64,
            skipped: skipped as u64,
            hits: hits.len() as u64,
            misses: counted,
        }
    }
}

pub(super) fn check_same(map: &OccupancyMap, naive: &Naive) {
    let got: HashMap<Cell, i32> = {
        let mut m = HashMap::new();
        map.store.for_each(|c, v| {
            m.insert(c, i32::from(v));
        });
        m
    };
    assert_eq!(got.len(), naive.cells.len(), "known cell counts differ");
    for (c, v) in &naive.cells {
        assert_eq!(got.get(c), Some(v), "cell {c:?}");
        let want = if *v >= i32::from(naive.f.threshold) {
            CellState::Occupied
        } else {
            CellState::Free
        };
        assert_eq!(map.state(*c), want);
    }
    let occ = naive
        .cells
        .values()
        .filter(|&&v| v >= i32::from(naive.f.threshold))
        .count() as u64;
    assert_eq!(map.occupied_count(), occ);
    assert_eq!(map.free_count(), naive.cells.len() as u64 - occ);
}

/// A coordinate: generic, or (with `snap`) exactly on a cell face. Only a
/// power-of-two resolution has faces that `floor(p / res)` and `k × res` agree on
/// exactly, so other resolutions get generic coordinates.
fn coord(rng: &mut Pcg64, span: f64, res: f64, snap: bool) -> f64 {
    if snap && res.log2().fract() == 0.0 {
        (rng.random_range(-span..span) / res).round() * res
    } else {
        rng.random_range(-span..span)
    }
}

#[test]
fn scans_match_the_naive_model() {
    for seed in 0..12u64 {
        let mut rng = Pcg64::seed_from_u64(seed);
        let res = [0.25, 0.1, 0.125, 0.05][seed as usize % 4];
        let sensor = SensorModel::octomap();
        let mut map = OccupancyMap::new(res, sensor).unwrap();
        let mut naive = Naive {
            cells: HashMap::new(),
            f: map.fixed,
            res,
        };
        let span = 2.0;
        for scan in 0..25 {
            let origin = [0, 1, 2].map(|_| coord(&mut rng, span / 2.0, res, false));
            let n = rng.random_range(0..300);
            let mut points = Vec::with_capacity(n);
            for _ in 0..n {
                let kind = rng.random_range(0..10);
                let mut p = [0, 1, 2].map(|_| coord(&mut rng, span, res, false));
                match kind {
                    // One coordinate exactly on a cell face.
                    0 | 1 => {
                        let a = rng.random_range(0..3);
                        p[a] = coord(&mut rng, span, res, true);
                    }
                    // Along an axis.
                    2 => {
                        let a = rng.random_range(0..3);
                        for b in 0..3 {
                            if b != a {
                                p[b] = origin[b];
                            }
                        }
                    }
                    // Along an axis, ending on a face.
                    3 => {
                        let a = rng.random_range(0..3);
                        p = origin;
                        p[a] = coord(&mut rng, span, res, true);
                    }
                    // Zero length.
                    4 => p = origin,
                    // Not finite.
                    5 if rng.random_range(0..4) == 0 => {
                        p[rng.random_range(0..3)] =
                            [f64::NAN, f64::INFINITY, -f64::INFINITY][rng.random_range(0..3)];
                    }
                    _ => {}
                }
                points.push(p);
            }
            let max_range = match scan % 3 {
                0 => None,
                1 => Some(rng.random_range(0.0..span)),
                _ => Some(rng.random_range(0.5..3.0 * span)),
            };
            for p in &points {
                if p.iter().all(|c| c.is_finite()) && max_range.is_none() {
                    let want = naive_ray(origin, *p, res).0;
                    let got: HashSet<Cell> = dda(origin, *p, res).into_iter().collect();
                    assert_eq!(got, want, "seed {seed} scan {scan}: {origin:?} -> {p:?}");
                }
            }
            let got = map.insert_scan(origin, &points, max_range);
            let want = naive.scan(origin, &points, max_range);
            assert_eq!(got, want, "seed {seed} scan {scan}: stats");
            map.assert_valid();
            check_same(&map, &naive);
        }
    }
}

#[test]
fn rays_through_edges_and_corners_are_those_of_the_segment() {
    // Dyadic coordinates (multiples of 1/64, cells of 1/4): the segment–box test is
    // exact. A ray through an edge or corner may visit a cell the segment only
    // touches (OctoMap's DDA breaks the tie by axis order); otherwise the cells are
    // exactly those the half-open boxes meet.
    let res = 0.25;
    let mut rng = Pcg64::seed_from_u64(7);
    let mut ties = 0;
    for _ in 0..20_000 {
        let grid = |rng: &mut Pcg64| -> f64 {
            let step = if rng.random_bool(0.5) { 64.0 } else { 4.0 };
            let step = step * if step == 4.0 { 16.0 } else { 1.0 };
            f64::from(rng.random_range(-256i32..256)) / step
        };
        let o = [0, 1, 2].map(|_| grid(&mut rng));
        let e = [0, 1, 2].map(|_| grid(&mut rng));
        let got = dda(o, e, res);
        let set: HashSet<Cell> = got.iter().copied().collect();
        assert_eq!(set.len(), got.len(), "a cell visited twice: {o:?} -> {e:?}");
        let (open, closed) = naive_ray(o, e, res);
        // A tie sends the walk to either side of the edge; it stays on cells the
        // segment touches.
        assert!(
            set.is_subset(&closed),
            "{o:?} -> {e:?}: extra {:?}",
            set.difference(&closed).collect::<Vec<_>>()
        );
        if open == closed {
            assert_eq!(set, open, "{o:?} -> {e:?}");
        } else {
            ties += 1;
        }
        if let Some(last) = got.last() {
            let ke = key(e, res);
            let d: i64 = (0..3).map(|a| (last[a] - ke[a]).abs()).sum();
            if open == closed {
                assert_eq!(d, 1, "{o:?} -> {e:?}: the walk ends beside the end cell");
            } else {
                assert!(
                    (1..=3).contains(&d),
                    "{o:?} -> {e:?}: the walk ends near the end cell"
                );
            }
            assert_eq!(got[0], key(o, res));
        }
        for w in got.windows(2) {
            let d: i64 = (0..3).map(|a| (w[0][a] - w[1][a]).abs()).sum();
            assert_eq!(d, 1, "{o:?} -> {e:?}: cells not face-adjacent");
        }
    }
    assert!(ties > 100, "the edge cases were exercised ({ties})");
}

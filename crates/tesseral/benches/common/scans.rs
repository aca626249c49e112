//! The synthetic scans of the occupancy benchmarks (fixed seeds), shared by the
//! criterion bench `occupancy` and the example `occupancy_peer`:
//! - indoor: a 12 × 9 × 3 m room with boxes, sensor inside, ranges to 10 m;
//! - outdoor: ground, buildings and poles over 200 m, ranges to 80 m (cut at 50 m by
//!   the benchmarks' maximum range, so longer rays clear space only).

use super::SplitMix64;

#[derive(Clone)]
pub struct Scan {
    pub origin: [f64; 3],
    pub points: Vec<[f64; 3]>,
}

fn unit(r: &mut SplitMix64) -> f64 {
    (r.next() >> 11) as f64 / (1u64 << 53) as f64
}

/// Distance along `o + t·d` to an axis-aligned box, if hit from outside.
fn hit_box(o: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        let inv = 1.0 / d[a];
        let (mut u, mut v) = ((lo[a] - o[a]) * inv, (hi[a] - o[a]) * inv);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
    }
    (t0 <= t1 && t0 > 0.0).then_some(t0)
}

/// Distance to leave the inside of a box.
fn exit_box(o: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> f64 {
    (0..3)
        .map(|a| {
            if d[a] > 0.0 {
                (hi[a] - o[a]) / d[a]
            } else if d[a] < 0.0 {
                (lo[a] - o[a]) / d[a]
            } else {
                f64::INFINITY
            }
        })
        .fold(f64::INFINITY, f64::min)
}

fn direction(r: &mut SplitMix64) -> [f64; 3] {
    loop {
        let d = [0, 1, 2].map(|_| 2.0 * unit(r) - 1.0);
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if n > 0.1 && n <= 1.0 {
            return d.map(|c| c / n);
        }
    }
}

pub fn scans(outdoor: bool, count: usize, rays: usize) -> Vec<Scan> {
    let mut r = SplitMix64(if outdoor { 0x0D00 } else { 0x1D00 });
    let (lo, hi) = if outdoor {
        ([-100.0, -100.0, 0.0], [100.0, 100.0, 1000.0])
    } else {
        ([0.0, 0.0, 0.0], [12.0, 9.0, 3.0])
    };
    let boxes: Vec<([f64; 3], [f64; 3])> = (0..if outdoor { 60 } else { 12 })
        .map(|_| {
            let c = [0, 1].map(|a| lo[a] + unit(&mut r) * (hi[a] - lo[a]));
            let s = if outdoor {
                [
                    2.0 + 15.0 * unit(&mut r),
                    2.0 + 15.0 * unit(&mut r),
                    3.0 + 25.0 * unit(&mut r),
                ]
            } else {
                [
                    0.3 + unit(&mut r),
                    0.3 + unit(&mut r),
                    0.4 + 1.2 * unit(&mut r),
                ]
            };
            ([c[0], c[1], 0.0], [c[0] + s[0], c[1] + s[1], s[2]])
        })
        .collect();
    (0..count)
        .map(|i| {
            let t = i as f64 / count.max(1) as f64;
            let origin = if outdoor {
                [-60.0 + 120.0 * t, 20.0 * (6.0 * t).sin(), 1.8]
            } else {
                [1.0 + 10.0 * t, 4.5 + 3.0 * (6.0 * t).sin(), 1.2]
            };
            let points = (0..rays)
                .map(|_| {
                    let d = direction(&mut r);
                    let mut t = exit_box(origin, d, lo, hi);
                    for (a, b) in &boxes {
                        if let Some(u) = hit_box(origin, d, *a, *b) {
                            t = t.min(u);
                        }
                    }
                    // Outdoors the sky returns nothing: cap at 80 m (cut at 50 m).
                    let t = t.min(if outdoor { 80.0 } else { 10.0 });
                    [0, 1, 2].map(|a| origin[a] + d[a] * t)
                })
                .collect();
            Scan { origin, points }
        })
        .collect()
}

use std::time::Instant;
use tesseral::linear::{CellClass, LinearOctree, SetOp};
use tesseral::Voxel;
fn ball(c: [f64; 3], r: f64) -> impl Fn(Voxel, u8) -> CellClass + Sync {
    move |min: Voxel, k: u8| {
        let s = (1i64 << k) as f64;
        let (mut near, mut far) = (0.0, 0.0);
        for a in 0..3 {
            let lo = min[a] as f64 + 0.5 - c[a];
            let hi = min[a] as f64 + s - 0.5 - c[a];
            let n = if lo > 0.0 {
                lo
            } else if hi < 0.0 {
                -hi
            } else {
                0.0
            };
            near += n * n;
            far += lo.abs().max(hi.abs()).powi(2);
        }
        if far <= r * r {
            CellClass::Inside
        } else if near > r * r {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    }
}
fn cpu() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap();
    let f: Vec<&str> = s.rsplit(')').next().unwrap().split_whitespace().collect();
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}
fn time<T>(name: &str, n: usize, mut f: impl FnMut() -> T) {
    let mut best = f64::MAX;
    let c0 = cpu();
    let w0 = Instant::now();
    let mut iters = 0;
    while w0.elapsed().as_secs_f64() < 2.0 || iters < n {
        let t = Instant::now();
        std::hint::black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
        iters += 1;
    }
    let c = (cpu() - c0) / iters as f64;
    println!(
        "{name:40} best wall {:.3} ms   cpu/iter {:.3} ms  ({iters} iters)",
        best * 1e3,
        c * 1e3
    );
}
fn main() {
    let a =
        LinearOctree::from_classifier(8, [0, 0, 0], &ball([128.0, 128.0, 128.0], 100.0)).unwrap();
    let b =
        LinearOctree::from_classifier(8, [0, 0, 0], &ball([178.0, 128.0, 128.0], 100.0)).unwrap();
    let what = std::env::args().nth(1).unwrap_or_default();
    let n: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0);
    if n > 0 {
        let t = std::time::Instant::now();
        for _ in 0..n {
            match what.as_str() {
                "none" => {}
                "union" => {
                    std::hint::black_box(a.set_op(&b, SetOp::Union).unwrap());
                }
                "inter" => {
                    std::hint::black_box(a.set_op(&b, SetOp::Intersection).unwrap());
                }
                "diff" => {
                    std::hint::black_box(a.set_op(&b, SetOp::Difference).unwrap());
                }
                "xor" => {
                    std::hint::black_box(a.set_op(&b, SetOp::SymmetricDifference).unwrap());
                }
                "t50" => {
                    std::hint::black_box(a.translate([50, 0, 0]).unwrap());
                }
                "t37" => {
                    std::hint::black_box(a.translate([37, -11, 5]).unwrap());
                }
                "t64" => {
                    std::hint::black_box(a.translate([64, 0, 0]).unwrap());
                }
                "p50" => {
                    let mut p = tesseral::pointer::PointerOctree::from_linear(&a);
                    std::hint::black_box(p.translate([50, 0, 0]).unwrap());
                }
                "p37" => {
                    let mut p = tesseral::pointer::PointerOctree::from_linear(&a);
                    let s = p.translate([37, -11, 5]).unwrap();
                    eprintln!("{s:?} nodes {}", p.node_count());
                }
                "p64" => {
                    let mut p = tesseral::pointer::PointerOctree::from_linear(&a);
                    std::hint::black_box(p.translate([64, 0, 0]).unwrap());
                }
                "pconv" => {
                    let p = tesseral::pointer::PointerOctree::from_linear(&a);
                    std::hint::black_box(p);
                }
                _ => panic!(),
            }
        }
        eprintln!("wall {:?}", t.elapsed());
        return;
    }
    if what.is_empty() || what == "ops" {
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            time(&format!("{op:?}"), 50, || a.set_op(&b, op).unwrap());
        }
        time("complement", 50, || a.complement());
    }
    if what == "tr64" {
        time("t64", 100, || a.translate([64, 0, 0]).unwrap());
    }
    if what == "tr37" {
        time("t37", 100, || a.translate([37, -11, 5]).unwrap());
    }
    if what.is_empty() || what == "tr" {
        for by in [[50, 0, 0], [37, -11, 5], [64, 0, 0], [1, 0, 0]] {
            time(&format!("translate {by:?}"), 20, || {
                a.translate(by).unwrap()
            });
        }
    }
}

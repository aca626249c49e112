//! Builds a solid sphere N times: `spherestat R DEPTH N` (for profiling the builder).
use std::time::Instant;
use tesseral::csg::{Shape, Solid};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let (r, d, n): (f64, u8, usize) = (
        a[0].parse().unwrap(),
        a[1].parse().unwrap(),
        a[2].parse().unwrap(),
    );
    let c = f64::from(1u32 << d) / 2.0;
    let csg = Solid::shape(Shape::sphere(r))
        .at([c, c, c])
        .compile()
        .unwrap();
    for _ in 0..n {
        let t = Instant::now();
        let tree = csg.build(d, [0, 0, 0]).unwrap();
        println!("{} leaves in {:?}", tree.leaf_count(), t.elapsed());
    }
}

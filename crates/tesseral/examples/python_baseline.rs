//! The Rust side of `benches/python/bench.py`: the same work as the Python calls, on
//! the same voxels (raw little-endian i64 triples in the files it is given), best of
//! 5. Prints one `name ms` line per measure.
//!
//! `cargo run --release -p tesseral --example python_baseline -- DYNAMIC.bin SOLID.bin`

use std::time::Instant;

use tesseral::dynamic::DynamicOctree;
use tesseral::linear::LinearOctree;
use tesseral::Voxel;

fn read(path: &str) -> Vec<Voxel> {
    let bytes = std::fs::read(path).expect("voxel file");
    bytes
        .chunks_exact(24)
        .map(|c| {
            std::array::from_fn(|a| i64::from_le_bytes(c[8 * a..8 * a + 8].try_into().unwrap()))
        })
        .collect()
}

fn best<T>(mut f: impl FnMut() -> T) -> f64 {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::MAX, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (dynamic, solid) = (read(&args[1]), read(&args[2]));
    let ms = best(|| {
        let mut t = DynamicOctree::with_faces();
        for &v in &dynamic {
            t.insert(v);
        }
        t
    });
    println!("dynamic_insert {ms:.2}");
    let ms = best(|| LinearOctree::from_voxels_fitted(&solid).unwrap());
    println!("from_voxels {ms:.2}");
    let tree = LinearOctree::from_voxels_fitted(&solid).unwrap();
    // The call `Octree.voxels()` makes (table-driven, parallel), into a fresh vector.
    let ms = best(|| {
        let mut v: Vec<Voxel> = Vec::new();
        tree.voxels_into(&mut v);
        v
    });
    println!("voxels {ms:.2}");
    let other = tree.translate([7, 3, 1]).unwrap();
    let ms = best(|| tree.union(&other).unwrap());
    println!("union {ms:.2}");
}

//! Builds a scene file and prints its size and build time: `scenestat FILE.tss`.
use std::time::Instant;
use tesseral::csg::Scene;
fn main() {
    let path = std::env::args().nth(1).expect("usage: scenestat FILE.tss");
    let scene = Scene::read(path.as_ref()).unwrap_or_else(|e| panic!("{e}"));
    let csg = scene.csg().unwrap();
    for _ in 0..3 {
        let t = Instant::now();
        let tree = csg.build(scene.depth, [0, 0, 0]).unwrap();
        println!(
            "depth {} primitives {} leaves {} voxels {} in {:?}",
            scene.depth,
            csg.primitive_count(),
            tree.leaf_count(),
            tree.voxel_count(),
            t.elapsed()
        );
    }
}

use std::time::Instant;
use tesseral::csg::Scene;
use tesseral::render::*;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let scene = Scene::read(path.as_ref()).unwrap();
    let tree = scene.build().unwrap();
    let rt = RayTree::new(&tree);
    println!("leaves {} gray {}", tree.leaf_count(), rt.gray_nodes());
    let opts = RenderOptions {
        width: 1024,
        height: 1024,
        ..Default::default()
    };
    let n: usize = std::env::var("N").map_or(3, |v| v.parse().unwrap());
    for _ in 0..n {
        let t = Instant::now();
        let h = primary_hits(&rt, &opts);
        let e = t.elapsed();
        println!(
            "hits {h} in {e:?}: {:.2} Mrays/s ",
            1.048576 / e.as_secs_f64()
        );
    }
}

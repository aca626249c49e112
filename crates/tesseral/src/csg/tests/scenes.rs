//! The scene format: every construct, the voxel space, hostile input, typo hints and
//! seeded mutations.

use super::*;

#[test]
fn scene_with_every_construct_builds_as_the_api_does() {
    let src = r##"
# every construct
depth 5
bounds [0, 0, 0] [32, 32, 32]
let r = 6          # a named parameter
let c = [16, 16, 16]
difference {
  box(size = 20)
  sphere(r = r + 1) at c - [16, 16, 16]
} at c colour "steel"
union {
  cylinder(r = [2, 3], h = 10) rotate [90, 0, 0]
  cone(r1 = 3, r2 = 1, h = 6) at [0, 0, 8]
} scale 0.5 rotate [0, 0, 45] at [8, 8, 8] colour [255, 0, 0]
intersection { torus(major = 5, minor = 2) halfspace(normal = [0, 0, 1], offset = 0.5) } at [24, 24, 24]
not { capsule(r = 100, h = 1) } colour "#00ff00"
polyhedron(planes = [[1,0,0,2],[-1,0,0,2],[0,1,0,2],[0,-1,0,2],[0,0,1,2],[0,0,-1,2]]) at [4, 28, 4]
ellipsoid(r = [4, 2, 3]) at [28, 4, 28]
prism(size = [2, 3, 4]) at [28, 28, 4]
spheroid(r = 3) at [4, 4, 28]
"##;
    let scene = parse(src).unwrap();
    assert_eq!((scene.depth, scene.objects), (5, 8));
    assert_eq!(scene.voxel, 1.0);
    let csg = scene.csg().unwrap();
    let tree = check_exact(&csg, 5, [0, 0, 0], "every construct");
    // The first object by the API.
    let api = Solid::shape(Shape::cuboid([20.0; 3]))
        .difference([Solid::shape(Shape::sphere(7.0))])
        .at([16.0; 3])
        .compile()
        .unwrap();
    assert!(tree.contains([16, 16, 6]) == api.contains([16.5, 16.5, 6.5]));
    assert!(!tree.contains([16, 16, 16]));
    assert_eq!(csg.colour_at([7.0, 16.0, 16.0]), Colour::parse("steel"));
}

#[test]
fn scene_space_from_voxel_size_and_bounding_box() {
    let s = parse("voxel 0.5\nsphere(r = 4) at [10, 0, 0]").unwrap();
    assert_eq!(s.depth, 4);
    assert_eq!(s.bounds_min, [6.0, -4.0, -4.0]);
    let t = s.build().unwrap();
    assert!(t.contains([8, 8, 8]));
    let s = parse("depth 3\nbox(size = [8, 4, 2])").unwrap();
    assert_eq!(s.voxel, 1.0);
}
#[test]
fn hostile_scenes_are_refused() {
    let deep = format!(
        "depth 6\n{}sphere(r = 1){}",
        "union { ".repeat(100),
        " }".repeat(100)
    );
    let e = parse(&deep).unwrap_err();
    assert!(e.to_string().contains("nesting deeper"), "{e}");
    let brackets = format!(
        "depth 6\nlet a = {}1{}\nsphere(r = 1)",
        "(".repeat(100),
        ")".repeat(100)
    );
    assert!(parse(&brackets)
        .unwrap_err()
        .to_string()
        .contains("nesting deeper"));
    let many = format!(
        "depth 6\n{}",
        "sphere(r = 1)\n".repeat(MAX_PRIMITIVES_TEST + 1)
    );
    assert!(parse(&many).unwrap_err().to_string().contains("primitives"));
    let long = format!("depth 6\nlet a = [{}]\nsphere(r = 1)", "1, ".repeat(5000));
    assert!(parse(&long).unwrap_err().to_string().contains("4096"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.tss");
    std::fs::write(&p, b"depth 6\nsphere(r = 1) \xff\n").unwrap();
    let e = Scene::read(&p).unwrap_err();
    assert!(
        e.to_string().contains(":2:15: the file is not valid UTF-8"),
        "{e}"
    );
    assert!(matches!(
        Scene::read(&dir.path().join("missing.tss")),
        Err(SceneError::Io { .. })
    ));
}

const MAX_PRIMITIVES_TEST: usize = scene::MAX_PRIMITIVES;

#[test]
fn closest_names() {
    assert_eq!(
        scene::closest("spere", scene::SHAPES.iter().copied()),
        Some("sphere")
    );
    assert_eq!(scene::closest("xyzzy", scene::SHAPES.iter().copied()), None);
    assert_eq!(
        scene::closest("Box", scene::SHAPES.iter().copied()),
        Some("box")
    );
}

/// Seeded mutations of the shipped scenes: the parser answers every one with a scene
/// or a located error, never a panic, and the location lies inside the text.
#[test]
fn mutated_scenes_never_panic() {
    let sources = [
        include_str!("../../../../../scenes/tank.tss"),
        include_str!("../../../../../scenes/truck.tss"),
        include_str!("../../../../../scenes/aircraft.tss"),
        include_str!("../../../../../scenes/showcase.tss"),
        include_str!("../../../../../scenes/fig4a-cone.tss"),
    ];
    let alphabet: Vec<char> = "()[]{},=+-*/#\"\n 0123456789.eE_abcxyzrh-éλ\u{0}"
        .chars()
        .collect();
    let seed = 0xf022_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for round in 0..600 {
        let src = sources[round % sources.len()];
        let mut chars: Vec<char> = src.chars().collect();
        for _ in 0..1 + rng.next() % 4 {
            let i = (rng.next() % (chars.len() as u64 + 1)) as usize;
            let c = alphabet[(rng.next() % alphabet.len() as u64) as usize];
            match rng.next() % 3 {
                0 if i < chars.len() => {
                    chars.remove(i);
                }
                1 if i < chars.len() => chars[i] = c,
                _ => chars.insert(i, c),
            }
        }
        let text: String = chars.into_iter().collect();
        match Scene::parse(&text, "m.tss".as_ref()) {
            Ok(scene) => {
                // Small enough ones also build.
                if scene.depth <= 7 {
                    let _ = scene.build();
                }
            }
            Err(e) => {
                let d = e.diagnostic().expect("a parse error");
                let lines: Vec<&str> = text.split('\n').collect();
                assert!(
                    d.line >= 1 && d.line <= lines.len(),
                    "round {round}: line {}",
                    d.line
                );
                let _ = e.to_string();
            }
        }
    }
}

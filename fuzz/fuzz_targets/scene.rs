#![no_main]
//! Fuzzes the `.tss` scene parser and builder: any text parses to `Ok` or `Err`,
//! never a panic, a stack overflow or unbounded memory; a scene that parses is built
//! at depth 5 at most, within a leaf budget, and its tree is valid.
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tesseral::csg::Scene;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(mut scene) = Scene::parse(text, Path::new("fuzz.tss")) {
        scene.depth = scene.depth.min(5);
        if let Ok(tree) = scene.build_limited(100_000) {
            tree.assert_valid();
        }
    }
});

#![no_main]
//! Fuzzes `rsmc --resume`'s checkpoint: any JSON is validated (never a panic, a hang
//! or a degenerate generator); a checkpoint that is accepted runs a few hundred steps
//! on both lattices, which must agree (the dense array is the octree's oracle).
use libfuzzer_sys::fuzz_target;
use tesseral::dynamic::DynamicOctree;
use tesseral::rsmc::{Chain, Checkpoint, DenseLattice, Lattice};

fuzz_target!(|data: &[u8]| {
    let Ok(cp) = serde_json::from_slice::<Checkpoint>(data) else {
        return;
    };
    let (Ok(mut octree), Ok(mut dense)) = (
        Chain::from_checkpoint(DynamicOctree::new(), cp.clone()),
        Chain::from_checkpoint(DenseLattice::empty(), cp),
    ) else {
        return;
    };
    for _ in 0..300 {
        assert_eq!(octree.step(), dense.step());
    }
    assert_eq!(octree.voxels(), dense.voxels());
    assert_eq!(octree.counters(), dense.counters());
});

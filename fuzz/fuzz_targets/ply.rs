#![no_main]
//! Fuzzes the ply parser and, for small meshes, the voxelizer behind it.
use libfuzzer_sys::fuzz_target;
use tesseral::mesh::{self, Resolution, VoxelizeOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = tesseral::io::mesh::parse(data, "ply") {
        if m.triangles.len() <= 1000 {
            for surface_only in [false, true] {
                let opts = VoxelizeOptions { resolution: Resolution::Depth(5), surface_only, ..Default::default() };
                if let Ok(model) = mesh::voxelize(&m, &opts) {
                    model.tree.assert_valid();
                }
            }
        }
    }
});

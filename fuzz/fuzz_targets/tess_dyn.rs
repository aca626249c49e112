#![no_main]
//! Fuzzes a dynamic octree's own `.tess` reader (`DynamicOctree::decode_tess_dyn`)
//! past its checksum: the trailing CRC-32 is recomputed, so the fuzzer explores the
//! header, the block keys and both block forms. Whatever decodes must be a valid
//! octree whose bytes, written again, read back to the same voxels.
use libfuzzer_sys::fuzz_target;
use tesseral::dynamic::DynamicOctree;

#[path = "shared/crc.rs"]
mod crc;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    crc::reseal(&mut bytes);
    let Ok(t) = DynamicOctree::decode_tess_dyn(&bytes) else {
        return;
    };
    t.assert_valid();
    let again = t.encode_tess_dyn();
    let back = DynamicOctree::decode_tess_dyn(&again).expect("an octree's own bytes read back");
    back.assert_valid();
    assert_eq!(back.voxel_count(), t.voxel_count());
    assert_eq!(back.bounds(), t.bounds());
    assert_eq!(
        back.encode_tess_dyn(),
        again,
        "a second write gives the same bytes"
    );
});

#![no_main]
//! Fuzzes an occupancy map's own `.tess` reader (`OccupancyMap::decode_tess_map`)
//! past its checksum: the trailing CRC-32 is recomputed, so the fuzzer explores the
//! header, the sensor model, the block keys and every block form. Whatever decodes
//! must be a valid map whose bytes, written again, read back to the same cells.
use libfuzzer_sys::fuzz_target;
use tesseral::occupancy::OccupancyMap;

#[path = "shared/crc.rs"]
mod crc;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    crc::reseal(&mut bytes);
    let Ok(map) = OccupancyMap::decode_tess_map(&bytes) else {
        return;
    };
    map.assert_valid();
    let again = map.encode_tess_map();
    let back = OccupancyMap::decode_tess_map(&again).expect("a map's own bytes read back");
    back.assert_valid();
    assert_eq!(back.cells(), map.cells());
    assert_eq!(back.sensor(), map.sensor());
});

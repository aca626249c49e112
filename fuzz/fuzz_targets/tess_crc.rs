#![no_main]
//! Fuzzes `.tess` decoding past the checksum: the last four bytes are overwritten
//! with the CRC-32 of the rest, so the fuzzer explores the header and the leaves
//! instead of failing the check. A file that decodes must be valid and must encode
//! and decode back to the same model.
use libfuzzer_sys::fuzz_target;
use tesseral::io::native;

#[path = "shared/crc.rs"]
mod crc;

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let mut bytes = data.to_vec();
    crc::reseal(&mut bytes);
    if let Ok(model) = native::decode(&bytes) {
        model.tree.assert_valid();
        let again = native::decode(&native::encode(&model))
            .expect("an encoded model decodes");
        assert_eq!(again.tree, model.tree);
    }
});

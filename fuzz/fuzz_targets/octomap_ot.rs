#![no_main]
//! Fuzzes `tesseral::io::octomap::decode_ot`: any bytes give `Ok` or `Err`, never a panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(model) = tesseral::io::octomap::decode_ot(data) {
        model.tree.assert_valid();
    }
});

#![no_main]
//! Fuzzes `tesseral::io::xyz::parse`: any bytes give `Ok` or `Err`, never a panic.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = tesseral::io::xyz::parse(data);
});

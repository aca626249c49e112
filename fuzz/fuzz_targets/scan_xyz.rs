#![no_main]
//! Fuzzes `tesseral::io::scan::parse` on the `.xyz` scan format: any bytes give `Ok`
//! or `Err`, never a panic.
use libfuzzer_sys::fuzz_target;
use tesseral::io::scan::{parse, ScanFormat};

fuzz_target!(|data: &[u8]| {
    let _ = parse(data, ScanFormat::Xyz);
});

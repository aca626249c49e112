//! Shared by the targets whose files end with a CRC-32 of all bytes before it.

/// Overwrites the last four bytes with the CRC-32 of the rest (nothing for fewer
/// than four), so that the fuzzer explores past the checksum.
pub fn reseal(bytes: &mut [u8]) {
    let n = bytes.len();
    if n >= 4 {
        let crc = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    }
}

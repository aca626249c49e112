#![no_main]
//! Fuzzes the chunked (version-2) `.tess` reader past its index checksum: when the
//! bytes end like a version-2 file, the trailer's CRC is recomputed, so the fuzzer
//! explores the index and the chunks. Whatever opens must read chunk by chunk and by
//! code range without panicking, and agree with the whole-file decoder (colour
//! regions read as streams included).
use libfuzzer_sys::fuzz_target;
use tesseral::io::{native, TessFile};
use tesseral::linear::LinearOctree;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    let n = bytes.len();
    if n >= 88 && bytes[n - 8..] == *b"TESSIDX\n" {
        let t = n - 48;
        let sections = u64::from_le_bytes(bytes[t..t + 8].try_into().unwrap());
        if let Ok(s) = usize::try_from(sections) {
            if s <= n - 12 {
                let mut crc = crc32fast::Hasher::new();
                crc.update(&bytes[..40]);
                crc.update(&bytes[s..n - 12]);
                let c = crc.finalize();
                bytes[t + 36..t + 40].copy_from_slice(&c.to_le_bytes());
            }
        }
    }
    let whole = native::decode(&bytes);
    let Ok(f) = TessFile::from_bytes(bytes, std::path::Path::new("fuzz.tess")) else {
        return;
    };
    let chunks = f.chunks();
    let mut all = Vec::new();
    for i in 0..chunks.len() {
        match f.chunk(i) {
            Ok(leaves) => all.extend(leaves),
            Err(_) => return,
        }
    }
    if let Some(c) = chunks.get(chunks.len() / 2) {
        let _ = f.leaves_in(c.lo, c.hi).count();
    }
    // The colour regions read as streams hold what the decoded layer holds.
    if let (Ok(Some(regions)), Ok(model)) = (f.colour_streams(), &whole) {
        let mut got = Vec::new();
        for (c, r) in regions {
            let Ok(leaves) = r.collect::<Result<Vec<_>, _>>() else {
                return;
            };
            let t = LinearOctree::from_sorted_leaves(f.depth(), f.origin(), leaves).unwrap();
            if !t.is_empty() {
                got.push((c, t));
            }
        }
        got.sort_by_key(|(c, _)| u32::from_le_bytes(*c));
        let want: Vec<_> = model
            .colors
            .as_ref()
            .map(|l| l.regions().to_vec())
            .unwrap_or_default();
        assert_eq!(got, want);
    }
    if let (Ok(model), Ok(streamed)) = (whole, f.to_model()) {
        model.tree.assert_valid();
        assert_eq!(model, streamed);
    }
});

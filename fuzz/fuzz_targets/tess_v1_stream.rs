#![no_main]
//! Fuzzes the streaming reader of version-1 `.tess` files
//! (`TessFile::from_bytes_streaming`) past the file's checksum: when the bytes
//! start like a version-1 file, the trailing CRC-32 is recomputed, so the fuzzer
//! explores the header, the payload index and the colour streams. Whatever opens
//! must read stretch by stretch and by code range without panicking, and agree
//! with the whole-file decoder (colour regions included).
use libfuzzer_sys::fuzz_target;
use tesseral::io::{native, TessFile};

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    let n = bytes.len();
    if n >= 60 && bytes[..8] == native::MAGIC && bytes[8..10] == [1, 0] {
        let c = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&c.to_le_bytes());
    }
    let whole = native::decode(&bytes);
    let Ok(f) = TessFile::from_bytes_streaming(bytes, std::path::Path::new("fuzz.tess")) else {
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
    if let Ok(model) = &whole {
        assert_eq!(all, model.tree.leaves());
        if let Ok(Some(regions)) = f.colour_streams() {
            let want = model.colors.as_ref().map_or(&[][..], |l| l.regions());
            let mut got = Vec::new();
            for (c, r) in regions {
                let Ok(leaves) = r.collect::<Result<Vec<_>, _>>() else {
                    return;
                };
                if !leaves.is_empty() {
                    got.push((c, leaves));
                }
            }
            // The decoded layer keeps the regions with voxels, sorted by colour.
            got.sort_by_key(|(c, _)| u32::from_le_bytes(*c));
            let want: Vec<_> = want.iter().map(|(c, t)| (*c, t.leaves().to_vec())).collect();
            assert_eq!(got, want);
        }
        if let Ok(m) = f.to_model() {
            assert_eq!(&m, model);
        }
    }
});

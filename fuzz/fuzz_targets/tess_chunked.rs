#![no_main]
//! Fuzzes the chunked (version-2) `.tess` reader past its index checksum: when the
//! bytes end like a version-2 file, the colour index's own CRC (when flagged) and
//! the trailer's CRC are recomputed, so the fuzzer explores the index, the colour
//! index and the chunks. Whatever opens must read chunk by chunk and by code range
//! without panicking, and agree with the whole-file decoder (colour regions read as
//! streams included); opened without reading its colours, a file's colour blocks
//! must each be refused or hold leaves of their region, never another colour's.
use libfuzzer_sys::fuzz_target;
use tesseral::io::{native, TessFile};
use tesseral::linear::LinearOctree;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    let n = bytes.len();
    if n >= 88 && bytes[n - 8..] == *b"TESSIDX\n" {
        let t = n - 48;
        let sections = u64::from_le_bytes(bytes[t..t + 8].try_into().unwrap());
        let index = u64::from_le_bytes(bytes[t + 8..t + 16].try_into().unwrap());
        if let (Ok(s), Ok(e)) = (usize::try_from(sections), usize::try_from(index)) {
            // The colour index (flag bit 5) ends the sections with its length.
            if s.saturating_add(34) <= e && e <= t && bytes[s] & 32 != 0 {
                let len = u64::from_le_bytes(bytes[e - 8..e].try_into().unwrap());
                if let Some(ix) = usize::try_from(len).ok().and_then(|l| e.checked_sub(l)) {
                    if ix >= s + 2 && ix.saturating_add(16) <= e {
                        let c = crc32fast::hash(&bytes[ix..e - 16]);
                        bytes[e - 16..e - 12].copy_from_slice(&c.to_le_bytes());
                    }
                }
            }
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
    if let Ok(lazy) = TessFile::from_bytes_lazy_colours(bytes.clone(), std::path::Path::new("f")) {
        if let Some(blocks) = lazy.indexed_colour_blocks() {
            for (c, b) in blocks {
                match (&whole, b) {
                    (Ok(model), Ok(leaves)) => {
                        let layer = model.colors.as_ref().expect("an indexed file has colours");
                        let (_, t) = layer.regions().iter().find(|(x, _)| *x == c).unwrap();
                        for l in leaves {
                            assert!(t.leaves().binary_search(&l).is_ok(), "a wrong colour");
                        }
                    }
                    (Ok(_), Err(e)) => panic!("a file that decodes has a bad colour block: {e}"),
                    _ => {}
                }
            }
        }
    }
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

//! The format of a byte stream that has no file name (standard input), told from its
//! first bytes.

/// The extension of the format `bytes` are in, told from their first bytes, or
/// `None` when no known format matches.
///
/// Binary formats are recognised by their magic numbers (`.tess`, `.binvox`, `.vox`,
/// OctoMap `.bt` and `.ot`, `.ply`, binary `.stl`, whose triangle count must match
/// the length). Text is an ASCII `.stl` when it starts with `solid`, an `.obj` when
/// its first data line is a `v`, `vn`, `vt`, `f`, `o`, `g`, `s`, `mtllib` or `usemtl`
/// statement, and an `.xyz` voxel list when that line is three integers.
///
/// # Runtime
/// O(1): at most the first kilobyte is looked at.
///
/// # Example
/// ```
/// use tesseral::io::sniff_format;
/// assert_eq!(sniff_format(b"#binvox 1\ndim 1 1 1\n"), Some("binvox"));
/// assert_eq!(sniff_format(b"# a list\n1 2 -3\n"), Some("xyz"));
/// assert_eq!(sniff_format(b"\x00\x01garbage"), None);
/// ```
#[must_use]
pub fn sniff_format(bytes: &[u8]) -> Option<&'static str> {
    const PLY: [&[u8]; 2] = [b"ply\n", b"ply\r\n"];
    const MAGIC: &[(&[u8], &str)] = &[
        (b"\x89TESSRL\n", "tess"),
        (b"#binvox", "binvox"),
        (b"VOX ", "vox"),
        (b"# Octomap OcTree binary file", "bt"),
        (b"# Octomap OcTree file", "ot"),
        (PLY[0], "ply"),
        (PLY[1], "ply"),
    ];
    for (magic, ext) in MAGIC {
        if bytes.starts_with(magic) {
            return Some(ext);
        }
    }
    if is_binary_stl(bytes) {
        return Some("stl");
    }
    // Text may start with a UTF-8 byte order mark, which its readers skip (a PLY
    // header among them).
    let body = super::strip_bom(bytes);
    if PLY.iter().any(|m| body.starts_with(m)) {
        return Some("ply");
    }
    let head = &body[..body.len().min(1024)];
    let text = match std::str::from_utf8(head) {
        Ok(t) => t,
        // A multi-byte character cut at the 1 KiB mark is still text.
        Err(e) if e.error_len().is_none() => std::str::from_utf8(&head[..e.valid_up_to()]).ok()?,
        Err(_) => return None,
    };
    if text.trim_start().starts_with("solid") {
        return Some("stl");
    }
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))?;
    let word = first.split_whitespace().next()?;
    const OBJ: [&str; 9] = ["v", "vn", "vt", "f", "o", "g", "s", "mtllib", "usemtl"];
    if OBJ.contains(&word) {
        return Some("obj");
    }
    let numbers: Vec<&str> = first.split_whitespace().collect();
    if numbers.len() == 3 && numbers.iter().all(|n| n.parse::<i64>().is_ok()) {
        return Some("xyz");
    }
    None
}

/// A binary STL: an 80-byte header, a triangle count n, and exactly 50·n bytes.
fn is_binary_stl(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let n = u64::from(u32::from_le_bytes([count[0], count[1], count[2], count[3]]));
    bytes.len() as u64 == 84 + 50 * n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{write_model, Model};
    use crate::linear::LinearOctree;

    /// Every format we write is told back from its own bytes.
    #[test]
    fn written_files_are_recognised() {
        let tree =
            LinearOctree::from_voxels(3, [0, 0, 0], [[0, 0, 0], [1, 0, 0], [1, 2, 3]]).unwrap();
        let dir = tempfile::tempdir().unwrap();
        for ext in [
            "tess", "xyz", "binvox", "vox", "bt", "ot", "stl", "obj", "ply",
        ] {
            let path = dir.path().join(format!("a.{ext}"));
            write_model(&path, &Model::new(tree.clone())).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(sniff_format(&bytes), Some(ext), "{ext}");
        }
    }

    #[test]
    fn text_and_garbage() {
        assert_eq!(
            sniff_format(b"solid cube\n facet normal 0 0 1\n"),
            Some("stl")
        );
        assert_eq!(
            sniff_format(b"# made by hand\n\nv 0 0 0\nv 1 0 0\n"),
            Some("obj")
        );
        assert_eq!(sniff_format(b"mtllib a.mtl\n"), Some("obj"));
        assert_eq!(sniff_format(b"1 2 3\n4 5 6\n"), Some("xyz"));
        assert_eq!(sniff_format(b"1 2\n"), None);
        assert_eq!(sniff_format(b"1.5 2 3\n"), None);
        assert_eq!(sniff_format(b""), None);
        assert_eq!(sniff_format(b"\xef\xbb\xbf1 2 3\n"), Some("xyz"));
        assert_eq!(sniff_format(b"\xef\xbb\xbfv 0 0 0\n"), Some("obj"));
        assert_eq!(sniff_format(b"\xef\xbb\xbfsolid a\n"), Some("stl"));
        assert_eq!(sniff_format(b"\xef\xbb\xbfply\n"), Some("ply"));
        assert_eq!(sniff_format(&[0xff, 0xfe, 0x00, 0x12]), None);
        // 84 bytes claiming one triangle but holding none is not an STL.
        let mut stl = vec![0u8; 84];
        stl[80] = 1;
        assert_eq!(sniff_format(&stl), None);
        stl.extend_from_slice(&[0u8; 50]);
        assert_eq!(sniff_format(&stl), Some("stl"));
    }
}

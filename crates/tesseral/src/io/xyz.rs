//! The plain voxel list `.xyz`: one `x y z` integer triple per line, in world
//! coordinates (negative allowed), with `#` comments and blank lines. A `.xyz` we write
//! lists exactly the black voxels, in tesseral order, after a comment header.

use std::io::{self, BufRead, Read, Write};
use std::path::Path;

use super::FormatError;
use crate::linear::LinearOctree;
use crate::Voxel;

/// Reads voxels from `path` into the smallest octree that holds them.
///
/// # Errors
/// [`FormatError::Syntax`] with `file:line:column` for a malformed line.
pub fn read(path: &Path) -> Result<LinearOctree, FormatError> {
    let attach = |e: FormatError| e.with_path(path);
    let file = std::fs::File::open(path).map_err(|e| attach(FormatError::Io(e)))?;
    let voxels = parse(io::BufReader::new(file)).map_err(attach)?;
    LinearOctree::from_voxels_fitted(&voxels).map_err(|e| {
        attach(match (e, widest_span(&voxels)) {
            (crate::linear::OctreeError::DepthTooLarge(_), Some((axis, lo, hi))) => {
                FormatError::unsupported(format!(
                    "the voxels span {lo} to {hi} in {}, more than the {} voxels a side that a tree holds",
                    ["x", "y", "z"][axis],
                    1u64 << crate::linear::MAX_DEPTH
                ))
            }
            (e, _) => FormatError::Octree(e),
        })
    })
}

/// The axis on which `voxels` span the most, with their lowest and highest
/// coordinates on it.
fn widest_span(voxels: &[Voxel]) -> Option<(usize, i64, i64)> {
    (0..3)
        .filter_map(|a| {
            let lo = voxels.iter().map(|v| v[a]).min()?;
            let hi = voxels.iter().map(|v| v[a]).max()?;
            Some((a, lo, hi))
        })
        .max_by_key(|&(_, lo, hi)| hi.abs_diff(lo))
}

/// The most voxels an `.xyz` file may list (24 bytes each in memory, 800 MB at the
/// cap); larger sets belong in a `.tess` file.
pub const MAX_XYZ_VOXELS: usize = 1 << 25;
/// The longest line, in bytes: a file with no newlines is not buffered whole.
pub const MAX_XYZ_LINE: usize = 4096;

/// Parses `.xyz` text.
///
/// # Errors
/// [`FormatError::Syntax`] for a malformed or overlong line, [`FormatError::Io`] if
/// reading fails, [`FormatError::TooLarge`] past [`MAX_XYZ_VOXELS`] voxels.
pub fn parse(mut reader: impl BufRead) -> Result<Vec<Voxel>, FormatError> {
    let mut voxels = Vec::new();
    let mut buf = Vec::new();
    for index in 0usize.. {
        buf.clear();
        let n = Read::take(&mut reader, MAX_XYZ_LINE as u64 + 1)
            .read_until(b'\n', &mut buf)
            .map_err(FormatError::Io)?;
        if n == 0 {
            break;
        }
        if buf.last() == Some(&b'\n') {
            buf.pop();
        } else if buf.len() > MAX_XYZ_LINE {
            return Err(FormatError::Syntax {
                line: index + 1,
                column: MAX_XYZ_LINE + 1,
                message: format!("line longer than {MAX_XYZ_LINE} bytes"),
            });
        }
        let text = if index == 0 {
            crate::io::text_start(&buf)?
        } else {
            &buf
        };
        let line = String::from_utf8_lossy(text);
        let syntax = |column: usize, message: String| FormatError::Syntax {
            line: index + 1,
            column,
            message,
        };
        let content = line.split('#').next().unwrap_or("");
        let mut fields = Vec::with_capacity(3);
        let mut rest = content;
        while let Some(start) = rest.find(|c: char| !c.is_whitespace()) {
            let len = rest[start..]
                .find(char::is_whitespace)
                .unwrap_or(rest.len() - start);
            let column = content.len() - rest.len() + start + 1;
            fields.push((column, &rest[start..start + len]));
            rest = &rest[start + len..];
        }
        if fields.is_empty() {
            continue;
        }
        if fields.len() != 3 {
            return Err(syntax(
                fields.get(3).map_or(content.trim_end().len() + 1, |f| f.0),
                format!(
                    "expected three integers `x y z`, found {} field(s)",
                    fields.len()
                ),
            ));
        }
        let mut v = [0i64; 3];
        for (a, (column, text)) in fields.into_iter().enumerate() {
            v[a] = text
                .parse()
                .map_err(|_| syntax(column, format!("`{text}` is not an integer coordinate")))?;
        }
        if voxels.len() == MAX_XYZ_VOXELS {
            return Err(FormatError::too_large(format!(
                "more than {MAX_XYZ_VOXELS} voxels (line {}); store large sets as .tess",
                index + 1
            )));
        }
        voxels.push(v);
    }
    Ok(voxels)
}

/// Writes the black voxels of `tree`, one per line, in tesseral order.
///
/// # Errors
/// Any I/O error of `w`.
pub fn write(w: &mut dyn Write, tree: &LinearOctree) -> io::Result<()> {
    write_header(w, tree.voxel_count())?;
    for [x, y, z] in tree.voxels() {
        writeln!(w, "{x} {y} {z}")?;
    }
    Ok(())
}

/// Writes the header line of a list of `voxels` voxels (what [`write()`] starts
/// with), for a writer that streams the leaves with [`write_leaf`].
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_header(w: &mut dyn Write, voxels: u64) -> io::Result<()> {
    writeln!(
        w,
        "# tesseral voxel list: {voxels} voxels, one `x y z` per line"
    )
}

/// Writes the voxels of `leaf` (a leaf of a space whose lowest voxel is
/// `origin`) one per line, in tesseral order, as [`write()`] does.
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_leaf(w: &mut dyn Write, origin: Voxel, leaf: crate::linear::Leaf) -> io::Result<()> {
    for c in leaf.code()..leaf.end() {
        let r = crate::code::decode(c);
        let [x, y, z] = [0, 1, 2].map(|a| origin[a] + i64::from(r[a]));
        writeln!(w, "{x} {y} {z}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_comments_blanks_and_negatives() {
        let text = "# header\n\n1 2 3\n  -4\t5 -6   # trailing\n";
        let v = parse(text.as_bytes()).unwrap();
        assert_eq!(v, vec![[1, 2, 3], [-4, 5, -6]]);
    }

    /// A UTF-8 byte order mark before the first line is skipped; columns count
    /// after it.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let v = parse("\u{feff}1 2 3\n4 5 6\n".as_bytes()).unwrap();
        assert_eq!(v, vec![[1, 2, 3], [4, 5, 6]]);
        let err = parse("\u{feff}1 y 3\n".as_bytes())
            .unwrap_err()
            .with_path("a.xyz");
        assert_eq!(
            err.to_string(),
            "a.xyz:1:3: `y` is not an integer coordinate"
        );
        // Only at the start of the file.
        assert!(parse("1 2 3\n\u{feff}4 5 6\n".as_bytes()).is_err());
        let err = parse(&b"\xff\xfe1\x00 \x002\x00"[..]).unwrap_err();
        assert!(err.to_string().contains("UTF-16 little-endian"), "{err}");
    }

    #[test]
    fn names_line_and_column_of_the_fault() {
        let err = parse("1 2 3\n1 2 x\n".as_bytes())
            .unwrap_err()
            .with_path("a.xyz");
        assert_eq!(
            err.to_string(),
            "a.xyz:2:5: `x` is not an integer coordinate"
        );
        let err = parse("1 2\n".as_bytes()).unwrap_err().with_path("a.xyz");
        assert_eq!(
            err.to_string(),
            "a.xyz:1:4: expected three integers `x y z`, found 2 field(s)"
        );
        let err = parse("1 2 3 4\n".as_bytes())
            .unwrap_err()
            .with_path("a.xyz");
        assert_eq!(
            err.to_string(),
            "a.xyz:1:7: expected three integers `x y z`, found 4 field(s)"
        );
    }

    #[test]
    fn round_trip_through_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.xyz");
        let tree =
            LinearOctree::from_voxels(3, [-4, 0, 2], [[-4, 0, 2], [3, 7, 9], [0, 0, 5]]).unwrap();
        crate::io::write_octree(&path, &tree).unwrap();
        let back = crate::io::read_octree(&path).unwrap();
        back.assert_valid();
        assert_eq!(
            back.voxels().collect::<std::collections::HashSet<_>>(),
            tree.voxels().collect()
        );
    }
}

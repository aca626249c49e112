//! The plain voxel list `.xyz`: one `x y z` integer triple per line, in world
//! coordinates (negative allowed), with `#` comments and blank lines. A `.xyz` we write
//! lists exactly the black voxels, in tesseral order, after a comment header.

use std::io::{self, BufRead, Write};
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
    LinearOctree::from_voxels_fitted(&voxels).map_err(|e| attach(FormatError::Octree(e)))
}

/// Parses `.xyz` text.
///
/// # Errors
/// [`FormatError::Syntax`] for a malformed line, [`FormatError::Io`] if reading fails.
pub fn parse(reader: impl BufRead) -> Result<Vec<Voxel>, FormatError> {
    let mut voxels = Vec::new();
    for (index, line) in reader.lines().enumerate() {
        let line = line.map_err(FormatError::Io)?;
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
        voxels.push(v);
    }
    Ok(voxels)
}

/// Writes the black voxels of `tree`, one per line, in tesseral order.
///
/// # Errors
/// Any I/O error of `w`.
pub fn write(w: &mut dyn Write, tree: &LinearOctree) -> io::Result<()> {
    writeln!(
        w,
        "# tesseral voxel list: {} voxels, one `x y z` per line",
        tree.voxel_count()
    )?;
    for [x, y, z] in tree.voxels() {
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

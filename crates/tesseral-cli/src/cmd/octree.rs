//! Helpers shared by the octree commands: reading and writing through
//! `tesseral::io`, and parsing of vectors and axes.

use std::path::Path;

use anyhow::Result;
use tesseral::linear::Axis;
use tesseral::model::{Frame, Model};

use super::budget::Budget;
use super::output::{self, Limits};
use super::stdio::{self, Stdin};

/// Reads a model: a `.tss` scene is built within `budget` with its frame (the
/// scene's voxel size and lower corner) and its objects' colours; any other file is
/// read in the format its extension names, with what the format carries.
pub fn read_model(
    path: &Path,
    budget: &Budget,
    options: &tesseral::io::ReadOptions,
) -> Result<Model> {
    if output::is_stdio(path) {
        let stdin = Stdin::read()?;
        return read_model(&stdin.path, budget, options).map_err(|e| stdin.rename(&e));
    }
    if tesseral::io::extension(path) == "tss" {
        return budget.build_scene_model(path);
    }
    // A `.tess` file or a dataset is checked against the budget from its header
    // before it is read; any other file once read, before the work.
    let what = format!("{} (read whole)", path.display());
    if let Some(leaves) = super::streamed::leaves_on_disk(path)? {
        budget.check_leaves(&what, leaves)?;
    }
    let model = if tesseral::partition::is_dataset(path) {
        // A partitioned dataset (a directory with manifest.json) reads as one model.
        tesseral::partition::read_dataset_model(path).map_err(|e| anyhow::anyhow!("{e}"))?
    } else {
        // The library's message already names the file and its cause; keep it as
        // one line rather than repeating the cause from the error chain.
        tesseral::io::read_model_with(path, options).map_err(|e| anyhow::anyhow!("{e}"))?
    };
    budget.check_leaves(&what, model.tree.leaf_count() as u64)?;
    Ok(model)
}

/// Reads a model from an octree file (any format `tesseral::io` knows by the
/// extension), a `.tss` scene (built within the default budget), or `-` for
/// standard input.
pub fn read(path: &Path) -> Result<Model> {
    read_model(path, &Budget::default(), &Default::default())
}

/// The output flags of commands that write an octree.
#[derive(clap::Args, Clone, Debug)]
pub struct OutArgs {
    #[command(flatten)]
    pub limits: Limits,
    /// The format written to standard output by `-o -`: an extension such as tess,
    /// xyz or stl.
    #[arg(long, value_name = "EXT")]
    pub format: Option<String>,
}

impl OutArgs {
    /// The format of `path`: its extension, or `--format` for `-`.
    pub fn format_of(&self, path: &Path) -> String {
        match (&self.format, output::is_stdio(path)) {
            (Some(f), true) => f.trim_start_matches('.').to_ascii_lowercase(),
            _ => tesseral::io::extension(path),
        }
    }
}

/// Checks an octree output before any work: a format we write (`--format` for `-`,
/// and only then), and not an input.
pub fn guard(path: &Path, inputs: &[&Path], out: &OutArgs) -> Result<()> {
    let formats = output::octree_formats();
    match (output::is_stdio(path), &out.format) {
        (true, None) => anyhow::bail!(
            "--output -: give the format of standard output with --format (one of {})",
            formats.join(", ")
        ),
        (false, Some(f)) => {
            anyhow::bail!("--format {f}: only for --output - (a file's extension names its format)")
        }
        (true, Some(_)) => {
            let f = out.format_of(path);
            if !formats.contains(&f.as_str()) {
                anyhow::bail!(
                    "--format {f}: not a format we write (one of {})",
                    formats.join(", ")
                );
            }
            Ok(())
        }
        (false, None) => output::guard("--output", path, &formats, inputs),
    }
}

/// Writes a model to `path` (or standard output for `-`), after checking its
/// estimated size against `--max-output`.
pub fn save(
    path: &Path,
    model: &Model,
    out: &OutArgs,
    options: &tesseral::io::WriteOptions,
) -> Result<()> {
    let ext = out.format_of(path);
    let estimate = tesseral::io::estimate_model_bytes(model, &ext);
    if let Some(bytes) = estimate {
        output::check_size(path, bytes, out.limits.max_output)?;
    }
    let write = |p: &Path| {
        tesseral::io::write_model_with(p, model, options).map_err(|e| anyhow::anyhow!("{e}"))
    };
    if output::is_stdio(path) {
        stdio::to_stdout(&ext, write)
    } else {
        output::with_progress(estimate.unwrap_or(0), || write(path))
    }
}

/// Writes bytes already encoded in format `ext` to `path` (or standard output for
/// `-`), atomically, after checking their size against `--max-output`.
pub fn save_encoded(path: &Path, ext: &str, bytes: &[u8], out: &OutArgs) -> Result<()> {
    output::check_size(path, bytes.len() as u64, out.limits.max_output)?;
    let write = |p: &Path| {
        tesseral::io::write_atomic(p, |w| w.write_all(bytes)).map_err(|e| anyhow::anyhow!("{e}"))
    };
    if output::is_stdio(path) {
        stdio::to_stdout(ext, write)
    } else {
        write(path)
    }
}

/// How a command that writes an octree reports: a line of text, or with `--json` an
/// object with the keys `output`, `voxels`, `leaves`, `depth`, `origin`, `bbox_min`,
/// `bbox_max` (null when empty), plus the command's own keys in `extra`.
pub struct Report {
    /// Print JSON instead of text.
    pub json: bool,
    /// The command's own keys (a JSON object), added to the JSON output.
    pub extra: serde_json::Value,
}

/// Writes a model atomically, in the format named by the extension, and reports it
/// (see [`Report`]; JSON also has `voxel_size` and `translate`, the frame). Refuses,
/// before writing, an output estimated above `--max-output`.
pub fn write(path: &Path, model: &Model, out: &OutArgs, report: Report) -> Result<()> {
    let tree = &model.tree;
    if output::is_stdio(path) && report.json {
        anyhow::bail!("--json: standard output already holds the octree (-o -)");
    }
    save(path, model, out, &Default::default())?;
    if output::is_stdio(path) {
        // Standard output holds the octree; the report goes to standard error.
        eprintln!(
            "wrote <stdout>: {} voxels, {} leaves, depth {}, origin {}",
            tree.voxel_count(),
            tree.leaf_count(),
            tree.depth(),
            fmt_voxel(tree.origin())
        );
        return Ok(());
    }
    if report.json {
        let bbox = tree.bbox();
        let mut v = serde_json::json!({
            "output": path,
            "voxels": tree.voxel_count(),
            "leaves": tree.leaf_count(),
            "depth": tree.depth(),
            "origin": tree.origin(),
            "bbox_min": bbox.map(|b| b.0),
            "bbox_max": bbox.map(|b| b.1),
            "voxel_size": model.frame.voxel_size,
            "translate": model.frame.translate,
        });
        if let (Some(map), serde_json::Value::Object(extra)) = (v.as_object_mut(), report.extra) {
            map.extend(extra);
        }
        crate::outln!("{v}")?;
        return Ok(());
    }
    crate::outln!(
        "{}",
        wrote_line(
            path,
            tree.voxel_count(),
            tree.leaf_count() as u64,
            tree.depth(),
            tree.origin(),
            &model.frame
        )
    )?;
    Ok(())
}

/// The line a command prints for an octree it wrote: `wrote PATH: N voxels, N
/// leaves, depth D, origin (x, y, z)`, then the frame unless it is the unit one.
pub fn wrote_line(
    path: &Path,
    voxels: u64,
    leaves: u64,
    depth: u8,
    origin: [i64; 3],
    frame: &Frame,
) -> String {
    let frame = if frame.is_unit() {
        String::new()
    } else {
        format!(", {frame}")
    };
    format!(
        "wrote {}: {}, {}, depth {depth}, origin {}{frame}",
        path.display(),
        output::plural(voxels, "voxel", "voxels"),
        output::plural(leaves, "leaf", "leaves"),
        fmt_voxel(origin)
    )
}

/// `(x, y, z)`.
pub fn fmt_voxel(v: [i64; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

/// Parses `DX,DY,DZ` (integers, negative allowed).
pub fn parse_vector(text: &str) -> Result<[i64; 3], String> {
    parse_ints(text, "DX,DY,DZ")
}

/// Parses `N` comma-separated integers (negative allowed); `form` names them in the
/// error (`X,Y,Z`, `DX,DY,DZ`, `X0,Y0,Z0,X1,Y1,Z1`).
pub fn parse_ints<const N: usize>(text: &str, form: &str) -> Result<[i64; N], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(format!("expected {N} integers `{form}`, got `{text}`"));
    }
    let mut v = [0i64; N];
    for (a, p) in parts.iter().enumerate() {
        v[a] = parse_int(p).map_err(|e| format!("{e} (in `{text}`)"))?;
    }
    Ok(v)
}

/// Parses one 64-bit integer of a list given on the command line; the error says
/// whether `p` is no integer at all or one past the 64-bit range.
pub fn parse_int(p: &str) -> Result<i64, String> {
    use std::num::IntErrorKind::{NegOverflow, PosOverflow};
    p.parse()
        .map_err(|e: std::num::ParseIntError| match e.kind() {
            PosOverflow | NegOverflow => {
                format!("`{p}` is past the 64-bit range (-2^63 to 2^63 - 1)")
            }
            _ => format!("`{p}` is not an integer"),
        })
}

/// An axis on the command line.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum AxisArg {
    /// x, east.
    X,
    /// y, north.
    Y,
    /// z, up.
    Z,
}

impl From<AxisArg> for Axis {
    fn from(a: AxisArg) -> Self {
        match a {
            AxisArg::X => Axis::X,
            AxisArg::Y => Axis::Y,
            AxisArg::Z => Axis::Z,
        }
    }
}

/// Parses a scale factor `2^K` (K may be negative) into K.
pub fn parse_power_of_two(text: &str) -> Result<i32, String> {
    let t = text.trim();
    if let Some(k) = t.strip_prefix("2^") {
        let k: i32 = k
            .trim_start_matches(['(', ' '])
            .trim_end_matches([')', ' '])
            .parse()
            .map_err(|_| format!("`{t}`: the exponent is not an integer"))?;
        if k.unsigned_abs() > 21 {
            return Err(format!("`{t}`: the exponent must lie in -21..=21"));
        }
        return Ok(k);
    }
    match t.parse::<u64>() {
        Ok(n) if n.is_power_of_two() && n.trailing_zeros() <= 21 => Ok(n.trailing_zeros() as i32),
        _ => Err(format!(
            "`{t}` is not a power of two; write `2^K` (for example 2^3 or 2^-1)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_written_line_counts_in_words_and_names_a_frame() {
        let at = Path::new("a.tess");
        assert_eq!(
            wrote_line(at, 1, 1, 3, [0, -1, 2], &Frame::default()),
            "wrote a.tess: 1 voxel, 1 leaf, depth 3, origin (0, -1, 2)"
        );
        assert_eq!(
            wrote_line(at, 8, 2, 4, [0; 3], &Frame::new(0.05, [1.0, 0.0, 0.0])),
            "wrote a.tess: 8 voxels, 2 leaves, depth 4, origin (0, 0, 0), voxel size 0.05 at (1, 0, 0)"
        );
    }

    #[test]
    fn an_integer_past_64_bits_is_named_as_such() {
        assert_eq!(
            parse_vector("-3, 0,9223372036854775807"),
            Ok([-3, 0, i64::MAX])
        );
        assert_eq!(parse_int("-9223372036854775808"), Ok(i64::MIN));
        for big in [
            "9223372036854775808",
            "-9223372036854775809",
            "99999999999999999999",
        ] {
            let e = parse_int(big).unwrap_err();
            assert!(e.contains("past the 64-bit range"), "{e}");
        }
        for bad in ["1.5", "x", "", "1e3"] {
            let e = parse_int(bad).unwrap_err();
            assert!(e.ends_with("is not an integer"), "{e}");
        }
        let e = parse_vector("1,99999999999999999999,0").unwrap_err();
        assert!(
            e.contains("past the 64-bit range") && e.contains("(in `1,9999"),
            "{e}"
        );
    }
}

//! `tesseral replay OPS`: applies an operations log to an unbounded dynamic octree
//! (`tesseral::dynamic::DynamicOctree`), as recorded by a robot exploring an
//! unbounded world or by a surface simulation.
//!
//! One operation per line: `+ x y z` creates, `- x y z` deletes, `? x y z` queries
//! (prints `1` or `0` on its own line, in order), `#` starts a comment; blank lines
//! are skipped. At the end one JSON object is printed with the keys `voxels`, `faces`,
//! `root_size_log2`, `root_min`, `expansions`, `contractions`, `nodes`, `bytes`.
//! With `-o FILE` the octree built is saved (any format `convert` writes, voxel size
//! 1), through the output-safety layer; the report then also has `output`. An
//! octree wider than a model holds (2^21 voxels on an axis) keeps its full range in
//! a `.tess` of its own (`DynamicOctree::encode_tess_dyn`); other formats refuse it.
//! A reader that closes standard output early (`| head`) does not stop the save.

use std::fs::File;
use std::io::{self, BufReader, BufWriter, IsTerminal, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use tesseral::dynamic::DynamicOctree;

use super::replay_log::{parse_line, read_line, Op};
use super::stdio::Detachable;

/// Arguments of `tesseral replay`.
#[derive(clap::Args)]
pub struct Args {
    /// The operations log (`-` for standard input).
    ops: PathBuf,
    /// Keep the face list while replaying (Libes §4 bookkeeping; more memory).
    /// Without it the face count is computed once at the end.
    #[arg(long)]
    track_faces: bool,
    /// The final report is always one JSON object (keys above); the flag is accepted
    /// so that every command takes --json.
    #[arg(long)]
    json: bool,
    /// Save the octree built to this file (.tess, .bt, .ot, .xyz, ...: any format
    /// `convert` writes). Standard output holds the queries and the report, so `-`
    /// is refused.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    #[command(flatten)]
    limits: super::output::Limits,
}

pub fn run(args: Args) -> Result<()> {
    let name = args.ops.display().to_string();
    if let Some(out) = &args.output {
        if super::output::is_stdio(out) {
            bail!("--output -: standard output holds the queries and the report; give a file");
        }
        super::output::guard(
            "--output",
            out,
            &super::output::octree_formats(),
            &[&args.ops],
        )?;
    }
    let (input, len): (Box<dyn Read>, Option<u64>) = if name == "-" {
        (Box::new(io::stdin().lock()), None)
    } else {
        let f = File::open(&args.ops).with_context(|| format!("cannot open {name}"))?;
        let len = f.metadata().ok().map(|m| m.len());
        (Box::new(f), len)
    };
    let mut reader = BufReader::with_capacity(1 << 16, input);
    // A reader that leaves early (`| head`) ends the queries' output, not the
    // replay: with -o, the octree is still built and saved.
    let mut out = Detachable::new(BufWriter::new(io::stdout().lock()));
    let mut tree = if args.track_faces {
        DynamicOctree::with_faces()
    } else {
        DynamicOctree::new()
    };

    let bar = if io::stderr().is_terminal() {
        len.map(|n| {
            let b = indicatif::ProgressBar::new(n);
            b.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        })
    } else {
        None
    };

    let mut buf = Vec::with_capacity(256);
    let mut line_no: u64 = 0;
    let mut bytes_read: u64 = 0;
    loop {
        let more = read_line(&mut reader, &mut buf);
        let fail = |msg: String, out: &mut Detachable<_>| -> Result<()> {
            out.flush().context("writing query results")?;
            bail!(
                "{name}: line {}: {msg} ({line_no} lines applied)",
                line_no + 1
            )
        };
        match more {
            Ok(false) => break,
            Ok(true) => {}
            Err(msg) => return fail(msg, &mut out),
        }
        bytes_read += buf.len() as u64 + 1;
        // A UTF-8 byte order mark before the first line is skipped.
        let line = match line_no {
            0 => tesseral::io::strip_bom(&buf),
            _ => &buf,
        };
        let text = match std::str::from_utf8(line) {
            Ok(t) => t,
            Err(_) => return fail("not valid UTF-8".to_string(), &mut out),
        };
        match parse_line(text) {
            Ok(Op::Insert(v)) => {
                tree.insert(v);
            }
            Ok(Op::Remove(v)) => {
                tree.remove(v);
            }
            Ok(Op::Query(v)) => {
                writeln!(out, "{}", u8::from(tree.contains(v))).context("writing to stdout")?;
                if out.closed() && args.output.is_none() {
                    return Ok(());
                }
            }
            Ok(Op::Skip) => {}
            Err(msg) => return fail(msg, &mut out),
        }
        line_no += 1;
        if let Some(b) = &bar {
            if line_no % 65_536 == 0 {
                b.set_position(bytes_read);
            }
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(path) = &args.output {
        save(&tree, path, args.limits)?;
    }
    let mut report = serde_json::json!({
        "voxels": tree.voxel_count(),
        "faces": tree.exposed_faces(),
        "root_size_log2": tree.root_size_log2(),
        "root_min": tree.root_min(),
        "expansions": tree.expansions(),
        "contractions": tree.contractions(),
        "nodes": tree.node_count(),
        "bytes": tree.bytes(),
    });
    if let Some(path) = &args.output {
        report["output"] = serde_json::json!(path);
    }
    writeln!(out, "{report}").context("writing to stdout")?;
    out.flush().context("writing to stdout")?;
    Ok(())
}

/// Saves the octree built: through a model when it fits one, else in its own `.tess`
/// (the only format that keeps its range).
fn save(tree: &DynamicOctree, path: &Path, limits: super::output::Limits) -> Result<()> {
    let out_args = super::octree::OutArgs {
        limits,
        format: None,
    };
    let ext = out_args.format_of(path);
    if !tree.fits_model() {
        if ext != "tess" {
            bail!(
                "{}: the octree spans 2^{} voxels on an axis, past a model's 2^{}: only .tess \
                 keeps it (the dynamic octree's own format)",
                path.display(),
                tree.root_size_log2(),
                tesseral::linear::MAX_DEPTH
            );
        }
        return super::octree::save_encoded(path, &ext, &tree.encode_tess_dyn(), &out_args);
    }
    let depth = u8::try_from(tree.root_size_log2()).unwrap_or(u8::MAX);
    let lin = tree
        .to_linear(depth, tree.root_min())
        .with_context(|| format!("{}: the octree does not fit a file", path.display()))?;
    super::octree::save(
        path,
        &tesseral::model::Model::new(lin),
        &out_args,
        &Default::default(),
    )
}

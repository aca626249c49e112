//! `tesseral replay OPS`: applies an operations log to an unbounded dynamic octree
//! (`tesseral::dynamic::DynamicOctree`), as recorded by a robot exploring an
//! unbounded world or by a surface simulation.
//!
//! One operation per line: `+ x y z` creates, `- x y z` deletes, `? x y z` queries
//! (prints `1` or `0` on its own line, in order), `#` starts a comment; blank lines
//! are skipped. At the end one JSON object is printed with the keys `voxels`, `faces`,
//! `root_size_log2`, `root_min`, `expansions`, `contractions`, `nodes`, `bytes`.

use std::fs::File;
use std::io::{self, BufReader, BufWriter, IsTerminal, Read, Write};
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use tesseral::dynamic::DynamicOctree;

use super::replay_log::{parse_line, read_line, Op};

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
}

pub fn run(args: Args) -> Result<()> {
    let name = args.ops.display().to_string();
    let (input, len): (Box<dyn Read>, Option<u64>) = if name == "-" {
        (Box::new(io::stdin().lock()), None)
    } else {
        let f = File::open(&args.ops).with_context(|| format!("cannot open {name}"))?;
        let len = f.metadata().ok().map(|m| m.len());
        (Box::new(f), len)
    };
    let mut reader = BufReader::with_capacity(1 << 16, input);
    let mut out = BufWriter::new(io::stdout().lock());
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
        let fail = |msg: String, out: &mut BufWriter<_>| -> Result<()> {
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
        let text = match std::str::from_utf8(&buf) {
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
    let report = serde_json::json!({
        "voxels": tree.voxel_count(),
        "faces": tree.exposed_faces(),
        "root_size_log2": tree.root_size_log2(),
        "root_min": tree.root_min(),
        "expansions": tree.expansions(),
        "contractions": tree.contractions(),
        "nodes": tree.node_count(),
        "bytes": tree.bytes(),
    });
    writeln!(out, "{report}").context("writing to stdout")?;
    out.flush().context("writing to stdout")?;
    Ok(())
}

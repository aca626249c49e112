//! `tesseral tables`: the papers' digit tables, computed, with the paper's misprints
//! marked and footnoted.

use std::fmt::Write as _;

use anyhow::{bail, Result};
use tesseral::code::digits::{ahuja_nash_tables, harakal_tables, PaperTable};

/// Arguments of `tesseral tables`.
#[derive(clap::Args)]
pub struct Args {
    /// Which paper: `ahuja-nash` (label increments and transitions) or `harakal`
    /// (digit addition and subtraction). Both when left out.
    #[arg(value_name = "PAPER")]
    paper: Option<String>,
    /// Print JSON for programs instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `tesseral tables`.
pub fn run(args: Args) -> Result<()> {
    let tables = match args.paper.as_deref() {
        None => {
            let mut t = ahuja_nash_tables();
            t.extend(harakal_tables());
            t
        }
        Some("ahuja-nash") => ahuja_nash_tables(),
        Some("harakal") => harakal_tables(),
        Some(other) => bail!("argument PAPER `{other}`: expected `ahuja-nash` or `harakal`"),
    };
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&serde_json::json!({ "tables": tables }))?;
        s.push('\n');
        s
    } else {
        tables.iter().map(render).collect::<Vec<_>>().join("\n")
    };
    crate::out!("{text}")?;
    Ok(())
}

/// One table as aligned text; a misprinted entry gets `*k` and footnote k.
fn render(t: &PaperTable) -> String {
    let mut notes = Vec::new();
    let mut marks: Vec<Vec<String>> = Vec::new();
    for row in &t.rows {
        let mut line = Vec::new();
        for (c, cell) in row.cells.iter().enumerate() {
            if cell.erratum {
                notes.push(format!(
                    "*{} row {}, column {}: the paper prints {}; the computed entry is {}.",
                    notes.len() + 1,
                    row.label,
                    t.columns[c],
                    cell.printed,
                    cell.value
                ));
                line.push(format!("*{}", notes.len()));
            } else {
                line.push(String::new());
            }
        }
        marks.push(line);
    }
    let valw = t
        .rows
        .iter()
        .flat_map(|r| r.cells.iter().map(|c| c.value.len()))
        .chain(t.columns.iter().map(String::len))
        .max()
        .unwrap_or(1);
    let markw = marks.iter().flatten().map(String::len).max().unwrap_or(0);
    let first = t
        .rows
        .iter()
        .map(|r| r.label.len())
        .chain([t.corner.len()])
        .max()
        .unwrap_or(1);
    let mut out = String::new();
    let _ = writeln!(out, "{}: {}", t.source, t.title);
    let _ = writeln!(out, "({})", t.legend);
    let mut header = format!("{:<first$}", t.corner);
    for c in &t.columns {
        let _ = write!(header, "  {c:>valw$}{:markw$}", "");
    }
    let _ = writeln!(out, "{}", header.trim_end());
    for (row, line) in t.rows.iter().zip(&marks) {
        let mut text = format!("{:<first$}", row.label);
        for (cell, mark) in row.cells.iter().zip(line) {
            let _ = write!(text, "  {:>valw$}{mark:<markw$}", cell.value);
        }
        let _ = writeln!(out, "{}", text.trim_end());
    }
    for n in notes {
        let _ = writeln!(out, "{n}");
    }
    for n in &t.notes {
        let _ = writeln!(out, "Note: {n}");
    }
    out
}

//! `tesseral`: the command line. It parses arguments and reports; the work lives in
//! the `tesseral` library.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;

/// Octrees of 3-D solids and surfaces.
#[derive(Parser)]
#[command(name = "tesseral", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Tesseral code arithmetic: encode, decode, add, sub, neg.
    Calc(cmd::calc::Args),
    /// The papers' digit tables, computed; misprints marked and footnoted.
    Tables(cmd::tables::Args),
    /// Monte Carlo of self-avoiding random surfaces (Libes §6).
    Rsmc(cmd::rsmc::Args),
    /// Draws a scene or an octree file as a PNG image.
    Render(cmd::render::Args),
    /// Builds a scene's octree and writes it to a file.
    Build(cmd::build::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Calc(args) => cmd::calc::run(args),
        Command::Tables(args) => cmd::tables::run(args),
        Command::Rsmc(args) => cmd::rsmc::run(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Build(args) => cmd::build::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            if is_broken_pipe(&err) {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}

/// A reader that closed our stdout early (`tesseral ... | head`) is not an error.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

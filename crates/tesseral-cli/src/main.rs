//! `tesseral`: the command line. It parses arguments and reports; the work lives in
//! the `tesseral` library.

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

mod cmd;

/// Octrees of 3-D solids and surfaces.
#[derive(Parser)]
#[command(name = "tesseral", version, about)]
pub(crate) struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Tesseral code arithmetic: encode, decode, add, sub, neg.
    Calc(cmd::calc::Args),
    /// Applies an operations log (+ x y z, - x y z, ? x y z) to an unbounded octree.
    Replay(cmd::replay::Args),
    /// The papers' digit tables, computed; misprints marked and footnoted.
    Tables(cmd::tables::Args),
    /// Monte Carlo of self-avoiding random surfaces (Libes §6).
    Rsmc(cmd::rsmc::Args),
    /// Converts between file formats, chosen by extension.
    Convert(cmd::convert::Args),
    /// Interference of two octrees: overlap, overlap volume, clearance.
    Collide(cmd::collide::Args),
    /// Run a world of moving objects; report every contact, with exact times.
    Simulate(cmd::simulate::Args),
    /// A collision-free path for an object through an environment.
    Plan(cmd::plan::Args),
    /// Prints what an octree file holds (--json for programs).
    Info(cmd::info::Args),
    /// Translates an octree by an integer vector.
    Translate(cmd::transform::TranslateArgs),
    /// Rotates an octree by quarter turns, or by any angle about any axis.
    Rotate(cmd::transform::RotateArgs),
    /// Maps an octree by any affine map x -> M x + offset (point sampling).
    Transform(cmd::affine::TransformArgs),
    /// Mirrors an octree in an axis.
    Mirror(cmd::transform::MirrorArgs),
    /// Scales an octree by 2^K or by any integer per axis.
    Scale(cmd::transform::ScaleArgs),
    /// Set operations: union, intersection, difference, xor.
    Op(cmd::op::Args),
    /// The complement of an octree within its space.
    Complement(cmd::transform::ComplementArgs),
    /// Draws a scene or an octree file as a PNG image.
    Render(cmd::render::Args),
    /// Builds a scene's octree and writes it to a file.
    Build(cmd::build::Args),
    /// Writes an interactive 3-D viewer of a scene or octree file (one HTML page).
    View(cmd::view::Args),
    /// Builds an occupancy map from range scans (OctoMap .graph/.log, .xyz, .ply, .pcd).
    Map(cmd::map::Args),
    /// Prints a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(cmd::shell::CompletionsArgs),
    /// Prints the man page (roff; view it with `tesseral man | man -l -`).
    Man(cmd::shell::ManArgs),
}

fn main() -> ExitCode {
    let matches = cmd::help::grouped(Cli::command()).get_matches();
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    cmd::output::install_signal_handler();
    let result = match cli.command {
        Command::Calc(args) => cmd::calc::run(args),
        Command::Replay(args) => cmd::replay::run(args),
        Command::Tables(args) => cmd::tables::run(args),
        Command::Rsmc(args) => cmd::rsmc::run(args),
        Command::Convert(args) => cmd::convert::run(args),
        Command::Collide(args) => cmd::collide::run(args),
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Plan(args) => cmd::plan::run(args),
        Command::Info(args) => cmd::info::run(args),
        Command::Translate(args) => cmd::transform::translate(args),
        Command::Rotate(args) => cmd::transform::rotate(args),
        Command::Transform(args) => cmd::affine::transform(args),
        Command::Mirror(args) => cmd::transform::mirror(args),
        Command::Scale(args) => cmd::transform::scale(args),
        Command::Op(args) => cmd::op::run(args),
        Command::Complement(args) => cmd::transform::complement(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Build(args) => cmd::build::run(args),
        Command::View(args) => cmd::view::run(args),
        Command::Map(args) => cmd::map::run(args),
        Command::Completions(args) => cmd::shell::completions(&args, Cli::command()),
        Command::Man(args) => cmd::shell::man(&args, Cli::command()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            if is_broken_pipe(&err) {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {}", one_line(&err));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes on one line, each cause once: library errors often repeat
/// their cause in their own message, and printing the chain would say it twice.
fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

/// A reader that closed our stdout early (`tesseral ... | head`) is not an error.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    use std::io::ErrorKind::BrokenPipe;
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == BrokenPipe)
            // serde_json wraps the writer's error in its own type.
            || e.downcast_ref::<serde_json::Error>()
                .is_some_and(|j| j.io_error_kind() == Some(BrokenPipe))
    })
}

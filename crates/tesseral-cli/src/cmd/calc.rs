//! `tesseral calc`: tesseral codes on the command line.

use anyhow::Result;

/// Arguments of `tesseral calc`.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    op: Op,
}

#[derive(clap::Subcommand)]
enum Op {
    /// Prints the octal tesseral code of X Y Z.
    Encode { x: u32, y: u32, z: u32 },
}

pub fn run(args: Args) -> Result<()> {
    match args.op {
        Op::Encode { x, y, z } => println!("{:o}", tesseral::code::encode(x, y, z)),
    }
    Ok(())
}

//! `tesseral completions bash|zsh|fish|...` and `tesseral man`: shell completion
//! scripts (clap_complete) and a roff man page (clap_mangen), both generated from the
//! same clap definitions as `--help`, so they never drift from the real flags.

use anyhow::Result;

/// Arguments of `tesseral completions`.
#[derive(clap::Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

/// Arguments of `tesseral man`.
#[derive(clap::Args)]
pub struct ManArgs {
    /// The page of one subcommand (`tesseral man render`) instead of the main page.
    command: Option<String>,
}

/// Prints the completion script for `args.shell` on stdout.
///
/// Install for bash: `tesseral completions bash > ~/.local/share/bash-completion/completions/tesseral`.
pub fn completions(args: &CompletionsArgs, mut command: clap::Command) -> Result<()> {
    let mut buf = Vec::new();
    clap_complete::generate(args.shell, &mut command, "tesseral", &mut buf);
    write_stdout(&buf)
}

/// Prints the man page on stdout (`tesseral man | man -l -`).
pub fn man(args: &ManArgs, command: clap::Command) -> Result<()> {
    let command = match &args.command {
        None => command,
        Some(name) => {
            let sub = command
                .get_subcommands()
                .find(|c| c.get_name() == name)
                .cloned()
                .ok_or_else(|| anyhow::anyhow!("man {name}: no such command"))?;
            // clap names are `'static` without its `string` feature; the page is
            // printed once and the process ends, so leaking this one name is free.
            sub.name(clap::builder::Str::from(
                format!("tesseral-{name}").leak() as &str
            ))
        }
    };
    let mut buf = Vec::new();
    clap_mangen::Man::new(command).render(&mut buf)?;
    write_stdout(&buf)
}

fn write_stdout(bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)?;
    out.flush()?;
    Ok(())
}

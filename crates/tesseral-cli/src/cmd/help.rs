//! `tesseral --help` with the commands in groups. clap lists subcommands in one
//! block, so the main help uses a template whose command list is generated here from
//! the subcommands' own descriptions.

/// The groups, in the order shown. Every subcommand belongs to exactly one (a test
/// checks it), so a new command cannot be left out of the help.
pub const GROUPS: &[(&str, &[&str])] = &[
    ("Build and view", &["build", "render", "view", "info"]),
    ("Formats", &["convert"]),
    (
        "Octree operations",
        &[
            "translate",
            "rotate",
            "transform",
            "mirror",
            "scale",
            "op",
            "complement",
        ],
    ),
    ("Motion", &["collide", "simulate", "plan"]),
    ("Dynamic octrees and Monte Carlo", &["replay", "rsmc"]),
    ("Maps from sensors", &["map"]),
    ("Tesseral arithmetic", &["calc", "tables"]),
    ("Shell", &["completions", "man", "help"]),
];

/// The main command with its help template listing the commands by group.
#[must_use]
pub fn grouped(command: clap::Command) -> clap::Command {
    let width = command
        .get_subcommands()
        .map(|c| c.get_name().len())
        .max()
        .unwrap_or(0);
    let about = |name: &str| -> String {
        command
            .find_subcommand(name)
            .and_then(|c| c.get_about().map(|a| a.to_string()))
            .unwrap_or_else(|| "Print this message or the help of the given command".into())
    };
    let mut list = String::new();
    for (title, names) in GROUPS {
        list.push_str(&format!("{title}:\n"));
        for name in *names {
            list.push_str(&format!("  {name:width$}  {}\n", about(name)));
        }
        list.push('\n');
    }
    // Braces in descriptions would be read as template keys.
    let list = list.replace('{', "{{").replace('}', "}}");
    command.help_template(format!(
        "{{before-help}}{{about-with-newline}}\n{{usage-heading}} {{usage}}\n\n{list}Options:\n{{options}}{{after-help}}"
    ))
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::*;

    #[test]
    fn every_command_is_in_one_group() {
        let mut command = crate::Cli::command();
        command.build();
        let mut names: Vec<&str> = GROUPS.iter().flat_map(|(_, n)| n.iter().copied()).collect();
        names.sort_unstable();
        let mut real: Vec<&str> = command.get_subcommands().map(|c| c.get_name()).collect();
        real.sort_unstable();
        assert_eq!(names, real);
    }
}

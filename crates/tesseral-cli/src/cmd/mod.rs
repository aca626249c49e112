//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod calc;
pub mod tables;
pub mod rsmc;

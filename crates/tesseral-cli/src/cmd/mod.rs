//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod build;
pub mod calc;
pub mod render;
pub mod rsmc;
pub mod tables;

//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod calc;
pub mod collide;
pub mod convert;
pub mod plan;
pub mod replay;
pub mod rsmc;
pub mod simulate;
pub mod tables;

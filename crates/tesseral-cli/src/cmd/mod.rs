//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod calc;
pub mod replay;
pub mod convert;
pub mod rsmc;
pub mod tables;
pub mod collide;
pub mod simulate;
pub mod plan;

//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod calc;
pub mod convert;
pub mod info;
pub mod octree;
pub mod op;
pub mod transform;

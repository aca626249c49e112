//! One module per subcommand. Each has an `Args` (clap derive) and a `run`.

pub mod affine;
pub mod budget;
pub mod build;
pub mod calc;
pub mod collide;
pub mod convert;
pub mod help;
pub mod info;
pub mod info_wide;
pub mod map;
pub mod octree;
pub mod op;
pub mod output;
pub mod plan;
pub mod render;
pub mod replay;
pub mod replay_log;
pub mod rsmc;
pub mod shell;
pub mod simulate;
pub mod stdio;
pub mod streamed;
pub mod tables;
pub mod transform;
pub mod view;

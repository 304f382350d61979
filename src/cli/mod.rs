//! Subcommand implementations. Each module defines its clap arguments and a `run` that returns
//! the process exit code; errors become one line on stderr and exit code 2 (see `main.rs`).

pub mod check;
pub mod compare;
pub mod export;
pub mod info;
pub mod render;
pub mod tessellate;

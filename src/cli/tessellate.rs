//! `apatch tessellate`.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch tessellate`.
#[derive(Args, Debug)]
pub struct TessellateArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `apatch tessellate`.
pub fn run(args: TessellateArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "{}: `apatch tessellate` is not available yet",
        args.input.display()
    )
}

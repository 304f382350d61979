//! `apatch check`.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `apatch check`.
pub fn run(args: CheckArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "{}: `apatch check` is not available yet",
        args.input.display()
    )
}

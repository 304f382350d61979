//! `apatch info`.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `apatch info`.
pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "{}: `apatch info` is not available yet",
        args.input.display()
    )
}

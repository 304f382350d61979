//! `apatch render`.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `apatch render`.
pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "{}: `apatch render` is not available yet",
        args.input.display()
    )
}

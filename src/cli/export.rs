//! `apatch export patches|…`.

use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// What to export.
#[derive(Subcommand, Debug)]
pub enum ExportCommand {
    /// The patch complex as JSON (format `apatch-patches`, version 1).
    Patches(PatchesArgs),
}

/// Arguments of `apatch export patches`.
#[derive(Args, Debug)]
pub struct PatchesArgs {
    /// A scene (.toml), a model file, or a patch complex (.json, re-validated and rewritten).
    pub input: PathBuf,
    /// Output JSON file.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Runs `apatch export …`.
pub fn run(cmd: ExportCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        ExportCommand::Patches(a) => {
            let complex = super::check::load_complex(&a.input)?;
            apatch::complex_io::write_json_file(&complex, &a.output)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

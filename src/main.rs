//! The `apatch` command line: one subcommand per user task; each lives in `cli/<verb>.rs`.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod cli;

/// Smooth implicit A-patch surfaces from polyhedra, ray traced directly.
#[derive(Parser)]
#[command(name = "apatch", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Measure a patch complex: continuity, interpolation, sheets. Non-zero exit on failure.
    Check(cli::check::CheckArgs),
    /// Compare two EXR renders: RMSE, PSNR, SSIM, difference pictures.
    Compare(cli::compare::CompareArgs),
    /// Write the patch complex (JSON) or a Mitsuba 3 scene.
    #[command(subcommand)]
    Export(cli::export::ExportCommand),
    /// Describe a mesh: counts, topology, convexity, validation findings.
    Info(cli::info::InfoArgs),
    /// Ray trace a scene to EXR and PNG.
    Render(cli::render::RenderArgs),
    /// Tessellate the A-patch surface to a watertight PLY or OBJ mesh.
    Tessellate(cli::tessellate::TessellateArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check(a) => cli::check::run(a),
        Command::Compare(a) => cli::compare::run(a),
        Command::Export(a) => cli::export::run(a),
        Command::Info(a) => cli::info::run(a),
        Command::Render(a) => cli::render::run(a),
        Command::Tessellate(a) => cli::tessellate::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            // One line, every cause joined: users and scripts read this.
            eprintln!("apatch: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

//! `apatch export patches|mitsuba`.

use anyhow::bail;
use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// What to export.
#[derive(Subcommand, Debug)]
pub enum ExportCommand {
    /// The patch complex as JSON (format `apatch-patches`, version 1).
    Patches(PatchesArgs),
    /// A Mitsuba 3 scene: `<dir>/<stem>.xml` plus the tessellated surface `<dir>/<stem>.ply`.
    Mitsuba(MitsubaArgs),
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

/// Arguments of `apatch export mitsuba`.
#[derive(Args, Debug)]
pub struct MitsubaArgs {
    /// The scene (.toml).
    pub scene: PathBuf,
    /// Output directory (created when missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Grid intervals per patch edge of the tessellation.
    #[arg(long, default_value_t = 8)]
    pub resolution: usize,
    /// Image size and samples per pixel (as `apatch render`).
    #[command(flatten)]
    pub film: super::FilmArgs,
}

/// Runs `apatch export …`.
pub fn run(cmd: ExportCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        ExportCommand::Patches(a) => {
            let complex = super::check::load_complex(&a.input)?;
            apatch::complex_io::write_json_file(&complex, &a.output)?;
            Ok(ExitCode::SUCCESS)
        }
        ExportCommand::Mitsuba(a) => {
            let is_toml = a
                .scene
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            if !is_toml {
                bail!("{}: expected a scene .toml", a.scene.display());
            }
            let mut scene = apatch::scene::load(&a.scene)?;
            a.film.apply(&mut scene.settings)?;
            let complex = super::check::load_complex(&a.scene)?;
            let done = apatch::export::mitsuba::export(&scene, &complex, &a.output, a.resolution)?;
            println!(
                "{}: {} ({} vertices, {} triangles)",
                done.xml.display(),
                done.ply.display(),
                done.vertices,
                done.triangles
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

//! `apatch tessellate`: sample the A-patch surface into a watertight triangle mesh (PLY or OBJ).

use apatch::export::{self, tessellate};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch tessellate`.
#[derive(Args, Debug)]
pub struct TessellateArgs {
    /// A scene (.toml) or a patch complex (.json, from `apatch export patches`).
    pub input: PathBuf,
    /// Output mesh: `.ply` (binary little-endian) or `.obj`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Grid intervals per patch edge.
    #[arg(long, default_value_t = 8)]
    pub resolution: usize,
}

/// Runs `apatch tessellate`.
pub fn run(args: TessellateArgs) -> anyhow::Result<ExitCode> {
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext != "ply" && ext != "obj" {
        anyhow::bail!(
            "{}: unknown output type (expected .ply or .obj)",
            args.output.display()
        );
    }
    let complex = super::check::load_complex(&args.input)?;
    let mesh = tessellate::tessellate(&complex, args.resolution)
        .map_err(|e| anyhow::anyhow!("{}: {e:#}", args.input.display()))?;
    export::write_atomically(&args.output, |out| {
        if ext == "ply" {
            export::ply::write(&mesh, out)
        } else {
            export::obj::write(&mesh, out)
        }
    })?;
    println!(
        "{}: {} vertices, {} triangles",
        args.output.display(),
        mesh.positions.len(),
        mesh.triangles.len()
    );
    Ok(ExitCode::SUCCESS)
}

//! Exporters of the A-patch surface: tessellation to a triangle mesh ([`tessellate`]) and the
//! PLY / OBJ writers ([`ply`], [`obj`]), and Mitsuba 3 scenes ([`mitsuba`]).

pub mod mitsuba;
pub mod obj;
pub mod ply;
pub mod tessellate;

pub use tessellate::{tessellate, TriMesh};

use anyhow::Context;
use std::io::Write;
use std::path::Path;

/// Writes `path` through a temporary sibling that is renamed into place only when `write`
/// succeeded, so a failed export leaves no half-written file.
///
/// # Errors
/// Any I/O error of creating, writing or renaming, with the path named.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    let tmp = crate::trace::output::temp_path(path);
    let result = (|| -> anyhow::Result<()> {
        let file = std::fs::File::create(&tmp)
            .with_context(|| format!("{}: cannot create", path.display()))?;
        let mut out = std::io::BufWriter::new(file);
        write(&mut out).with_context(|| format!("{}: cannot write", path.display()))?;
        out.flush()
            .with_context(|| format!("{}: cannot write", path.display()))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("{}: cannot rename", path.display()))?;
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

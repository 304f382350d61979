//! Exploration: start the quintic's last steps (the sign projection, the hole repair) from a
//! complex exported earlier from the same scene instead of solving again
//! (`APATCH_QUINTIC_RESUME=patches.json`).
//!
//! fandisk's solve takes 40–70 minutes and 18.5 GB; its hole repair is what is left to try.
//! The system ([`System`]) and the tetrahedra are rebuilt from the scene (seconds), and the
//! solved value of every slot is read back from the exported patches' weights, which JSON
//! carries exactly (shortest round-trip decimals). The complex must come from the same scene
//! and build: the same tetrahedra, bit for bit, and one value per slot.

use super::system::{HullTet, System};
use crate::error::{Error, Result};
use std::path::Path;

/// The environment variable naming the complex to resume from.
pub const RESUME_VAR: &str = "APATCH_QUINTIC_RESUME";

/// The environment variable naming a complex whose groups too large to pin (fandisk's joint
/// group) are taken up, the stages after them solved again ([`System::preset`]).
pub const RESTAGE_VAR: &str = "APATCH_QUINTIC_RESTAGE";

/// The complex named by [`RESTAGE_VAR`], if set.
#[must_use]
pub fn restage_requested() -> Option<std::path::PathBuf> {
    std::env::var_os(RESTAGE_VAR).map(Into::into)
}

/// The complex named by [`RESUME_VAR`], if set.
#[must_use]
pub fn requested() -> Option<std::path::PathBuf> {
    std::env::var_os(RESUME_VAR).map(Into::into)
}

/// The value of every slot of `sys`, read from the patches of the complex at `path`.
///
/// # Errors
/// [`Error::Input`] naming `path` when the file cannot be read, when its patches are not
/// `tets` (count, corners, degree), or when two patches disagree on a shared slot.
pub fn slot_values(sys: &System, tets: &[HullTet], path: &Path) -> Result<Vec<f64>> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message: format!("{message} (`{RESUME_VAR}` needs a complex exported from this scene)"),
    };
    let complex = crate::complex_io::read_json_file(path)?;
    if complex.patches.len() != tets.len() {
        return Err(bad(format!(
            "{} patches, the scene builds {} tetrahedra",
            complex.patches.len(),
            tets.len()
        )));
    }
    let mut value = vec![f64::NAN; sys.keys.len()];
    for (t, (p, tet)) in complex.patches.iter().zip(tets).enumerate() {
        let same_tet = p
            .tet
            .iter()
            .zip(&tet.pts)
            .all(|(a, b)| a.map(f64::to_bits) == b.to_array().map(f64::to_bits));
        if !same_tet || p.weights.len() != sys.slot_of[t].len() {
            return Err(bad(format!("patch {t} is not the scene's tetrahedron {t}")));
        }
        for (&s, &w) in sys.slot_of[t].iter().zip(&p.weights) {
            let v = &mut value[s as usize];
            if v.is_nan() {
                *v = w;
            } else if v.to_bits() != w.to_bits() {
                return Err(bad(format!(
                    "patch {t} gives a shared weight {w:e}, another patch {v:e}"
                )));
            }
        }
    }
    Ok(value)
}

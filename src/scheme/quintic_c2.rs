//! C2 quintic A-patches on the inner simplicial hull (Bajaj, Chen, Xu 1994, §6, appendices D–E).

use crate::complex::PatchComplex;
use crate::mesh::Mesh;
use anyhow::bail;
use glam::DVec3;
use std::path::Path;

/// Builds the `quintic-c2` patch complex of `mesh` with unit vertex normals `normals`; `scheme` is
/// the scene's `[scheme]` table (its keys are this scheme's options), `scene` the scene file
/// named in errors.
///
/// # Errors
/// Unknown or bad options, and meshes the scheme cannot build, naming the file and element.
pub fn build_from_scene(
    mesh: &Mesh,
    normals: &[DVec3],
    scheme: &toml::Table,
    scene: &Path,
) -> anyhow::Result<PatchComplex> {
    let _ = (mesh, normals, scheme);
    bail!(
        "{}: scheme `quintic-c2` is not implemented yet",
        scene.display()
    )
}

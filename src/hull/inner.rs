//! The inner "corner-cutting" simplicial hull of Bajaj, Chen, Xu (1994), §3–5 and appendices
//! A–C: from a simple polyhedron with vertex normals to a smoothable simplicial hull
//! ([`SimplicialHull`], Definition 3.6).

use crate::error::{Error, Result};
use crate::hull::simplicial::SimplicialHull;
use crate::mesh::Mesh;
use glam::DVec3;

/// Shape-control parameters of the hull (§7.1).
#[derive(Clone, Debug, PartialEq)]
pub struct InnerOptions {
    /// α of the pseudo-centroid C_0 = αV + (1-α)V̄ of a non-trihedral vertex (Algorithm 1 (4)).
    pub alpha: f64,
}

impl Default for InnerOptions {
    fn default() -> Self {
        InnerOptions { alpha: 0.5 }
    }
}

/// Builds the inner simplicial hull of `mesh` (polygons, counter-clockwise from outside) with
/// unit vertex normals `normals`.
///
/// # Errors
/// Not implemented yet.
pub fn build(mesh: &Mesh, normals: &[DVec3], options: &InnerOptions) -> Result<SimplicialHull> {
    let _ = (mesh, normals, options);
    Err(Error::Invalid(
        "the inner simplicial hull (1994) is not implemented yet".into(),
    ))
}

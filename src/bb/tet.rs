//! A tetrahedron with its barycentric map (world ↔ barycentric, barycentric gradients).

use glam::DVec3;

/// A non-degenerate tetrahedron [v1 v2 v3 v4] with precomputed barycentric gradients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tet {
    /// Vertices.
    pub v: [DVec3; 4],
    /// ∇αi in world coordinates (Σ ∇αi = 0).
    pub grad: [DVec3; 4],
}

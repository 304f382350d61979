//! A tetrahedron with its barycentric map (world ↔ barycentric, barycentric gradients).

use glam::{DMat3, DVec3};

/// Tetrahedra whose |det[v1−v4, v2−v4, v3−v4]| is below this fraction of L³ (L the longest
/// edge) are rejected as degenerate. A regular tetrahedron has the ratio 1/√2; 1e-12 keeps the
/// barycentric map's condition number below ~1e12, beyond which f64 barycentrics are noise.
const MIN_RELATIVE_VOLUME: f64 = 1e-12;

/// A non-degenerate tetrahedron [v1 v2 v3 v4] with precomputed barycentric gradients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tet {
    /// Vertices.
    pub v: [DVec3; 4],
    /// ∇αi in world coordinates (Σ ∇αi = 0).
    pub grad: [DVec3; 4],
}

impl Tet {
    /// The tetrahedron with vertices `v`, or `None` when it is degenerate (relative volume
    /// below 1e-12 of the longest edge cubed) or has non-finite coordinates.
    #[must_use]
    pub fn new(v: [DVec3; 4]) -> Option<Tet> {
        if !v.iter().all(|p| p.is_finite()) {
            return None;
        }
        let e = [v[0] - v[3], v[1] - v[3], v[2] - v[3]];
        let mut longest: f64 = 0.0;
        for i in 0..4 {
            for j in i + 1..4 {
                longest = longest.max((v[i] - v[j]).length());
            }
        }
        let m = DMat3::from_cols(e[0], e[1], e[2]);
        let det = m.determinant();
        if longest == 0.0
            || det
                .abs()
                .partial_cmp(&(MIN_RELATIVE_VOLUME * longest.powi(3)))
                != Some(std::cmp::Ordering::Greater)
        {
            return None;
        }
        // Rows of M⁻¹ are ∇α1, ∇α2, ∇α3 (α = M⁻¹ (p − v4) for the first three).
        let inv = m.inverse().transpose();
        let (g0, g1, g2) = (inv.x_axis, inv.y_axis, inv.z_axis);
        Some(Tet {
            v,
            grad: [g0, g1, g2, -(g0 + g1 + g2)],
        })
    }

    /// Barycentric coordinates α of world point `p` (Σ αi = 1; all ≥ 0 inside).
    #[inline]
    #[must_use]
    pub fn bary(&self, p: DVec3) -> [f64; 4] {
        let d = p - self.v[3];
        let a0 = self.grad[0].dot(d);
        let a1 = self.grad[1].dot(d);
        let a2 = self.grad[2].dot(d);
        [a0, a1, a2, 1.0 - a0 - a1 - a2]
    }

    /// World point Σ αi vi of barycentric coordinates `a`.
    #[inline]
    #[must_use]
    pub fn point(&self, a: [f64; 4]) -> DVec3 {
        self.v[0] * a[0] + self.v[1] * a[1] + self.v[2] * a[2] + self.v[3] * a[3]
    }

    /// World gradient Σ gi ∇αi of a function whose partial derivatives with respect to the
    /// four barycentric coordinates (treated as independent variables) are `g`.
    #[inline]
    #[must_use]
    pub fn world_gradient(&self, g: [f64; 4]) -> DVec3 {
        self.grad[0] * g[0] + self.grad[1] * g[1] + self.grad[2] * g[2] + self.grad[3] * g[3]
    }

    /// World Hessian Jᵀ H J of a function whose 4×4 barycentric Hessian is `h` (J has the rows
    /// ∇αi; the barycentric map is affine, so there is no second-order term).
    #[must_use]
    pub fn world_hessian(&self, h: [[f64; 4]; 4]) -> DMat3 {
        let mut out = DMat3::ZERO;
        for (i, hi) in h.iter().enumerate() {
            // Row i of H·J as a vector: Σ_j h_ij ∇αj.
            let hj = self.world_gradient(*hi);
            // Accumulate ∇αi ⊗ hj.
            out += outer(self.grad[i], hj);
        }
        out
    }
}

/// The outer product u vᵀ.
#[inline]
fn outer(u: DVec3, v: DVec3) -> DMat3 {
    DMat3::from_cols(u * v.x, u * v.y, u * v.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Tet {
        Tet::new([
            DVec3::new(0.1, -0.3, 0.2),
            DVec3::new(2.0, 0.1, -0.4),
            DVec3::new(0.3, 1.7, 0.5),
            DVec3::new(-0.2, 0.4, 1.9),
        ])
        .expect("non-degenerate")
    }

    #[test]
    fn bary_of_vertices_is_unit() {
        let t = sample();
        for i in 0..4 {
            let a = t.bary(t.v[i]);
            for (j, aj) in a.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                // Rounding of a 3×3 inverse on O(1) coordinates.
                assert!((aj - want).abs() < 1e-13, "vertex {i} α{j} = {aj}");
            }
        }
    }

    #[test]
    fn point_inverts_bary() {
        let t = sample();
        let p = DVec3::new(0.37, 0.21, 0.66);
        let q = t.point(t.bary(p));
        // Rounding of a 3×3 inverse on O(1) coordinates.
        assert!((p - q).length() < 1e-13);
    }

    #[test]
    fn degenerate_is_rejected() {
        let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        assert!(Tet::new(flat).is_none());
        let nan = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.0, 0.0, f64::NAN),
        ];
        assert!(Tet::new(nan).is_none());
        assert!(Tet::new([DVec3::ZERO; 4]).is_none());
    }
}

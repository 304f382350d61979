//! Fair free weights for the cubic scheme (issue 7; the paper's "free weights … shape control",
//! §6–7): targets from a smooth function near the surface.
//!
//! The target is the blend of the quadratic Taylor polynomials
//! T_k(x) = c·(n_k·(x − p_k) + ½(x − p_k)ᵀ S_k (x − p_k)) at the points p_k of T of a
//! tetrahedron, with n_k the unit normal, S_k the shape operator estimated from how the
//! neighbouring normals turn ([`crate::scheme::quintic_c2::jets::estimate`], exact on a sphere)
//! and c the gradient scale: near every point of T it behaves like c × a signed distance. The
//! target of the weight at multi-index λ is the cubic blossom of each T_k at λ's domain point
//! (the multiset of tetrahedron vertices λ names), blended with the weights (λ_k + ½) of the
//! points of T in the tetrahedron, as the quintic scheme does for its free weights. A cubic whose
//! weights are a single quadratic's blossoms is that quadratic, so where the data come from one
//! quadric the surface is that quadric.
//!
//! Why: the `level` rule gives the apex-side free weights (numbers 4 and 6) one value that puts
//! the zero of F at a fixed fraction of the way from the base's centroid to the apex. The apex
//! distance is a property of the hull (far over a sharp corner of the polyhedron, near over a
//! flat region), not of the surface, so neighbouring triangles bulge by unrelated heights and
//! the surface dents at their edges (the nut's wrinkled stars, torus_quad's isophotes).
//! The targets are only where the free weights start: the sign conditions of Theorem 2.1 still
//! raise them where needed, and C¹ is untouched (every constrained weight is still computed
//! from the free ones by the same equations).

use crate::scheme::quintic_c2::jets::Jet;
use glam::DVec3;

/// The quadratic Taylor data at the points of T, scaled by the gradient scale.
#[derive(Clone, Debug)]
pub struct FairTarget {
    jets: Vec<Jet>,
    scale: f64,
}

impl FairTarget {
    /// The jets of `hull`'s points (curvature 1: the estimated shape operator), ∇F scaled by
    /// `scale`.
    #[must_use]
    pub fn new(hull: &crate::hull::simplicial::SimplicialHull, scale: f64) -> FairTarget {
        FairTarget {
            jets: crate::scheme::quintic_c2::jets::estimate(hull, 1.0),
            scale,
        }
    }

    /// The cubic blossom of point `k`'s Taylor polynomial at `args`.
    #[must_use]
    pub fn blossom(&self, k: u32, args: [DVec3; 3]) -> f64 {
        let jet = &self.jets[k as usize];
        let d = args.map(|x| x - jet.p);
        let lin = (jet.g.dot(d[0]) + jet.g.dot(d[1]) + jet.g.dot(d[2])) / 3.0;
        // Polar form of ½xᵀSx in degree 3: Σ_{a<b} ½ d_aᵀ S d_b / 3.
        let quad = (d[0].dot(jet.h * d[1]) + d[0].dot(jet.h * d[2]) + d[1].dot(jet.h * d[2])) / 6.0;
        self.scale * (lin + quad)
    }

    /// Target of the weight whose domain point is `args` in a tetrahedron whose points of T are
    /// `points` (index into the hull, multiplicity of that point in `args`): the blend of their
    /// blossoms with weights multiplicity + ½.
    #[must_use]
    pub fn weight(&self, args: [DVec3; 3], points: &[(u32, u8)]) -> f64 {
        let mut sum = 0.0;
        let mut wsum = 0.0;
        for &(k, m) in points {
            let w = f64::from(m) + 0.5;
            sum += w * self.blossom(k, args);
            wsum += w;
        }
        if wsum == 0.0 {
            0.0
        } else {
            sum / wsum
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    /// A sphere of radius 2 with exact normals: the Taylor blossom of one point reproduces the
    /// quadratic c·(|x|² − r²)/(2r) (whose gradient at p is c·n and whose Hessian is c·I/r), whose
    /// blossom at (a, b, d) is c·((a·b + a·d + b·d)/3 − r²)/(2r), computed independently.
    #[test]
    fn blossom_of_sphere_quadratic() {
        let r = 2.0;
        let c = 0.7;
        let p = DVec3::new(0.0, 0.0, r);
        let n = DVec3::Z;
        // The shape operator on the tangent plane (the quadratic's Hessian is I/r in every
        // direction; along n the jet has 0 — so compare with a quadratic flat along n).
        let h = DMat3::from_diagonal(DVec3::new(1.0 / r, 1.0 / r, 0.0));
        let t = FairTarget {
            jets: vec![Jet { p, g: n, h }],
            scale: c,
        };
        // Q(x) = c·(n·(x−p) + ½ (x−p)ᵀ h (x−p)); its blossom by polarisation.
        let q_blossom = |a: DVec3, b: DVec3, d: DVec3| {
            let (a, b, d) = (a - p, b - p, d - p);
            c * ((n.dot(a) + n.dot(b) + n.dot(d)) / 3.0
                + (a.dot(h * b) + a.dot(h * d) + b.dot(h * d)) / 6.0)
        };
        let args = [
            DVec3::new(0.3, -0.2, 1.9),
            DVec3::new(1.0, 0.5, 1.5),
            DVec3::new(0.0, 0.0, 3.0),
        ];
        // Round-off on O(1) values.
        assert!((t.blossom(0, args) - q_blossom(args[0], args[1], args[2])).abs() < 1e-14);
        // On the diagonal the blossom is the quadratic: Q(p + (1, 0, 0)) = c/(2r).
        let x = p + DVec3::X;
        assert!((t.blossom(0, [x, x, x]) - c / (2.0 * r)).abs() < 1e-14);
        assert!((t.weight([x, x, x], &[(0, 3)]) - c / (2.0 * r)).abs() < 1e-14);
    }
}

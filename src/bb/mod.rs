//! Bernstein–Bézier math: multi-indices, trivariate BB polynomials on a tetrahedron, and
//! univariate Bernstein polynomials with a robust first-root finder.
//!
//! Knows nothing of meshes, hulls or rays. The trivariate routines also exist on plain
//! coefficient slices in [`poly`] for callers with their own storage.

// Index loops mirror the formulas (multi-index and matrix subscripts) in this module tree.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3};

pub mod poly;
pub mod rational;
pub mod tet;
pub mod uni;

pub use tet::Tet;

/// Number of BB coefficients of a trivariate polynomial of degree `n`: C(n+3, 3).
#[must_use]
pub const fn num_coeffs(n: usize) -> usize {
    (n + 1) * (n + 2) * (n + 3) / 6
}

/// All multi-indices λ with |λ| = n in decreasing lexicographic order
/// ((n,0,0,0), (n-1,1,0,0), (n-1,0,1,0), (n-1,0,0,1), (n-2,2,0,0), …, (0,0,0,n)).
#[must_use]
pub fn multi_indices(n: usize) -> Vec<[u8; 4]> {
    let mut out = Vec::with_capacity(num_coeffs(n));
    for a in (0..=n).rev() {
        for b in (0..=n - a).rev() {
            for c in (0..=n - a - b).rev() {
                out.push([a as u8, b as u8, c as u8, (n - a - b - c) as u8]);
            }
        }
    }
    out
}

/// Position of multi-index `lambda` (|λ| = n) in the order of [`multi_indices`].
#[must_use]
pub fn index_of(lambda: [u8; 4]) -> usize {
    let [a, b, c, _] = lambda.map(usize::from);
    let n: usize = lambda.iter().map(|&x| usize::from(x)).sum();
    // Indices whose first component exceeds a: C(n-a+2, 3) of them.
    let before_a = (n - a) * (n - a + 1) * (n - a + 2) / 6;
    // Among first = a, those whose second component exceeds b.
    let m = n - a;
    let before_b = (m - b) * (m - b + 1) / 2;
    // Among first = a, second = b, those whose third component exceeds c.
    let before_c = m - b - c;
    before_a + before_b + before_c
}

/// A trivariate polynomial of degree `degree` in BB form over barycentric coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct BbPoly {
    /// Degree n.
    pub degree: usize,
    /// C(n+3,3) coefficients in multi-index order.
    pub coeffs: Vec<f64>,
}

impl BbPoly {
    /// The polynomial of degree `degree` with `coeffs` in multi-index order.
    ///
    /// # Panics
    /// When `coeffs.len() != C(degree+3, 3)`.
    #[must_use]
    pub fn new(degree: usize, coeffs: Vec<f64>) -> BbPoly {
        assert_eq!(
            coeffs.len(),
            num_coeffs(degree),
            "degree {degree} needs {} BB coefficients",
            num_coeffs(degree)
        );
        BbPoly { degree, coeffs }
    }

    /// F(α) by de Casteljau.
    #[must_use]
    pub fn eval(&self, a: [f64; 4]) -> f64 {
        poly::eval(self.degree, &self.coeffs, a)
    }

    /// The blossom b(`args[0]`, …, `args[n−1]`); `args.len()` must equal the degree.
    #[must_use]
    pub fn blossom(&self, args: &[[f64; 4]]) -> f64 {
        poly::blossom(self.degree, &self.coeffs, args)
    }

    /// The same function written in degree + 1.
    #[must_use]
    pub fn elevate(&self) -> BbPoly {
        BbPoly {
            degree: self.degree + 1,
            coeffs: poly::elevate(self.degree, &self.coeffs),
        }
    }

    /// World-space ∇F at barycentric point `a` of `tet`.
    #[must_use]
    pub fn gradient(&self, tet: &Tet, a: [f64; 4]) -> DVec3 {
        tet.world_gradient(poly::gradient_bary(self.degree, &self.coeffs, a))
    }

    /// World-space Hessian of F at barycentric point `a` of `tet`.
    #[must_use]
    pub fn hessian(&self, tet: &Tet, a: [f64; 4]) -> DMat3 {
        tet.world_hessian(poly::hessian_bary(self.degree, &self.coeffs, a))
    }

    /// Writes the n+1 univariate Bernstein coefficients of s ↦ F((1−s)·a0 + s·a1), s ∈ \[0, 1\],
    /// into `out` and returns n+1 (no allocation up to degree [`poly::STACK_DEGREE`]).
    pub fn restrict(&self, a0: [f64; 4], a1: [f64; 4], out: &mut [f64]) -> usize {
        poly::restrict(self.degree, &self.coeffs, a0, a1, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_round_trip() {
        for n in 0..=7 {
            let idx = multi_indices(n);
            assert_eq!(idx.len(), num_coeffs(n));
            for (k, l) in idx.iter().enumerate() {
                assert_eq!(index_of(*l), k, "n={n} λ={l:?}");
            }
        }
    }
}

//! Bernstein–Bézier math: multi-indices, trivariate BB polynomials on a tetrahedron, and
//! univariate Bernstein polynomials with a robust first-root finder.
//!
//! This file fixes the API the rest of the crate codes against; bodies are filled by the `bb`
//! work (issue 2). Knows nothing of meshes, hulls or rays.

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

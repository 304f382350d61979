//! Evaluation of a patch for measuring: F, its gradient and Hessian in barycentric space (F as
//! a function of four independent α) and in world space.
//!
//! The polynomial part uses de Casteljau steps down to degree 2: with c the remaining quadratic
//! BB coefficients (blossom values b[α^(n−2), e_i, e_j]), ∂²F/∂αi∂αj = n(n−1)·c_ij,
//! ∂F/∂αi = n·Σ_j c_ij αj and F = Σ_ij αi c_ij αj. Rational terms (Σ w_m α^μm)/(Σ α^μm)·B^n_κ
//! are differentiated with the quotient and product rules; where their denominator vanishes (on
//! an edge or vertex of the tetrahedron) the term is taken as its limit 0 (B^n_κ vanishes
//! faster there, see [`crate::complex::RationalTerm`]).
//!
//! This evaluator is deliberately independent of `bb` (plain sums, no shared tables beyond the
//! multi-index order), so the checker also cross-checks the tracer's arithmetic.

// Index loops over the four barycentric coordinates read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::bb::{index_of, multi_indices, num_coeffs};
use crate::complex::{Patch, RationalTerm};
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Value, gradient and Hessian of F with respect to the four barycentric coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaryJet {
    /// F(α).
    pub value: f64,
    /// ∂F/∂αi.
    pub grad: [f64; 4],
    /// ∂²F/∂αi∂αj.
    pub hess: [[f64; 4]; 4],
}

/// Value, gradient and Hessian of F in world coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorldJet {
    /// F(x).
    pub value: f64,
    /// ∇F(x).
    pub grad: DVec3,
    /// Hessian of F at x.
    pub hess: DMat3,
}

/// A patch prepared for evaluation: its barycentric gradients ∇αi.
#[derive(Clone, Copy, Debug)]
pub struct PatchEval<'a> {
    /// The patch.
    pub patch: &'a Patch,
    /// Its index in the complex (for reports).
    pub id: usize,
    /// ∇αi in world coordinates.
    pub bary_grad: [DVec3; 4],
}

impl<'a> PatchEval<'a> {
    /// Prepares `patch`, number `id` of its complex (it must have passed
    /// [`crate::complex_io::validate_patch`]).
    #[must_use]
    pub fn new(patch: &'a Patch, id: usize) -> Self {
        let v = patch.tet_points();
        let m = DMat3::from_cols(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
        let inv_t = m.inverse().transpose();
        let g1 = inv_t.col(0);
        let g2 = inv_t.col(1);
        let g3 = inv_t.col(2);
        PatchEval {
            patch,
            id,
            bary_grad: [-(g1 + g2 + g3), g1, g2, g3],
        }
    }

    /// Barycentric coordinates of `x` (Σ = 1).
    #[must_use]
    pub fn bary(&self, x: DVec3) -> [f64; 4] {
        let d = x - DVec3::from_array(self.patch.tet[0]);
        let a1 = self.bary_grad[1].dot(d);
        let a2 = self.bary_grad[2].dot(d);
        let a3 = self.bary_grad[3].dot(d);
        [1.0 - a1 - a2 - a3, a1, a2, a3]
    }

    /// F at barycentric `alpha`.
    #[must_use]
    pub fn value(&self, alpha: [f64; 4]) -> f64 {
        let p = self.patch;
        let mut f = poly_value(&p.weights, usize::from(p.degree), alpha);
        for r in &p.rational {
            f += rational_value(r, usize::from(p.degree), alpha);
        }
        f
    }

    /// Barycentric jet of F at `alpha`.
    #[must_use]
    pub fn bary_jet(&self, alpha: [f64; 4]) -> BaryJet {
        let p = self.patch;
        let n = usize::from(p.degree);
        let mut j = poly_jet(&p.weights, n, alpha);
        for r in &p.rational {
            let t = rational_jet(r, n, alpha);
            j.value += t.value;
            for a in 0..4 {
                j.grad[a] += t.grad[a];
                for b in 0..4 {
                    j.hess[a][b] += t.hess[a][b];
                }
            }
        }
        j
    }

    /// World-space jet of F at barycentric `alpha`.
    #[must_use]
    pub fn world_jet(&self, alpha: [f64; 4]) -> WorldJet {
        let b = self.bary_jet(alpha);
        let g = &self.bary_grad;
        let mut grad = DVec3::ZERO;
        let mut hess = DMat3::ZERO;
        for i in 0..4 {
            grad += b.grad[i] * g[i];
            // Σ_j h_ij ∇αj, then the outer product with ∇αi.
            let mut row = DVec3::ZERO;
            for j in 0..4 {
                row += b.hess[i][j] * g[j];
            }
            hess += DMat3::from_cols(g[i] * row.x, g[i] * row.y, g[i] * row.z);
        }
        WorldJet {
            value: b.value,
            grad,
            hess,
        }
    }

    /// The patch's hull role and mesh element, e.g. "face 12", as the reports name it.
    #[must_use]
    pub fn element(&self) -> String {
        format!("{} {}", self.patch.role.name(), self.patch.element)
    }

    /// The largest magnitude among the patch's weights (polynomial and rational): the scale
    /// against which values of F are judged.
    #[must_use]
    pub fn weight_scale(&self) -> f64 {
        let p = self.patch;
        let mut s = p.weights.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        for r in &p.rational {
            for (w, _) in &r.terms {
                s = s.max(w.abs());
            }
        }
        s
    }

    /// True when F cannot vanish in the closed tetrahedron: every BB coefficient (with each
    /// rational term's blended weight bounded by its extreme weights) has the same strict sign.
    #[must_use]
    pub fn has_no_zero(&self) -> bool {
        let p = self.patch;
        let mut lo = p.weights.clone();
        let mut hi = p.weights.clone();
        for r in &p.rational {
            let k = index_of(r.index);
            let (mn, mx) = r
                .terms
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (w, _)| {
                    (a.min(*w), b.max(*w))
                });
            lo[k] += mn;
            hi[k] += mx;
        }
        lo.iter().all(|&w| w > 0.0) || hi.iter().all(|&w| w < 0.0)
    }
}

/// For each degree m in 1..=7 and each multi-index μ of degree m−1 (in order), the positions of
/// μ + e_i in the degree-m order.
fn raise_tables() -> &'static [Vec<[u16; 4]>] {
    static TABLES: OnceLock<Vec<Vec<[u16; 4]>>> = OnceLock::new();
    TABLES.get_or_init(|| {
        (0..=8usize)
            .map(|m| {
                if m == 0 {
                    return Vec::new();
                }
                multi_indices(m - 1)
                    .into_iter()
                    .map(|mu| {
                        std::array::from_fn(|i| {
                            let mut l = mu;
                            l[i] += 1;
                            index_of(l) as u16
                        })
                    })
                    .collect()
            })
            .collect()
    })
}

/// de Casteljau: reduces degree-`from` coefficients to degree `to` at α (in place, prefix).
fn de_casteljau(c: &mut [f64], from: usize, to: usize, alpha: [f64; 4]) {
    let tables = raise_tables();
    for m in (to + 1..=from).rev() {
        let table = &tables[m];
        // Output index k < input indices table[k][i] (k ≤ table[k][0]), so in-place is safe.
        for (k, up) in table.iter().enumerate() {
            c[k] = alpha[0] * c[usize::from(up[0])]
                + alpha[1] * c[usize::from(up[1])]
                + alpha[2] * c[usize::from(up[2])]
                + alpha[3] * c[usize::from(up[3])];
        }
    }
}

/// Σ w_λ B^n_λ(α).
#[must_use]
pub fn poly_value(weights: &[f64], n: usize, alpha: [f64; 4]) -> f64 {
    debug_assert_eq!(weights.len(), num_coeffs(n));
    let mut c = [0.0; 120];
    c[..weights.len()].copy_from_slice(weights);
    de_casteljau(&mut c, n, 0, alpha);
    c[0]
}

/// Barycentric jet of Σ w_λ B^n_λ(α).
#[must_use]
pub fn poly_jet(weights: &[f64], n: usize, alpha: [f64; 4]) -> BaryJet {
    debug_assert_eq!(weights.len(), num_coeffs(n));
    if n == 1 {
        let g = [weights[0], weights[1], weights[2], weights[3]];
        return BaryJet {
            value: (0..4).map(|i| g[i] * alpha[i]).sum(),
            grad: g,
            hess: [[0.0; 4]; 4],
        };
    }
    let mut c = [0.0; 120];
    c[..weights.len()].copy_from_slice(weights);
    de_casteljau(&mut c, n, 2, alpha);
    // Quadratic order: 2000 1100 1010 1001 0200 0110 0101 0020 0011 0002.
    let q = [
        [c[0], c[1], c[2], c[3]],
        [c[1], c[4], c[5], c[6]],
        [c[2], c[5], c[7], c[8]],
        [c[3], c[6], c[8], c[9]],
    ];
    let nf = n as f64;
    let mut j = BaryJet::default();
    for i in 0..4 {
        let qa: f64 = (0..4).map(|k| q[i][k] * alpha[k]).sum();
        j.grad[i] = nf * qa;
        j.value += alpha[i] * qa;
        for k in 0..4 {
            j.hess[i][k] = nf * (nf - 1.0) * q[i][k];
        }
    }
    j
}

/// αi^k, with 0 for negative k (the derivative factor is then 0 anyway).
fn pow(a: f64, k: i32) -> f64 {
    if k < 0 {
        0.0
    } else {
        a.powi(k)
    }
}

/// Barycentric jet of c·α^μ.
fn monomial_jet(c: f64, mu: [u8; 4], alpha: [f64; 4]) -> BaryJet {
    let e = mu.map(i32::from);
    let mut j = BaryJet::default();
    let prod_except = |skip: &[usize], exps: [i32; 4]| -> f64 {
        (0..4)
            .filter(|i| !skip.contains(i))
            .map(|i| pow(alpha[i], exps[i]))
            .product()
    };
    j.value = c * prod_except(&[], e);
    for i in 0..4 {
        if e[i] == 0 {
            continue;
        }
        let ei = f64::from(e[i]);
        j.grad[i] = c * ei * pow(alpha[i], e[i] - 1) * prod_except(&[i], e);
        j.hess[i][i] = c * ei * (ei - 1.0) * pow(alpha[i], e[i] - 2) * prod_except(&[i], e);
        for k in 0..4 {
            if k != i && e[k] > 0 {
                j.hess[i][k] = c
                    * ei
                    * f64::from(e[k])
                    * pow(alpha[i], e[i] - 1)
                    * pow(alpha[k], e[k] - 1)
                    * prod_except(&[i, k], e);
            }
        }
    }
    j
}

/// n!/(κ1!κ2!κ3!κ4!).
fn multinomial(n: usize, kappa: [u8; 4]) -> f64 {
    let fact = |k: usize| (1..=k).map(|x| x as f64).product::<f64>();
    fact(n) / kappa.iter().map(|&k| fact(usize::from(k))).product::<f64>()
}

/// Value of one rational term at α.
fn rational_value(r: &RationalTerm, n: usize, alpha: [f64; 4]) -> f64 {
    let mono = |mu: [u8; 4]| {
        (0..4)
            .map(|i| alpha[i].powi(i32::from(mu[i])))
            .product::<f64>()
    };
    let d: f64 = r.terms.iter().map(|(_, mu)| mono(*mu)).sum();
    if d <= 0.0 || !d.is_finite() {
        return 0.0;
    }
    let num: f64 = r.terms.iter().map(|(w, mu)| w * mono(*mu)).sum();
    num / d * multinomial(n, r.index) * mono(r.index)
}

/// Barycentric jet of one rational term at α.
fn rational_jet(r: &RationalTerm, n: usize, alpha: [f64; 4]) -> BaryJet {
    let mut num = BaryJet::default();
    let mut den = BaryJet::default();
    for (w, mu) in &r.terms {
        add(&mut num, &monomial_jet(*w, *mu, alpha));
        add(&mut den, &monomial_jet(1.0, *mu, alpha));
    }
    if den.value <= 0.0 || !den.value.is_finite() {
        return BaryJet::default();
    }
    let b = monomial_jet(multinomial(n, r.index), r.index, alpha);
    // Q = N/D: Q_i = (N_i − Q D_i)/D; Q_ij = (N_ij − Q_i D_j − Q_j D_i − Q D_ij)/D.
    let d = den.value;
    let mut q = BaryJet {
        value: num.value / d,
        ..BaryJet::default()
    };
    for i in 0..4 {
        q.grad[i] = (num.grad[i] - q.value * den.grad[i]) / d;
    }
    for i in 0..4 {
        for k in 0..4 {
            q.hess[i][k] = (num.hess[i][k]
                - q.grad[i] * den.grad[k]
                - q.grad[k] * den.grad[i]
                - q.value * den.hess[i][k])
                / d;
        }
    }
    // R = Q·B.
    let mut out = BaryJet {
        value: q.value * b.value,
        ..BaryJet::default()
    };
    for i in 0..4 {
        out.grad[i] = q.grad[i] * b.value + q.value * b.grad[i];
        for k in 0..4 {
            out.hess[i][k] = q.hess[i][k] * b.value
                + q.grad[i] * b.grad[k]
                + q.grad[k] * b.grad[i]
                + q.value * b.hess[i][k];
        }
    }
    out
}

fn add(acc: &mut BaryJet, t: &BaryJet) {
    acc.value += t.value;
    for i in 0..4 {
        acc.grad[i] += t.grad[i];
        for k in 0..4 {
            acc.hess[i][k] += t.hess[i][k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{kuhn_tets, plain_patch as patch, quadric_weights, Quadric};

    /// The quadric's exact value, gradient and Hessian are the truth for every degree.
    #[test]
    fn quadric_jets_match_analytic() {
        let q = Quadric::ellipsoid(DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.0, 2.0, 0.5));
        let tet = kuhn_tets(DVec3::new(-0.5, -0.3, 0.1), DVec3::new(0.7, 0.4, 0.6))[3];
        for n in 2..=7 {
            let p = patch(tet, n, quadric_weights(&q, &tet, n));
            let e = PatchEval::new(&p, 0);
            for alpha in [[0.25; 4], [0.1, 0.2, 0.3, 0.4], [1.0, 0.0, 0.0, 0.0]] {
                let x: DVec3 = (0..4).map(|i| alpha[i] * tet[i]).sum();
                let j = e.world_jet(alpha);
                // Rounding of a few dozen O(10) operations: 1e-12 absolute is ample.
                assert!((j.value - q.value(x)).abs() < 1e-12, "n={n} value");
                assert!(
                    (e.value(alpha) - q.value(x)).abs() < 1e-12,
                    "n={n} value-only"
                );
                assert!((j.grad - q.gradient(x)).length() < 1e-11, "n={n} grad");
                let h = 2.0 * q.a;
                assert!(
                    (j.hess - h).abs().to_cols_array().iter().all(|d| *d < 1e-9),
                    "n={n}"
                );
                // Barycentric coordinates of x reproduce alpha.
                let b = e.bary(x);
                assert!((0..4).all(|i| (b[i] - alpha[i]).abs() < 1e-12));
            }
        }
    }

    /// Rational-term jets against central finite differences of the value.
    #[test]
    fn rational_jet_matches_finite_differences() {
        let tet = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(0.2, 1.0, 0.1),
            DVec3::new(0.1, 0.3, 1.2),
        ];
        let mut p = patch(tet, 3, (0..20).map(|k| (k as f64 * 0.37).sin()).collect());
        p.rational.push(RationalTerm {
            index: [1, 1, 1, 0],
            terms: [
                (0.7, [0, 1, 1, 0]),
                (-0.4, [1, 0, 1, 0]),
                (1.3, [1, 1, 0, 0]),
            ]
            .into(),
        });
        p.rational.push(RationalTerm {
            index: [1, 1, 0, 1],
            terms: [(0.5, [1, 0, 0, 0]), (-0.9, [0, 0, 0, 1])].into(),
        });
        let e = PatchEval::new(&p, 0);
        let x0 = DVec3::new(0.35, 0.3, 0.25);
        let j = e.world_jet(e.bary(x0));
        let f = |x: DVec3| e.value(e.bary(x));
        let h = 1e-5;
        for (axis, unit) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
            let fd = (f(x0 + h * unit) - f(x0 - h * unit)) / (2.0 * h);
            // Central differences: O(h²) ≈ 1e-10 truncation plus 1e-16/h rounding.
            assert!(
                (fd - j.grad[axis]).abs() < 1e-8,
                "grad {axis}: {fd} vs {}",
                j.grad[axis]
            );
            let g = |x: DVec3| e.world_jet(e.bary(x)).grad;
            let hd = (g(x0 + h * unit) - g(x0 - h * unit)) / (2.0 * h);
            assert!((hd - j.hess.col(axis)).length() < 1e-7, "hess {axis}");
        }
        assert!((j.value - f(x0)).abs() < 1e-14);
    }
}

//! The rational terms of the 2001 scheme: (Σ w_m α^μm)/(Σ α^μm) · B^n_κ(α).
//!
//! Write N = Σ w_m α^μm (numerator), D = Σ α^μm (denominator), q = N/D and
//! B = B^n_κ = n!/κ! α^κ. D > 0 inside the tetrahedron except on the edges where it vanishes;
//! there B vanishes to higher order, so the term and its derivatives tend to 0. Wherever
//! |D| < [`MIN_DENOMINATOR`] the term is taken to be 0 (value, gradient and Hessian), which
//! never produces NaN.
//!
//! On a segment, F·Π D_g (the product over the *distinct* denominators of a patch's terms) is a
//! polynomial: [`segment_poly`] computes its Bernstein coefficients.

use super::{poly, uni};
use crate::complex::RationalTerm;

/// Below this |D| the term counts as on a vanishing edge and contributes 0. At this size the
/// term is below 1e-100 of the weights' scale (B vanishes faster than D), so dropping it is
/// exact in f64 while it keeps 1/D far from overflow.
pub const MIN_DENOMINATOR: f64 = 1e-100;

/// Most distinct denominators [`segment_poly`] clears at once.
pub const MAX_DENOMINATORS: usize = 4;

/// Value, barycentric gradient and barycentric Hessian of a function of (α1..α4).
pub type Jet = (f64, [f64; 4], [[f64; 4]; 4]);

/// n!/(κ1!κ2!κ3!κ4!).
#[must_use]
pub fn multinomial(kappa: [u8; 4]) -> f64 {
    let fact = |k: u32| (1..=k).fold(1.0, |acc, i| acc * f64::from(i));
    let n: u32 = kappa.iter().map(|&k| u32::from(k)).sum();
    kappa
        .iter()
        .fold(fact(n), |acc, &k| acc / fact(u32::from(k)))
}

/// α^μ with its derivatives with respect to α1..α4 (treated as independent).
#[must_use]
pub fn monomial_jet(mu: [u8; 4], a: [f64; 4]) -> Jet {
    let mut p = [1.0; 4];
    let mut dp = [0.0; 4];
    let mut ddp = [0.0; 4];
    for i in 0..4 {
        let e = i32::from(mu[i]);
        p[i] = a[i].powi(e);
        if e >= 1 {
            dp[i] = f64::from(e) * a[i].powi(e - 1);
        }
        if e >= 2 {
            ddp[i] = f64::from(e * (e - 1)) * a[i].powi(e - 2);
        }
    }
    let prod_except = |skip: &[usize]| {
        (0..4)
            .filter(|k| !skip.contains(k))
            .fold(1.0, |acc, k| acc * p[k])
    };
    let v = prod_except(&[]);
    let mut g = [0.0; 4];
    let mut h = [[0.0; 4]; 4];
    for i in 0..4 {
        g[i] = dp[i] * prod_except(&[i]);
        h[i][i] = ddp[i] * prod_except(&[i]);
        for j in 0..i {
            let x = dp[i] * dp[j] * prod_except(&[i, j]);
            h[i][j] = x;
            h[j][i] = x;
        }
    }
    (v, g, h)
}

/// Σ_m w_m α^μm (numerator, `weighted`) or Σ_m α^μm (denominator) with derivatives.
fn sum_jet(term: &RationalTerm, a: [f64; 4], weighted: bool) -> Jet {
    let mut out: Jet = (0.0, [0.0; 4], [[0.0; 4]; 4]);
    for &(w, mu) in &term.terms {
        let k = if weighted { w } else { 1.0 };
        let (v, g, h) = monomial_jet(mu, a);
        out.0 += k * v;
        for i in 0..4 {
            out.1[i] += k * g[i];
            for j in 0..4 {
                out.2[i][j] += k * h[i][j];
            }
        }
    }
    out
}

/// The whole term (N/D)·B^n_κ(α) at barycentric `a` for a patch of degree `degree`
/// (|κ| must equal `degree`); 0 where |D| < [`MIN_DENOMINATOR`].
#[must_use]
pub fn term_value(term: &RationalTerm, degree: usize, a: [f64; 4]) -> f64 {
    debug_assert_eq!(
        term.index.iter().map(|&k| usize::from(k)).sum::<usize>(),
        degree
    );
    let mut num = 0.0;
    let mut den = 0.0;
    for &(w, mu) in &term.terms {
        let m = monomial_jet_value(mu, a);
        num += w * m;
        den += m;
    }
    if den.abs() < MIN_DENOMINATOR {
        return 0.0;
    }
    num / den * multinomial(term.index) * monomial_jet_value(term.index, a)
}

#[inline]
fn monomial_jet_value(mu: [u8; 4], a: [f64; 4]) -> f64 {
    (0..4).fold(1.0, |acc, i| acc * a[i].powi(i32::from(mu[i])))
}

/// The term with its exact barycentric gradient and Hessian (quotient and product rules);
/// all 0 where |D| < [`MIN_DENOMINATOR`].
#[must_use]
pub fn term_jet(term: &RationalTerm, degree: usize, a: [f64; 4]) -> Jet {
    debug_assert_eq!(
        term.index.iter().map(|&k| usize::from(k)).sum::<usize>(),
        degree
    );
    let (n, gn, hn) = sum_jet(term, a, true);
    let (d, gd, hd) = sum_jet(term, a, false);
    if d.abs() < MIN_DENOMINATOR {
        return (0.0, [0.0; 4], [[0.0; 4]; 4]);
    }
    let c = multinomial(term.index);
    let (b, gb, hb) = monomial_jet(term.index, a);
    let (b, gb, hb) = (c * b, gb.map(|x| c * x), hb.map(|r| r.map(|x| c * x)));
    // q = N/D, ∇q = (∇N − q∇D)/D, Hq = (HN − q HD − ∇q∇Dᵀ − ∇D∇qᵀ)/D.
    let q = n / d;
    let gq: [f64; 4] = std::array::from_fn(|i| (gn[i] - q * gd[i]) / d);
    let hq: [[f64; 4]; 4] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (hn[i][j] - q * hd[i][j] - gq[i] * gd[j] - gd[i] * gq[j]) / d)
    });
    // R = q·B: ∇R = B∇q + q∇B, HR = B Hq + ∇q∇Bᵀ + ∇B∇qᵀ + q HB.
    let g = std::array::from_fn(|i| b * gq[i] + q * gb[i]);
    let h = std::array::from_fn(|i| {
        std::array::from_fn(|j| b * hq[i][j] + gq[i] * gb[j] + gb[i] * gq[j] + q * hb[i][j])
    });
    (q * b, g, h)
}

/// True when the two terms have the same denominator (the same set of monomials μm).
#[must_use]
pub fn same_denominator(a: &RationalTerm, b: &RationalTerm) -> bool {
    a.terms.len() == b.terms.len()
        && a.terms
            .iter()
            .all(|(_, m)| b.terms.iter().any(|(_, k)| k == m))
}

/// Degree of a term's numerator and denominator (the largest |μm|).
#[must_use]
pub fn denominator_degree(term: &RationalTerm) -> usize {
    term.terms
        .iter()
        .map(|(_, mu)| mu.iter().map(|&k| usize::from(k)).sum::<usize>())
        .max()
        .unwrap_or(0)
}

/// Degree of the cleared segment polynomial: n + Σ over distinct denominators of their degree.
#[must_use]
pub fn segment_degree(degree: usize, rational: &[RationalTerm]) -> usize {
    let mut total = degree;
    for (r, term) in rational.iter().enumerate() {
        if !rational[..r].iter().any(|t| same_denominator(t, term)) {
            total += denominator_degree(term);
        }
    }
    total
}

/// Coefficients (length e+1) of α^μ along α(s) = (1−s)a0 + s·a1, elevated to degree `e`.
#[inline]
fn monomial_on_segment(mu: [u8; 4], a0: [f64; 4], a1: [f64; 4], e: usize, out: &mut [f64]) {
    // The denominators of the 2001 scheme are sums of α_i and α_iα_j: write those directly.
    let degree: usize = mu.iter().map(|&k| usize::from(k)).sum();
    if degree == e && (1..=2).contains(&degree) {
        let mut factors = [0usize; 2];
        let mut k = 0;
        for i in 0..4 {
            for _ in 0..mu[i] {
                factors[k] = i;
                k += 1;
            }
        }
        let (i, j) = (factors[0], factors[1]);
        if degree == 1 {
            out[0] = a0[i];
            out[1] = a1[i];
        } else {
            out[0] = a0[i] * a0[j];
            out[1] = 0.5 * (a0[i] * a1[j] + a1[i] * a0[j]);
            out[2] = a1[i] * a1[j];
        }
        return;
    }
    let mut len = 1;
    out[0] = 1.0;
    for i in 0..4 {
        for _ in 0..mu[i] {
            // Multiply by the linear factor with Bernstein coefficients [a0_i, a1_i].
            let inv = 1.0 / len as f64; // 1/(new degree)
            out[len] = a1[i] * out[len - 1];
            for j in (1..len).rev() {
                let w = j as f64 * inv;
                out[j] = w * a1[i] * out[j - 1] + (1.0 - w) * a0[i] * out[j];
            }
            out[0] *= a0[i];
            len += 1;
        }
    }
    while len < e + 1 {
        len = uni::elevate_in_place(out, len);
    }
}

/// Σ_m (w_m or 1)·α^μm along the segment, degree `e`.
fn sum_on_segment(
    term: &RationalTerm,
    a0: [f64; 4],
    a1: [f64; 4],
    e: usize,
    weighted: bool,
) -> [f64; 16] {
    let mut out = [0.0; 16];
    let mut m = [0.0; 16];
    for &(w, mu) in &term.terms {
        monomial_on_segment(mu, a0, a1, e, &mut m);
        let k = if weighted { w } else { 1.0 };
        for j in 0..=e {
            out[j] += k * m[j];
        }
    }
    out
}

/// Bernstein coefficients in s ∈ \[0, 1\] of F(α(s))·Π_g D_g(α(s)), α(s) = (1−s)a0 + s·a1, where
/// F is the polynomial (degree `degree`, `weights`) plus the `rational` terms and the product
/// runs over their distinct denominators. Writes them to `out` and returns their number
/// (degree + 1 without rational terms). No heap allocation.
///
/// # Panics
/// When the cleared degree ([`segment_degree`]) exceeds 15 or there are more than
/// [`MAX_DENOMINATORS`] distinct denominators.
pub fn segment_poly(
    degree: usize,
    weights: &[f64],
    rational: &[RationalTerm],
    a0: [f64; 4],
    a1: [f64; 4],
    out: &mut [f64; 16],
) -> usize {
    let len = poly::restrict(degree, weights, a0, a1, out);
    if rational.is_empty() {
        return len;
    }
    // Distinct denominators along the segment.
    let mut dens = [[0.0; 16]; MAX_DENOMINATORS];
    let mut den_len = [0usize; MAX_DENOMINATORS];
    let mut group = [0usize; 16];
    let mut first = [0usize; MAX_DENOMINATORS];
    let mut ng = 0;
    for (r, term) in rational.iter().enumerate() {
        let g = (0..ng).find(|&g| same_denominator(&rational[first[g]], term));
        let g = g.unwrap_or_else(|| {
            assert!(
                ng < MAX_DENOMINATORS,
                "more than {MAX_DENOMINATORS} distinct rational denominators"
            );
            let e = denominator_degree(term);
            dens[ng] = sum_on_segment(term, a0, a1, e, false);
            den_len[ng] = e + 1;
            first[ng] = r;
            ng += 1;
            ng - 1
        });
        if r < group.len() {
            group[r] = g;
        }
    }
    let total = degree + den_len[..ng].iter().map(|l| l - 1).sum::<usize>();
    assert!(
        total <= 15,
        "cleared segment polynomial of degree {total} exceeds 15"
    );
    // Polynomial part times every denominator.
    let mut acc = [0.0; 16];
    let mut tmp = [0.0; 16];
    let mut acc_len = len;
    acc[..len].copy_from_slice(&out[..len]);
    for g in 0..ng {
        acc_len = uni::multiply_into(&acc[..acc_len], &dens[g][..den_len[g]], &mut tmp);
        acc[..acc_len].copy_from_slice(&tmp[..acc_len]);
    }
    // Each rational term: N_r·B_r times the other denominators.
    let mut bk = [0.0; 16];
    let mut t = [0.0; 16];
    for (r, term) in rational.iter().enumerate() {
        let g = if r < group.len() {
            group[r]
        } else {
            (0..ng)
                .find(|&g| same_denominator(&rational[first[g]], term))
                .unwrap_or(0)
        };
        let e = den_len[g] - 1;
        let num = sum_on_segment(term, a0, a1, e, true);
        monomial_on_segment(term.index, a0, a1, degree, &mut bk);
        let c = multinomial(term.index);
        for x in &mut bk[..=degree] {
            *x *= c;
        }
        let mut t_len = uni::multiply_into(&num[..=e], &bk[..=degree], &mut t);
        for h in (0..ng).filter(|&h| h != g) {
            t_len = uni::multiply_into(&t[..t_len], &dens[h][..den_len[h]], &mut tmp);
            t[..t_len].copy_from_slice(&tmp[..t_len]);
        }
        debug_assert_eq!(t_len, acc_len);
        for j in 0..acc_len {
            acc[j] += t[j];
        }
    }
    out[..acc_len].copy_from_slice(&acc[..acc_len]);
    acc_len
}

//! The tracer's compiled form of the patches: barycentric maps, weights and rational terms
//! packed into shared arrays for the hot loop. Restriction of F to a segment (univariate
//! Bernstein coefficients, rational denominators cleared) and value/gradient/Hessian at a point.
//!
//! Memory: one [`PatchHeader`] per patch (barycentric map, tolerances, small-integer degrees
//! and sheet masks, an offset into the shared f64 array), the patch's BB weights followed by
//! its rational numerator weights in one shared `Vec<f64>`, and the integer structure of the
//! rational terms (κ, monomials μ) interned once per distinct shape ([`RationalForm`]): every
//! face patch of the 2001 scheme shares one form, every edge patch another.

// Index loops over the four barycentric components read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use crate::bb::rational::{monomial_jet, multinomial, MIN_DENOMINATOR};
use crate::bb::{index_of, multi_indices, num_coeffs, poly, uni};
use crate::complex::{Patch, SheetRule};
use glam::{DMat3, DVec3};

/// Relative size of an empty ray interval [t0, t1] (t0 > t1) still treated as a touching point.
const CLIP_SLACK: f64 = 1e-12;

/// Highest degree a segment polynomial may have (the stack limit of [`uni::first_root_in_tol`]).
pub const MAX_DEGREE: usize = uni::STACK_LEN - 1;

/// Coefficient storage for one segment polynomial.
pub type Coeffs = [f64; MAX_DEGREE + 1];

/// Largest polynomial degree a patch may have.
pub const MAX_PATCH_DEGREE: usize = 7;
const MAX_COEFFS: usize = num_coeffs(MAX_PATCH_DEGREE);

/// Position of e_i + e_j among the degree-2 multi-indices.
const IDX2: [[usize; 4]; 4] = [[0, 1, 2, 3], [1, 4, 5, 6], [2, 5, 7, 8], [3, 6, 8, 9]];

/// Which roots of F inside the tetrahedron are on the surface (see [`SheetRule`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sheet {
    /// Every root.
    Any,
    /// The 2001 shooting-line rule; masks of the base and top tetrahedron vertices.
    Shooting {
        /// Bit i set when vertex i spans the base.
        base: u8,
        /// Bit i set when vertex i spans the top.
        top: u8,
    },
}

/// One rational term's integer structure: κ, its multinomial factor n!/κ!, and the numerator
/// monomials μ_m (the weights w_m live in the shared f64 array).
#[derive(Clone, Debug, PartialEq)]
struct FormTerm {
    kappa: [u8; 4],
    mult: f64,
    numer: Vec<[u8; 4]>,
}

/// Rational terms sharing one denominator Σ_m α^μm.
#[derive(Clone, Debug, PartialEq)]
struct FormGroup {
    denominator: Vec<[u8; 4]>,
    terms: Vec<FormTerm>,
}

/// The integer structure of a patch's rational terms, grouped by denominator; the numerator
/// weights follow the polynomial weights in the shared array in group, term, monomial order.
#[derive(Clone, Debug, PartialEq)]
pub struct RationalForm {
    groups: Vec<FormGroup>,
}

impl RationalForm {
    /// Approximate bytes of the form.
    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self
                .groups
                .iter()
                .map(|g| {
                    std::mem::size_of::<FormGroup>()
                        + g.denominator.len() * 4
                        + g.terms
                            .iter()
                            .map(|t| std::mem::size_of::<FormTerm>() + t.numer.len() * 4)
                            .sum::<usize>()
                })
                .sum::<usize>()
    }

    /// How many numerator weights the form reads.
    fn numer_len(&self) -> usize {
        self.groups
            .iter()
            .flat_map(|g| &g.terms)
            .map(|t| t.numer.len())
            .sum()
    }
}

/// Sentinel [`PatchHeader::form`] of a polynomial patch.
const NO_FORM: u16 = u16::MAX;

/// The per-patch record: barycentric map, tolerances and small integers (120 bytes).
#[derive(Clone, Copy, Debug)]
pub struct PatchHeader {
    /// First tetrahedron vertex (origin of the barycentric map).
    v0: DVec3,
    /// ∇α1, ∇α2, ∇α3 in world coordinates (∇α0 = −their sum).
    grad: [DVec3; 3],
    /// Values of the cleared segment polynomial below this count as zero at a segment's ends:
    /// rounding of F near its zeros, from the patch's largest weight.
    zero_tol: f64,
    /// Offset of the patch's weights in the shared array.
    offset: u32,
    /// Index of the rational form, or [`NO_FORM`].
    form: u16,
    /// How many rational numerator weights follow the polynomial weights.
    numer_len: u16,
    degree: u8,
    segment_degree: u8,
    base_order: u8,
    /// Sheet masks (both 0 for [`Sheet::Any`]).
    base: u8,
    top: u8,
    no_zero: bool,
}

/// Every patch of a complex compiled for tracing, in shared arrays.
#[derive(Clone, Debug, Default)]
pub struct PatchStore {
    headers: Vec<PatchHeader>,
    data: Vec<f64>,
    forms: Vec<RationalForm>,
}

/// A borrowed view of one compiled patch.
#[derive(Clone, Copy, Debug)]
pub struct CompiledPatch<'a> {
    h: &'a PatchHeader,
    weights: &'a [f64],
    numer: &'a [f64],
    form: Option<&'a RationalForm>,
}

/// Position of the multi-index λ in the decreasing lexicographic order ([`index_of`], as a
/// const fn for the step tables).
const fn const_index_of(l: [usize; 4]) -> usize {
    let n = l[0] + l[1] + l[2] + l[3];
    let m = n - l[0];
    m * (m + 1) * (m + 2) / 6 + (m - l[1]) * (m - l[1] + 1) / 2 + (m - l[1] - l[2])
}

/// For each multi-index μ of degree d − 1 (in order, `K` = C(d+2, 3) of them), the positions
/// of μ + e_0 … μ + e_3 among the degree-d weights: one de Casteljau step reads those four.
const fn step_table<const K: usize>(d: usize) -> [[u8; 4]; K] {
    let mut t = [[0u8; 4]; K];
    let n = d - 1;
    let mut k = 0;
    let mut a = n as isize;
    while a >= 0 {
        let mut b = (n as isize) - a;
        while b >= 0 {
            let mut c = (n as isize) - a - b;
            while c >= 0 {
                let mu = [a as usize, b as usize, c as usize, n - (a + b + c) as usize];
                let mut i = 0;
                while i < 4 {
                    let mut up = mu;
                    up[i] += 1;
                    t[k][i] = const_index_of(up) as u8;
                    i += 1;
                }
                k += 1;
                c -= 1;
            }
            b -= 1;
        }
        a -= 1;
    }
    t
}

const STEP3: [[u8; 4]; 10] = step_table::<10>(3);
const STEP2: [[u8; 4]; 4] = step_table::<4>(2);

/// One de Casteljau step with the table `t`: w'_μ = Σ_i a_i·w_(μ+e_i) (the operations of
/// `poly::step_into`, in the same order).
#[inline(always)]
fn step_with<const K: usize>(w: &[f64], t: &[[u8; 4]; K], a: &[f64; 4]) -> [f64; K] {
    let mut out = [0.0; K];
    for k in 0..K {
        let [i0, i1, i2, i3] = t[k];
        let (i0, i1, i2, i3) = (
            usize::from(i0),
            usize::from(i1),
            usize::from(i2),
            usize::from(i3),
        );
        out[k] = a[0] * w[i0] + a[1] * w[i1] + a[2] * w[i2] + a[3] * w[i3];
    }
    out
}

/// The cubic's restriction to the segment from `a` to `b` (Bernstein coefficients
/// c_k = blossom(a^(3−k), b^k)): `poly::restrict` for degree 3 by the same steps in the same
/// order, inlined into the ray loop (the cubic polynomial part of every 2001 patch).
#[inline]
fn restrict_cubic(w: &[f64], a: &[f64; 4], b: &[f64; 4], out: &mut Coeffs) {
    let w = &w[..20];
    let (wa, wb) = (step_with(w, &STEP3, a), step_with(w, &STEP3, b));
    let (waa, wbb) = (step_with(&wa, &STEP2, a), step_with(&wb, &STEP2, b));
    let dot = |x: &[f64; 4], y: &[f64; 4]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2] + x[3] * y[3];
    out[0] = dot(a, &waa);
    out[1] = dot(b, &waa);
    out[2] = dot(a, &wbb);
    out[3] = dot(b, &wbb);
}

/// α^μ and its gradient with respect to α1..α4: the value and gradient of
/// [`monomial_jet`] by the same operations (so bit-identical), without the Hessian.
#[inline]
fn monomial_value_gradient(mu: [u8; 4], a: &[f64; 4]) -> (f64, [f64; 4]) {
    let mut p = [1.0; 4];
    let mut dp = [0.0; 4];
    for i in 0..4 {
        let e = i32::from(mu[i]);
        p[i] = a[i].powi(e);
        if e >= 1 {
            dp[i] = f64::from(e) * a[i].powi(e - 1);
        }
    }
    let v = p[0] * p[1] * p[2] * p[3];
    let g = [
        dp[0] * (p[1] * p[2] * p[3]),
        dp[1] * (p[0] * p[2] * p[3]),
        dp[2] * (p[0] * p[1] * p[3]),
        dp[3] * (p[0] * p[1] * p[2]),
    ];
    (v, g)
}

/// Binomial coefficients C(m, j) and their inverses for m ≤ [`MAX_DEGREE`] (exact in f64).
const BINOM: [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] = {
    let mut t = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
    let mut m = 0;
    while m <= MAX_DEGREE {
        t[m][0] = 1.0;
        let mut j = 1;
        while j <= m {
            t[m][j] = t[m - 1][j - 1] + if j < m { t[m - 1][j] } else { 0.0 };
            j += 1;
        }
        m += 1;
    }
    t
};
const INV_BINOM: [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] = {
    let mut t = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
    let mut m = 0;
    while m <= MAX_DEGREE {
        let mut j = 0;
        while j <= m {
            t[m][j] = 1.0 / BINOM[m][j];
            j += 1;
        }
        m += 1;
    }
    t
};

// The rational part of a segment is built in the *scaled* Bernstein basis, d_j = C(m, j)·c_j
// (f(s) = Σ d_j s^j (1−s)^(m−j)): there a product is the plain convolution of the coefficient
// sequences, multiplying by a linear factor (1−s)·a + s·b is d'_j = a·d_j + b·d_(j−1), and
// degree elevation is multiplying by (1−s) + s. No binomial and no division until the one
// conversion back at the end.

/// Multiplies the scaled polynomial `d` of degree `deg` by (1−s)·a + s·b; returns deg + 1.
#[inline(always)]
fn scaled_mul_linear(d: &mut Coeffs, deg: usize, a: f64, b: f64) -> usize {
    d[deg + 1] = b * d[deg];
    for j in (1..=deg).rev() {
        d[j] = a * d[j] + b * d[j - 1];
    }
    d[0] *= a;
    deg + 1
}

/// Scaled coefficients of w·α(s)^μ with α(s) = (1−s)a + s·b; returns the degree |μ|.
#[inline]
fn scaled_monomial(mu: [u8; 4], w: f64, a: &[f64; 4], b: &[f64; 4], out: &mut Coeffs) -> usize {
    out[0] = w;
    let mut deg = 0;
    for i in 0..4 {
        for _ in 0..mu[i] {
            deg = scaled_mul_linear(out, deg, a[i], b[i]);
        }
    }
    deg
}

/// `acc` (degree `*deg`) += `p` (degree `d`), elevating the lower one (scaled basis).
#[inline]
fn scaled_add(acc: &mut Coeffs, deg: &mut usize, p: &Coeffs, d: usize) {
    if d == *deg {
        for k in 0..=d {
            acc[k] += p[k];
        }
        return;
    }
    let mut q = *p;
    let mut dq = d;
    while dq < *deg {
        dq = scaled_mul_linear(&mut q, dq, 1.0, 1.0);
    }
    while *deg < dq {
        *deg = scaled_mul_linear(acc, *deg, 1.0, 1.0);
    }
    for k in 0..=*deg {
        acc[k] += q[k];
    }
}

/// `out[..=m+n]` = the product of `p[..=m]` and `q[..=n]` (scaled basis: a convolution).
#[inline]
fn scaled_product(p: &Coeffs, m: usize, q: &Coeffs, n: usize, out: &mut Coeffs) {
    out[..=m + n].fill(0.0);
    for i in 0..=m {
        for j in 0..=n {
            out[i + j] += p[i] * q[j];
        }
    }
}

/// BB weights of the product of two homogeneous BB polynomials of degrees `m` and `k`:
/// B^m_λ·B^k_μ = (m!/λ!)(k!/μ!)/((m+k)!/(λ+μ)!)·B^(m+k)_(λ+μ).
fn bb_product(m: usize, p: &[f64], k: usize, q: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; num_coeffs(m + k)];
    let (lp, lq) = (multi_indices(m), multi_indices(k));
    for (i, l) in lp.iter().enumerate() {
        if p[i] == 0.0 {
            continue;
        }
        for (j, u) in lq.iter().enumerate() {
            if q[j] == 0.0 {
                continue;
            }
            let s = [l[0] + u[0], l[1] + u[1], l[2] + u[2], l[3] + u[3]];
            out[index_of(s)] += p[i] * q[j] * multinomial(*l) * multinomial(*u) / multinomial(s);
        }
    }
    out
}

/// `p` (degree `m`) elevated to degree `e` ≥ m (multiplied by (Σα)^(e−m) = 1).
fn bb_elevate_to(m: usize, p: Vec<f64>, e: usize) -> Vec<f64> {
    (m..e).fold(p, |c, d| poly::elevate(d, &c))
}

/// Sum of two BB polynomials, at the larger degree.
fn bb_add(m: usize, p: Vec<f64>, k: usize, q: Vec<f64>) -> (usize, Vec<f64>) {
    let e = m.max(k);
    let mut p = bb_elevate_to(m, p, e);
    let q = bb_elevate_to(k, q, e);
    for (x, y) in p.iter_mut().zip(&q) {
        *x += y;
    }
    (e, p)
}

/// The monomial α^μ as a BB polynomial of degree |μ|: B_μ / (|μ|!/μ!).
fn bb_monomial(mu: [u8; 4]) -> (usize, Vec<f64>) {
    let d: usize = mu.iter().map(|&x| usize::from(x)).sum();
    let mut c = vec![0.0; num_coeffs(d)];
    c[index_of(mu)] = 1.0 / multinomial(mu);
    (d, c)
}

/// BB weights of the cleared polynomial G = P·Π_g D_g + Σ_g (Σ_r N_r·B_κr)·Π_{g'≠g} D_g' of a
/// patch with polynomial part `weights` (degree `n`), rational `form` and numerator weights
/// `numer`, following the degrees of the univariate construction (so its degree is the
/// patch's segment degree). Used at compile time for the sign-definite test.
fn clear_denominators(n: usize, weights: &[f64], form: &RationalForm, numer: &[f64]) -> Vec<f64> {
    let (mut deg, mut out) = (n, weights.to_vec());
    let (mut qdeg, mut q) = (0usize, vec![1.0]);
    let mut w = numer.iter();
    for g in &form.groups {
        let (mut dden, mut den) = (0usize, vec![0.0]);
        for mu in &g.denominator {
            let (d, m) = bb_monomial(*mu);
            (dden, den) = bb_add(dden, den, d, m);
        }
        let (mut dsum, mut sum) = (0usize, vec![0.0]);
        for t in &g.terms {
            let (mut dnum, mut num) = (0usize, vec![0.0]);
            for mu in &t.numer {
                let wm = *w.next().expect("numerator weight");
                let (d, mut m) = bb_monomial(*mu);
                for x in &mut m {
                    *x *= wm;
                }
                (dnum, num) = bb_add(dnum, num, d, m);
            }
            // B^n_κ: weight 1 at κ.
            let mut bern = vec![0.0; num_coeffs(n)];
            bern[index_of(t.kappa)] = 1.0;
            let prod = bb_product(dnum, &num, n, &bern);
            (dsum, sum) = bb_add(dsum, sum, dnum + n, prod);
        }
        let left = bb_product(deg, &out, dden, &den);
        let right = bb_product(dsum, &sum, qdeg, &q);
        (deg, out) = bb_add(deg + dden, left, dsum + qdeg, right);
        q = bb_product(qdeg, &q, dden, &den);
        qdeg += dden;
    }
    out
}

impl PatchStore {
    /// An empty store with room for `n` patches.
    #[must_use]
    pub fn with_capacity(n: usize) -> Self {
        PatchStore {
            headers: Vec::with_capacity(n),
            data: Vec::with_capacity(n * 20),
            forms: Vec::new(),
        }
    }

    /// Number of patches.
    #[must_use]
    pub fn len(&self) -> usize {
        self.headers.len()
    }

    /// True when the store holds no patch.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.headers.is_empty()
    }

    /// The compiled patch `i`.
    #[must_use]
    #[inline]
    pub fn get(&self, i: usize) -> CompiledPatch<'_> {
        let h = &self.headers[i];
        let start = h.offset as usize;
        let nw = num_coeffs(usize::from(h.degree));
        let form = self.forms.get(usize::from(h.form));
        let nn = usize::from(h.numer_len);
        CompiledPatch {
            h,
            weights: &self.data[start..start + nw],
            numer: &self.data[start + nw..start + nw + nn],
            form,
        }
    }

    /// The header of patch `i` alone: enough to clip a ray ([`PatchHeader::clip`]) before
    /// touching the patch's weights.
    #[must_use]
    #[inline]
    pub fn header(&self, i: usize) -> &PatchHeader {
        &self.headers[i]
    }

    /// Bytes of the headers, the shared weights and the forms.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.headers.len() * std::mem::size_of::<PatchHeader>()
            + self.data.len() * 8
            + self
                .forms
                .iter()
                .map(RationalForm::memory_bytes)
                .sum::<usize>()
    }

    /// Compiles `patch` and appends it; `index` names it in errors.
    ///
    /// # Errors
    /// A degenerate tetrahedron, a degree outside 1..=7, a wrong weight count, rational terms
    /// whose cleared segment degree exceeds [`MAX_DEGREE`], or more than 65535 distinct
    /// rational forms.
    pub fn push(&mut self, patch: &Patch, index: usize) -> Result<(), String> {
        let n = usize::from(patch.degree);
        if !(1..=MAX_PATCH_DEGREE).contains(&n) {
            return Err(format!("patch {index}: degree {n} is outside 1..=7"));
        }
        if patch.weights.len() != num_coeffs(n) {
            return Err(format!(
                "patch {index}: {} weights for degree {n} (expected {})",
                patch.weights.len(),
                num_coeffs(n)
            ));
        }
        if patch.weights.iter().any(|w| !w.is_finite()) {
            return Err(format!("patch {index}: a weight is not finite"));
        }
        let v = patch.tet_points();
        let m = DMat3::from_cols(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
        let det = m.determinant();
        let scale = (v[1] - v[0])
            .length()
            .max((v[2] - v[0]).length())
            .max((v[3] - v[0]).length());
        if !det.is_finite() || det.abs() <= 1e-14 * scale.powi(3) {
            return Err(format!("patch {index}: degenerate tetrahedron"));
        }
        let inv = m.inverse().transpose();
        let grad = [inv.x_axis, inv.y_axis, inv.z_axis];

        let mut groups: Vec<FormGroup> = Vec::new();
        let mut group_weights: Vec<Vec<Vec<f64>>> = Vec::new();
        for (r, term) in patch.rational.iter().enumerate() {
            let kdeg: u8 = term.index.iter().sum();
            if usize::from(kdeg) != n {
                return Err(format!("patch {index}: rational term {r} has |κ| ≠ {n}"));
            }
            if term.terms.is_empty() || term.terms.iter().any(|(w, _)| !w.is_finite()) {
                return Err(format!(
                    "patch {index}: rational term {r} is empty or not finite"
                ));
            }
            let mut denom: Vec<[u8; 4]> = term.terms.iter().map(|t| t.1).collect();
            denom.sort_unstable();
            let ft = FormTerm {
                kappa: term.index,
                mult: multinomial(term.index),
                numer: term.terms.iter().map(|t| t.1).collect(),
            };
            let ws: Vec<f64> = term.terms.iter().map(|t| t.0).collect();
            match groups.iter().position(|g| g.denominator == denom) {
                Some(k) => {
                    groups[k].terms.push(ft);
                    group_weights[k].push(ws);
                }
                None => {
                    groups.push(FormGroup {
                        denominator: denom,
                        terms: vec![ft],
                    });
                    group_weights.push(vec![ws]);
                }
            }
        }
        let mu_deg = |l: &[u8; 4]| l.iter().map(|&x| usize::from(x)).sum::<usize>();
        // Follow the degrees of `segment` step by step.
        let mut segment_degree = n;
        let mut qdeg = 0;
        for g in &groups {
            let dden = g.denominator.iter().map(mu_deg).max().unwrap_or(0);
            let dsum = g
                .terms
                .iter()
                .map(|t| t.numer.iter().map(mu_deg).max().unwrap_or(0) + n)
                .max()
                .unwrap_or(0);
            segment_degree = (segment_degree + dden).max(dsum + qdeg);
            qdeg += dden;
        }
        if segment_degree > MAX_DEGREE {
            return Err(format!(
                "patch {index}: rational terms raise the segment degree to {segment_degree} (> {MAX_DEGREE})"
            ));
        }
        let (base, top) = match &patch.sheet {
            SheetRule::Any => (0, 0),
            SheetRule::Shooting { base, top } => {
                let mask = |s: &[u8]| -> Result<u8, String> {
                    let mut m = 0u8;
                    for &i in s {
                        if i > 3 {
                            return Err(format!("patch {index}: sheet vertex {i} is not 0..=3"));
                        }
                        m |= 1 << i;
                    }
                    Ok(m)
                };
                let (b, t) = (mask(base)?, mask(top)?);
                if b == 0 || t == 0 || b & t != 0 {
                    return Err(format!(
                        "patch {index}: sheet base and top must be disjoint and non-empty"
                    ));
                }
                (b, t)
            }
        };
        let base_order: usize = if top == 0 {
            0
        } else {
            groups
                .iter()
                .map(|g| {
                    g.denominator
                        .iter()
                        .map(|mu| {
                            (0..4)
                                .filter(|&i| top & (1 << i) != 0)
                                .map(|i| usize::from(mu[i]))
                                .sum::<usize>()
                        })
                        .min()
                        .unwrap_or(0)
                })
                .sum()
        };
        let all = patch.weights.iter().copied().chain(
            patch
                .rational
                .iter()
                .flat_map(|r| r.terms.iter().map(|t| t.0)),
        );
        let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), w| {
            (l.min(w), h.max(w))
        });
        let numer: Vec<f64> = group_weights.into_iter().flatten().flatten().collect();
        let numer_len = u16::try_from(numer.len())
            .map_err(|_| format!("patch {index}: more than 65535 rational numerator weights"))?;
        let form = RationalForm { groups };
        debug_assert_eq!(form.numer_len(), numer.len());
        let cleared = if form.groups.is_empty() {
            Vec::new()
        } else {
            clear_denominators(n, &patch.weights, &form, &numer)
        };
        debug_assert!(cleared.is_empty() || cleared.len() == num_coeffs(segment_degree));
        // G = F·Π D_g with D_g ≥ 0 in the tetrahedron: weights of G of one strict sign also
        // exclude a zero (the convex hull property of G).
        let g_sign =
            |w: &[f64]| !w.is_empty() && (w.iter().all(|&x| x > 0.0) || w.iter().all(|&x| x < 0.0));
        let no_zero = lo > 0.0 || hi < 0.0 || g_sign(&cleared);
        let zero_tol = 64.0 * f64::EPSILON * lo.abs().max(hi.abs()) * segment_degree as f64;
        let form_id = if form.groups.is_empty() {
            NO_FORM
        } else if let Some(k) = self.forms.iter().position(|f| *f == form) {
            k as u16
        } else {
            if self.forms.len() >= usize::from(NO_FORM) {
                return Err(format!("patch {index}: too many distinct rational forms"));
            }
            self.forms.push(form);
            (self.forms.len() - 1) as u16
        };
        let offset = u32::try_from(self.data.len())
            .map_err(|_| format!("patch {index}: more weights than the tracer can address"))?;
        self.data.extend_from_slice(&patch.weights);
        self.data.extend_from_slice(&numer);
        self.headers.push(PatchHeader {
            v0: v[0],
            grad,
            zero_tol,
            offset,
            form: form_id,
            numer_len,
            degree: n as u8,
            segment_degree: segment_degree as u8,
            base_order: base_order.min(255) as u8,
            base,
            top,
            no_zero,
        });
        Ok(())
    }
}

impl PatchHeader {
    /// Barycentric coordinates of `x`.
    #[must_use]
    #[inline]
    pub fn bary(&self, x: DVec3) -> [f64; 4] {
        let d = x - self.v0;
        let a1 = self.grad[0].dot(d);
        let a2 = self.grad[1].dot(d);
        let a3 = self.grad[2].dot(d);
        [1.0 - a1 - a2 - a3, a1, a2, a3]
    }

    /// The parameter interval [t0, t1] in which `o + t·d` lies inside the tetrahedron, with
    /// α(o) and dα/dt (barycentrics along the ray are α(o) + t·rate), or `None`.
    #[must_use]
    #[inline]
    pub fn clip(&self, o: DVec3, d: DVec3) -> Option<(f64, f64, [f64; 4], [f64; 4])> {
        let a = self.bary(o);
        let mut t0 = f64::NEG_INFINITY;
        let mut t1 = f64::INFINITY;
        let r1 = self.grad[0].dot(d);
        let r2 = self.grad[1].dot(d);
        let r3 = self.grad[2].dot(d);
        let rate = [-(r1 + r2 + r3), r1, r2, r3];
        // αi(t) = a_i + t·rate_i ≥ 0.
        for i in 0..4 {
            let r = rate[i];
            if r > 0.0 {
                t0 = t0.max(-a[i] / r);
            } else if r < 0.0 {
                t1 = t1.min(-a[i] / r);
            } else if a[i] < 0.0 {
                return None;
            }
        }
        if !t0.is_finite() || !t1.is_finite() {
            return None;
        }
        if t0 > t1 {
            // A ray through a vertex or edge touches the closed tetrahedron in one point, which
            // rounding can turn into an empty interval: keep it when the gap is rounding-sized.
            if t0 - t1 > CLIP_SLACK * (t0.abs() + t1.abs()) {
                return None;
            }
            let m = 0.5 * (t0 + t1);
            return Some((m, m, a, rate));
        }
        Some((t0, t1, a, rate))
    }

    /// See [`CompiledPatch::no_zero`].
    #[must_use]
    #[inline]
    pub fn no_zero(&self) -> bool {
        self.no_zero
    }
}

impl CompiledPatch<'_> {
    /// Polynomial degree n.
    #[must_use]
    #[inline]
    pub fn degree(&self) -> usize {
        usize::from(self.h.degree)
    }

    /// Degree of the segment polynomial once denominators are cleared.
    #[must_use]
    #[inline]
    pub fn segment_degree(&self) -> usize {
        usize::from(self.h.segment_degree)
    }

    /// True when every weight (rational blends included) has the same strict sign: by the
    /// convex hull property F has no zero in the tetrahedron and rays skip the patch.
    #[must_use]
    #[inline]
    pub fn no_zero(&self) -> bool {
        self.h.no_zero
    }

    /// Values of the cleared segment polynomial below this count as zero at a segment's ends.
    #[must_use]
    #[inline]
    pub fn zero_tol(&self) -> f64 {
        self.h.zero_tol
    }

    /// How many factors of t the cleared polynomial on a shooting line carries at its base
    /// point (denominators that vanish on the base simplex, e.g. α3 + α4 for edge patches):
    /// those roots at t = 0 are not zeros of F and are divided out.
    #[must_use]
    #[inline]
    pub fn base_order(&self) -> usize {
        usize::from(self.h.base_order)
    }

    /// The sheet rule.
    #[must_use]
    #[inline]
    pub fn sheet(&self) -> Sheet {
        if self.h.top == 0 {
            Sheet::Any
        } else {
            Sheet::Shooting {
                base: self.h.base,
                top: self.h.top,
            }
        }
    }

    /// The weight at the first top vertex of a shooting rule (0 for `Any`): F at a shooting
    /// line's base point must not have its strict sign.
    #[must_use]
    pub fn top_weight(&self) -> f64 {
        if self.h.top == 0 {
            return 0.0;
        }
        let k = self.h.top.trailing_zeros() as usize;
        let mut l = [0u8; 4];
        l[k] = self.h.degree;
        self.weights[index_of(l)]
    }

    /// ∇αi in world coordinates.
    #[must_use]
    #[inline]
    pub fn grad(&self) -> [DVec3; 4] {
        let [g1, g2, g3] = self.h.grad;
        [-(g1 + g2 + g3), g1, g2, g3]
    }

    /// Barycentric coordinates of `x`.
    #[must_use]
    #[inline]
    pub fn bary(&self, x: DVec3) -> [f64; 4] {
        self.h.bary(x)
    }

    /// The parameter interval [t0, t1] in which `o + t·d` lies inside the tetrahedron, with
    /// α(o) and dα/dt (barycentrics along the ray are α(o) + t·rate), or `None`.
    #[must_use]
    #[inline]
    pub fn clip(&self, o: DVec3, d: DVec3) -> Option<(f64, f64, [f64; 4], [f64; 4])> {
        self.h.clip(o, d)
    }

    /// Bernstein coefficients on s ∈ [0, 1] of F((1−s)·a + s·b) (barycentric endpoints), with
    /// rational denominators cleared (multiplied by their positive values): the polynomial
    /// part restricted by blossoms, times the restricted denominators, plus each rational
    /// term's restricted numerator and Bernstein polynomial. Returns the degree.
    #[inline]
    pub fn segment(&self, a: &[f64; 4], b: &[f64; 4], out: &mut Coeffs) -> usize {
        let n = self.degree();
        if n == 3 {
            restrict_cubic(self.weights, a, b, out);
        } else {
            poly::restrict(n, self.weights, *a, *b, out);
        }
        let Some(form) = self.form else {
            return n;
        };
        // G = P·ΠD_g + Σ_g (Σ_r N_r·B_r)·Π_{g'≠g} D_g', built group by group in the scaled
        // basis (see `scaled_mul_linear`).
        let mut g = [0.0; MAX_DEGREE + 1];
        for j in 0..=n {
            g[j] = out[j] * BINOM[n][j];
        }
        let mut w = self.numer.iter();
        let mut deg = n;
        let mut q = [0.0; MAX_DEGREE + 1]; // Π of the denominators so far
        q[0] = 1.0;
        let mut qdeg = 0;
        let mut m = [0.0; MAX_DEGREE + 1];
        for grp in &form.groups {
            let mut den = [0.0; MAX_DEGREE + 1];
            let mut dden = 0;
            for (k, mu) in grp.denominator.iter().enumerate() {
                if k == 0 {
                    dden = scaled_monomial(*mu, 1.0, a, b, &mut den);
                } else {
                    let d = scaled_monomial(*mu, 1.0, a, b, &mut m);
                    scaled_add(&mut den, &mut dden, &m, d);
                }
            }
            let mut sum = [0.0; MAX_DEGREE + 1];
            let mut dsum = 0;
            for (r, t) in grp.terms.iter().enumerate() {
                let mut num = [0.0; MAX_DEGREE + 1];
                let mut dnum = 0;
                for (k, mu) in t.numer.iter().enumerate() {
                    let wm = w.next().copied().unwrap_or(0.0);
                    if k == 0 {
                        dnum = scaled_monomial(*mu, wm, a, b, &mut num);
                    } else {
                        let d = scaled_monomial(*mu, wm, a, b, &mut m);
                        scaled_add(&mut num, &mut dnum, &m, d);
                    }
                }
                // N_r·B_r: multiply N_r by mult·α^κ one linear factor at a time.
                for x in &mut num[..=dnum] {
                    *x *= t.mult;
                }
                for i in 0..4 {
                    for _ in 0..t.kappa[i] {
                        dnum = scaled_mul_linear(&mut num, dnum, a[i], b[i]);
                    }
                }
                if r == 0 {
                    sum = num;
                    dsum = dnum;
                } else {
                    scaled_add(&mut sum, &mut dsum, &num, dnum);
                }
            }
            let mut left = [0.0; MAX_DEGREE + 1];
            scaled_product(&g, deg, &den, dden, &mut left);
            let mut dl = deg + dden;
            if qdeg == 0 {
                // Π of no denominators is 1 (the only group of a face or edge patch).
                scaled_add(&mut left, &mut dl, &sum, dsum);
            } else {
                let mut right = [0.0; MAX_DEGREE + 1];
                scaled_product(&sum, dsum, &q, qdeg, &mut right);
                scaled_add(&mut left, &mut dl, &right, dsum + qdeg);
            }
            g = left;
            deg = dl;
            if qdeg == 0 {
                q = den;
            } else {
                let mut nq = [0.0; MAX_DEGREE + 1];
                scaled_product(&q, qdeg, &den, dden, &mut nq);
                q = nq;
            }
            qdeg += dden;
        }
        for j in 0..=deg {
            out[j] = g[j] * INV_BINOM[deg][j];
        }
        deg
    }

    /// F, its gradient and Hessian with respect to the four barycentric variables at `alpha`.
    #[must_use]
    pub fn bary_derivatives(&self, alpha: &[f64; 4]) -> Jet {
        self.bary_jet::<true>(alpha)
    }

    /// [`Self::bary_derivatives`], with the Hessian left 0 unless `HESSIAN`: the value and
    /// gradient take the same operations either way (bit-identical), the gradient-only form
    /// skips the second-order work the shading of most modes does not need.
    #[inline]
    fn bary_jet<const HESSIAN: bool>(&self, alpha: &[f64; 4]) -> Jet {
        let n = self.degree();
        let mut jet = Jet::default();
        if n == 1 {
            for i in 0..4 {
                jet.v += alpha[i] * self.weights[i];
                jet.g[i] = self.weights[i];
            }
        } else {
            let mut work = [0.0; MAX_COEFFS];
            work[..self.weights.len()].copy_from_slice(self.weights);
            for level in (3..=n).rev() {
                poly::step_in_place_fast(&mut work, level, *alpha);
            }
            let nf = n as f64;
            for i in 0..4 {
                let mut ci = 0.0;
                for j in 0..4 {
                    let d = work[IDX2[i][j]];
                    ci += alpha[j] * d;
                    if HESSIAN {
                        jet.h[i][j] = nf * (nf - 1.0) * d;
                    }
                }
                jet.v += alpha[i] * ci;
                jet.g[i] = nf * ci;
            }
        }
        let Some(form) = self.form else {
            return jet;
        };
        let mono = |mu: [u8; 4]| {
            if HESSIAN {
                monomial_jet(mu, *alpha)
            } else {
                let (v, g) = monomial_value_gradient(mu, alpha);
                (v, g, [[0.0; 4]; 4])
            }
        };
        let mut w = self.numer.iter();
        for g in &form.groups {
            // D = Σ α^μ over the group's monomials (shared by its terms).
            let (mut d, mut gd, mut hd) = (0.0, [0.0; 4], [[0.0; 4]; 4]);
            for mu in &g.denominator {
                let (v, gv, hv) = mono(*mu);
                d += v;
                for i in 0..4 {
                    gd[i] += gv[i];
                    if HESSIAN {
                        for k in 0..4 {
                            hd[i][k] += hv[i][k];
                        }
                    }
                }
            }
            for t in &g.terms {
                let (mut nv, mut gn, mut hn) = (0.0, [0.0; 4], [[0.0; 4]; 4]);
                for mu in &t.numer {
                    let wm = w.next().copied().unwrap_or(0.0);
                    let (v, gv, hv) = mono(*mu);
                    nv += wm * v;
                    for i in 0..4 {
                        gn[i] += wm * gv[i];
                        if HESSIAN {
                            for k in 0..4 {
                                hn[i][k] += wm * hv[i][k];
                            }
                        }
                    }
                }
                if d.abs() < MIN_DENOMINATOR {
                    // The term is 0 where its denominator vanishes (bb::rational's convention).
                    continue;
                }
                let c = t.mult;
                let (bv, gb, hb) = mono(t.kappa);
                let (bv, gb) = (c * bv, gb.map(|x| c * x));
                let hb = if HESSIAN {
                    hb.map(|r| r.map(|x| c * x))
                } else {
                    hb
                };
                // q = N/D, ∇q = (∇N − q∇D)/D, Hq = (HN − q HD − ∇q∇Dᵀ − ∇D∇qᵀ)/D.
                let qv = nv / d;
                let gq: [f64; 4] = std::array::from_fn(|i| (gn[i] - qv * gd[i]) / d);
                jet.v += qv * bv;
                for i in 0..4 {
                    jet.g[i] += bv * gq[i] + qv * gb[i];
                    if HESSIAN {
                        for k in 0..4 {
                            let hq = (hn[i][k] - qv * hd[i][k] - gq[i] * gd[k] - gd[i] * gq[k]) / d;
                            // R = q·B: HR = B Hq + ∇q∇Bᵀ + ∇B∇qᵀ + q HB.
                            jet.h[i][k] += bv * hq + gq[i] * gb[k] + gb[i] * gq[k] + qv * hb[i][k];
                        }
                    }
                }
            }
        }
        jet
    }

    /// F and its world gradient at the point with barycentrics `alpha`: [`Self::derivatives`]
    /// without assembling the world Hessian (the shading of every mode but curvature); the
    /// gradient is bit-identical to the one `derivatives` returns.
    #[must_use]
    pub fn value_gradient(&self, alpha: &[f64; 4]) -> (f64, DVec3) {
        let j = self.bary_jet::<false>(alpha);
        let grad = self.grad();
        let mut g = DVec3::ZERO;
        for i in 0..4 {
            g += j.g[i] * grad[i];
        }
        (j.v, g)
    }

    /// F, world gradient and world Hessian at the point with barycentrics `alpha`.
    #[must_use]
    pub fn derivatives(&self, alpha: &[f64; 4]) -> (f64, DVec3, DMat3) {
        let j = self.bary_derivatives(alpha);
        let grad = self.grad();
        let mut g = DVec3::ZERO;
        let mut h = DMat3::ZERO;
        for i in 0..4 {
            g += j.g[i] * grad[i];
            for k in 0..4 {
                let gi = grad[i] * j.h[i][k];
                let gk = grad[k];
                h += DMat3::from_cols(gi * gk.x, gi * gk.y, gi * gk.z);
            }
        }
        (j.v, g, h)
    }

    #[cfg(test)]
    /// [`Self::segment`] computed another way: the BB-form cleared polynomial G restricted by
    /// blossoms (the reference for the univariate products).
    fn segment_by_bb_form(&self, a: &[f64; 4], b: &[f64; 4], out: &mut Coeffs) -> usize {
        let Some(form) = self.form else {
            poly::restrict(self.degree(), self.weights, *a, *b, out);
            return self.degree();
        };
        let g = clear_denominators(self.degree(), self.weights, form, self.numer);
        poly::restrict(self.segment_degree(), &g, *a, *b, out);
        self.segment_degree()
    }
}

/// Value, gradient and Hessian of a function of four variables (second-order forward jet).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Jet {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; 4],
    /// Hessian.
    pub h: [[f64; 4]; 4],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::complex::RationalTerm;
    use crate::fixtures::{quadric_patch, Quadric};

    fn compile(p: &Patch) -> PatchStore {
        let mut s = PatchStore::default();
        s.push(p, 0).unwrap();
        s
    }

    fn tet() -> [DVec3; 4] {
        [
            DVec3::new(-0.3, -0.2, -0.4),
            DVec3::new(1.2, 0.1, -0.1),
            DVec3::new(0.2, 1.1, 0.3),
            DVec3::new(0.1, 0.2, 1.3),
        ]
    }

    fn patch(q: &Quadric, n: usize) -> Patch {
        quadric_patch(q, tet(), n)
    }

    #[test]
    fn segment_and_derivatives_match_the_quadric() {
        let q = Quadric::ellipsoid(DVec3::new(0.2, 0.3, 0.1), DVec3::new(0.7, 0.5, 0.9));
        for n in 2..=5 {
            let store = compile(&patch(&q, n));
            let c = store.get(0);
            let x0 = DVec3::new(0.1, 0.2, 0.1);
            let x1 = DVec3::new(0.3, 0.25, 0.4);
            let (a, b) = (c.bary(x0), c.bary(x1));
            let mut co = [0.0; MAX_DEGREE + 1];
            let d = c.segment(&a, &b, &mut co);
            assert_eq!(d, n);
            for k in 0..=4 {
                let s = k as f64 / 4.0;
                let want = q.value(x0.lerp(x1, s));
                // Blossom rounding on O(1) weights.
                assert!(
                    (uni::eval(&co[..=d], s) - want).abs() < 1e-13,
                    "n={n} s={s}"
                );
            }
            let x = DVec3::new(0.2, 0.3, 0.35);
            let (v, g, h) = c.derivatives(&c.bary(x));
            assert_eq!(c.value_gradient(&c.bary(x)), (v, g));
            // Rounding only: exact representation of a quadric.
            assert!((v - q.value(x)).abs() < 1e-13);
            assert!(
                (g - q.gradient(x)).length() < 1e-12,
                "{g} vs {}",
                q.gradient(x)
            );
            assert!(
                (h - 2.0 * q.a)
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|e| *e < 1e-11),
                "{h}"
            );
        }
    }

    #[test]
    fn rational_term_is_cleared_consistently() {
        // F = P + (2α1² + 3α2²)/(α1² + α2²)·B_κ: compare the cleared segment polynomial
        // with F·D sampled directly, and the jet gradient with finite differences.
        let q = Quadric::sphere(DVec3::new(0.3, 0.3, 0.3), 0.4);
        let mut p = patch(&q, 3);
        p.rational.push(RationalTerm {
            index: [1, 1, 1, 0],
            terms: [(2.0, [2, 0, 0, 0]), (3.0, [0, 2, 0, 0])].into(),
        });
        let store = compile(&p);
        let c = store.get(0);
        let f = |x: DVec3| c.derivatives(&c.bary(x)).0;
        let den = |x: DVec3| {
            let a = c.bary(x);
            a[0] * a[0] + a[1] * a[1]
        };
        let x0 = DVec3::new(0.1, 0.2, 0.1);
        let x1 = DVec3::new(0.3, 0.25, 0.4);
        let mut co = [0.0; MAX_DEGREE + 1];
        let d = c.segment(&c.bary(x0), &c.bary(x1), &mut co);
        assert_eq!(d, 5);
        for k in 0..=4 {
            let s = k as f64 / 4.0;
            let x = x0.lerp(x1, s);
            // Rounding of O(1) products.
            assert!((uni::eval(&co[..=d], s) - f(x) * den(x)).abs() < 1e-13);
        }
        let x = DVec3::new(0.25, 0.3, 0.2);
        let (v, g, h) = c.derivatives(&c.bary(x));
        assert_eq!(c.value_gradient(&c.bary(x)), (v, g));
        let e = 1e-5;
        for axis in 0..3 {
            let mut dx = DVec3::ZERO;
            dx[axis] = e;
            let fd = (f(x + dx) - f(x - dx)) / (2.0 * e);
            // Central differences: O(e²) truncation with O(1) third derivatives.
            assert!((fd - g[axis]).abs() < 1e-8, "{fd} vs {}", g[axis]);
            let gp = c.derivatives(&c.bary(x + dx)).1;
            let gm = c.derivatives(&c.bary(x - dx)).1;
            let hd = (gp - gm) / (2.0 * e);
            assert!(
                (hd - h.col(axis)).length() < 1e-7,
                "{hd} vs {}",
                h.col(axis)
            );
        }
    }

    #[test]
    fn cubic_restriction_is_poly_restrict_bit_for_bit() {
        // The inlined cubic restriction takes poly::restrict's steps in its order: equal bits
        // on random weights and segments (barycentrics outside [0, 1] included).
        let mut rng = crate::fixtures::Lcg(99);
        let mut rnd = || rng.uniform() * 2.0 - 0.5;
        for _ in 0..200 {
            let w: Vec<f64> = (0..20).map(|_| rnd()).collect();
            let a = [rnd(), rnd(), rnd(), rnd()];
            let b = [rnd(), rnd(), rnd(), rnd()];
            let (mut x, mut y) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
            restrict_cubic(&w, &a, &b, &mut x);
            poly::restrict(3, &w, a, b, &mut y);
            assert_eq!(x[..4], y[..4]);
        }
    }

    #[test]
    fn univariate_products_match_the_bb_cleared_form() {
        // Two denominator groups (an edge-patch style α3 + α4 and a face-patch style
        // α1α2 + α1α3 + α2α3), three terms: the term-by-term univariate construction on random
        // segments must equal the BB-form G restricted by blossoms.
        let q = Quadric::sphere(DVec3::new(0.3, 0.3, 0.3), 0.4);
        let mut p = patch(&q, 3);
        p.rational.push(RationalTerm {
            index: [1, 0, 1, 1],
            terms: [(0.7, [0, 0, 1, 0]), (-1.3, [0, 0, 0, 1])].into(),
        });
        p.rational.push(RationalTerm {
            index: [0, 1, 1, 1],
            terms: [(2.0, [0, 0, 0, 1]), (0.4, [0, 0, 1, 0])].into(),
        });
        p.rational.push(RationalTerm {
            index: [1, 1, 1, 0],
            terms: [
                (0.5, [1, 1, 0, 0]),
                (-0.2, [1, 0, 1, 0]),
                (1.1, [0, 1, 1, 0]),
            ]
            .into(),
        });
        let store = compile(&p);
        let c = store.get(0);
        assert_eq!(c.segment_degree(), 6);
        let mut rng = crate::fixtures::Lcg(12345);
        let mut rnd = || rng.uniform();
        for _ in 0..50 {
            let mut pick = || {
                let w = [rnd(), rnd(), rnd(), rnd()];
                let s: f64 = w.iter().sum();
                w.map(|x| x / s)
            };
            let (a, b) = (pick(), pick());
            let (mut x, mut y) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
            let dx = c.segment(&a, &b, &mut x);
            let dy = c.segment_by_bb_form(&a, &b, &mut y);
            assert_eq!(dx, dy);
            for k in 0..=dx {
                // Both are sums of O(1) products of O(1) barycentrics: rounding only.
                assert!((x[k] - y[k]).abs() < 1e-13, "{k}: {} vs {}", x[k], y[k]);
            }
        }
    }
}

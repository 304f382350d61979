//! Univariate Bernstein polynomials on [0, 1] for the ray × patch hot path: evaluation,
//! subdivision, products and the first root. Fixed-size arrays only (degree ≤ [`MAX_DEGREE`]),
//! no allocation.

// Index loops over the four barycentric components read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

/// Highest degree a segment polynomial may have (16 coefficients).
pub const MAX_DEGREE: usize = 15;

/// Coefficient storage for one univariate Bernstein polynomial.
pub type Coeffs = [f64; MAX_DEGREE + 1];

/// Binomial coefficients C(n, k) for n ≤ 2·MAX_DEGREE (products stay below that).
const fn binomials() -> [[f64; 2 * MAX_DEGREE + 1]; 2 * MAX_DEGREE + 1] {
    let mut t = [[0.0; 2 * MAX_DEGREE + 1]; 2 * MAX_DEGREE + 1];
    let mut n = 0;
    while n <= 2 * MAX_DEGREE {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
}

/// Table of binomial coefficients.
pub const BINOM: [[f64; 2 * MAX_DEGREE + 1]; 2 * MAX_DEGREE + 1] = binomials();

/// Value at `s` of the degree-`n` polynomial with Bernstein coefficients `c[..=n]`
/// (de Casteljau, stable for s ∈ [0, 1]).
#[must_use]
#[inline]
pub fn eval(c: &[f64], n: usize, s: f64) -> f64 {
    let mut b = [0.0; MAX_DEGREE + 1];
    b[..=n].copy_from_slice(&c[..=n]);
    let r = 1.0 - s;
    for level in (1..=n).rev() {
        for i in 0..level {
            b[i] = r * b[i] + s * b[i + 1];
        }
    }
    b[0]
}

/// Value and derivative at `s` (derivative from the last de Casteljau level).
#[must_use]
#[inline]
pub fn eval_with_derivative(c: &[f64], n: usize, s: f64) -> (f64, f64) {
    if n == 0 {
        return (c[0], 0.0);
    }
    let mut b = [0.0; MAX_DEGREE + 1];
    b[..=n].copy_from_slice(&c[..=n]);
    let r = 1.0 - s;
    for level in (2..=n).rev() {
        for i in 0..level {
            b[i] = r * b[i] + s * b[i + 1];
        }
    }
    (r * b[0] + s * b[1], n as f64 * (b[1] - b[0]))
}

/// Splits `c` (degree n) at `s`: `left` gets the coefficients on [0, s], `right` on [s, 1]
/// (each re-parametrised to [0, 1]).
#[inline]
pub fn split(c: &[f64], n: usize, s: f64, left: &mut [f64], right: &mut [f64]) {
    let mut b = [0.0; MAX_DEGREE + 1];
    b[..=n].copy_from_slice(&c[..=n]);
    let r = 1.0 - s;
    left[0] = b[0];
    right[n] = b[n];
    for level in (1..=n).rev() {
        for i in 0..level {
            b[i] = r * b[i] + s * b[i + 1];
        }
        left[n + 1 - level] = b[0];
        right[level - 1] = b[level - 1];
    }
}

/// Product of two Bernstein polynomials (degrees `m` and `n`, m + n ≤ MAX_DEGREE), written to
/// `out[..=m+n]`.
#[inline]
pub fn product(p: &[f64], m: usize, q: &[f64], n: usize, out: &mut [f64]) {
    let d = m + n;
    for (k, o) in out.iter_mut().enumerate().take(d + 1) {
        let mut acc = 0.0;
        let lo = k.saturating_sub(n);
        let hi = k.min(m);
        for i in lo..=hi {
            acc += BINOM[m][i] * BINOM[n][k - i] * p[i] * q[k - i];
        }
        *o = acc / BINOM[d][k];
    }
}

/// Raises the degree of `c` from `n` to `to` in place (`to` ≤ MAX_DEGREE).
#[inline]
pub fn elevate(c: &mut [f64], n: usize, to: usize) {
    let mut deg = n;
    while deg < to {
        let m = deg + 1;
        c[m] = c[deg];
        for i in (1..m).rev() {
            let a = i as f64 / m as f64;
            c[i] = a * c[i - 1] + (1.0 - a) * c[i];
        }
        deg = m;
    }
}

/// Coefficients within this factor of the largest one (times the degree) count as zero at the
/// segment's ends: rounding of the blossom is a few ulps of the weights, and a root exactly on a
/// shared tetrahedron face must not slip through both neighbours.
const END_ZERO: f64 = 64.0 * f64::EPSILON;

/// Smallest interval the subdivision refines before it gives up on separating roots.
const MIN_WIDTH: f64 = 1e-13;

/// The first root of the degree-`n` polynomial `c` in [lo, hi] ⊆ [0, 1], or `None`.
///
/// Bernstein subdivision (left half first; no sign change in the control polygon means no root;
/// one sign change means exactly one root, found by safeguarded Newton on the original
/// coefficients). A value within rounding of zero at `lo` is a root at `lo`.
#[must_use]
pub fn first_root_in(c: &[f64], n: usize, lo: f64, hi: f64) -> Option<f64> {
    first_root_in_tol(c, n, lo, hi, 0.0)
}

/// [`first_root_in`] where values up to `zero` in magnitude also count as zero at the ends
/// (the caller's scale: e.g. a patch's largest weight, when the segment is so short that its
/// own coefficients are all rounding noise — a ray through a mesh vertex).
#[must_use]
pub fn first_root_in_tol(c: &[f64], n: usize, lo: f64, hi: f64, zero: f64) -> Option<f64> {
    if lo > hi || n > MAX_DEGREE {
        return None;
    }
    let scale = c[..=n].iter().fold(0.0f64, |m, &x| m.max(x.abs()));
    if scale == 0.0 {
        return Some(lo);
    }
    let zero = zero.max(END_ZERO * scale * (n.max(1) as f64));
    // Restrict to [lo, hi] first.
    let mut work = [0.0; MAX_DEGREE + 1];
    work[..=n].copy_from_slice(&c[..=n]);
    let mut tmp = [0.0; MAX_DEGREE + 1];
    let mut tmp2 = [0.0; MAX_DEGREE + 1];
    if hi < 1.0 {
        split(&work, n, hi, &mut tmp, &mut tmp2);
        work[..=n].copy_from_slice(&tmp[..=n]);
    }
    if lo > 0.0 {
        let s = if hi > 0.0 { lo / hi } else { 0.0 };
        split(&work, n, s, &mut tmp, &mut tmp2);
        work[..=n].copy_from_slice(&tmp2[..=n]);
    }
    if work[0].abs() <= zero {
        return Some(lo);
    }
    // Fast paths (most calls): no sign change, or exactly one with opposite end signs.
    match sign_changes(&work, n) {
        0 => {
            return if work[n].abs() <= zero {
                Some(hi)
            } else {
                None
            };
        }
        1 if work[n] != 0.0 && (work[0] > 0.0) != (work[n] > 0.0) => {
            return Some(polish(c, n, lo, hi));
        }
        _ => {}
    }
    subdivide(c, n, &work, lo, hi, zero)
}

/// The general case of [`first_root_in`]: Bernstein subdivision of `work` (c restricted to
/// [lo, hi]).
fn subdivide(c: &[f64], n: usize, work: &Coeffs, lo: f64, hi: f64, zero: f64) -> Option<f64> {
    // Explicit stack of (coefficients, interval); left halves pop first.
    const DEPTH: usize = 64;
    let mut stack = [([0.0; MAX_DEGREE + 1], 0.0, 0.0); DEPTH];
    let mut top = 0usize;
    stack[0] = (*work, lo, hi);
    top += 1;
    while top > 0 {
        top -= 1;
        let (b, a0, a1) = stack[top];
        let changes = sign_changes(&b, n);
        if changes == 0 {
            // The end value may still be a root within rounding (shared faces).
            if a1 == hi && b[n].abs() <= zero {
                return Some(hi);
            }
            continue;
        }
        if changes == 1 && b[0] != 0.0 && b[n] != 0.0 && (b[0] > 0.0) != (b[n] > 0.0) {
            return Some(polish(c, n, a0, a1));
        }
        if a1 - a0 < MIN_WIDTH || top + 2 > DEPTH {
            // Roots not separated at this width: a tangent or multiple root.
            if (b[0] > 0.0) != (b[n] > 0.0) || b[0] == 0.0 || b[n] == 0.0 {
                return Some(polish(c, n, a0, a1));
            }
            continue;
        }
        let mut l = [0.0; MAX_DEGREE + 1];
        let mut r = [0.0; MAX_DEGREE + 1];
        split(&b, n, 0.5, &mut l, &mut r);
        let mid = 0.5 * (a0 + a1);
        stack[top] = (r, mid, a1);
        stack[top + 1] = (l, a0, mid);
        top += 2;
    }
    None
}

/// The first root of `c` (degree `n`) in [0, 1].
#[must_use]
pub fn first_root(c: &[f64], n: usize) -> Option<f64> {
    first_root_in(c, n, 0.0, 1.0)
}

fn sign_changes(b: &[f64], n: usize) -> usize {
    let mut changes = 0;
    let mut last = 0.0f64;
    for &x in &b[..=n] {
        if x != 0.0 {
            if last != 0.0 && (x > 0.0) != (last > 0.0) {
                changes += 1;
            }
            last = x;
        }
    }
    changes
}

/// The root of `c` in [a0, a1] where the values at the ends have opposite signs (or one is
/// zero): Newton steps kept inside a shrinking bracket, bisection when Newton leaves it.
fn polish(c: &[f64], n: usize, a0: f64, a1: f64) -> f64 {
    let (mut lo, mut hi) = (a0, a1);
    let flo = eval(c, n, lo);
    if flo == 0.0 {
        return lo;
    }
    let fhi = eval(c, n, hi);
    if fhi == 0.0 {
        return hi;
    }
    if (flo > 0.0) == (fhi > 0.0) {
        // No bracket (tangent root): take the point of smallest |value| by golden search.
        return tangent_min(c, n, lo, hi);
    }
    let lo_positive = flo > 0.0;
    let mut s = lo + (hi - lo) * flo / (flo - fhi);
    for _ in 0..100 {
        let (f, df) = eval_with_derivative(c, n, s);
        if f == 0.0 {
            return s;
        }
        if (f > 0.0) == lo_positive {
            lo = s;
        } else {
            hi = s;
        }
        let mut next = s - f / df;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - s).abs() <= 2.0 * f64::EPSILON * s.abs().max(1e-300) || hi - lo <= f64::EPSILON {
            return next;
        }
        s = next;
    }
    s
}

fn tangent_min(c: &[f64], n: usize, mut lo: f64, mut hi: f64) -> f64 {
    const G: f64 = 0.618_033_988_749_894_8;
    for _ in 0..60 {
        let m1 = hi - G * (hi - lo);
        let m2 = lo + G * (hi - lo);
        if eval(c, n, m1).abs() < eval(c, n, m2).abs() {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bernstein coefficients of Π (s − r_i) on [0, 1], built by products of linear factors.
    fn from_roots(roots: &[f64]) -> (Coeffs, usize) {
        let mut c = [0.0; MAX_DEGREE + 1];
        c[0] = 1.0;
        let mut n = 0;
        for &r in roots {
            let lin = [-r, 1.0 - r];
            let mut out = [0.0; MAX_DEGREE + 1];
            product(&c, n, &lin, 1, &mut out);
            c = out;
            n += 1;
        }
        (c, n)
    }

    #[test]
    fn finds_first_of_several_roots() {
        let (c, n) = from_roots(&[0.7, 0.2, 0.45, 1.8]);
        let r = first_root(&c, n).unwrap();
        // Simple well-separated root: Newton converges to a few ulps.
        assert!((r - 0.2).abs() < 1e-14, "{r}");
        let r = first_root_in(&c, n, 0.3, 1.0).unwrap();
        assert!((r - 0.45).abs() < 1e-14, "{r}");
        assert!(first_root_in(&c, n, 0.71, 1.0).is_none());
    }

    #[test]
    fn close_roots_and_no_roots() {
        let (c, n) = from_roots(&[0.5 + 1e-7, 0.5 - 1e-7, 0.9]);
        let r = first_root(&c, n).unwrap();
        // Roots 2e-7 apart are separated by subdivision; the smaller one is returned. There
        // |F'| ≈ 0.4·2e-7, so evaluation rounding (~1e-17) moves the root by up to ~1e-10.
        assert!((r - (0.5 - 1e-7)).abs() < 1e-9, "{r}");
        let (c, n) = from_roots(&[-0.5, 1.5]);
        assert!(first_root(&c, n).is_none());
    }

    #[test]
    fn eval_matches_power_form_and_elevation_keeps_values() {
        let (mut c, n) = from_roots(&[0.1, 0.3, 0.8]);
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let want = (s - 0.1) * (s - 0.3) * (s - 0.8);
            // Products of O(1) numbers: rounding only.
            assert!((eval(&c, n, s) - want).abs() < 1e-15);
        }
        elevate(&mut c, n, 7);
        let s = 0.37;
        assert!((eval(&c, 7, s) - (s - 0.1) * (s - 0.3) * (s - 0.8)).abs() < 1e-15);
    }
}

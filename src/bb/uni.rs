//! Univariate Bernstein polynomials on [0, 1]: evaluation, subdivision, product, first root.
//!
//! A polynomial is a slice of its Bernstein coefficients c0..cn (degree n = len − 1):
//! f(t) = Σ ck·C(n,k)·t^k·(1−t)^(n−k). Up to [`STACK_LEN`] coefficients nothing allocates
//! except the functions that return `Vec`s.

mod root;

pub use root::{first_root, first_root_in, first_root_in_tol, TOUCH_TOL};

/// Longest coefficient slice handled with stack scratch space (degree 15).
pub const STACK_LEN: usize = 16;

/// Binomial coefficients C(n,k) for n < 32, as f64 (exact).
const BINOM: [[f64; 32]; 32] = {
    let mut t = [[0.0; 32]; 32];
    let mut n = 0;
    while n < 32 {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
};

/// 1/C(n,k) for n < 32 (saves a division per coefficient in products).
const INV_BINOM: [[f64; 32]; 32] = {
    let mut t = [[0.0; 32]; 32];
    let mut n = 0;
    while n < 32 {
        let mut k = 0;
        while k <= n {
            t[n][k] = 1.0 / BINOM[n][k];
            k += 1;
        }
        n += 1;
    }
    t
};

/// C(n, k) as f64 (exact for n < 32; computed by the product formula beyond).
#[inline]
#[must_use]
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        0.0
    } else if n < 32 {
        BINOM[n][k]
    } else {
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    }
}

/// Runs `f` on a mutable copy of `c` (stack scratch up to [`STACK_LEN`]).
#[inline]
fn with_copy<R>(c: &[f64], f: impl FnOnce(&mut [f64]) -> R) -> R {
    if c.len() <= STACK_LEN {
        let mut buf = [0.0; STACK_LEN];
        buf[..c.len()].copy_from_slice(c);
        f(&mut buf[..c.len()])
    } else {
        let mut buf = c.to_vec();
        f(&mut buf)
    }
}

/// f(t) by de Casteljau (0 for an empty slice). Any real t is accepted (extrapolation outside
/// [0, 1]).
#[inline]
#[must_use]
pub fn eval(c: &[f64], t: f64) -> f64 {
    if c.is_empty() {
        return 0.0;
    }
    with_copy(c, |b| {
        let s = 1.0 - t;
        for r in (1..b.len()).rev() {
            for i in 0..r {
                b[i] = s * b[i] + t * b[i + 1];
            }
        }
        b[0]
    })
}

/// (f(t), f′(t)) by de Casteljau: the last two intermediate points give the derivative.
#[inline]
#[must_use]
pub fn eval_with_derivative(c: &[f64], t: f64) -> (f64, f64) {
    match c.len() {
        0 => (0.0, 0.0),
        1 => (c[0], 0.0),
        len => with_copy(c, |b| {
            let s = 1.0 - t;
            for r in (2..len).rev() {
                for i in 0..r {
                    b[i] = s * b[i] + t * b[i + 1];
                }
            }
            (s * b[0] + t * b[1], (len - 1) as f64 * (b[1] - b[0]))
        }),
    }
}

/// f′(t).
#[inline]
#[must_use]
pub fn derivative_eval(c: &[f64], t: f64) -> f64 {
    eval_with_derivative(c, t).1
}

/// Splits f at t: the coefficients of f on [0, t] and on [t, 1], each reparametrised to [0, 1].
#[must_use]
pub fn subdivide(c: &[f64], t: f64) -> (Vec<f64>, Vec<f64>) {
    let mut left = vec![0.0; c.len()];
    let mut right = vec![0.0; c.len()];
    subdivide_into(c, t, &mut left, &mut right);
    (left, right)
}

/// [`subdivide`] into caller storage: `left` and `right` must hold at least `c.len()` values.
#[inline]
pub fn subdivide_into(c: &[f64], t: f64, left: &mut [f64], right: &mut [f64]) {
    let len = c.len();
    if len == 0 {
        return;
    }
    right[..len].copy_from_slice(c);
    let s = 1.0 - t;
    left[0] = c[0];
    for r in 1..len {
        for i in 0..len - r {
            right[i] = s * right[i] + t * right[i + 1];
        }
        left[r] = right[0];
    }
}

/// The product f·g (degree m+n): c_k = Σ_{i+j=k} C(m,i)·C(n,j)/C(m+n,k)·a_i·b_j.
#[must_use]
pub fn multiply(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    multiply_into(a, b, &mut out);
    out
}

/// [`multiply`] into caller storage; returns the product's length a.len() + b.len() − 1
/// (0 when either factor is empty).
///
/// # Panics
/// When `out` is too short.
#[inline]
pub fn multiply_into(a: &[f64], b: &[f64], out: &mut [f64]) -> usize {
    if a.is_empty() || b.is_empty() {
        return 0;
    }
    let (m, n) = (a.len() - 1, b.len() - 1);
    let len = m + n + 1;
    assert!(out.len() >= len, "product needs {len} coefficients");
    out[..len].fill(0.0);
    for (i, ai) in a.iter().enumerate() {
        let wi = binomial(m, i) * ai;
        for (j, bj) in b.iter().enumerate() {
            out[i + j] += wi * binomial(n, j) * bj;
        }
    }
    if m + n < 32 {
        for (k, o) in out[..len].iter_mut().enumerate() {
            *o *= INV_BINOM[m + n][k];
        }
    } else {
        for (k, o) in out[..len].iter_mut().enumerate() {
            *o /= binomial(m + n, k);
        }
    }
    len
}

/// Degree elevation in place: the first `len` values of `c` become the len+1 coefficients of
/// the same polynomial one degree higher; returns len+1.
///
/// # Panics
/// When `c` is shorter than len+1.
#[inline]
pub fn elevate_in_place(c: &mut [f64], len: usize) -> usize {
    assert!(
        c.len() > len,
        "elevation needs room for {} coefficients",
        len + 1
    );
    if len == 0 {
        c[0] = 0.0;
        return 1;
    }
    let inv = 1.0 / len as f64; // 1/(n+1), the new degree being len
    c[len] = c[len - 1];
    for k in (1..len).rev() {
        let w = k as f64 * inv;
        c[k] = w * c[k - 1] + (1.0 - w) * c[k];
    }
    len + 1
}

/// Divides out a factor t: when f(t) = t·h(t) (so c0 = 0, up to rounding that is ignored),
/// the first `len` values of `c` become the len − 1 coefficients of h (h_k = c_{k+1}·n/(k+1)
/// with n = len − 1); returns len − 1. Used where a factor of the parametrisation vanishes at
/// t = 0 by construction (a cleared rational denominator), whose root there is not a zero of
/// the function itself.
///
/// # Panics
/// When `len` is 0 or exceeds `c.len()`.
#[inline]
pub fn deflate_at_zero(c: &mut [f64], len: usize) -> usize {
    assert!(len > 0 && len <= c.len(), "deflation of {len} coefficients");
    let n = len - 1;
    for k in 0..n {
        c[k] = c[k + 1] * n as f64 / (k + 1) as f64;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn power(c: &[f64], t: f64) -> f64 {
        let n = c.len() - 1;
        c.iter()
            .enumerate()
            .map(|(k, ck)| ck * binomial(n, k) * t.powi(k as i32) * (1.0 - t).powi((n - k) as i32))
            .sum()
    }

    #[test]
    fn eval_derivative_subdivide_multiply_elevate() {
        let a = [0.3, -1.2, 2.0, 0.7, -0.4];
        let b = [1.0, -0.5, 0.25];
        for &t in &[0.0, 0.2, 0.5, 0.9, 1.0] {
            // Rounding of a degree-4 sum of O(1) terms.
            let tol = 1e-14;
            assert!((eval(&a, t) - power(&a, t)).abs() < tol);
            let h = 1e-6;
            let fd = (power(&a, t + h) - power(&a, t - h)) / (2.0 * h);
            // Central difference error O(h²·f‴) ≈ 1e-11 plus rounding 1e-16/h ≈ 1e-10.
            assert!((derivative_eval(&a, t) - fd).abs() < 1e-8);
            let p = multiply(&a, &b);
            assert!((eval(&p, t) - power(&a, t) * power(&b, t)).abs() < tol);
        }
        let (l, r) = subdivide(&a, 0.3);
        for &u in &[0.0, 0.25, 0.6, 1.0] {
            // Rounding only.
            assert!((eval(&l, u) - eval(&a, 0.3 * u)).abs() < 1e-14);
            assert!((eval(&r, u) - eval(&a, 0.3 + 0.7 * u)).abs() < 1e-14);
        }
        let mut e = [0.0; 8];
        e[..5].copy_from_slice(&a);
        assert_eq!(elevate_in_place(&mut e, 5), 6);
        // Rounding only.
        assert!((eval(&e[..6], 0.37) - eval(&a, 0.37)).abs() < 1e-14);
    }

    #[test]
    fn deflation_divides_out_t() {
        // f(t) = t·h(t) with h = a (degree 4): deflation must give back h.
        let a = [0.3, -1.2, 2.0, 0.7, -0.4];
        let mut f = [0.0; 8];
        let len = multiply_into(&a, &[0.0, 1.0], &mut f);
        assert_eq!(len, 6);
        assert_eq!(deflate_at_zero(&mut f, len), 5);
        for &t in &[0.0, 0.3, 0.77, 1.0] {
            // Rounding only.
            assert!((eval(&f[..5], t) - eval(&a, t)).abs() < 1e-14, "t={t}");
        }
    }
}

//! Trivariate BB polynomials on plain coefficient slices: de Casteljau steps, evaluation,
//! blossom, partial derivatives, degree elevation and restriction to a segment.
//!
//! Every routine takes the degree `n` and the C(n+3,3) coefficients in the crate's multi-index
//! order, so the tracer can call them on its own compact storage. [`super::BbPoly`] wraps them.

use super::{index_of, multi_indices, num_coeffs};

/// Largest degree whose scratch space lives on the stack (`eval`, `restrict`); higher degrees
/// fall back to the heap.
pub const STACK_DEGREE: usize = 9;
const STACK_COEFFS: usize = num_coeffs(STACK_DEGREE);

/// One de Casteljau step in place: the C(d+3,3) coefficients of degree `d` at the front of `c`
/// become the C(d+2,3) coefficients of degree d−1 of the blossom with one argument fixed to `a`.
///
/// With the decreasing-lexicographic order, the children of λ (|λ| = d−1, position j) sit at
/// j (λ+e1), j+s (λ+e2), j+s+r+1 (λ+e3) and j+s+r+2 (λ+e4), where m = d−1−λ1, s = (m+1)(m+2)/2
/// and r = m−λ2. All are ≥ j, so a forward sweep can overwrite in place.
#[inline(always)]
pub fn step_in_place(c: &mut [f64], d: usize, a: [f64; 4]) {
    debug_assert!(d >= 1 && c.len() >= num_coeffs(d));
    let mut j = 0;
    for m in 0..d {
        let s = (m + 1) * (m + 2) / 2;
        for r in 0..=m {
            // A run of r+1 outputs reads four contiguous runs; all but the first lie beyond
            // the outputs (s ≥ r+1), so splitting there lets them be read while writing.
            let run = r + 1;
            let (head, tail) = c.split_at_mut(j + run);
            let out = &mut head[j..];
            let base = s - run;
            let p1 = &tail[base..base + run];
            let p23 = &tail[base + r + 1..base + r + 2 + run];
            for i in 0..run {
                out[i] = a[0] * out[i] + a[1] * p1[i] + a[2] * p23[i] + a[3] * p23[i + 1];
            }
            j += run;
        }
    }
}

/// One de Casteljau step from `src` (degree `d`) into `dst` (degree d−1); see [`step_in_place`].
#[inline(always)]
pub fn step_into(src: &[f64], dst: &mut [f64], d: usize, a: [f64; 4]) {
    debug_assert!(d >= 1 && src.len() >= num_coeffs(d) && dst.len() >= num_coeffs(d - 1));
    let mut j = 0;
    for m in 0..d {
        let s = (m + 1) * (m + 2) / 2;
        for r in 0..=m {
            let run = r + 1;
            let out = &mut dst[j..j + run];
            let p0 = &src[j..j + run];
            let p1 = &src[j + s..j + s + run];
            let p23 = &src[j + s + r + 1..j + s + r + 2 + run];
            for i in 0..run {
                out[i] = a[0] * p0[i] + a[1] * p1[i] + a[2] * p23[i] + a[3] * p23[i + 1];
            }
            j += run;
        }
    }
}

/// [`step_in_place`] for the constant degree D: the loops unroll into straight-line code.
#[inline]
fn step_in_place_c<const D: usize>(c: &mut [f64], a: [f64; 4]) {
    let c = &mut c[..num_coeffs(D)];
    step_in_place(c, D, a);
}

/// [`step_into`] for the constant degree D: the loops unroll into straight-line code.
#[inline]
fn step_into_c<const D: usize>(src: &[f64], dst: &mut [f64], a: [f64; 4]) {
    let src = &src[..num_coeffs(D)];
    let dst = &mut dst[..num_coeffs(D - 1)];
    step_into(src, dst, D, a);
}

/// [`step_in_place`] through a degree-specialised body for d ≤ 9.
#[inline(never)]
pub fn step_in_place_fast(c: &mut [f64], d: usize, a: [f64; 4]) {
    match d {
        1 => step_in_place_c::<1>(c, a),
        2 => step_in_place_c::<2>(c, a),
        3 => step_in_place_c::<3>(c, a),
        4 => step_in_place_c::<4>(c, a),
        5 => step_in_place_c::<5>(c, a),
        6 => step_in_place_c::<6>(c, a),
        7 => step_in_place_c::<7>(c, a),
        8 => step_in_place_c::<8>(c, a),
        9 => step_in_place_c::<9>(c, a),
        _ => step_in_place(c, d, a),
    }
}

/// [`step_into`] through a degree-specialised body for d ≤ 9.
#[inline(never)]
pub fn step_into_fast(src: &[f64], dst: &mut [f64], d: usize, a: [f64; 4]) {
    match d {
        1 => step_into_c::<1>(src, dst, a),
        2 => step_into_c::<2>(src, dst, a),
        3 => step_into_c::<3>(src, dst, a),
        4 => step_into_c::<4>(src, dst, a),
        5 => step_into_c::<5>(src, dst, a),
        6 => step_into_c::<6>(src, dst, a),
        7 => step_into_c::<7>(src, dst, a),
        8 => step_into_c::<8>(src, dst, a),
        9 => step_into_c::<9>(src, dst, a),
        _ => step_into(src, dst, d, a),
    }
}

/// Runs `f` on a mutable copy of the coefficients (on the stack up to [`STACK_DEGREE`]).
#[inline]
fn with_copy<R>(n: usize, c: &[f64], f: impl FnOnce(&mut [f64]) -> R) -> R {
    let len = num_coeffs(n);
    assert_eq!(c.len(), len, "degree {n} needs {len} BB coefficients");
    if n <= STACK_DEGREE {
        let mut buf = [0.0; STACK_COEFFS];
        buf[..len].copy_from_slice(c);
        f(&mut buf[..len])
    } else {
        let mut buf = c.to_vec();
        f(&mut buf)
    }
}

/// F(α) by de Casteljau (α need not sum to 1: the homogeneous form is evaluated).
#[must_use]
pub fn eval(n: usize, c: &[f64], a: [f64; 4]) -> f64 {
    with_copy(n, c, |w| {
        for d in (1..=n).rev() {
            step_in_place_fast(w, d, a);
        }
        w[0]
    })
}

/// The blossom b(`args[0]`, …, `args[n−1]`) (symmetric, multi-affine, b(α,…,α) = F(α)).
///
/// # Panics
/// When `args.len() != n` or `c` has the wrong length.
#[must_use]
pub fn blossom(n: usize, c: &[f64], args: &[[f64; 4]]) -> f64 {
    assert_eq!(
        args.len(),
        n,
        "the blossom of degree {n} takes {n} arguments"
    );
    with_copy(n, c, |w| {
        for (k, a) in args.iter().enumerate() {
            step_in_place_fast(w, n - k, *a);
        }
        w[0]
    })
}

/// ∂F/∂αi (i = 1..4) of the homogeneous form at α: n times the degree-1 de Casteljau
/// coefficients. Zero for n = 0.
#[must_use]
pub fn gradient_bary(n: usize, c: &[f64], a: [f64; 4]) -> [f64; 4] {
    if n == 0 {
        return [0.0; 4];
    }
    with_copy(n, c, |w| {
        for d in (2..=n).rev() {
            step_in_place_fast(w, d, a);
        }
        let k = n as f64;
        [k * w[0], k * w[1], k * w[2], k * w[3]]
    })
}

/// Positions of e_i + e_j among the degree-2 multi-indices.
const PAIR: [[usize; 4]; 4] = [[0, 1, 2, 3], [1, 4, 5, 6], [2, 5, 7, 8], [3, 6, 8, 9]];

/// ∂²F/∂αi∂αj of the homogeneous form at α: n(n−1) times the degree-2 de Casteljau
/// coefficients. Zero for n < 2.
#[must_use]
pub fn hessian_bary(n: usize, c: &[f64], a: [f64; 4]) -> [[f64; 4]; 4] {
    if n < 2 {
        return [[0.0; 4]; 4];
    }
    with_copy(n, c, |w| {
        for d in (3..=n).rev() {
            step_in_place_fast(w, d, a);
        }
        let k = (n * (n - 1)) as f64;
        PAIR.map(|row| row.map(|p| k * w[p]))
    })
}

/// The same polynomial in degree n+1: c'_λ = Σ_i λi/(n+1) · c_{λ−ei}.
#[must_use]
pub fn elevate(n: usize, c: &[f64]) -> Vec<f64> {
    assert_eq!(
        c.len(),
        num_coeffs(n),
        "degree {n} needs {} BB coefficients",
        num_coeffs(n)
    );
    let up = (n + 1) as f64;
    multi_indices(n + 1)
        .into_iter()
        .map(|l| {
            let mut sum = 0.0;
            for i in 0..4 {
                if l[i] > 0 {
                    let mut lower = l;
                    lower[i] -= 1;
                    sum += f64::from(l[i]) / up * c[index_of(lower)];
                }
            }
            sum
        })
        .collect()
}

/// Restriction of F to the segment α(s) = (1−s)·a0 + s·a1, s ∈ \[0, 1\]: writes the n+1
/// univariate Bernstein coefficients b_k = blossom(a0 ×(n−k), a1 ×k) to `out[..n+1]` and
/// returns n+1. No heap allocation up to degree [`STACK_DEGREE`].
///
/// Two chains of de Casteljau steps (a0^j and a1^j) are stored; b_k for k ≤ n/2 finishes the
/// a0^(n−k) node with k steps at a1, the others finish the a1^k node with n−k steps at a0.
///
/// # Panics
/// When `c` has the wrong length or `out` is shorter than n+1.
pub fn restrict(n: usize, c: &[f64], a0: [f64; 4], a1: [f64; 4], out: &mut [f64]) -> usize {
    assert_eq!(
        c.len(),
        num_coeffs(n),
        "degree {n} needs {} BB coefficients",
        num_coeffs(n)
    );
    assert!(
        out.len() > n,
        "restrict of degree {n} writes {} coefficients",
        n + 1
    );
    match n {
        0 => {
            out[0] = c[0];
            1
        }
        1 => restrict_with::<1, { chain_len(1) }>(c, a0, a1, out),
        2 => restrict_with::<2, { chain_len(2) }>(c, a0, a1, out),
        3 => restrict_with::<3, { chain_len(3) }>(c, a0, a1, out),
        4 => restrict_with::<4, { chain_len(4) }>(c, a0, a1, out),
        5 => restrict_with::<5, { chain_len(5) }>(c, a0, a1, out),
        6 => restrict_with::<6, { chain_len(6) }>(c, a0, a1, out),
        7 => restrict_with::<7, { chain_len(7) }>(c, a0, a1, out),
        8 => restrict_with::<8, { chain_len(8) }>(c, a0, a1, out),
        9 => restrict_with::<9, { chain_len(9) }>(c, a0, a1, out),
        _ => restrict_heap(n, c, a0, a1, out),
    }
}

/// Storage for one chain: Σ_{j<n} C(j+3,3) = C(n+3,4) (at least 1).
const fn chain_len(n: usize) -> usize {
    let l = n * (n + 1) * (n + 2) * (n + 3) / 24;
    if l == 0 {
        1
    } else {
        l
    }
}

/// Offset of the degree-`d` node in a chain of degree `n` (nodes of degree n−1, n−2, … 0 are
/// stored in that order).
#[inline]
const fn chain_offset(n: usize, d: usize) -> usize {
    chain_len_exact(n) - chain_len_exact(d + 1)
}

#[inline]
const fn chain_len_exact(n: usize) -> usize {
    n * (n + 1) * (n + 2) * (n + 3) / 24
}

/// [`restrict`] for the constant degree N (chains of length L = C(N+3,4)): every loop has a
/// constant trip count, so the index arithmetic folds away.
#[inline]
fn restrict_with<const N: usize, const L: usize>(
    c: &[f64],
    a0: [f64; 4],
    a1: [f64; 4],
    out: &mut [f64],
) -> usize {
    let mut c0 = [0.0; L];
    let mut c1 = [0.0; L];
    restrict_chains(N, c, a0, a1, &mut c0, &mut c1, out)
}

fn restrict_heap(n: usize, c: &[f64], a0: [f64; 4], a1: [f64; 4], out: &mut [f64]) -> usize {
    let mut c0 = vec![0.0; chain_len(n)];
    let mut c1 = vec![0.0; chain_len(n)];
    restrict_chains(n, c, a0, a1, &mut c0, &mut c1, out)
}

#[inline(always)]
fn restrict_chains(
    n: usize,
    c: &[f64],
    a0: [f64; 4],
    a1: [f64; 4],
    c0: &mut [f64],
    c1: &mut [f64],
    out: &mut [f64],
) -> usize {
    // Chains: node of degree d = n−j holds a0^j (resp. a1^j) applied to c.
    step_into_fast(c, &mut c0[chain_offset(n, n - 1)..], n, a0);
    step_into_fast(c, &mut c1[chain_offset(n, n - 1)..], n, a1);
    for d in (1..n).rev() {
        let (src, dst) = c0.split_at_mut(chain_offset(n, d - 1));
        step_into_fast(&src[chain_offset(n, d)..], dst, d, a0);
        let (src, dst) = c1.split_at_mut(chain_offset(n, d - 1));
        step_into_fast(&src[chain_offset(n, d)..], dst, d, a1);
    }
    out[0] = c0[chain_offset(n, 0)];
    out[n] = c1[chain_offset(n, 0)];
    let half = n / 2;
    // b_k = a1^k on the a0^(n−k) node (degree k).
    for k in 1..=half {
        let node = &mut c0[chain_offset(n, k)..];
        for d in (1..=k).rev() {
            step_in_place_fast(node, d, a1);
        }
        out[k] = node[0];
    }
    // b_k = a0^(n−k) on the a1^k node (degree n−k).
    for k in half + 1..n {
        let node = &mut c1[chain_offset(n, n - k)..];
        for d in (1..=n - k).rev() {
            step_in_place_fast(node, d, a0);
        }
        out[k] = node[0];
    }
    n + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Power-basis evaluation Σ c_λ n!/λ! α^λ: the independent truth.
    fn power_eval(n: usize, c: &[f64], a: [f64; 4]) -> f64 {
        let fact = |k: u8| (1..=u64::from(k)).product::<u64>() as f64;
        let nf = (1..=n as u64).product::<u64>() as f64;
        multi_indices(n)
            .iter()
            .zip(c)
            .map(|(l, w)| {
                let mut m = nf;
                for i in 0..4 {
                    m *= a[i].powi(i32::from(l[i])) / fact(l[i]);
                }
                w * m
            })
            .sum()
    }

    fn coeffs(n: usize) -> Vec<f64> {
        (0..num_coeffs(n))
            .map(|k| ((k * 37 + 11) % 17) as f64 / 8.0 - 1.0)
            .collect()
    }

    #[test]
    fn eval_matches_power_basis() {
        let a = [0.1, 0.4, 0.3, 0.2];
        for n in 0..=10 {
            let c = coeffs(n);
            let (x, y) = (eval(n, &c, a), power_eval(n, &c, a));
            // Both sums have O(C(n+3,3)) terms of size ≤ 1: rounding only.
            assert!((x - y).abs() < 1e-13, "n={n}: {x} vs {y}");
        }
    }

    #[test]
    fn restrict_matches_blossom() {
        let a0 = [0.5, 0.2, -0.1, 0.4];
        let a1 = [0.0, 0.3, 0.6, 0.1];
        for n in 0..=11 {
            let c = coeffs(n);
            let mut out = [0.0; 16];
            assert_eq!(restrict(n, &c, a0, a1, &mut out), n + 1);
            for k in 0..=n {
                let mut args = vec![a0; n - k];
                args.extend(std::iter::repeat_n(a1, k));
                let want = blossom(n, &c, &args);
                // Same blossom along different step orders: rounding only.
                assert!(
                    (out[k] - want).abs() < 1e-13,
                    "n={n} k={k}: {} vs {want}",
                    out[k]
                );
            }
        }
    }
}

//! Dense minimum-change solves for the coupled weight systems of one vertex star, hull edge or
//! face tetrahedron: Householder QR with column pivoting of Aᵀ, which reveals the rank, finds
//! the solution of A x = c closest to a target, and says how far from consistent the equations
//! are when they are singular.

/// Result of [`solve_near`].
#[derive(Clone, Debug)]
pub struct Solution {
    /// The unknowns.
    pub x: Vec<f64>,
    /// Numerical rank of A.
    pub rank: usize,
    /// max |A x − c| after the solve.
    pub residual: f64,
}

impl Solution {
    /// A solve that was not made (a group too large to factor): `x` as given (the targets),
    /// rank 0 and an infinite residual, which no consistency test accepts.
    #[must_use]
    pub fn unsolved(x: &[f64]) -> Solution {
        Solution {
            x: x.to_vec(),
            rank: 0,
            residual: f64::INFINITY,
        }
    }
}

/// Householder QR with column pivoting of M = Aᵀ (A is `m`×`n`, row-major), shared by
/// [`solve_near`] and [`dependencies`]: Πᵀ A = Rᵀ Qᵀ.
struct PivotedQr {
    /// Column k of M after the reflections, in pivot order: R[i][k] = `cols[k][i]` for i ≤ k
    /// (a column is not touched again after its own step, so `cols[k][k]` is R's diagonal);
    /// columns past the rank hold the dependent rows' reduced coordinates.
    cols: Vec<Vec<f64>>,
    /// Π: pivot position → row of A.
    perm: Vec<usize>,
    /// Q = H_0 H_1 … H_{r−1}, each H_k = I − β v vᵀ acting on coordinates k.. as (v, β).
    reflectors: Vec<(Vec<f64>, f64)>,
    /// Numerical rank: pivots stop at `rank_tol` × the largest row norm.
    rank: usize,
}

fn factor(a: &[f64], m: usize, n: usize, rank_tol: f64) -> PivotedQr {
    debug_assert_eq!(a.len(), m * n);
    // M = Aᵀ stored by columns: column i of M is row i of A (length n).
    let mut cols: Vec<Vec<f64>> = (0..m).map(|i| a[i * n..(i + 1) * n].to_vec()).collect();
    let mut perm: Vec<usize> = (0..m).collect();
    let kmax = m.min(n);
    let mut reflectors: Vec<(Vec<f64>, f64)> = Vec::with_capacity(kmax);
    let max_norm = cols
        .iter()
        .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    let mut rank = 0;
    for k in 0..kmax {
        // Pivot: the remaining column (equation) of largest norm below row k.
        let (p, pn) = (k..m)
            .map(|j| (j, cols[j][k..].iter().map(|x| x * x).sum::<f64>()))
            .fold(
                (k, -1.0),
                |best, cur| if cur.1 > best.1 { cur } else { best },
            );
        if pn.sqrt() <= rank_tol * max_norm || pn <= 0.0 {
            break;
        }
        cols.swap(k, p);
        perm.swap(k, p);
        // Householder vector for cols[k][k..].
        let x = &cols[k][k..];
        let norm = pn.sqrt();
        let alpha = if x[0] >= 0.0 { -norm } else { norm };
        let mut v = x.to_vec();
        v[0] -= alpha;
        let vv: f64 = v.iter().map(|t| t * t).sum();
        let beta = if vv > 0.0 { 2.0 / vv } else { 0.0 };
        for col in cols.iter_mut().skip(k) {
            let s: f64 = beta * v.iter().zip(&col[k..]).map(|(a, b)| a * b).sum::<f64>();
            for (ci, vi) in col[k..].iter_mut().zip(&v) {
                *ci -= s * vi;
            }
        }
        reflectors.push((v, beta));
        rank = k + 1;
    }
    PivotedQr {
        cols,
        perm,
        reflectors,
        rank,
    }
}

/// Solves A x = c (A is `m`×`n`, row-major) for the x closest to `target` in the Euclidean norm:
/// x = target + δ with δ the minimum-norm solution of A δ = c − A·target. Rows whose pivot falls
/// below `rank_tol` × the largest row norm are treated as dependent; whether they are satisfied
/// shows in [`Solution::residual`] (the caller decides what is consistent enough).
#[must_use]
pub fn solve_near(
    a: &[f64],
    m: usize,
    n: usize,
    c: &[f64],
    target: &[f64],
    rank_tol: f64,
) -> Solution {
    debug_assert_eq!(a.len(), m * n);
    // Right-hand side of the correction.
    let mut rhs: Vec<f64> = (0..m)
        .map(|i| c[i] - (0..n).map(|j| a[i * n + j] * target[j]).sum::<f64>())
        .collect();
    let PivotedQr {
        cols,
        perm,
        reflectors,
        rank,
    } = factor(a, m, n, rank_tol);
    // Πᵀ A = Rᵀ Qᵀ: forward substitution Rᵀ z = Πᵀ rhs on the first `rank` permuted equations.
    let mut z = vec![0.0; n];
    for j in 0..rank {
        let mut s = rhs[perm[j]];
        for (k, zk) in z.iter().enumerate().take(j) {
            s -= cols[j][k] * zk;
        }
        z[j] = s / cols[j][j];
    }
    // δ = Q z = H_0 H_1 … H_{r−1} z.
    for k in (0..rank).rev() {
        let (v, beta) = &reflectors[k];
        let s: f64 = beta * v.iter().zip(&z[k..]).map(|(a, b)| a * b).sum::<f64>();
        for (zi, vi) in z[k..].iter_mut().zip(v) {
            *zi -= s * vi;
        }
    }
    let x: Vec<f64> = target.iter().zip(&z).map(|(t, d)| t + d).collect();
    for (i, r) in rhs.iter_mut().enumerate() {
        *r = (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - c[i];
    }
    let residual = rhs.iter().fold(0.0_f64, |acc, r| acc.max(r.abs()));
    Solution { x, rank, residual }
}

/// The least-squares solution of B u ≈ c for B given by its columns as the rows of `bt`
/// (`n`×`m`, row-major: column j of B is `bt[j*m..(j+1)*m]`, m ≥ n rows): u minimizes
/// |B u − c|. Columns whose pivot falls below `rank_tol` × the largest column norm are left out
/// (their u is 0), so nearly parallel columns do not give huge, cancelling coefficients.
#[must_use]
pub fn least_squares(bt: &[f64], n: usize, m: usize, c: &[f64], rank_tol: f64) -> Vec<f64> {
    debug_assert_eq!(bt.len(), n * m);
    debug_assert_eq!(c.len(), m);
    // factor(bt) is the pivoted QR of M = btᵀ = B: B Π = Q R.
    let PivotedQr {
        cols,
        perm,
        reflectors,
        rank,
    } = factor(bt, n, m, rank_tol);
    // Qᵀ c = H_{r−1} … H_0 c.
    let mut y = c.to_vec();
    for (k, (v, beta)) in reflectors.iter().enumerate() {
        let s: f64 = beta * v.iter().zip(&y[k..]).map(|(a, b)| a * b).sum::<f64>();
        for (yi, vi) in y[k..].iter_mut().zip(v) {
            *yi -= s * vi;
        }
    }
    // R w = (Qᵀ c)[..rank], R[i][k] = cols[k][i]; u = Π w.
    let mut w = vec![0.0; rank];
    for p in (0..rank).rev() {
        let mut s = y[p];
        for (j, wj) in w.iter().enumerate().skip(p + 1) {
            s -= cols[j][p] * wj;
        }
        w[p] = s / cols[p][p];
    }
    let mut u = vec![0.0; n];
    for (p, wp) in w.into_iter().enumerate() {
        u[perm[p]] = wp;
    }
    u
}

/// The dependencies among the rows of A (`m`×`n`, row-major): vectors y with yᵀA = 0, one per
/// row beyond the numerical rank (pivots below `rank_tol` × the largest row norm, as in
/// [`solve_near`]). A x = c is consistent exactly when yᵀc = 0 for each of them.
#[must_use]
pub fn dependencies(a: &[f64], m: usize, n: usize, rank_tol: f64) -> Vec<Vec<f64>> {
    let PivotedQr {
        cols, perm, rank, ..
    } = factor(a, m, n, rank_tol);
    // Row perm[j] (j ≥ rank) = Σ_k w_k row perm[k] with R w = (its first `rank` coordinates),
    // R upper triangular: R[i][k] = cols[k][i].
    let mut out = Vec::new();
    for j in rank..m {
        let mut w = vec![0.0; rank];
        for i in (0..rank).rev() {
            let mut s = cols[j][i];
            for k in i + 1..rank {
                s -= cols[k][i] * w[k];
            }
            w[i] = s / cols[i][i];
        }
        let mut y = vec![0.0; m];
        y[perm[j]] = 1.0;
        for k in 0..rank {
            y[perm[k]] -= w[k];
        }
        out.push(y);
    }
    out
}

/// One-sided Jacobi: rotates the columns `c` (each of the same length) until they are
/// orthogonal to rounding, applying the same rotations to the columns of `acc` (one per column
/// of `c`, any length) when given. Afterwards the column norms of `c` are the singular values
/// of the matrix whose columns `c` were, and `acc` (started as the identity) holds the
/// matching right singular vectors.
///
/// A sweep visits the pairs (p, q), p < q, by anti-diagonals p + q. Every two pairs that share
/// a column come in the same order as in the cyclic row order (p, then q), and pairs without a
/// common column commute, so the result is bit for bit the row-order sweep's; but the pairs of
/// one anti-diagonal are disjoint, so their dot products run interleaved, and the squared
/// column norms are kept rather than recomputed for every pair (the stars' SVDs are most of a
/// large model's quintic build).
fn jacobi_columns(c: &mut [Vec<f64>], mut acc: Option<&mut [Vec<f64>]>) {
    let cols = c.len();
    let mut norm2: Vec<f64> = c.iter().map(|v| squared_norm(v)).collect();
    let diagonals: Vec<Vec<(usize, usize)>> = (1..(2 * cols).saturating_sub(2))
        .map(|s| {
            (s.saturating_sub(cols - 1)..s.div_ceil(2))
                .map(|p| (p, s - p))
                .collect()
        })
        .collect();
    for _sweep in 0..60 {
        let mut rotated = false;
        for diagonal in &diagonals {
            for chunk in diagonal.chunks(4) {
                let gammas = dot_products(c, chunk);
                for (&(p, q), gamma) in chunk.iter().zip(gammas) {
                    let (alpha, beta) = (norm2[p], norm2[q]);
                    // Columns orthogonal to rounding already.
                    if gamma == 0.0 || gamma.abs() <= 1e-15 * (alpha * beta).sqrt() {
                        continue;
                    }
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let t = if zeta == 0.0 { 1.0 } else { t };
                    let cs = 1.0 / (1.0 + t * t).sqrt();
                    let sn = cs * t;
                    // ζ overflowed (γ tiny against a column far larger than the other): the
                    // rotation is the identity. Not counted, so that sweeps made only of these
                    // end the loop instead of running to the sweep limit.
                    if sn == 0.0 {
                        continue;
                    }
                    rotated = true;
                    let (np, nq) = rotate_pair(c, p, q, cs, sn);
                    norm2[p] = np;
                    norm2[q] = nq;
                    if let Some(a) = acc.as_deref_mut() {
                        rotate_pair(a, p, q, cs, sn);
                    }
                }
            }
        }
        if !rotated {
            break;
        }
    }
}

/// Σ x², summed in index order (the order the norms are compared in, so cached and fresh
/// norms agree bit for bit).
fn squared_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |s, x| s + x * x)
}

/// The dot products c[p]·c[q] of up to four disjoint pairs, each summed in index order; four
/// at once in one pass, so the additions of different pairs overlap.
fn dot_products(c: &[Vec<f64>], pairs: &[(usize, usize)]) -> Vec<f64> {
    if let [a, b, e, f] = pairs {
        let n = c[a.0].len();
        let (a0, a1, b0, b1) = (&c[a.0][..n], &c[a.1][..n], &c[b.0][..n], &c[b.1][..n]);
        let (e0, e1, f0, f1) = (&c[e.0][..n], &c[e.1][..n], &c[f.0][..n], &c[f.1][..n]);
        let mut g = [0.0; 4];
        for i in 0..n {
            g[0] += a0[i] * a1[i];
            g[1] += b0[i] * b1[i];
            g[2] += e0[i] * e1[i];
            g[3] += f0[i] * f1[i];
        }
        return g.to_vec();
    }
    pairs
        .iter()
        .map(|&(p, q)| c[p].iter().zip(&c[q]).fold(0.0, |s, (x, y)| s + x * y))
        .collect()
}

/// Rotates columns p < q of `v` by (cs, sn); returns their new squared norms.
fn rotate_pair(v: &mut [Vec<f64>], p: usize, q: usize, cs: f64, sn: f64) -> (f64, f64) {
    let (lo, hi) = v.split_at_mut(q);
    let (mut np, mut nq) = (0.0, 0.0);
    for (x, y) in lo[p].iter_mut().zip(hi[0].iter_mut()) {
        let (u, w) = (*x, *y);
        *x = cs * u - sn * w;
        *y = sn * u + cs * w;
        np += *x * *x;
        nq += *y * *y;
    }
    (np, nq)
}

/// The singular values of A (`m`×`n`, row-major), largest first: one-sided Jacobi rotations
/// of A's columns until they are orthogonal to rounding (small singular values keep their
/// relative accuracy, so σ_min/σ_max near 1e-16 is told apart from 1e-10). A diagnostic for the
/// vertex-star systems; O(m n² · sweeps).
#[must_use]
pub fn singular_values(a: &[f64], m: usize, n: usize) -> Vec<f64> {
    debug_assert_eq!(a.len(), m * n);
    // Columns of A (or of Aᵀ when it has fewer), which the rotations orthogonalise.
    let (rows, cols) = if m >= n { (m, n) } else { (n, m) };
    let mut c: Vec<Vec<f64>> = (0..cols)
        .map(|j| {
            (0..rows)
                .map(|i| if m >= n { a[i * n + j] } else { a[j * n + i] })
                .collect()
        })
        .collect();
    jacobi_columns(&mut c, None);
    let mut s: Vec<f64> = c
        .iter()
        .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
        .collect();
    s.sort_unstable_by(|a, b| b.total_cmp(a));
    s
}

/// The left singular vectors u of A (`m`×`n`, row-major) whose singular value is at most
/// `tau` × the largest, as pairs (σ, u), smallest σ first; rows of A beyond its column count
/// give σ = 0. A x = c amplifies the component uᵀc by 1/σ, so where these are small and c is
/// data, requiring uᵀc = 0 keeps the solution from following the data's noise.
#[must_use]
pub fn near_null_left(a: &[f64], m: usize, n: usize, tau: f64) -> Vec<(f64, Vec<f64>)> {
    debug_assert_eq!(a.len(), m * n);
    // The columns of Aᵀ are A's rows; rotating them (Aᵀ W = B) leaves A = W Bᵀ with B's
    // columns orthogonal, so W's columns are the left singular vectors, B's norms the σ.
    let mut c: Vec<Vec<f64>> = (0..m).map(|i| a[i * n..(i + 1) * n].to_vec()).collect();
    let mut w: Vec<Vec<f64>> = (0..m)
        .map(|i| (0..m).map(|k| if k == i { 1.0 } else { 0.0 }).collect())
        .collect();
    jacobi_columns(&mut c, Some(&mut w));
    let sigma: Vec<f64> = c
        .iter()
        .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
        .collect();
    let top = sigma.iter().fold(0.0_f64, |a, s| a.max(*s));
    let mut out: Vec<(f64, Vec<f64>)> = sigma
        .iter()
        .zip(w)
        .filter(|(s, _)| **s <= tau * top)
        .map(|(s, u)| (*s, u))
        .collect();
    out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Square nonsingular system: the unique solution whatever the target.
    #[test]
    fn square_system_unique() {
        let a = [2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0];
        let x0 = [1.0, -2.0, 0.5];
        let c: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i * 3 + j] * x0[j]).sum())
            .collect();
        let s = solve_near(&a, 3, 3, &c, &[10.0, 10.0, 10.0], 1e-12);
        assert_eq!(s.rank, 3);
        for (x, y) in s.x.iter().zip(x0) {
            // Rounding of a 3×3 QR with entries O(1).
            assert!((x - y).abs() < 1e-13, "{x} vs {y}");
        }
    }

    /// Underdetermined: x1 + x2 = 2 closest to (3, 0) is (2.5, −0.5); a duplicated row is
    /// dependent and consistent.
    #[test]
    fn closest_point_and_dependent_rows() {
        let a = [1.0, 1.0, 2.0, 2.0];
        let s = solve_near(&a, 2, 2, &[2.0, 4.0], &[3.0, 0.0], 1e-12);
        assert_eq!(s.rank, 1);
        // Rounding only.
        assert!((s.x[0] - 2.5).abs() < 1e-14 && (s.x[1] + 0.5).abs() < 1e-14);
        assert!(s.residual < 1e-14);
        // Inconsistent dependent row shows in the residual.
        let s = solve_near(&a, 2, 2, &[2.0, 5.0], &[0.0, 0.0], 1e-12);
        assert!(s.residual > 0.1);
    }

    /// Least squares on a tall random B: the residual B u − c is orthogonal to B's columns
    /// (the normal equations hold), and a c in B's range is fitted exactly; a repeated column
    /// is left out (u 0 there) with the same fit.
    #[test]
    fn least_squares_fits_and_skips_repeated_columns() {
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let (m, n) = (40, 6);
        let mut seed = 3_u64;
        let mut bt: Vec<f64> = (0..n * m).map(|_| lcg(&mut seed)).collect();
        let c: Vec<f64> = (0..m).map(|_| lcg(&mut seed)).collect();
        let times = |bt: &[f64], n: usize, u: &[f64]| -> Vec<f64> {
            (0..m)
                .map(|i| (0..n).map(|j| bt[j * m + i] * u[j]).sum())
                .collect()
        };
        let u = least_squares(&bt, n, m, &c, 1e-12);
        let r: Vec<f64> = times(&bt, n, &u)
            .iter()
            .zip(&c)
            .map(|(a, b)| a - b)
            .collect();
        for j in 0..n {
            let g: f64 = (0..m).map(|i| bt[j * m + i] * r[i]).sum();
            // Rounding of a 40×6 QR with O(1) entries (|r| ~ 5, |B| ~ 4).
            assert!(g.abs() < 1e-12, "column {j}: Bᵀr = {g:e}");
        }
        let u0 = [1.0, -2.0, 0.5, 3.0, 0.0, -1.0];
        let exact = times(&bt, n, &u0);
        let u = least_squares(&bt, n, m, &exact, 1e-12);
        for (a, b) in u.iter().zip(u0) {
            // Rounding only (B is well conditioned).
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // Column 6 repeats column 0: one of the two gets 0 and the fit is the same.
        bt.extend_from_within(0..m);
        let u = least_squares(&bt, n + 1, m, &exact, 1e-12);
        assert!(u[0] == 0.0 || u[n] == 0.0, "{u:?}");
        let fit = times(&bt, n + 1, &u);
        assert!(fit.iter().zip(&exact).all(|(a, b)| (a - b).abs() < 1e-12));
    }

    /// U·diag(3, 1e-9, 0)·Vᵀ (row-major) with U, V rotations: U (rotating axes 0, 1), the
    /// singular values, and the product.
    fn known_matrix() -> ([[f64; 3]; 3], [f64; 3], [f64; 9]) {
        let (c1, s1) = (0.6_f64, 0.8_f64);
        let (c2, s2) = (0.28_f64, 0.96_f64);
        // U rotates axes 0, 1; V rotates axes 1, 2.
        let u = [[c1, -s1, 0.0], [s1, c1, 0.0], [0.0, 0.0, 1.0]];
        let v = [[1.0, 0.0, 0.0], [0.0, c2, -s2], [0.0, s2, c2]];
        let d = [3.0, 1e-9, 0.0];
        let mut a = [0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                a[i * 3 + j] = (0..3).map(|k| u[i][k] * d[k] * v[j][k]).sum();
            }
        }
        (u, d, a)
    }

    /// Singular values of a product U·diag(3, 1e-9, 0)·Vᵀ of rotations: found to their own
    /// relative accuracy, the rank drop as an exact zero up to rounding.
    #[test]
    fn singular_values_of_a_known_matrix() {
        let (_, _, a) = known_matrix();
        let s = singular_values(&a, 3, 3);
        // Relative accuracy of one-sided Jacobi: a few ulps of the largest for each.
        assert!((s[0] - 3.0).abs() < 1e-14, "{s:?}");
        assert!((s[1] - 1e-9).abs() < 1e-14, "{s:?}");
        assert!(s[2] < 1e-15, "{s:?}");
        // Wide matrix: the same values as its transpose's.
        let at: Vec<f64> = (0..9).map(|k| a[(k % 3) * 3 + k / 3]).collect();
        let st = singular_values(&at[..6], 2, 3);
        assert_eq!(st.len(), 2);
    }

    /// The same U·diag(3, 1e-9, 0)·Vᵀ: the left singular vectors below 1e-6 × σ_max are U's
    /// last two columns (up to sign), smallest σ first.
    #[test]
    fn near_null_left_vectors_of_a_known_matrix() {
        let (u, d, a) = known_matrix();
        let near = near_null_left(&a, 3, 3, 1e-6);
        assert_eq!(near.len(), 2, "{near:?}");
        for ((sigma, w), k) in near.iter().zip([2, 1]) {
            // Rounding of Jacobi rotations on entries O(1): a few ulps of σ_max.
            assert!((sigma - d[k]).abs() < 1e-14, "{sigma} vs {}", d[k]);
            let dot: f64 = (0..3).map(|i| w[i] * u[i][k]).sum();
            // Unit vectors equal up to sign; the 1e-9 one is separated from 0 by 1e-9 / 3,
            // so rounding of 1e-16 rotates it by at most ~1e-7.
            assert!((dot.abs() - 1.0).abs() < 1e-12, "{dot}");
        }
        // Nothing is that small in a well-conditioned matrix.
        assert!(near_null_left(&[2.0, 1.0, 1.0, 3.0], 2, 2, 1e-6).is_empty());
    }

    /// Row 3 = row 1 + 2·row 2: one dependency, yᵀA = 0, against the construction.
    #[test]
    fn dependencies_of_rows() {
        let a = [1.0, 2.0, 0.0, 0.0, 1.0, 3.0, 1.0, 4.0, 6.0];
        let ys = dependencies(&a, 3, 3, 1e-12);
        assert_eq!(ys.len(), 1);
        let y = &ys[0];
        for j in 0..3 {
            let s: f64 = (0..3).map(|i| y[i] * a[i * 3 + j]).sum();
            // Rounding of a 3×3 QR with entries O(1).
            assert!(s.abs() < 1e-13, "{y:?}");
        }
        // Proportional to (1, 2, −1).
        let r = y[0] / 1.0;
        assert!(
            (y[1] - 2.0 * r).abs() < 1e-13 && (y[2] + r).abs() < 1e-13,
            "{y:?}"
        );
        assert!(dependencies(&[2.0, 1.0, 1.0, 3.0], 2, 2, 1e-12).is_empty());
    }

    /// The cyclic row-order sweep, recomputing every norm for every pair: the plain form of
    /// one-sided Jacobi that [`jacobi_columns`] must equal bit for bit.
    fn jacobi_row_order(c: &mut [Vec<f64>], acc: &mut [Vec<f64>]) {
        let cols = c.len();
        for _sweep in 0..60 {
            let mut rotated = false;
            for p in 0..cols {
                for q in p + 1..cols {
                    let (alpha, beta, gamma) = c[p]
                        .iter()
                        .zip(&c[q])
                        .fold((0.0, 0.0, 0.0), |(al, be, ga), (x, y)| {
                            (al + x * x, be + y * y, ga + x * y)
                        });
                    if gamma == 0.0 || gamma.abs() <= 1e-15 * (alpha * beta).sqrt() {
                        continue;
                    }
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let t = if zeta == 0.0 { 1.0 } else { t };
                    let cs = 1.0 / (1.0 + t * t).sqrt();
                    let sn = cs * t;
                    if sn == 0.0 {
                        continue;
                    }
                    rotated = true;
                    for v in [&mut *c, &mut *acc] {
                        let (lo, hi) = v.split_at_mut(q);
                        for (x, y) in lo[p].iter_mut().zip(hi[0].iter_mut()) {
                            let (u, w) = (*x, *y);
                            *x = cs * u - sn * w;
                            *y = sn * u + cs * w;
                        }
                    }
                }
            }
            if !rotated {
                break;
            }
        }
    }

    /// Anti-diagonal order with kept norms gives the row order's bits exactly, on seeded random
    /// matrices of every shape from 1 to 13 columns, full rank, rank-deficient (repeated and
    /// combined columns, whose rotations end inside the null space) and with columns 1e-150 of
    /// the others (where ζ overflows and the rotation is the identity).
    #[test]
    fn anti_diagonal_sweep_equals_row_order_bits() {
        let mut rng = crate::fixtures::Lcg(7);
        let mut next = || rng.uniform() - 0.5;
        for cols in 1..=13 {
            for kind in 0..3 {
                let len = 3 + (cols * 7) % 11;
                let mut c: Vec<Vec<f64>> = (0..cols)
                    .map(|_| (0..len).map(|_| next()).collect())
                    .collect();
                if kind == 1 && cols > 2 {
                    c[cols - 1] = c[0].clone();
                    c[1] = c[0].iter().zip(&c[2]).map(|(x, y)| 2.0 * x - y).collect();
                }
                if kind == 2 {
                    c[cols / 2].iter_mut().for_each(|x| *x *= 1e-150);
                }
                let eye: Vec<Vec<f64>> = (0..cols)
                    .map(|i| (0..cols).map(|k| f64::from(u8::from(i == k))).collect())
                    .collect();
                let (mut c1, mut w1) = (c.clone(), eye.clone());
                jacobi_columns(&mut c1, Some(&mut w1));
                let (mut c2, mut w2) = (c, eye);
                jacobi_row_order(&mut c2, &mut w2);
                let bits = |v: &[Vec<f64>]| -> Vec<u64> {
                    v.iter().flatten().map(|x| x.to_bits()).collect()
                };
                assert_eq!(bits(&c1), bits(&c2), "columns, {cols} cols, kind {kind}");
                assert_eq!(bits(&w1), bits(&w2), "vectors, {cols} cols, kind {kind}");
            }
        }
    }
}

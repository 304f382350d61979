//! Sparse minimum-change solves for coupled weight systems too large for [`super::dense`]
//! (large coplanar regions couple whole regions of vertex stars, and the global fallback of
//! [`super::system::System::solve`] couples everything): Craig's method, i.e. conjugate
//! gradients on A Aᵀ y = c − A·target with x = target + Aᵀ y.
//!
//! Every iterate of the correction Aᵀ y lies in the row space of A, so when A x = c is
//! consistent the iteration converges to the same answer as the dense solve: the solution
//! closest to the target. Equations are scaled to unit norm first (the solution set does not
//! change, the conditioning does). The rank is not computed; an inconsistent system shows as a
//! residual that does not fall below the tolerance.

use super::dense::Solution;

/// Iterations over which the residual must at least halve (else the system is taken as
/// inconsistent and the solve stops).
const STALL: usize = 10_000;

/// One sparse row: (column, coefficient) pairs.
pub type Row = Vec<(usize, f64)>;

/// `terms` sorted by index, with the coefficients of a repeated index summed (in the order
/// the sort leaves them).
pub(super) fn merged(mut terms: Vec<(u32, f64)>) -> Vec<(u32, f64)> {
    terms.sort_unstable_by_key(|t| t.0);
    let mut out: Vec<(u32, f64)> = Vec::with_capacity(terms.len());
    for (j, a) in terms {
        match out.last_mut() {
            Some(last) if last.0 == j => last.1 += a,
            _ => out.push((j, a)),
        }
    }
    out
}

/// Solves A x = c (rows of A as sparse `rows`, `n` unknowns) for the x closest to `target` in
/// the Euclidean norm, iterating until max |A x − c| ≤ `tol` or `max_iter` iterations.
/// [`Solution::rank`] is the number of equations (not computed).
#[must_use]
pub fn solve_near(
    rows: &[Row],
    n: usize,
    c: &[f64],
    target: &[f64],
    tol: f64,
    max_iter: usize,
) -> Solution {
    let m = rows.len();
    // Unit-norm rows.
    let scale: Vec<f64> = rows
        .iter()
        .map(|r| {
            let s = r.iter().map(|(_, a)| a * a).sum::<f64>().sqrt();
            if s > 0.0 {
                1.0 / s
            } else {
                0.0
            }
        })
        .collect();
    let mul_a = |x: &[f64], out: &mut [f64]| {
        for (i, r) in rows.iter().enumerate() {
            out[i] = scale[i] * r.iter().map(|&(j, a)| a * x[j]).sum::<f64>();
        }
    };
    let mul_at = |y: &[f64], out: &mut [f64]| {
        out.iter_mut().for_each(|o| *o = 0.0);
        for (i, r) in rows.iter().enumerate() {
            let yi = scale[i] * y[i];
            if yi != 0.0 {
                for &(j, a) in r {
                    out[j] += a * yi;
                }
            }
        }
    };
    let mut x = target.to_vec();
    let mut ax = vec![0.0; m];
    // Scaled residual r = Âĉ − Â x (Â, ĉ: the unit-norm rows); |r_i| / scale_i is the
    // residual of equation i.
    let scaled_residual = |x: &[f64], ax: &mut [f64], r: &mut [f64]| {
        mul_a(x, ax);
        for i in 0..m {
            r[i] = scale[i] * c[i] - ax[i];
        }
    };
    let max_residual = |r: &[f64]| {
        r.iter()
            .zip(&scale)
            .map(|(ri, si)| if *si > 0.0 { ri.abs() / si } else { 0.0 })
            .fold(0.0_f64, f64::max)
    };
    let mut r = vec![0.0; m];
    scaled_residual(&x, &mut ax, &mut r);
    let mut p = r.clone();
    let mut atp = vec![0.0; n];
    let mut rr: f64 = r.iter().map(|v| v * v).sum();
    let mut it = 0;
    let mut checkpoint = f64::INFINITY;
    // Iterate until the recurred residual meets `tol`, then confirm with the true one (and
    // restart from it if rounding made them drift apart). Stopping at once matters: CG on a
    // singular A Aᵀ that goes on after convergence takes ever larger steps whose rounding
    // leaves the row space, and the answer would drift from the closest solution.
    loop {
        if max_residual(&r) <= tol {
            scaled_residual(&x, &mut ax, &mut r);
            if max_residual(&r) <= tol {
                break;
            }
            p.clone_from(&r);
            rr = r.iter().map(|v| v * v).sum();
        }
        if it >= max_iter || rr <= 0.0 {
            break;
        }
        // An inconsistent system never meets `tol`: give up when the residual has not halved
        // in `STALL` iterations (consistent ones fall by orders of magnitude in that time on
        // every model tried; torus_quad's group of 7635 needs more than 2000).
        if it % STALL == 0 {
            let now = max_residual(&r);
            if it > 0 && now > 0.5 * checkpoint {
                break;
            }
            checkpoint = now;
        }
        // Craig: α = rᵀr / |Âᵀp|², x += α Âᵀp, r −= α Â Âᵀ p.
        mul_at(&p, &mut atp);
        let pap: f64 = atp.iter().map(|v| v * v).sum();
        if pap <= 0.0 || !pap.is_finite() {
            break;
        }
        let alpha = rr / pap;
        for (xj, aj) in x.iter_mut().zip(&atp) {
            *xj += alpha * aj;
        }
        mul_a(&atp, &mut ax);
        for (ri, ai) in r.iter_mut().zip(&ax) {
            *ri -= alpha * ai;
        }
        let rr_new: f64 = r.iter().map(|v| v * v).sum();
        let beta = rr_new / rr;
        for (pi, ri) in p.iter_mut().zip(&r) {
            *pi = ri + beta * *pi;
        }
        rr = rr_new;
        it += 1;
    }
    scaled_residual(&x, &mut ax, &mut r);
    let residual = max_residual(&r);
    Solution {
        x,
        rank: m,
        residual,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::quintic_c2::cholesky::tests::{sparse_rows, times};

    /// Agrees with the dense solve on a random underdetermined, rank-deficient but consistent
    /// system (two dependent rows), seeded.
    #[test]
    fn matches_dense_on_rank_deficient_system() {
        let (m, n) = (30, 50);
        let mut seed = 12345_u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut a = vec![0.0; m * n];
        for i in 0..m - 2 {
            // Sparse rows: 6 nonzeros each.
            for _ in 0..6 {
                let j = ((rnd() + 1.0) * 0.5 * n as f64) as usize % n;
                a[i * n + j] = rnd();
            }
        }
        // Two dependent rows.
        for j in 0..n {
            a[(m - 2) * n + j] = a[j] + 2.0 * a[n + j];
            a[(m - 1) * n + j] = a[2 * n + j] - a[3 * n + j];
        }
        let x0: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let c = times(&a, m, n, &x0);
        let target: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let rows = sparse_rows(&a, m, n);
        let d = crate::scheme::quintic_c2::dense::solve_near(&a, m, n, &c, &target, 1e-11);
        let s = solve_near(&rows, n, &c, &target, 1e-13, 10_000);
        // Consistent system: rounding-level residual, as asked.
        assert!(s.residual <= 1e-13, "{}", s.residual);
        for (x, y) in s.x.iter().zip(&d.x) {
            // Both are the unique closest solution; CG stops at a 1e-13 residual, and this
            // system's condition number is modest (entries O(1), 30 rows).
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
    }
}

//! The sign program of [`super::signfit`] in pure Rust: a primal-dual interior point method
//! (Mehrotra's predictor-corrector) whose Newton systems are weighted projections onto the
//! C1/C2 equations, made with the projection's own double-double factor
//! ([`cholesky::Projector::precise`]) on column-scaled rows.
//!
//! The program, in units of the median |weight| (m the margin, w_i each miss's cost, j_i the
//! weight of condition i, s_i its sign):
//!
//! ```text
//! minimise Σ w_i v_i   subject to   A x = c,
//!                                   v_i + s_i x_{j_i} − b_i = m,   v_i ≥ 0,   b_i ≥ 0.
//! ```
//!
//! Its dual has one z_i per condition, 0 ≤ z_i ≤ w_i, and asks Aᵀ y + Σ_i s_i z_i e_{j_i} = 0.
//! Eliminating (v, b, z) condition by condition leaves, for the step in x, a diagonal
//! Hessian H (θ_i on the signed weights, θ_i = 1 / (v_i / (w_i − z_i) + b_i / z_i)) and
//! A dx = r: the step is the projection of H^{-1/2} q onto {A H^{-1/2} u = r}, scaled back.
//! The weights without a sign condition are free variables; a small primal regularisation
//! ([`REGULARISE`]) keeps H positive.
//!
//! Why not a general LP solver: the rows are nearly dependent (the equations of the flat nets
//! and of C2 across nearly flat faces), and a program that meets them to 1e-6 only is moved
//! back onto them by O(1) (session 33, Clarabel). Here every step meets the rows with the
//! same factor that the projection uses, so the iterates stay on them. f64 factors of the
//! column-scaled rows are not enough (session 34: rounding pivots of exactly dependent rows
//! rise above the drop threshold once the columns are scaled, and the steps miss the rows by
//! up to 1e4); double-double ones meet them to 1e-12.

use super::cholesky::{Ordering, Projector, PRECISE_PIVOT};
use super::sparse::Row;

/// Primal regularisation added to every diagonal entry of H (per median weight squared): a
/// step of one median in a free weight costs as much as the barrier's pull at a distance of
/// 1e3 medians; small against every θ of a condition near its margin.
const REGULARISE: f64 = 1e-6;

/// Fraction of the way to the boundary that a step may go.
const STEP_FRACTION: f64 = 0.99;

/// Iterations at most.
const MAX_ITERATIONS: usize = 80;

/// Stop when the mean complementarity μ is below this (in median weights): a condition that
/// holds at the optimum has v_i ≈ μ / (w_i − z_i) ≤ μ (its z_i → 0 and w_i ≥ 1), a hundredth
/// of the margin ([`super::signfit::PROGRAM_MARGIN`] = 1e-3), so its weight keeps its sign.
const FINAL_MU: f64 = 1e-5;

/// One sign condition: its weight, side and cost.
struct Condition {
    j: usize,
    s: f64,
    w: f64,
}

/// The iterate: primal x, v, b; dual z and p = Aᵀ y (or a Newton direction for them).
struct Point {
    x: Vec<f64>,
    v: Vec<f64>,
    b: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
}

/// The weights (units of `x`) of [`super::signfit`]'s least-violation program, from the
/// solved `x`, which meets `rows` = `c` (over `n` unknowns, `ordering` made for them: the
/// weighted rows below share their structure). `signed` (index, ±1) are the
/// sign conditions, `cost` their weights (1 where short), `margin` the sign margin in units
/// of `median`.
///
/// # Errors
/// When the iterations produce values that are not finite or do not converge.
#[allow(clippy::too_many_arguments)]
pub fn least_violation(
    rows: &[Row],
    n: usize,
    c: &[f64],
    ordering: &Ordering,
    x: &[f64],
    signed: &[(usize, f64)],
    cost: &[f64],
    median: f64,
    margin: f64,
) -> Result<Vec<f64>, String> {
    let conds: Vec<Condition> = signed
        .iter()
        .enumerate()
        .map(|(i, &(j, s))| Condition {
            j,
            s,
            w: super::signfit::miss_cost(cost, i),
        })
        .collect();
    let k = conds.len();
    let cs: Vec<f64> = c.iter().map(|v| v / median).collect();
    let xs: Vec<f64> = x.iter().map(|v| v / median).collect();
    // Start: v, b ≥ 1 with the condition rows met, z in the middle of its box, y = 0. (z
    // where each pair's products v (w − z) and b z are equal was tried: on mpi_poly the
    // steps shrank to 0.01 and μ grew.)
    let v: Vec<f64> = conds
        .iter()
        .map(|q| (margin - q.s * xs[q.j]).max(0.0) + 1.0)
        .collect();
    let b: Vec<f64> = conds
        .iter()
        .zip(&v)
        .map(|(q, vi)| vi + q.s * xs[q.j] - margin)
        .collect();
    let z: Vec<f64> = conds.iter().map(|q| 0.5 * q.w).collect();
    let mut pt = Point {
        x: xs,
        v,
        b,
        z,
        p: vec![0.0; n],
    };
    let trace = std::env::var_os("APATCH_SIGN_TRACE").is_some();
    for it in 0..MAX_ITERATIONS {
        let mu = complementarity(&conds, &pt) / (2 * k) as f64;
        // Residuals: the rows (r1), the condition rows (r2), dual feasibility in x (rd).
        let r1: Vec<f64> = rows
            .iter()
            .zip(&cs)
            .map(|(row, ci)| ci - row.iter().map(|&(j, a)| a * pt.x[j]).sum::<f64>())
            .collect();
        let r2: Vec<f64> = conds
            .iter()
            .enumerate()
            .map(|(i, q)| margin - pt.v[i] - q.s * pt.x[q.j] + pt.b[i])
            .collect();
        let mut rd: Vec<f64> = pt.p.iter().map(|pj| -pj).collect();
        for (i, q) in conds.iter().enumerate() {
            rd[q.j] -= q.s * pt.z[i];
        }
        let norm = |r: &[f64]| r.iter().fold(0.0_f64, |a, t| a.max(t.abs()));
        if trace {
            eprintln!(
                "sign interior point: iteration {it}, mu {mu:.3e}, rows {:.1e}, conditions {:.1e}, dual {:.1e}, objective {:.6e}",
                norm(&r1),
                norm(&r2),
                norm(&rd),
                conds.iter().zip(&pt.v).map(|(q, vi)| q.w * vi).sum::<f64>()
            );
        }
        if !mu.is_finite() {
            return Err(format!("interior point: not finite at iteration {it}"));
        }
        if mu <= FINAL_MU && norm(&r2) <= 1e-9 {
            return Ok(pt.x.iter().map(|v| v * median).collect());
        }
        crate::progress::report(|| {
            format!("quintic-c2 sign program: interior point iteration {it}")
        });
        // θ and the weighted rows: one double-double factor for both solves.
        let theta: Vec<f64> = conds
            .iter()
            .enumerate()
            .map(|(i, q)| 1.0 / (pt.v[i] / (q.w - pt.z[i]) + pt.b[i] / pt.z[i]))
            .collect();
        let mut h = vec![REGULARISE; n];
        for (i, q) in conds.iter().enumerate() {
            h[q.j] += theta[i];
        }
        let d: Vec<f64> = h.iter().map(|hj| 1.0 / hj.sqrt()).collect();
        let scaled: Vec<Row> = rows
            .iter()
            .map(|r| r.iter().map(|&(j, a)| (j, a * d[j])).collect())
            .collect();
        let projector = Projector::precise(&scaled, n, &r1, ordering, PRECISE_PIVOT);
        let solve = |k1: &[f64], k2: &[f64]| -> Point {
            newton(&conds, &pt, &theta, &h, &d, &r2, &rd, k1, k2, &projector)
        };
        // Predictor: μ → 0.
        let k1: Vec<f64> = conds
            .iter()
            .enumerate()
            .map(|(i, q)| -pt.v[i] * (q.w - pt.z[i]))
            .collect();
        let k2: Vec<f64> = (0..k).map(|i| -pt.b[i] * pt.z[i]).collect();
        let aff = solve(&k1, &k2);
        let (ap, ad) = step_lengths(&conds, &pt, &aff);
        let mut mu_aff = 0.0;
        for (i, q) in conds.iter().enumerate() {
            let vi = pt.v[i] + ap * aff.v[i];
            let bi = pt.b[i] + ap * aff.b[i];
            let zi = pt.z[i] + ad * aff.z[i];
            mu_aff += vi * (q.w - zi) + bi * zi;
        }
        mu_aff /= (2 * k) as f64;
        let sigma = (mu_aff / mu).powi(3).clamp(0.0, 1.0);
        // Corrector: centring towards σμ with the predictor's second-order terms.
        let k1: Vec<f64> = conds
            .iter()
            .enumerate()
            .map(|(i, q)| sigma * mu - pt.v[i] * (q.w - pt.z[i]) + aff.v[i] * aff.z[i])
            .collect();
        let k2: Vec<f64> = (0..k)
            .map(|i| sigma * mu - pt.b[i] * pt.z[i] - aff.b[i] * aff.z[i])
            .collect();
        let dir = solve(&k1, &k2);
        let (ap, ad) = step_lengths(&conds, &pt, &dir);
        let (ap, ad) = (STEP_FRACTION * ap, STEP_FRACTION * ad);
        if trace {
            eprintln!("sign interior point: sigma {sigma:.2e}, steps {ap:.3} / {ad:.3}");
        }
        for j in 0..n {
            pt.x[j] += ap * dir.x[j];
            pt.p[j] += ad * dir.p[j];
        }
        for i in 0..k {
            pt.v[i] += ap * dir.v[i];
            pt.b[i] += ap * dir.b[i];
            pt.z[i] += ad * dir.z[i];
        }
    }
    Err(format!(
        "interior point: not converged after {MAX_ITERATIONS} iterations"
    ))
}

/// Σ v_i (w_i − z_i) + b_i z_i.
fn complementarity(conds: &[Condition], pt: &Point) -> f64 {
    conds
        .iter()
        .enumerate()
        .map(|(i, q)| pt.v[i] * (q.w - pt.z[i]) + pt.b[i] * pt.z[i])
        .sum()
}

/// The Newton direction with complementarity right-hand sides `k1` (for v (w − z)) and `k2`
/// (for b z), the condition rows' residual `r2` and the dual residual `rd`.
#[allow(clippy::too_many_arguments)]
fn newton(
    conds: &[Condition],
    pt: &Point,
    theta: &[f64],
    h: &[f64],
    d: &[f64],
    r2: &[f64],
    rd: &[f64],
    k1: &[f64],
    k2: &[f64],
    projector: &Projector,
) -> Point {
    let n = pt.x.len();
    // ρ_i and q = Eᵀ S θ ρ − r_d.
    let rho: Vec<f64> = conds
        .iter()
        .enumerate()
        .map(|(i, q)| r2[i] - k1[i] / (q.w - pt.z[i]) + k2[i] / pt.z[i])
        .collect();
    let mut qv: Vec<f64> = rd.iter().map(|r| -r).collect();
    for (i, q) in conds.iter().enumerate() {
        qv[q.j] += q.s * theta[i] * rho[i];
    }
    // dx = D u, u the projection of D q onto {A D u = r1}.
    let mut u: Vec<f64> = (0..n).map(|j| d[j] * qv[j]).collect();
    let scale = u.iter().fold(0.0_f64, |a, t| a.max(t.abs()));
    projector.meet(&mut u, 1e-14 * scale.max(f64::MIN_POSITIVE));
    let dx: Vec<f64> = (0..n).map(|j| d[j] * u[j]).collect();
    // Aᵀ dy = H dx − q.
    let dp: Vec<f64> = (0..n).map(|j| h[j] * dx[j] - qv[j]).collect();
    let dz: Vec<f64> = conds
        .iter()
        .enumerate()
        .map(|(i, q)| theta[i] * (rho[i] - q.s * dx[q.j]))
        .collect();
    let dv: Vec<f64> = conds
        .iter()
        .enumerate()
        .map(|(i, q)| (k1[i] + pt.v[i] * dz[i]) / (q.w - pt.z[i]))
        .collect();
    let db: Vec<f64> = (0..conds.len())
        .map(|i| (k2[i] - pt.b[i] * dz[i]) / pt.z[i])
        .collect();
    Point {
        x: dx,
        v: dv,
        b: db,
        z: dz,
        p: dp,
    }
}

/// The longest primal (v, b ≥ 0) and dual (0 ≤ z ≤ w) steps along `dir`, at most 1.
fn step_lengths(conds: &[Condition], pt: &Point, dir: &Point) -> (f64, f64) {
    let mut ap: f64 = 1.0;
    let mut ad: f64 = 1.0;
    for (i, q) in conds.iter().enumerate() {
        if dir.v[i] < 0.0 {
            ap = ap.min(-pt.v[i] / dir.v[i]);
        }
        if dir.b[i] < 0.0 {
            ap = ap.min(-pt.b[i] / dir.b[i]);
        }
        if dir.z[i] < 0.0 {
            ad = ad.min(-pt.z[i] / dir.z[i]);
        }
        if dir.z[i] > 0.0 {
            ad = ad.min((q.w - pt.z[i]) / dir.z[i]);
        }
    }
    (ap, ad)
}

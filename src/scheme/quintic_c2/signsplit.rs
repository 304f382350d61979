//! Theorem 2.1's signs in a group too large to pin (`QuinticOptions::joint_sign_fit`): the
//! sign program's objective ([`super::signfit`]) by a splitting method that needs nothing but
//! the group's one factor.
//!
//! The alternating projections of [`super::cholesky::sign_rounds`] spread the misses over
//! thousands of weights (a least-squares compromise) and, where the box and the rows do not
//! meet, stop improving after a few rounds (fandisk's joint group: 10677 → 9100 weights off).
//! What keeps the surface single sheeted is as few weights off as possible, the L1 objective
//! of the sign program:
//!
//! ```text
//! minimise  Σ_signed max(0, μ m − s_j x_j) · m  +  ε/2 |x − x₀|²   over x with A x = c,
//!           and x − x₀ orthogonal to the basis Q the dropped rows were met with,
//! ```
//!
//! where x₀ is the solved group (its dropped rows met by [`super::cholesky::meet_dropped`]),
//! m the sign box's margin, μ ([`FIT_MARGIN`]) small, so that only the weights off their sign
//! are pushed, and ε ([`STAY`]) keeps the move from wandering where no sign gains.
//! The program is split as ADMM (x in the affine set, z in the objective, x = z): the x step
//! is one projection with the factor, the z step is closed form per weight, so a round costs
//! one solve (seconds where the factor took minutes). The move stays orthogonal to Q: the
//! rows Q was made for are met by x₀ and see a move only through its Q part (a move in the
//! kept rows' null space meets a row a as Π a · move, and Π a lies in Q's span).

use super::cholesky::{NormalSolve, SignBox, UnitRows};

/// ε of the stay term, in units of the box's margin: fixing a weight that is off by one unit
/// gains about 1 in the hinge and moving it by that costs ε/2, so a sign is worth moving its
/// weight and about a thousand neighbours by as much. At 0.1 the stay won on the tests' random
/// systems (58 → 25 off where 0 can be reached); at 1e-3 and 1e-5 both reach 0.
const STAY: f64 = 1e-3;

/// The margin the fit asks of a signed weight, as a fraction of the sign box's margin (its
/// unit here). The hinge pushes every weight below its margin, so with the box's own margin
/// (1 median of the targets) it pushed half of fandisk's 1.37M signed weights at once, and
/// their projections back onto the rows took 13031 weights off to 32000 within 60 rounds: the
/// fit is for the weights off their sign, not for the box.
const FIT_MARGIN: f64 = 0.01;

/// The ADMM penalty to start with, in the same units (adapted by residual balancing).
const RHO: f64 = 1.0;

/// Residual balancing: ρ is doubled (halved) when the primal residual |x − z| is this many
/// times the dual one ρ |z − z_prev| (or the other way round).
const BALANCE: f64 = 10.0;

/// `d ← (I − Q Qᵀ) Π d`: d's projection onto the kept rows' null space, less its part in
/// span Q (Q orthonormal and in that null space).
fn project_move<F: NormalSolve>(unit: &UnitRows, f: &F, q: &[Vec<f64>], d: &mut Vec<f64>) {
    f.project(&unit.rows, std::slice::from_mut(d));
    for qk in q {
        let h: f64 = qk.iter().zip(d.iter()).map(|(a, b)| a * b).sum();
        d.iter_mut().zip(qk).for_each(|(v, w)| *v -= h * w);
    }
}

/// Most projections [`settle`] makes of a move: on fandisk's joint group one projection of the
/// fit's move left the rows missed by 1.3e-7 and each of the next two removed most of what the
/// one before left (nearly dependent kept rows amplify the projection's rounding).
const SETTLE: usize = 8;

/// Projects y's move from x₀ onto the kept rows' null space (less its part in span `q`) again
/// and again while that lowers max |A y − c|, at most [`SETTLE`] times: the fit's last round
/// is one projection of a long move, whose rounding the rows see. Returns the residual of the
/// y kept (the lowest; y as it came if no projection lowers it).
pub(super) fn settle<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    q: &[Vec<f64>],
    x0: &[f64],
    y: &mut Vec<f64>,
    r: &mut [f64],
) -> f64 {
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    let mut res = unit.residual(y, r);
    for round in 0..SETTLE {
        let mut d: Vec<f64> = y.iter().zip(x0).map(|(a, b)| a - b).collect();
        project_move(unit, f, q, &mut d);
        let z: Vec<f64> = x0.iter().zip(&d).map(|(a, b)| a + b).collect();
        let got = unit.residual(&z, r);
        if trace {
            eprintln!("quintic-c2 sign fit, settling the move, projection {round}: residual {res:.2e} -> {got:.2e}");
        }
        if got.is_nan() || got >= res {
            break;
        }
        (*y, res) = (z, got);
    }
    // r holds the last projection's residuals, which may not be y's.
    unit.residual(y, r)
}

/// Runs `sb.fit` rounds of the split sign program from x (the solved group), with moves
/// orthogonal to `q`; x is moved to the round with the fewest weights off their sign (each
/// counted at its [`SignBox::cost`]) if that has fewer than x and misses the rows by at most
/// `bound`: then its max |A x − c| is returned, else `None` (x left as it was).
pub(super) fn fit<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    x: &mut Vec<f64>,
    q: &[Vec<f64>],
    sb: &SignBox,
    bound: f64,
) -> Option<f64> {
    let margin = sb.margin;
    if sb.fit == 0 || sb.signed.is_empty() || margin.is_nan() || margin <= 0.0 {
        return None;
    }
    let n = x.len();
    let m = unit.rows.len();
    let x0 = x.clone();
    let mut r = vec![0.0; m];
    let start = unit.residual(x, &mut r);
    let tiny = super::cholesky::zero_up_to_rounding(x);
    let off_before = sb.off(x, tiny);
    let mut sign = vec![0.0; n];
    let mut cost = vec![1.0; n];
    for (i, &(j, s)) in sb.signed.iter().enumerate() {
        sign[j] = s;
        cost[j] = sb.cost.get(i).copied().unwrap_or(1.0);
    }
    let off_cost_before = sb.off_cost(x, tiny);
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    // In units of the box's margin: stay ε/2 |z − x₀|² + Σ max(0, FIT_MARGIN − s z) over the
    // signed weights.
    // Exploration (`APATCH_FIT_MARGIN`): another margin, in the same units.
    let fit_margin = super::cholesky::positive_env("APATCH_FIT_MARGIN").unwrap_or(FIT_MARGIN);
    let mut rho = RHO;
    let mut z = x0.clone();
    let mut u = vec![0.0; n];
    let mut best: Option<(f64, Vec<f64>)> = None;
    for round in 0..sb.fit {
        let t = std::time::Instant::now();
        // x step: x₀ + P (z − u − x₀).
        let mut d: Vec<f64> = (0..n).map(|j| z[j] - u[j] - x0[j]).collect();
        project_move(unit, f, q, &mut d);
        let xk: Vec<f64> = (0..n).map(|j| x0[j] + d[j]).collect();
        // z step, per weight: argmin ε/2 (z − x₀)² + ρ/2 (z − v)² + hinge, v = x + u.
        let kappa = STAY + rho;
        let (mut primal, mut dual) = (0.0, 0.0);
        for j in 0..n {
            let v = xk[j] + u[j];
            let a = (STAY * x0[j] + rho * v) / kappa;
            let s = sign[j];
            let zj = if s == 0.0 {
                a
            } else {
                // In the weight's own sign and the unit: the hinge's slope −cost below the
                // margin.
                let w = s * a / margin;
                let step = cost[j] / kappa;
                let w = if w >= fit_margin {
                    w
                } else if w + step < fit_margin {
                    w + step
                } else {
                    fit_margin
                };
                s * w * margin
            };
            primal += (xk[j] - zj).powi(2);
            dual += (zj - z[j]).powi(2);
            u[j] += xk[j] - zj;
            z[j] = zj;
        }
        let (primal, dual) = (primal.sqrt(), rho * dual.sqrt());
        let weighed = sb.off_cost(&xk, tiny);
        if trace {
            let off = sb.off(&xk, tiny);
            eprintln!(
                "quintic-c2 sign fit, round {round}: {off} off their sign (was {off_before}; at their cost {weighed} was {off_cost_before}), primal {primal:.2e}, dual {dual:.2e}, rho {rho}, {:.1} s",
                t.elapsed().as_secs_f64()
            );
        }
        if best.as_ref().is_none_or(|b| weighed < b.0) {
            best = Some((weighed, xk));
        }
        // Residual balancing; u is the scaled dual λ/ρ, so it scales by 1/the factor.
        if primal > BALANCE * dual {
            rho *= 2.0;
            u.iter_mut().for_each(|v| *v *= 0.5);
        } else if dual > BALANCE * primal {
            rho *= 0.5;
            u.iter_mut().for_each(|v| *v *= 2.0);
        }
    }
    let (_, mut y) = best?;
    let res = settle(unit, f, q, &x0, &mut y, &mut r);
    let off = sb.off(&y, tiny);
    if trace {
        eprintln!(
            "quintic-c2 sign fit: {off_before} -> {off} off their sign, residual {start:.2e} -> {res:.2e} (bound {bound:.2e})"
        );
    }
    (res <= bound && sb.off_cost(&y, tiny) < off_cost_before).then(|| {
        *x = y;
        res
    })
}

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

use super::cholesky::{dot, new_direction, projected_rows, NormalSolve, SignBox, UnitRows};

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
/// span Q (Q = `q` and `sealed`, orthonormal and in that null space; two slices, so that
/// neither is copied: each vector is the group's length).
fn project_move<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    q: &[Vec<f64>],
    sealed: &[Vec<f64>],
    d: &mut Vec<f64>,
) {
    f.project(&unit.rows, std::slice::from_mut(d));
    for qk in q.iter().chain(sealed) {
        let h: f64 = qk.iter().zip(d.iter()).map(|(a, b)| a * b).sum();
        d.iter_mut().zip(qk).for_each(|(v, w)| *v -= h * w);
    }
}

/// Rows a round of [`seal`] takes: the worst the move misses.
const SEAL_ROWS: usize = 32;

/// Most directions [`seal`] takes out of a fit's moves, over all its passes: each is a dense
/// vector of the group's length (14.6 MB on fandisk's joint group, whose factors already hold
/// ~17 GB), so 128 of them add ~1.9 GB.
const SEAL_BASIS: usize = 128;

/// Passes of seal and refit: after a seal the fit resumes for [`REFIT`] of its rounds with
/// the sealed directions out of every move, so that the signs the seal cost are sought
/// again elsewhere; the last pass only seals.
const SEAL_PASSES: usize = 3;

/// The share of `SignBox::fit`'s rounds a refit runs.
const REFIT: f64 = 0.25;

/// Makes the move `d` (from x₀, in the kept rows' null space and orthogonal to `q`) blind to
/// the dropped rows it misses by more than `goal` (or x₀'s own residual, if larger), adding
/// the directions taken out to `sealed`. A dropped row a sees a move in the null space only
/// through its projection Π a (|Π a| = its distance δ from the kept span), so the move misses
/// it by Π a · d: taking Π a's direction out of d meets it again as x₀ did, with a change no
/// longer than d's part along it. Meeting the row's miss by a move along Π a instead
/// ([`super::cholesky::meet_dropped`]) needs the miss over δ: on fandisk's boundary-weighted
/// fit (session 55) its second round asked a move of 2.1 (10× x's largest value) and the fit
/// was discarded. Directions are orthogonalised against `q` and `sealed`; rows are taken
/// worst first, [`SEAL_ROWS`] a round, until the goal is met or `sealed` holds `limit`.
/// Returns the residual of x₀ + d.
#[allow(clippy::too_many_arguments)]
fn seal<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    q: &[Vec<f64>],
    sealed: &mut Vec<Vec<f64>>,
    x0: &[f64],
    d: &mut [f64],
    goal: f64,
    limit: usize,
) -> f64 {
    let (m, n) = (unit.rows.len(), x0.len());
    let mut r0 = vec![0.0; m];
    let goal = goal.max(unit.residual(x0, &mut r0));
    let mut r = vec![0.0; m];
    let at = |d: &[f64]| -> Vec<f64> { x0.iter().zip(d).map(|(a, b)| a + b).collect() };
    let mut res = unit.residual(&at(d), &mut r);
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    let mut used = vec![false; m];
    let mut round = 0;
    while res > goal && sealed.len() < limit {
        let t = std::time::Instant::now();
        // Rows missed beyond the goal where the move, not x₀, misses them.
        let miss = |i: usize| r[i].abs() * unit.scale[i];
        let mut missed: Vec<usize> = (0..m)
            .filter(|&i| {
                !used[i] && miss(i) > goal && (r[i] - r0[i]).abs() * unit.scale[i] > 0.1 * goal
            })
            .collect();
        missed.sort_by(|&a, &b| miss(b).total_cmp(&miss(a)).then(a.cmp(&b)));
        let all_missed = missed.len();
        missed.truncate(SEAL_ROWS.min(limit - sealed.len()));
        if missed.is_empty() {
            break;
        }
        let ps = projected_rows(&unit.rows, f, &missed, n);
        let mut added = 0;
        for (&i, p) in missed.iter().zip(ps) {
            used[i] = true;
            let Some((p, _)) = new_direction(p, q, sealed) else {
                continue;
            };
            let h = dot(&p, d);
            d.iter_mut().zip(&p).for_each(|(v, w)| *v -= h * w);
            sealed.push(p);
            added += 1;
        }
        let before = res;
        res = unit.residual(&at(d), &mut r);
        if trace {
            eprintln!(
                "quintic-c2 sign fit seal, round {round}: {all_missed} rows missed, {added} directions taken out ({} in all), residual {before:.2e} -> {res:.2e} (goal {goal:.2e}), {:.1} s",
                sealed.len(),
                t.elapsed().as_secs_f64()
            );
        }
        round += 1;
    }
    res
}

/// The split program's state between rounds, kept across a seal so that a refit resumes.
struct Admm {
    /// Each column's sign (0: unsigned) and the cost of its miss.
    sign: Vec<f64>,
    cost: Vec<f64>,
    /// The z iterate, the scaled dual and the penalty.
    z: Vec<f64>,
    u: Vec<f64>,
    rho: f64,
}

impl Admm {
    /// `rounds` rounds from x₀ with moves orthogonal to `q`; the round with the fewest
    /// weights off their sign (at their cost) and that count.
    #[allow(clippy::too_many_arguments)]
    fn run<F: NormalSolve>(
        &mut self,
        unit: &UnitRows,
        f: &F,
        q: &[Vec<f64>],
        sealed: &[Vec<f64>],
        x0: &[f64],
        sb: &SignBox,
        rounds: usize,
        tiny: f64,
        counts: (usize, f64),
    ) -> Option<(f64, Vec<f64>)> {
        let (margin, n) = (sb.margin, x0.len());
        let (off_before, off_cost_before) = counts;
        let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
        let mut best: Option<(f64, Vec<f64>)> = None;
        for round in 0..rounds {
            let t = std::time::Instant::now();
            let (z, u, rho) = (&mut self.z, &mut self.u, self.rho);
            // x step: x₀ + P (z − u − x₀).
            let mut d: Vec<f64> = (0..n).map(|j| z[j] - u[j] - x0[j]).collect();
            project_move(unit, f, q, sealed, &mut d);
            let xk: Vec<f64> = (0..n).map(|j| x0[j] + d[j]).collect();
            // z step, per weight: argmin ε/2 (z − x₀)² + ρ/2 (z − v)² + hinge, v = x + u.
            let kappa = STAY + rho;
            let (mut primal, mut dual) = (0.0, 0.0);
            for j in 0..n {
                let v = xk[j] + u[j];
                let a = (STAY * x0[j] + rho * v) / kappa;
                let s = self.sign[j];
                let zj = if s == 0.0 {
                    a
                } else {
                    // In the weight's own sign and the unit: the hinge's slope −cost below the
                    // margin.
                    let w = s * a / margin;
                    let step = self.cost[j] / kappa;
                    let w = if w >= FIT_MARGIN {
                        w
                    } else if w + step < FIT_MARGIN {
                        w + step
                    } else {
                        FIT_MARGIN
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
                self.rho *= 2.0;
                u.iter_mut().for_each(|v| *v *= 0.5);
            } else if dual > BALANCE * primal {
                self.rho *= 0.5;
                u.iter_mut().for_each(|v| *v *= 2.0);
            }
        }
        best
    }
}

/// Runs `sb.fit` rounds of the split sign program from x (the solved group), with moves
/// orthogonal to `q`; x is moved to the round with the fewest weights off their sign (each
/// counted at its [`SignBox::cost`]) if that has fewer than x and misses the rows by at most
/// `bound`: then its max |A x − c| is returned, else `None` (x left as it was). Where the
/// best round's move misses the rows by more than `goal` (dropped rows see it), it is made
/// blind to the rows it misses ([`seal`]) and the fit resumes with those directions out of
/// its moves ([`SEAL_PASSES`]).
pub(super) fn fit<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    x: &mut Vec<f64>,
    q: &[Vec<f64>],
    sb: &SignBox,
    bound: f64,
    goal: f64,
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
    // Weights this small are zero up to the solves' rounding (as `sign_rounds`).
    let tiny = 1e-12 * x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let off_before = sb.off(x, tiny);
    let off_cost_before = sb.off_cost(x, tiny);
    let mut admm = Admm {
        sign: vec![0.0; n],
        cost: vec![1.0; n],
        z: x0.clone(),
        u: vec![0.0; n],
        rho: RHO,
    };
    for (i, &(j, s)) in sb.signed.iter().enumerate() {
        admm.sign[j] = s;
        admm.cost[j] = sb.cost.get(i).copied().unwrap_or(1.0);
    }
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    let counts = (off_before, off_cost_before);
    // In units of the box's margin: stay ε/2 |z − x₀|² + Σ max(0, FIT_MARGIN − s z) over the
    // signed weights.
    let (_, mut xb) = admm.run(unit, f, q, &[], &x0, sb, sb.fit, tiny, counts)?;
    let mut sealed: Vec<Vec<f64>> = Vec::new();
    let mut d: Vec<f64>;
    let mut pass = 0;
    loop {
        // The best round's move projected twice more: one projection of fandisk's moves left
        // the rows missed by 1.3e-7 (nearly dependent kept rows amplify its rounding), the
        // next removes most of what the first left.
        d = (0..n).map(|j| xb[j] - x0[j]).collect();
        project_move(unit, f, q, &sealed, &mut d);
        project_move(unit, f, q, &sealed, &mut d);
        if trace {
            let y: Vec<f64> = (0..n).map(|j| x0[j] + d[j]).collect();
            let res = unit.residual(&y, &mut r);
            let off = sb.off(&y, tiny);
            eprintln!(
                "quintic-c2 sign fit, pass {pass}: before the seal {off} off their sign, residual {res:.2e}"
            );
        }
        let had = sealed.len();
        // Each pass may fill its share of the basis, the last all of it.
        let limit = SEAL_BASIS * (pass + 1) / SEAL_PASSES;
        seal(unit, f, q, &mut sealed, &x0, &mut d, goal, limit);
        pass += 1;
        if sealed.len() == had || pass == SEAL_PASSES || sealed.len() >= SEAL_BASIS {
            break;
        }
        let rounds = ((sb.fit as f64 * REFIT).ceil() as usize).max(1);
        match admm.run(unit, f, q, &sealed, &x0, sb, rounds, tiny, counts) {
            Some((_, x)) => xb = x,
            None => break,
        }
    }
    let y: Vec<f64> = (0..n).map(|j| x0[j] + d[j]).collect();
    let res = unit.residual(&y, &mut r);
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

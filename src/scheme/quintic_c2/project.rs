//! Theorem 2.1's signs by alternating projections (`QuinticOptions::sign_rounds`).
//!
//! The solve picks every free weight closest to its target, and the targets (blended Taylor
//! polynomials) know nothing of the signs that keep a patch single sheeted (Theorem 2.1, k = 1,
//! [`super::signs`]). Where the C2 conditions carry large corrections far from the data, as on
//! mpi_poly's coarse hull, thousands of weights end up with the wrong sign and the surface
//! crosses the hull's boundary faces (holes) or a j-line twice (j-sheets).
//!
//! This step moves the solved weights, keeping the jets (numbers 0–2) fixed, alternately onto
//! the box of the signs (each weight with a sign condition clamped to at least [`SIGN_MARGIN`]
//! on its side) and back onto the scheme's C1/C2 equations (the closest point, one sparse
//! factor of the equations reused in every round: [`cholesky::Projector::meet`]). Each round
//! is two Euclidean projections onto convex sets, so the distance to their intersection never
//! grows; where the intersection is empty (the signs are sufficient, not necessary, and some
//! cannot all hold) the weights still move towards it. The last move is onto the equations,
//! so C2 holds to the factor's refinement whatever the signs do; the result is kept only when
//! fewer weights miss their signs than before and the equations are met to [`KEEP_RESIDUAL`].

use super::cholesky::{self, Projector};
use super::sparse::Row;
use super::system::{stage, System};

/// Margin of the sign box, in units of the median |weight| of the moved weights: a weight is
/// clamped to at least this far on its side. The projection back onto the equations pulls
/// most clamped weights part of the way back, so a margin of the weights' own size does more
/// than one near zero: on mpi_poly (300 rounds, session 30) margins of 1e-3, 1e-2, 0.1, 0.3,
/// 1, 3, 10 medians left 179, 171, 156, 127, 98, 91, 132 holes and 31, 30, 21, 17, 9, 13, 24
/// j-sheets.
pub const SIGN_MARGIN: f64 = 1.0;

/// Largest residual of the unit-norm equations, relative to the largest moved weight, with
/// which the projected weights are kept: ten times the refinement's own target
/// ([`REFINE_TARGET`]), so only projections whose refinement converged are kept. Measured
/// (session 31, mpi_poly): a kept projection met its rows to 8e-14 of its largest weight and the
/// check's Hessian jump was 3.6e-9 (bound 1e-7); one that met them to 1e-10 (1e-9 was the bound
/// then) gave a Hessian jump of 6.9e-6 and gradient jump 1.5e-8, which `apatch check` fails.
/// The nut's f64 factor misses by 0.42 (session 30); [`project_signs`] then makes the last
/// move with a double-double factor ([`Projector::precise`]).
pub const KEEP_RESIDUAL: f64 = 10.0 * REFINE_TARGET;

/// Residual, relative to the largest moved weight, to which every move onto the equations is
/// refined (iterative refinement, then conjugate gradients with the factor).
pub const REFINE_TARGET: f64 = 1e-13;

/// Cost of a sign miss on a boundary face of the hull in the linear program
/// ([`super::signfit`]), against 1 for any other weight. A boundary weight off its sign is
/// where the surface can cross the hull's boundary (a hole); an inner one risks a second
/// sheet only where its neighbours turn too. Measured on mpi_poly's pending quintic (session
/// 34, HiGHS): costs 1, 3, 10, 100 left 1, 1, 0, 0 holes (608, 669, 750, 915 weights off in
/// all), j-sheets 0 and the Hessian jump ≤ 4.7e-10 with every cost.
pub const BOUNDARY_COST: f64 = 10.0;

/// What [`project_signs`] did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SignProjection {
    /// Rounds run (each a clamp and a projection onto the equations).
    pub rounds: usize,
    /// Weights off their sign condition before the rounds.
    pub off_before: usize,
    /// Weights off their sign condition after them (as before when not kept).
    pub off_after: usize,
    /// Largest residual of the (unit-norm) equations after the last projection.
    pub residual: f64,
    /// Whether the projected weights were kept: fewer off their signs than before, and the
    /// equations met to [`KEEP_RESIDUAL`] of the largest weight.
    pub kept: bool,
    /// Whether the last move was made again with a double-double factor because the f64 one
    /// missed [`KEEP_RESIDUAL`].
    pub precise: bool,
    /// Whether the equations were too large to factor ([`cholesky::MAX_FACTOR_ROWS`],
    /// [`cholesky::MAX_FACTOR_ENTRIES`]): nothing was done.
    pub too_large: bool,
    /// Whether the weights came from the linear program of [`super::signfit`]
    /// (`sign_program`) instead of the rounds.
    pub program: bool,
    /// Why the program was asked for but not used (the rounds ran instead).
    pub program_error: Option<String>,
}

/// Moves the non-jet weights of `value` towards Theorem 2.1's signs by at most `rounds`
/// alternating projections (module docs), or with `program` to the least violation of the
/// signs ([`super::signfit`]), keeping every C1/C2 equation of `sys`.
pub fn project_signs(
    sys: &System,
    value: &mut [f64],
    rounds: usize,
    program: bool,
) -> SignProjection {
    let ns = sys.keys.len();
    let jet: Vec<bool> = (0..ns).map(|s| stage(sys.keys[s], sys.np).0 == 0).collect();
    let mut col = vec![usize::MAX; ns];
    let mut slots = Vec::new();
    for s in 0..ns {
        if !jet[s] {
            col[s] = slots.len();
            slots.push(s);
        }
    }
    let n = slots.len();
    // The equations over the moved weights, the jets' terms on the right-hand side.
    let mut rows: Vec<Row> = Vec::new();
    let mut c = Vec::new();
    for eq in &sys.equations {
        let mut row = Vec::new();
        let mut rhs = 0.0;
        for &(sl, k) in &eq.terms {
            if jet[sl as usize] {
                rhs -= k * value[sl as usize];
            } else {
                row.push((col[sl as usize], k));
            }
        }
        if !row.is_empty() {
            rows.push(row);
            c.push(rhs);
        }
    }
    let signed: Vec<(usize, f64)> = slots
        .iter()
        .enumerate()
        .filter_map(|(j, &s)| match sys.req[s] {
            1 => Some((j, 1.0)),
            -1 => Some((j, -1.0)),
            _ => None,
        })
        .collect();
    let cost: Vec<f64> = signed
        .iter()
        .map(|&(j, _)| {
            if sys.boundary[slots[j]] {
                BOUNDARY_COST
            } else {
                1.0
            }
        })
        .collect();
    let mut x: Vec<f64> = slots.iter().map(|&s| value[s]).collect();
    let report = project_rows(&rows, n, &c, &mut x, &signed, &cost, rounds, program);
    if report.kept {
        for (j, &s) in slots.iter().enumerate() {
            value[s] = x[j];
        }
    }
    report
}

/// The alternating projections of [`project_signs`] on plain equations: `rows` (sparse, over
/// `n` unknowns) = `c`, the weights `x`, the sign conditions `signed` (index, ±1). `x` is
/// changed only when the result is kept (module docs); the report says what happened. Where
/// the f64 factor's last move misses [`KEEP_RESIDUAL`], that move is made again with a
/// double-double factor ([`Projector::precise`]: pivots of nearly dependent rows, which f64
/// rounds away, kept down to [`cholesky::PRECISE_PIVOT`]). With `program` the rounds are
/// replaced by one move from the linear program's solution ([`super::signfit`], each miss
/// weighted by `cost`, parallel to `signed`; empty for 1 each) onto the equations, when the
/// program is solved.
#[allow(clippy::too_many_arguments)]
pub fn project_rows(
    rows: &[Row],
    n: usize,
    c: &[f64],
    x: &mut Vec<f64>,
    signed: &[(usize, f64)],
    cost: &[f64],
    rounds: usize,
    program: bool,
) -> SignProjection {
    let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    // As in `signs::SignStats`: weights this small are zero up to the solves' rounding.
    let tiny = -1e-12 * scale;
    let mut report = SignProjection {
        off_before: off(x, signed, tiny),
        ..SignProjection::default()
    };
    report.off_after = report.off_before;
    if n == 0 || signed.is_empty() || report.off_before == 0 || (rounds == 0 && !program) {
        return report;
    }
    let limits = (cholesky::MAX_FACTOR_ROWS, cholesky::MAX_FACTOR_ENTRIES);
    let Some(ordering) = cholesky::Ordering::within(rows, n, limits) else {
        report.too_large = true;
        return report;
    };
    crate::progress::report(|| {
        format!(
            "quintic-c2 sign projection: factoring {} equations",
            rows.len()
        )
    });
    let projector = Projector::new(rows, n, c, &ordering);
    let margin = SIGN_MARGIN * median_abs(x);
    let trace = std::env::var_os("APATCH_SIGN_TRACE").is_some();
    let start = x.clone();
    let mut residual = 0.0;
    let mut rounds = rounds;
    if program {
        crate::progress::report(|| format!("quintic-c2 sign program ({})", super::signfit::SOLVER));
        match super::signfit::least_violation(rows, n, c, &ordering, x, signed, cost) {
            Ok(y) => {
                *x = y;
                residual = projector.meet(x, REFINE_TARGET * scale);
                report.program = true;
                rounds = 0;
            }
            Err(e) => report.program_error = Some(e),
        }
    }
    for r in 0..rounds {
        crate::progress::report(|| format!("quintic-c2 sign projection: round {}", r + 1));
        let clamped = clamp(x, signed, margin);
        report.rounds = r + 1;
        if clamped == 0 {
            break;
        }
        residual = projector.meet(x, REFINE_TARGET * scale);
        if trace && r % 25 == 0 {
            // Opt-in exploration on stderr (results unaffected).
            eprintln!(
                "quintic-c2 sign projection: round {r}, {clamped} clamped, residual {residual:.2e}, {} off",
                off(x, signed, tiny)
            );
        }
    }
    if residual > KEEP_RESIDUAL * scale {
        // The last move again, from the same clamped weights, with the precise factor.
        crate::progress::report(|| "quintic-c2 sign projection: double-double factor".into());
        drop(projector);
        let precise = Projector::precise(rows, n, c, &ordering, cholesky::PRECISE_PIVOT);
        if !report.program {
            clamp(x, signed, margin);
        }
        // A precise move that does no better leaves the residual above the bound: refused
        // below either way, and `x` restored to the start.
        residual = residual.min(precise.meet(x, REFINE_TARGET * scale));
        report.precise = true;
    }
    report.residual = residual;
    let after = off(x, signed, tiny);
    if after < report.off_before && residual <= KEEP_RESIDUAL * scale {
        report.kept = true;
        report.off_after = after;
    } else {
        *x = start;
    }
    report
}

/// Clamps every weight of `signed` (index, sign) to at least `margin` on its side (the sign
/// box); returns how many moved.
fn clamp(x: &mut [f64], signed: &[(usize, f64)], margin: f64) -> usize {
    let mut clamped = 0;
    for &(j, sign) in signed {
        if sign * x[j] < margin {
            x[j] = sign * margin;
            clamped += 1;
        }
    }
    clamped
}

/// Weights of `signed` (index, sign) on the wrong side of `margin`.
fn off(x: &[f64], signed: &[(usize, f64)], margin: f64) -> usize {
    signed.iter().filter(|&&(j, s)| s * x[j] < margin).count()
}

/// Median of |x| (0 for none).
pub(super) fn median_abs(x: &[f64]) -> f64 {
    let mut a: Vec<f64> = x.iter().map(|v| v.abs()).collect();
    if a.is_empty() {
        return 0.0;
    }
    let mid = a.len() / 2;
    *a.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x0 + x1 = 1 and x1 − x2 = 0 (x3 free), with x0 and x3 asked to be positive, x2
    /// negative. The solve's point (1, 0, 0, −1) has x3 off its sign (x2 = 0 counts as on it:
    /// zero up to rounding); the box and the plane
    /// meet (e.g. x = (2, −1, −1, 1)), so the projection keeps the equations exactly (up to the
    /// refinement) and takes every weight onto its sign.
    #[test]
    fn consistent_rows_are_met_and_the_signs_taken() {
        let rows: Vec<Row> = vec![vec![(0, 1.0), (1, 1.0)], vec![(1, 1.0), (2, -1.0)]];
        let c = [1.0, 0.0];
        let signed = [(0, 1.0), (2, -1.0), (3, 1.0)];
        let mut x = vec![1.0, 0.0, 0.0, -1.0];
        let p = project_rows(&rows, 4, &c, &mut x, &signed, &[], 200, false);
        assert!(p.kept && !p.precise, "{p:?}");
        assert_eq!((p.off_before, p.off_after), (1, 0), "{p:?} {x:?}");
        // Equations to the keep bound of the largest weight (module docs).
        let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        assert!((x[0] + x[1] - 1.0).abs() <= KEEP_RESIDUAL * scale, "{x:?}");
        assert!((x[1] - x[2]).abs() <= KEEP_RESIDUAL * scale, "{x:?}");
        for &(j, s) in &signed {
            assert!(s * x[j] > 0.0, "{j}: {x:?}");
        }
    }

    /// Rows that contradict each other by 1e-9 of the data (x0 = 1 and x0 = 1 + 1e-9): no
    /// factor meets both, so the move is refused after the double-double retry, and the
    /// weights are left exactly as they were. (With the old bound, 1e-9 of the largest weight,
    /// such a miss was kept.)
    #[test]
    fn contradicting_rows_are_refused_and_the_weights_kept() {
        let rows: Vec<Row> = vec![vec![(0, 1.0)], vec![(0, 1.0)], vec![(1, 1.0), (2, 1.0)]];
        let c = [1.0, 1.0 + 1e-9, 0.0];
        let signed = [(1, 1.0), (2, 1.0)];
        let start = vec![1.0, -0.5, 0.5];
        let mut x = start.clone();
        let p = project_rows(&rows, 3, &c, &mut x, &signed, &[], 20, false);
        assert!(!p.kept && p.precise, "{p:?}");
        assert!(p.residual > KEEP_RESIDUAL, "{p:?}");
        assert_eq!(p.off_after, p.off_before);
        assert_eq!(x, start);
    }

    /// x0 + x1 + 2 x2 = 1 with all three asked to be ≤ 0: no point meets every sign, and the
    /// fewest misses put only x2 off (at 1/2 plus a margin), where the alternating projections
    /// spread the miss over all three: their limit is the plane's point closest to the box
    /// corner (−m, −m, −m), which is −m + (1 + 4m)/6 > 0 in x0 and x1 for the margin m = 0.2
    /// (the median of the start). With the program (HiGHS with the feature `highs`, the
    /// interior point method without) exactly one weight is off and the row is met.
    #[test]
    fn the_sign_program_leaves_the_fewest_weights_off() {
        let rows: Vec<Row> = vec![vec![(0, 1.0), (1, 1.0), (2, 2.0)]];
        let c = [1.0];
        let signed = [(0, -1.0), (1, -1.0), (2, -1.0)];
        let start = vec![0.2, 0.2, 0.3];
        let mut rounds = start.clone();
        let p = project_rows(&rows, 3, &c, &mut rounds, &signed, &[], 200, false);
        // All three stay off: nothing gained, so not kept.
        assert!(!p.kept && p.off_after == 3, "{p:?} {rounds:?}");
        let mut x = start.clone();
        let q = project_rows(&rows, 3, &c, &mut x, &signed, &[], 200, true);
        assert!(q.kept && q.program && q.off_after == 1, "{q:?} {x:?}");
        assert!(x[0] < 0.0 && x[1] < 0.0 && x[2] > 0.0, "{x:?}");
        let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let miss = (x[0] + x[1] + 2.0 * x[2] - 1.0).abs() / 6f64.sqrt();
        assert!(miss <= KEEP_RESIDUAL * scale, "{miss:e} {x:?}");
    }

    /// x0 − x1 = 1 with x0 asked to be ≤ 0 and x1 ≥ 0: one of them must miss, and either miss
    /// is as large (x0 = −m gives x1 = −1 − m, 1 + 2m short of its margin m; x1 = m gives
    /// x0 = 1 + m, as short), so only the costs decide: the cheap condition takes the miss,
    /// whichever of the two it is (HiGHS with the feature `highs`, the interior point method
    /// without).
    #[test]
    fn the_sign_program_puts_misses_where_they_cost_least() {
        let rows: Vec<Row> = vec![vec![(0, 1.0), (1, -1.0)]];
        let c = [1.0];
        let signed = [(0, -1.0), (1, 1.0)];
        let start = vec![0.5, -0.5];
        for (cost, off) in [([BOUNDARY_COST, 1.0], 1), ([1.0, BOUNDARY_COST], 0)] {
            let mut x = start.clone();
            let q = project_rows(&rows, 2, &c, &mut x, &signed, &cost, 0, true);
            // Both start off; after the program only `off` is.
            assert!(q.kept && q.program && q.off_after == 1, "{q:?} {x:?}");
            let (j, s) = signed[off];
            assert!(s * x[j] < 0.0, "{cost:?}: {x:?}");
            let (k, t) = signed[1 - off];
            assert!(t * x[k] > 0.0, "{cost:?}: {x:?}");
        }
    }

    /// x0 − x1 = 1 and x0 − x2 = 1, x0 asked to be ≤ 0 (cost 2), x1 and x2 ≥ 0 (cost 1 each):
    /// raising x0 by t costs 2t and saves t on each of x1 and x2, so every x0 in [−m, 1 + m]
    /// is optimal (a tie). An interior point method ends at the centre of that segment, with
    /// all three off (x0 + m = (1 + 2m)/3 maximises log(x0 + m) + 2 log(1 + m − x0)); the
    /// program must end at an end of it, as HiGHS's crossover does and the interior point
    /// method's reweighted solve ([`super::super::signfit::REWEIGHTINGS`]) does: either x0
    /// alone off, or x1 and x2 alone.
    #[test]
    fn the_sign_program_ends_at_a_vertex_of_a_tie() {
        let rows: Vec<Row> = vec![vec![(0, 1.0), (1, -1.0)], vec![(0, 1.0), (2, -1.0)]];
        let c = [1.0, 1.0];
        let signed = [(0, -1.0), (1, 1.0), (2, 1.0)];
        let cost = [2.0, 1.0, 1.0];
        let mut x = vec![0.5, -0.5, -0.5];
        let q = project_rows(&rows, 3, &c, &mut x, &signed, &cost, 0, true);
        assert!(q.kept && q.program, "{q:?} {x:?}");
        let off: Vec<bool> = signed.iter().map(|&(j, s)| s * x[j] < 0.0).collect();
        assert!(
            off == [true, false, false] || off == [false, true, true],
            "{off:?}: {x:?}"
        );
    }

    /// A row 1e-7 (relative) from the span of another: its squared pivot, 5e-15, is below the
    /// f64 factor's drop threshold (`DEPENDENT_PIVOT` = 1e-13), so the f64 moves drop it and miss
    /// it by ~1e-7; the double-double factor keeps pivots down to `PRECISE_PIVOT` = 1e-15 and
    /// meets it, and the projection is kept.
    #[test]
    fn nearly_dependent_rows_are_met_by_the_precise_factor() {
        let eps = 1e-7;
        let rows: Vec<Row> = vec![vec![(0, 1.0), (1, 1.0)], vec![(0, 1.0), (1, 1.0), (2, eps)]];
        // Solutions: x0 + x1 = 1, x2 = 1; the start misses the second row by 1e-7.
        let c = [1.0, 1.0 + eps];
        let signed = [(3, 1.0)];
        let mut x = vec![0.5, 0.5, 0.0, -1.0];
        let p = project_rows(&rows, 4, &c, &mut x, &signed, &[], 5, false);
        assert!(p.kept && p.precise, "{p:?}");
        let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        // The second row's own miss, unit-normalised (its norm is √2 to 1e-14).
        let miss = (x[0] + x[1] + eps * x[2] - c[1]).abs() / 2f64.sqrt();
        assert!(miss <= KEEP_RESIDUAL * scale, "{miss:e} {x:?}");
        assert!(x[3] > 0.0);
    }
}

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

/// Largest residual of the unit-norm equations, relative to the largest weight, with which the
/// projected weights are kept (the staged solve's own consistency bound). The nut's equations
/// (246411 unknowns) are not met by the f64 factor's projections (session 30: `sign_rounds =
/// 100` gave a Hessian jump of 1.2e3 before this bound), as its hole repair's groups needed
/// double-double factors; the projection is then refused and the solve's weights kept.
pub const KEEP_RESIDUAL: f64 = 1e-9;

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
    /// Whether the equations were too large to factor ([`cholesky::MAX_FACTOR_ROWS`],
    /// [`cholesky::MAX_FACTOR_ENTRIES`]): nothing was done.
    pub too_large: bool,
}

/// Moves the non-jet weights of `value` towards Theorem 2.1's signs by at most `rounds`
/// alternating projections (module docs), keeping every C1/C2 equation of `sys`.
pub fn project_signs(sys: &System, value: &mut [f64], rounds: usize) -> SignProjection {
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
    let mut x: Vec<f64> = slots.iter().map(|&s| value[s]).collect();
    let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    // As in `signs::SignStats`: weights this small are zero up to the solves' rounding.
    let tiny = -1e-12 * scale;
    let mut report = SignProjection {
        off_before: off(&x, &signed, tiny),
        ..SignProjection::default()
    };
    report.off_after = report.off_before;
    if n == 0 || signed.is_empty() || report.off_before == 0 {
        return report;
    }
    let limits = (cholesky::MAX_FACTOR_ROWS, cholesky::MAX_FACTOR_ENTRIES);
    let Some(ordering) = cholesky::Ordering::within(&rows, n, limits) else {
        report.too_large = true;
        return report;
    };
    crate::progress::report(|| {
        format!(
            "quintic-c2 sign projection: factoring {} equations",
            rows.len()
        )
    });
    let projector = Projector::new(&rows, n, &c, &ordering);
    let margin = SIGN_MARGIN * median_abs(&x);
    let trace = std::env::var_os("APATCH_SIGN_TRACE").is_some();
    let mut residual = 0.0;
    for r in 0..rounds {
        crate::progress::report(|| format!("quintic-c2 sign projection: round {}", r + 1));
        let mut clamped = 0;
        for &(j, sign) in &signed {
            if sign * x[j] < margin {
                x[j] = sign * margin;
                clamped += 1;
            }
        }
        report.rounds = r + 1;
        if clamped == 0 {
            break;
        }
        residual = projector.meet(&mut x, 1e-13 * scale);
        if trace && r % 25 == 0 {
            // Opt-in exploration on stderr (results unaffected).
            eprintln!(
                "quintic-c2 sign projection: round {r}, {clamped} clamped, residual {residual:.2e}, {} off",
                off(&x, &signed, tiny)
            );
        }
    }
    report.off_after = off(&x, &signed, tiny);
    report.residual = residual;
    if report.off_after < report.off_before && residual <= KEEP_RESIDUAL * scale {
        report.kept = true;
        for (j, &s) in slots.iter().enumerate() {
            value[s] = x[j];
        }
    } else {
        report.off_after = report.off_before;
    }
    report
}

/// Weights of `signed` (index, sign) on the wrong side of `margin`.
fn off(x: &[f64], signed: &[(usize, f64)], margin: f64) -> usize {
    signed.iter().filter(|&&(j, s)| s * x[j] < margin).count()
}

/// Median of |x| (0 for none).
fn median_abs(x: &[f64]) -> f64 {
    let mut a: Vec<f64> = x.iter().map(|v| v.abs()).collect();
    if a.is_empty() {
        return 0.0;
    }
    let mid = a.len() / 2;
    *a.select_nth_unstable_by(mid, f64::total_cmp).1
}

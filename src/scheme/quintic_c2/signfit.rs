//! Theorem 2.1's signs by a linear program (`QuinticOptions::sign_program`): HiGHS with the
//! cargo feature `highs`, else the pure-Rust interior point method of [`super::interior`].
//!
//! Where the C1/C2 equations and the sign box of Theorem 2.1 (k = 1) do not meet, the
//! alternating projections of [`super::project`] converge towards a compromise that spreads
//! the misses over thousands of weights (least squares), and slowly. What keeps the surface
//! single sheeted is the opposite: as few weights off their sign as possible. This step solves
//! the linear program
//!
//! ```text
//! minimise Σ w_i v_i   subject to   A x = c   (the C1/C2 equations, jets held),
//!                                   s_i x_i + v_i ≥ m,  v_i ≥ 0   (each sign condition i),
//! ```
//!
//! whose optimal violations v are sparse (an L1 objective; a miss on a boundary face of the
//! hull, where the surface can leave through the boundary, costs w_i =
//! [`super::project::BOUNDARY_COST`], any other 1). With the feature `highs` HiGHS solves it
//! (interior point, then crossover to a vertex, so the equations are met to the simplex's
//! accuracy); HiGHS is C++ built from source (cmake, libclang), so it is not the default.
//! Without it [`super::interior`] does (Mehrotra's predictor-corrector on the projection's own
//! double-double factor): an interior solution, slower. The caller moves the result onto the
//! equations with its own factor, as every projection ends.
//!
//! Without HiGHS the program is solved again with reweighted costs ([`REWEIGHTINGS`]): an
//! interior solution spreads its misses where a vertex would not.
//!
//! On mpi_poly's quintic (session 33): 3619 weights off their signs after the solve; the
//! program leaves 608 (alternating projections: 2683 after 1000 rounds), and the check's holes
//! and j-sheets go from 24 and 7 to 1 and 0; with boundary misses costing 10 (session 34), 750
//! weights off and no hole (HiGHS); the interior point method reweighted once (session 35):
//! 590 off, no hole, no j-sheet.

use super::sparse::Row;

/// Margin m of the sign conditions, in units of the median |weight|: clearly signed, far above
/// the solves' rounding, small against the data.
pub const PROGRAM_MARGIN: f64 = 1e-3;

/// Which solver [`least_violation`] uses, for reports.
#[cfg(feature = "highs")]
pub const SOLVER: &str = "HiGHS";
/// Which solver [`least_violation`] uses, for reports.
#[cfg(not(feature = "highs"))]
pub const SOLVER: &str = "interior point";

/// Box on each weight's move, in units of the largest |weight|: keeps the program bounded
/// (its optimum is not unique); far wider than any move the equations ask for.
pub const MOVE_BOX: f64 = 50.0;

/// The weights closest (in the L1 sense above, miss i weighted by `cost[i]`, 1 where `cost` is
/// short; [`super::project::BOUNDARY_COST`] on the hull's boundary faces) to Theorem 2.1's
/// `signed` conditions (index, ±1) with `rows` (over `n` unknowns, `ordering` made for them)
/// = `c`, from the solved `x`: by HiGHS with the feature `highs`, else by
/// [`super::interior`].
///
/// # Errors
/// HiGHS's status when the program is invalid or not solved to optimality; the interior point
/// method's message when it fails.
pub fn least_violation(
    rows: &[Row],
    n: usize,
    c: &[f64],
    ordering: &super::cholesky::Ordering,
    x: &[f64],
    signed: &[(usize, f64)],
    cost: &[f64],
) -> Result<Vec<f64>, String> {
    let median = super::project::median_abs(x).max(f64::MIN_POSITIVE);
    #[cfg(feature = "highs")]
    {
        let _ = ordering;
        highs_program(rows, n, c, x, signed, cost, median)
    }
    #[cfg(not(feature = "highs"))]
    {
        // The first solve with the given costs, each later one from the last solve's weights.
        let mut y = x.to_vec();
        let mut costs = cost.to_vec();
        for solve in 0..=REWEIGHTINGS {
            if solve > 0 {
                costs = reweighted(&y, signed, cost, median);
            }
            y = super::interior::least_violation(
                rows,
                n,
                c,
                ordering,
                &y,
                signed,
                &costs,
                median,
                PROGRAM_MARGIN,
            )?;
        }
        Ok(y)
    }
}

/// Solves of the program again with [`reweighted`] costs after the first, without HiGHS. An
/// interior point method ends at the centre of the optimal face: where several sets of misses
/// cost the same it misses a little on all of them, where a vertex (HiGHS's crossover) picks
/// one set. Weighting each miss by the inverse of the last solve's (reweighted L1) draws the
/// misses onto the conditions that already miss. Measured on mpi_poly's quintic (session 35,
/// `apatch check`): one solve leaves 757 weights off, 3 holes and 1 j-sheet; one reweighted
/// solve after it 590 off, no hole and no j-sheet (twice the time).
pub const REWEIGHTINGS: usize = 1;

/// The floor of the reweighting, in units of the median |weight|: a condition that held in
/// the last solve costs `cost / REWEIGHT_FLOOR`, one missed by d costs `cost / (d + floor)`.
pub const REWEIGHT_FLOOR: f64 = 0.1;

/// The costs for the next solve of the program from the last solve `y` (reweighted L1: see
/// [`REWEIGHTINGS`]).
pub fn reweighted(y: &[f64], signed: &[(usize, f64)], cost: &[f64], median: f64) -> Vec<f64> {
    signed
        .iter()
        .enumerate()
        .map(|(i, &(j, s))| {
            let miss = (PROGRAM_MARGIN - s * y[j] / median).max(0.0);
            miss_cost(cost, i) / (miss + REWEIGHT_FLOOR)
        })
        .collect()
}

/// The cost of missing condition `i`: `cost[i]`, 1 where `cost` is short.
pub(super) fn miss_cost(cost: &[f64], i: usize) -> f64 {
    cost.get(i).copied().unwrap_or(1.0)
}

/// [`least_violation`] by HiGHS, `median` the median |weight| of `x`.
#[cfg(feature = "highs")]
fn highs_program(
    rows: &[Row],
    n: usize,
    c: &[f64],
    x: &[f64],
    signed: &[(usize, f64)],
    cost: &[f64],
    median: f64,
) -> Result<Vec<f64>, String> {
    use highs::{HighsModelStatus, RowProblem, Sense};
    let scale = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let margin = PROGRAM_MARGIN * median;
    let mut pb = RowProblem::default();
    let cols: Vec<_> = x
        .iter()
        .map(|&v| pb.add_column(0.0, (v - MOVE_BOX * scale)..=(v + MOVE_BOX * scale)))
        .collect();
    // Unit rows with duplicate columns merged, as the projections see them (an empty row
    // asks nothing).
    let unit = super::cholesky::UnitRows::new(rows, c);
    for (row, &ci) in unit.rows.iter().zip(&unit.c) {
        if row.iter().all(|t| t.1 == 0.0) {
            continue;
        }
        pb.add_row(ci..=ci, row.iter().map(|&(j, k)| (cols[j as usize], k)));
    }
    for (i, &(j, s)) in signed.iter().enumerate() {
        let v = pb.add_column(miss_cost(cost, i) / median, 0.0..);
        pb.add_row(margin.., [(cols[j], s), (v, 1.0)]);
    }
    let mut model = pb
        .try_optimise(Sense::Minimise)
        .map_err(|e| format!("HiGHS refused the program: {e:?}"))?;
    model.make_quiet();
    model.set_option("solver", "ipm");
    model.set_option("run_crossover", "on");
    model.set_option("threads", 1);
    model.set_option("random_seed", 0);
    let solved = model.solve();
    match solved.status() {
        HighsModelStatus::Optimal => Ok(solved.get_solution().columns()[..n].to_vec()),
        other => Err(format!("{other:?}")),
    }
}

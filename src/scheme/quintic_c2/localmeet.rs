//! The rows of a large group that its solve leaves missed, met region by region
//! (`[scheme] joint_local_meet`).
//!
//! A group beyond the dense solves (fandisk's joint group: 1.88M rows) is factored once with a
//! drop threshold on its pivots, and its exactly dependent rows are told from its independent
//! ones by that threshold alone. The sign fit then moves the weights in the kept rows' null
//! space, and the dropped rows it reaches are missed (fandisk: 1013 rows, up to 3.5e-10).
//! Meeting them with the same factor takes moves of 1e-2, which undo the fit's signs
//! (docs/quintic.md, sessions 62–63). Around each missed row, though, the group's rows with
//! the nearby unknowns free and the rest held have a clean gap in their singular values
//! (session 64: exact dependencies at ~1e-15 of the largest, every other value above ~1e-9),
//! which a dense rank-revealing factor of the region (a QR with pivoting; an SVD gives the
//! same move at four times the cost) resolves where a sparse factor's pivots in a fixed order
//! cannot; its minimum-norm move meets every row of the region, the missed ones to ~1e-14,
//! by moves of 1e-10 … 1e-7.
//!
//! A region is the `size` unknowns nearest (by their domain points) to the missed row, found
//! through the rows; its rows are every row with a term in it, so rows outside see no change.
//! A region's move is kept only if it lowers the region's worst miss and is no longer than
//! `max_move`. Regions are solved one after another, worst row first, so the result does not
//! depend on the thread count.

use glam::DVec3;

/// Singular values at or below this share of a region's largest are its rows' exact
/// dependencies (rounding, ~1e-15 on fandisk); above it (~1e-9 and up) they are constraints.
const RANK_CUT: f64 = 1e-11;
/// Passes over the rows still missed: a region's move can leave a row at its edge missed
/// (the held unknowns bind it) that a region centred on it meets.
const PASSES: usize = 3;
/// Unknowns gathered through the rows before the nearest `size` are taken: enough that the
/// region is the nearest by distance, not the first reached.
const GATHER: usize = 4;

/// What [`meet`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalMeet {
    /// Rows missed beyond the tolerance before and after.
    pub missed_before: usize,
    /// See `missed_before`.
    pub missed_after: usize,
    /// Largest |row · x − c| before and after.
    pub worst_before: f64,
    /// See `worst_before`.
    pub worst_after: f64,
    /// Regions solved, and of those, kept.
    pub regions: usize,
    /// See `regions`.
    pub kept: usize,
    /// Largest |Δx| of a kept region.
    pub largest_move: f64,
}

/// Meets the rows of `rows` · x = `c` that `x` misses by more than `tol`, moving `x` region by
/// region (module doc). `pos` is each unknown's domain point.
#[must_use]
pub fn meet(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    x: &mut [f64],
    pos: &[DVec3],
    tol: f64,
    size: usize,
    max_move: f64,
) -> LocalMeet {
    debug_assert_eq!(rows.len(), c.len());
    debug_assert_eq!(x.len(), pos.len());
    let n = x.len();
    let mut rows_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (i, row) in rows.iter().enumerate() {
        for &(j, _) in row {
            rows_of[j].push(i as u32);
        }
    }
    let miss = |i: usize, x: &[f64]| rows[i].iter().map(|&(j, k)| k * x[j]).sum::<f64>() - c[i];
    let mut r: Vec<f64> = (0..rows.len()).map(|i| miss(i, x)).collect();
    let worst = |r: &[f64]| r.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let count = |r: &[f64]| r.iter().filter(|v| v.abs() > tol).count();
    let mut out = LocalMeet {
        missed_before: count(&r),
        worst_before: worst(&r),
        ..LocalMeet::default()
    };
    // Scratch marks, cleared after each region.
    let mut in_region = vec![false; n];
    let mut row_seen = vec![false; rows.len()];
    for _ in 0..PASSES {
        let mut missed: Vec<usize> = (0..rows.len()).filter(|&i| r[i].abs() > tol).collect();
        if missed.is_empty() {
            break;
        }
        missed.sort_by(|&a, &b| r[b].abs().total_cmp(&r[a].abs()).then(a.cmp(&b)));
        let mut progress = false;
        for i in missed {
            if r[i].abs() <= tol {
                continue;
            }
            let unknowns = region(i, rows, &rows_of, pos, size, &mut in_region);
            let region_rows = rows_touching(&unknowns, &rows_of, &mut row_seen);
            out.regions += 1;
            let before = region_rows.iter().fold(0.0_f64, |a, &k| a.max(r[k].abs()));
            let Some(step) = min_norm_step(rows, &region_rows, &unknowns, &r) else {
                continue;
            };
            let longest = worst(&step);
            let saved: Vec<f64> = unknowns.iter().map(|&j| x[j]).collect();
            for (&j, d) in unknowns.iter().zip(&step) {
                x[j] += d;
            }
            let after: Vec<f64> = region_rows.iter().map(|&k| miss(k, x)).collect();
            let worst_after = worst(&after);
            if worst_after < before && longest <= max_move {
                for (&k, v) in region_rows.iter().zip(after) {
                    r[k] = v;
                }
                out.kept += 1;
                out.largest_move = out.largest_move.max(longest);
                progress = true;
            } else {
                for (&j, v) in unknowns.iter().zip(saved) {
                    x[j] = v;
                }
            }
        }
        if !progress {
            break;
        }
    }
    out.missed_after = count(&r);
    out.worst_after = worst(&r);
    out
}

/// The `size` unknowns nearest row `i`'s terms (the mean of their domain points), gathered
/// through the rows from the row's own unknowns; sorted.
fn region(
    i: usize,
    rows: &[Vec<(usize, f64)>],
    rows_of: &[Vec<u32>],
    pos: &[DVec3],
    size: usize,
    mark: &mut [bool],
) -> Vec<usize> {
    let centre = rows[i].iter().map(|&(j, _)| pos[j]).sum::<DVec3>() / rows[i].len() as f64;
    let mut found: Vec<usize> = Vec::new();
    for &(j, _) in &rows[i] {
        if !mark[j] {
            mark[j] = true;
            found.push(j);
        }
    }
    let mut next = 0;
    while next < found.len() && found.len() < GATHER * size {
        let j = found[next];
        next += 1;
        for &k in &rows_of[j] {
            for &(l, _) in &rows[k as usize] {
                if !mark[l] {
                    mark[l] = true;
                    found.push(l);
                }
            }
        }
    }
    for &j in &found {
        mark[j] = false;
    }
    found.sort_by(|&a, &b| {
        pos[a]
            .distance_squared(centre)
            .total_cmp(&pos[b].distance_squared(centre))
            .then(a.cmp(&b))
    });
    found.truncate(size);
    found.sort_unstable();
    found
}

/// Every row with a term in `unknowns`, sorted.
fn rows_touching(unknowns: &[usize], rows_of: &[Vec<u32>], seen: &mut [bool]) -> Vec<usize> {
    let mut out = Vec::new();
    for &j in unknowns {
        for &k in &rows_of[j] {
            if !seen[k as usize] {
                seen[k as usize] = true;
                out.push(k as usize);
            }
        }
    }
    for &k in &out {
        seen[k] = false;
    }
    out.sort_unstable();
    out
}

/// The least-norm Δ over `unknowns` with M Δ = −r on `region_rows` (M: those rows' columns
/// of the unknowns): a QR of Mᵀ with column pivoting (the region's rows in order of their
/// distance from the rows before them), rows whose pivot falls to [`RANK_CUT`] of the largest
/// left out as dependent, Δ = Q₁ R₁₁⁻ᵀ (−r) in the kept rows' span. With the regions' clean gap
/// between dependent rows and constraints this is the SVD's minimum-norm move for less: a
/// 2300 × 2000 region ~1.4 s against ~5 s, fandisk's whole local meet 10.4 CPU min against
/// 17.8. `None` where no pivot is above zero.
fn min_norm_step(
    rows: &[Vec<(usize, f64)>],
    region_rows: &[usize],
    unknowns: &[usize],
    r: &[f64],
) -> Option<Vec<f64>> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::householder;
    let (m, n) = (region_rows.len(), unknowns.len());
    if m == 0 || n == 0 {
        return None;
    }
    // Column of each region unknown (held unknowns have none).
    let col: std::collections::HashMap<usize, usize> =
        unknowns.iter().enumerate().map(|(a, &j)| (j, a)).collect();
    // Mᵀ: column ri is region row ri over the unknowns.
    let mut mt = faer::Mat::<f64>::zeros(n, m);
    for (ri, &k) in region_rows.iter().enumerate() {
        for &(j, v) in &rows[k] {
            if let Some(&a) = col.get(&j) {
                mt[(a, ri)] += v;
            }
        }
    }
    let qr = mt.col_piv_qr();
    let rr = qr.thin_R();
    let (order, _) = qr.P().arrays();
    let size = m.min(n);
    let top = rr[(0, 0)].abs();
    if !top.is_finite() || top <= 0.0 {
        return None;
    }
    let rank = (0..size)
        .take_while(|&k| rr[(k, k)].abs() > RANK_CUT * top)
        .count();
    // R₁₁ᵀ y = −r of the kept rows, in pivot order (forward substitution).
    let mut z = faer::Mat::<f64>::zeros(n, 1);
    for k in 0..rank {
        let s = (0..k).map(|i| rr[(i, k)] * z[(i, 0)]).sum::<f64>();
        z[(k, 0)] = (-r[region_rows[order[k]]] - s) / rr[(k, k)];
    }
    // Δ = Q [y; 0].
    let mut buf = MemBuffer::new(
        householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(
            n,
            qr.Q_coeff().nrows(),
            1,
        ),
    );
    householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
        qr.Q_basis(),
        qr.Q_coeff(),
        faer::Conj::No,
        z.as_mut(),
        faer::Par::Seq,
        MemStack::new(&mut buf),
    );
    Some((0..n).map(|a| z[(a, 0)]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unknowns on a line with rows x_j − x_{j+1} = c_j, each row also given twice over
    /// (an exact dependency the SVD must leave out), and the exact solution with x_0 = 1.
    #[allow(clippy::type_complexity)]
    fn chain(n: usize) -> (Vec<Vec<(usize, f64)>>, Vec<f64>, Vec<DVec3>, Vec<f64>) {
        let mut rows = Vec::new();
        let mut c = Vec::new();
        for j in 0..n - 1 {
            rows.push(vec![(j, 1.0), (j + 1, -1.0)]);
            c.push(step(j));
            rows.push(vec![(j, 2.0), (j + 1, -2.0)]);
            c.push(2.0 * step(j));
        }
        let pos = (0..n).map(|j| DVec3::new(j as f64, 0.0, 0.0)).collect();
        let mut exact = vec![1.0; n];
        for j in 0..n - 1 {
            exact[j + 1] = exact[j] - step(j);
        }
        (rows, c, pos, exact)
    }

    /// Steps of the chain: bounded, so that its values stay near 1 and its rows' rounding
    /// (~1e-16) far below the tolerances asked.
    fn step(j: usize) -> f64 {
        0.01 * ((j % 7) as f64 - 3.0)
    }

    #[test]
    fn a_local_miss_is_met_by_a_short_move_near_it() {
        let n = 400;
        let (rows, c, pos, exact) = chain(n);
        let mut x = exact.clone();
        // A miss of 1e-9 at unknown 200 only.
        x[200] += 1e-9;
        let out = meet(&rows, &c, &mut x, &pos, 1e-13, 40, 1e-3);
        assert_eq!(out.missed_before, 4, "{out:?}");
        assert!(out.worst_before > 0.9e-9, "{out:?}");
        // Met to the rounding of values near 1 (a few 1e-16).
        assert!(out.worst_after < 1e-14, "{out:?}");
        assert_eq!(out.missed_after, 0, "{out:?}");
        // Only unknowns near 200 moved (within the region of 40), by at most the miss.
        for j in 0..n {
            let d = (x[j] - exact[j]).abs();
            if (j as i64 - 200).abs() > 20 {
                assert_eq!(x[j], exact[j], "unknown {j} moved");
            } else {
                assert!(d <= 1.1e-9, "unknown {j} moved by {d:e}");
            }
        }
        assert!(out.largest_move > 0.0 && out.largest_move <= 1.1e-9);
    }

    /// The region's step is the minimum-norm solution of its rows (the SVD's, computed
    /// here independently), on rows of which a third are combinations of the others.
    #[test]
    fn the_step_is_the_least_move_that_meets_the_rows() {
        let (n, m) = (60, 50);
        let mut seed = 7_u64;
        // Uniform in [−0.5, 0.5).
        let mut lcg = || 0.5 * crate::scheme::quintic_c2::cholesky::tests::lcg(&mut seed);
        let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
        for _ in 0..2 * m / 3 {
            let mut row = Vec::new();
            for j in 0..n {
                if lcg() > 0.2 {
                    row.push((j, lcg()));
                }
            }
            rows.push(row);
        }
        while rows.len() < m {
            // A combination of two earlier rows: an exact dependency.
            let (a, b) = (rows.len() % 7, rows.len() % 11 + 3);
            let (wa, wb) = (lcg(), lcg());
            let mut dense = vec![0.0; n];
            rows[a].iter().for_each(|&(j, v)| dense[j] += wa * v);
            rows[b].iter().for_each(|&(j, v)| dense[j] += wb * v);
            rows.push(
                dense
                    .into_iter()
                    .enumerate()
                    .filter(|p| p.1 != 0.0)
                    .collect(),
            );
        }
        // Residuals of a consistent system: r = M d for some d.
        let d: Vec<f64> = (0..n).map(|_| 1e-9 * lcg()).collect();
        let mut r = vec![0.0; rows.len()];
        for (i, row) in rows.iter().enumerate() {
            r[i] = row.iter().map(|&(j, v)| v * d[j]).sum();
        }
        let region_rows: Vec<usize> = (0..rows.len()).collect();
        let unknowns: Vec<usize> = (0..n).collect();
        let step = min_norm_step(&rows, &region_rows, &unknowns, &r).unwrap();
        // The SVD's minimum-norm solution of M Δ = −r.
        let a = faer::Mat::<f64>::from_fn(rows.len(), n, |i, j| {
            rows[i].iter().filter(|p| p.0 == j).map(|p| p.1).sum()
        });
        let svd = a.thin_svd().unwrap();
        let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
        let mut want = vec![0.0; n];
        for k in 0..s.nrows() {
            if s[k] > 1e-11 * s[0] {
                let c = -(0..rows.len()).map(|i| u[(i, k)] * r[i]).sum::<f64>() / s[k];
                (0..n).for_each(|j| want[j] += c * v[(j, k)]);
            }
        }
        let size = want.iter().fold(0.0_f64, |t, v| t.max(v.abs()));
        let diff = step
            .iter()
            .zip(&want)
            .fold(0.0_f64, |t, (p, q)| t.max((p - q).abs()));
        // Both are the same projection of d, computed by two factorizations of a matrix of
        // condition ~1e2: they agree to ~1e-13 of the step.
        assert!(size > 0.0 && diff <= 1e-10 * size, "{diff:e} of {size:e}");
        let miss = rows
            .iter()
            .zip(&r)
            .map(|(row, ri)| (ri + row.iter().map(|&(j, v)| v * step[j]).sum::<f64>()).abs())
            .fold(0.0_f64, f64::max);
        assert!(
            miss <= 1e-22,
            "rows met to the rounding of 1e-9 data: {miss:e}"
        );
    }

    #[test]
    fn a_move_beyond_the_bound_is_refused() {
        let n = 100;
        let (rows, c, pos, exact) = chain(n);
        let mut x = exact.clone();
        x[50] += 1e-3;
        let before = x.clone();
        let out = meet(&rows, &c, &mut x, &pos, 1e-13, 20, 1e-6);
        assert_eq!(out.kept, 0, "{out:?}");
        assert_eq!(x, before);
        assert_eq!(out.missed_after, out.missed_before);
    }
}

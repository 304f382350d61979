//! The hole repair's minimum-change solves on large groups, with some unknowns pinned: the x
//! closest to the solved values x0 that meets the group's equations A x = c, with the pins
//! x_j = v_j either as equations (hard) or as targets weighted w times more than the other
//! unknowns (soft).
//!
//! The solved values already meet the equations, so every such x is x0 (moved onto the
//! equations) plus a change in the null space N of A. The change closest to x0 with given pin
//! values is dx = Π Eₚ z, a combination of the projections Π e_j onto N of the pinned
//! unknowns' unit vectors, with z from a small dense system in the Gram matrix
//! G = Eₚᵀ Π Eₚ:
//! - hard: G z = δ (δ = the pins less x0's values there), consistent iff the pins are;
//! - soft, weight w (minimising ‖dx_free‖² + w² ‖dx_pinned − δ‖² over N):
//!   (I/w² + (1 − 1/w²) G) z = δ, always solvable.
//!
//! Why: the solves before this factored Â Âᵀ anew for every round and weight, with the pinned
//! columns moved to the right-hand side (hard) or scaled by 1/w (soft). The scaling made rows
//! that differ only in pinned columns nearly dependent; the factor dropped them and the move
//! violated them (the nut's Face(1239, 2): residual 0.30 of 1.7e3). Here A is factored once per
//! repair, unpinned and unscaled, and every dx lies in its null space however ill-conditioned
//! G is: the weights only decide how close the pins come.

use super::cholesky::{Ordering, Projector, PRECISE_PIVOT};
use super::dense::{self, Solution};
use super::sparse::Row;
use std::cell::{Cell, RefCell};
use std::collections::HashMap;

/// Rank tolerance of the dense solves in G (relative to its largest pivot), as the dense
/// repair solves use on their systems.
const G_RANK: f64 = 1e-11;

/// One repair group's factored equations and the projections computed so far.
pub(super) struct PinnedSolves {
    /// The group's factor: in f64 at first, in double-double ([`Projector::precise`]) once a
    /// solve in f64 missed the rows.
    proj: RefCell<Projector>,
    /// x0 moved onto the equations (its change is at rounding: the staged solve met them).
    base: RefCell<Vec<f64>>,
    /// x0 as given.
    x0: Vec<f64>,
    /// Π e_j of each pinned unknown j met so far (the rounds add pins; the weights reuse them).
    columns: RefCell<HashMap<usize, Vec<f64>>>,
    /// The group's largest datum (right-hand side or x0).
    scale: f64,
    /// Residual goal of the moves: 1e-13 of `scale`, as the staged solves'.
    tol: f64,
    /// Whether `proj` is the double-double factor already.
    precise: Cell<bool>,
}

impl PinnedSolves {
    /// Factors the group `rows`·x = `c` (`n` unknowns) in `ordering` and moves `x0` onto it.
    pub(super) fn new(
        rows: &[Row],
        c: &[f64],
        n: usize,
        x0: &[f64],
        ordering: &Ordering,
    ) -> PinnedSolves {
        PinnedSolves::with(Projector::new(rows, n, c, ordering), c, x0)
    }

    /// [`PinnedSolves::new`] on a given factored group.
    fn with(proj: Projector, c: &[f64], x0: &[f64]) -> PinnedSolves {
        let scale = c.iter().chain(x0).fold(1e-300_f64, |a, x| a.max(x.abs()));
        let tol = 1e-13 * scale;
        let mut base = x0.to_vec();
        proj.meet(&mut base, tol);
        PinnedSolves {
            proj: RefCell::new(proj),
            base: RefCell::new(base),
            x0: x0.to_vec(),
            columns: RefCell::new(HashMap::new()),
            scale,
            tol,
            precise: Cell::new(false),
        }
    }

    /// The x closest to x0 meeting the equations with `pins` (unknown, value): as equations
    /// (`weight` `None`) or as targets weighted `weight`. [`Solution::residual`] is the largest
    /// miss of the equations as given (`rows`, `c`) and, for hard pins, of the pins;
    /// [`Solution::rank`] is the group's (equations less dependent ones).
    ///
    /// A solve whose f64 factor misses the rows by more than the repair accepts (`holes`'
    /// `CONSISTENT` hard, `SOFT_CONSISTENT` weighted, of the group's largest datum) is done
    /// again with the group factored in double-double, kept for the repair's later solves:
    /// the nearly dependent rows of spot's Hessian-pass groups were missed by 3e-7 and 1.8e-3
    /// of their data in f64.
    pub(super) fn solve(
        &self,
        rows: &[Row],
        c: &[f64],
        pins: &[(usize, f64)],
        weight: Option<f64>,
    ) -> Solution {
        let (sol, rows_miss) = self.solve_once(rows, c, pins, weight);
        // Inconsistent hard pins are the caller's to judge: only the rows' miss is the
        // factor's.
        let standard = match weight {
            None => super::holes::CONSISTENT,
            Some(_) => super::holes::SOFT_CONSISTENT,
        };
        if self.precise.get() || rows_miss <= standard * self.scale {
            return sol;
        }
        let n = self.base.borrow().len();
        let t = std::time::Instant::now();
        let ordering = Ordering::of(rows, n);
        let proj = Projector::precise(rows, n, c, &ordering, PRECISE_PIVOT);
        let mut base = self.x0.clone();
        proj.meet(&mut base, self.tol);
        *self.proj.borrow_mut() = proj;
        *self.base.borrow_mut() = base;
        self.columns.borrow_mut().clear();
        self.precise.set(true);
        let (again, again_miss) = self.solve_once(rows, c, pins, weight);
        if std::env::var_os("APATCH_HOLE_TRACE").is_some() {
            // Opt-in exploration on stderr (results unaffected).
            eprintln!(
                "quintic-c2 hole repair: double-double factor ({n} unknowns, {} rows, {} pins, {}): rows missed {rows_miss:.2e} → {again_miss:.2e} of {:.2e}, {:.2} s",
                rows.len(),
                pins.len(),
                if weight.is_some() { "weighted" } else { "hard" },
                self.scale,
                t.elapsed().as_secs_f64()
            );
        }
        // The better of the two (NaN-safe: a number beats a NaN).
        if again.residual.partial_cmp(&sol.residual) == Some(std::cmp::Ordering::Greater) {
            sol
        } else {
            again
        }
    }

    /// [`PinnedSolves::solve`] with the current factor, and the largest miss of the rows alone.
    fn solve_once(
        &self,
        rows: &[Row],
        c: &[f64],
        pins: &[(usize, f64)],
        weight: Option<f64>,
    ) -> (Solution, f64) {
        let proj = self.proj.borrow();
        let base = self.base.borrow();
        let k = pins.len();
        let n = base.len();
        let mut columns = self.columns.borrow_mut();
        let mut new: Vec<usize> = pins
            .iter()
            .map(|p| p.0)
            .filter(|j| !columns.contains_key(j))
            .collect();
        new.sort_unstable();
        new.dedup();
        // Unit vectors: the staged solves' standard, 1e-13 of their size.
        for (j, (v, _)) in new.iter().zip(proj.project_units(&new, n, 1e-13)) {
            columns.insert(*j, v);
        }
        let cols: Vec<&Vec<f64>> = pins.iter().map(|(j, _)| &columns[j]).collect();
        // G, symmetrised (its two halves differ by the projections' rounding).
        let mut g = vec![0.0; k * k];
        for a in 0..k {
            for b in 0..k {
                g[a * k + b] = 0.5 * (cols[b][pins[a].0] + cols[a][pins[b].0]);
            }
        }
        let delta: Vec<f64> = pins.iter().map(|&(j, v)| v - base[j]).collect();
        if let Some(w) = weight {
            let inv = 1.0 / (w * w);
            for (i, gi) in g.iter_mut().enumerate() {
                *gi *= 1.0 - inv;
                if i % (k + 1) == 0 {
                    *gi += inv;
                }
            }
        }
        let z = dense::solve_near(&g, k, k, &delta, &vec![0.0; k], G_RANK).x;
        let mut dx = vec![0.0; n];
        for (col, &za) in cols.iter().zip(&z) {
            for (d, &v) in dx.iter_mut().zip(col.iter()) {
                *d += za * v;
            }
        }
        drop(columns);
        // The combination's residual grows with z: project once more where it shows.
        proj.project(&mut dx, self.tol);
        let x: Vec<f64> = base.iter().zip(&dx).map(|(b, d)| b + d).collect();
        let rows_miss = largest(
            rows.iter()
                .zip(c)
                .map(|(row, &ci)| (row.iter().map(|&(j, a)| a * x[j]).sum::<f64>() - ci).abs()),
        );
        let pins_miss = pins
            .iter()
            .filter(|_| weight.is_none())
            .map(|&(j, v)| (x[j] - v).abs());
        let residual = largest(pins_miss.chain([rows_miss]));
        let rank = proj.rank();
        (Solution { x, rank, residual }, rows_miss)
    }
}

/// The largest of `misses`, NaN if any is NaN (`f64::max` would pass over a NaN, and a NaN
/// residual must refuse the solve).
fn largest(misses: impl Iterator<Item = f64>) -> f64 {
    misses.fold(0.0_f64, |a, r| {
        if a.is_nan() || r.is_nan() {
            f64::NAN
        } else {
            a.max(r)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::super::cholesky::tests::lcg;
    use super::*;

    /// A random sparse consistent group: `m` rows over `n` unknowns (6 entries each, the last
    /// row the sum of the first two: a dependent one), its right-hand side and a point on it.
    fn group(m: usize, n: usize, seed: u64) -> (Vec<Row>, Vec<f64>, Vec<f64>) {
        let mut s = seed;
        let mut rows: Vec<Row> = (0..m - 1)
            .map(|_| {
                (0..6)
                    .map(|_| {
                        let j = ((lcg(&mut s) + 1.0) * 0.5 * n as f64) as usize % n;
                        (j, lcg(&mut s))
                    })
                    .collect()
            })
            .collect();
        let last: Row = rows[0].iter().chain(&rows[1]).copied().collect();
        rows.push(last);
        let x0: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        let c = rows
            .iter()
            .map(|r| r.iter().map(|&(j, a)| a * x0[j]).sum())
            .collect();
        (rows, c, x0)
    }

    /// Exploration: a group dumped by the repair (`APATCH_HOLE_DUMP`), solved hard and soft
    /// (w = 100), with the rows each solve misses (`CLEAN=t` first drops terms below t of their
    /// row's largest; `EQUIL=1` solves for the unknowns over their columns' norms).
    #[test]
    #[ignore = "exploration: DUMP=/tmp/dump_<defect>_<n>.json [CLEAN=1e-13] [EQUIL=1] [PRECISE=drop] [SWEEP=1]"]
    fn explore_dump() {
        let path = std::env::var("DUMP").expect("DUMP=path");
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let n = j["n"].as_u64().unwrap() as usize;
        let mut rows: Vec<Row> = serde_json::from_value(j["rows"].clone()).unwrap();
        if let Ok(t) = std::env::var("CLEAN") {
            let t: f64 = t.parse().unwrap();
            let mut removed = 0;
            for r in &mut rows {
                let big = r.iter().fold(0.0_f64, |a, t| a.max(t.1.abs()));
                let before = r.len();
                r.retain(|e| e.1.abs() > t * big);
                removed += before - r.len();
            }
            eprintln!("cleaned {removed} terms");
        }
        let c: Vec<f64> = serde_json::from_value(j["c"].clone()).unwrap();
        let x0: Vec<f64> = serde_json::from_value(j["x0"].clone()).unwrap();
        let pins: Vec<(usize, f64)> = serde_json::from_value(j["pins"].clone()).unwrap();
        let (mut x0, mut pins) = (x0, pins);
        let orig_rows = rows.clone();
        let mut colscale = vec![1.0; n];
        if std::env::var("EQUIL").is_ok() {
            let mut norm = vec![0.0_f64; n];
            for r in &rows {
                for &(j, a) in r {
                    norm[j] += a * a;
                }
            }
            for j in 0..n {
                if norm[j] > 0.0 {
                    colscale[j] = 1.0 / norm[j].sqrt();
                }
            }
            for r in &mut rows {
                for t in r.iter_mut() {
                    t.1 *= colscale[t.0];
                }
            }
            for (x, d) in x0.iter_mut().zip(&colscale) {
                *x /= d;
            }
            for p in &mut pins {
                p.1 /= colscale[p.0];
            }
        }
        let scale = c.iter().chain(&x0).fold(1e-300_f64, |a, x| a.max(x.abs()));
        eprintln!(
            "n {n} m {} pins {} scale {scale:.3e}",
            rows.len(),
            pins.len()
        );
        let ordering = Ordering::of(&rows, n);
        if std::env::var("SWEEP").is_ok() {
            // Dropped rows of the precise factor per threshold: a gap shows as a plateau.
            for e in 9..=24 {
                let drop = 10f64.powi(-e);
                let p = Projector::precise(&rows, n, &c, &ordering, drop);
                eprintln!("  drop 1e-{e}: dropped {}", rows.len() - p.rank());
            }
        }
        let solves = match std::env::var("PRECISE") {
            Ok(d) => PinnedSolves::with(
                Projector::precise(&rows, n, &c, &ordering, d.parse().unwrap()),
                &c,
                &x0,
            ),
            Err(_) => PinnedSolves::new(&rows, &c, n, &x0, &ordering),
        };
        let miss_of = |x: &[f64]| {
            largest(
                rows.iter()
                    .zip(&c)
                    .map(|(row, &ci)| (row.iter().map(|&(j, a)| a * x[j]).sum::<f64>() - ci).abs()),
            )
        };
        eprintln!(
            "x0 misses {:.3e}, base {:.3e}",
            miss_of(&x0),
            miss_of(&solves.base.borrow())
        );
        for &(j, _) in pins.iter().take(5) {
            let mut v = vec![0.0; n];
            v[j] = 1.0;
            let got = solves.proj.borrow().project(&mut v, 1e-13);
            eprintln!(
                "  column {j}: projection residual {got:.3e}, |Π e_j|² {:.3e}",
                v[j]
            );
        }
        if std::env::var("TIMEPROJ").is_ok() {
            // One by one against batched (the same values), in one run.
            let js: Vec<usize> = pins.iter().map(|p| p.0).collect();
            let proj = solves.proj.borrow();
            let t = std::time::Instant::now();
            for &j in &js {
                let mut v = vec![0.0; n];
                v[j] = 1.0;
                proj.project(&mut v, 1e-13);
            }
            let single = t.elapsed().as_secs_f64();
            let t = std::time::Instant::now();
            let _ = proj.project_units(&js, n, 1e-13);
            let batched = t.elapsed().as_secs_f64();
            eprintln!(
                "{} projections: one by one {single:.3} s, batched {batched:.3} s",
                js.len()
            );
        }
        let dropped = solves.proj.borrow().dropped_rows();
        eprintln!(
            "rank {} dropped {}",
            solves.proj.borrow().rank(),
            dropped.len()
        );
        for w in [None, Some(1e2)] {
            let mut sol = solves.solve(&rows, &c, &pins, w);
            eprintln!("precise factor: {}", solves.precise.get());
            for (x, d) in sol.x.iter_mut().zip(&colscale) {
                *x *= d;
            }
            let rows = &orig_rows;
            eprintln!(
                "  original rows: {:.3e}",
                rows.iter()
                    .zip(&c)
                    .map(
                        |(row, &ci)| (row.iter().map(|&(j, a)| a * sol.x[j]).sum::<f64>() - ci)
                            .abs()
                    )
                    .fold(0.0_f64, f64::max)
            );
            let miss: Vec<(usize, f64, f64)> = rows
                .iter()
                .zip(&c)
                .enumerate()
                .map(|(i, (row, &ci))| {
                    let norm = row.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt();
                    (
                        i,
                        (row.iter().map(|&(j, a)| a * sol.x[j]).sum::<f64>() - ci).abs(),
                        norm,
                    )
                })
                .filter(|t| t.1 > 1e-10 * scale)
                .collect();
            let mut miss = miss;
            miss.sort_by(|a, b| b.1.total_cmp(&a.1));
            let dropped_miss = miss
                .iter()
                .filter(|t| dropped.binary_search(&t.0).is_ok())
                .count();
            eprintln!(
                "{w:?}: residual {:.3e}, rows missed {} (dropped {dropped_miss})",
                sol.residual,
                miss.len()
            );
            for t in miss.iter().take(12) {
                eprintln!(
                    "  row {} miss {:.3e} norm {:.3e} dropped {} terms {:?}",
                    t.0,
                    t.1,
                    t.2,
                    dropped.binary_search(&t.0).is_ok(),
                    rows[t.0]
                );
            }
        }
    }

    /// A NaN miss anywhere makes the residual NaN (a fold with `f64::max` alone forgets a NaN
    /// once a later miss is a number).
    #[test]
    fn largest_keeps_a_nan() {
        assert_eq!(largest([1.0, 3.0, 2.0].into_iter()), 3.0);
        assert!(largest([1.0, f64::NAN, 2.0].into_iter()).is_nan());
        assert!(largest([f64::NAN, 0.5].into_iter()).is_nan());
    }

    /// The dense A (row-major) of sparse rows, duplicates summed.
    fn dense_of(rows: &[Row], n: usize) -> Vec<f64> {
        let mut a = vec![0.0; rows.len() * n];
        for (i, r) in rows.iter().enumerate() {
            for &(j, v) in r {
                a[i * n + j] += v;
            }
        }
        a
    }

    /// Hard pins give what the dense pivoted QR (independent) gives for the rows with the pins
    /// appended as equations: the same closest solution, pins and rows met, with the f64
    /// factor and with the double-double one.
    #[test]
    fn hard_pins_match_the_dense_solve() {
        let (m, n) = (60, 90);
        let (rows, c, x0) = group(m, n, 41);
        let ordering = Ordering::of(&rows, n);
        let precise = Projector::precise(&rows, n, &c, &ordering, PRECISE_PIVOT);
        for solves in [
            PinnedSolves::new(&rows, &c, n, &x0, &ordering),
            PinnedSolves::with(precise, &c, &x0),
        ] {
            hard_pins_check(&solves, &rows, &c, &x0, m, n);
        }
    }

    fn hard_pins_check(
        solves: &PinnedSolves,
        rows: &[Row],
        c: &[f64],
        x0: &[f64],
        m: usize,
        n: usize,
    ) {
        let pins = [(3, 0.7), (17, -0.2), (50, 1.5)];
        let got = solves.solve(rows, c, &pins, None);
        let mut a = dense_of(rows, n);
        let mut rhs = c.to_vec();
        for &(j, v) in &pins {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            a.extend(e);
            rhs.push(v);
        }
        let want = dense::solve_near(&a, m + pins.len(), n, &rhs, x0, 1e-11);
        // Consistent, modestly conditioned, entries O(1): rounding-level agreement.
        assert!(got.residual < 1e-12, "{}", got.residual);
        assert_eq!(got.rank, m - 1, "one dependent row");
        for (u, v) in got.x.iter().zip(&want.x) {
            assert!((u - v).abs() < 1e-9, "{u} vs {v}");
        }
    }

    /// Soft pins minimise ‖dx_free‖² + w² ‖dx_pinned − δ‖² over the equations: the same as the
    /// dense closest solution in y = W x (the pinned columns scaled by 1/w), the formulation
    /// the repair used before.
    #[test]
    fn soft_pins_match_the_scaled_dense_solve() {
        let (m, n) = (60, 90);
        let (rows, c, x0) = group(m, n, 7);
        let ordering = Ordering::of(&rows, n);
        let solves = PinnedSolves::new(&rows, &c, n, &x0, &ordering);
        let pins = [(5, 2.0), (40, -1.0)];
        let w = 30.0;
        let got = solves.solve(&rows, &c, &pins, Some(w));
        let mut wts = vec![1.0; n];
        let mut y0 = x0.clone();
        for &(j, v) in &pins {
            wts[j] = w;
            y0[j] = w * v;
        }
        let scaled: Vec<Row> = rows
            .iter()
            .map(|r| r.iter().map(|&(j, a)| (j, a / wts[j])).collect())
            .collect();
        let want = dense::solve_near(&dense_of(&scaled, n), m, n, &c, &y0, 1e-11);
        // Equations met to rounding; the two formulations agree to the (w²-amplified) rounding
        // of the dense scaled solve.
        assert!(got.residual < 1e-12, "{}", got.residual);
        for (j, (u, v)) in got.x.iter().zip(&want.x).enumerate() {
            assert!((u - v / wts[j]).abs() < 1e-8, "{j}: {u} vs {}", v / wts[j]);
        }
        // The pins pull: each pinned value moved from x0 towards its pin.
        for &(j, v) in &pins {
            assert!((got.x[j] - v).abs() < (x0[j] - v).abs(), "{j}");
        }
    }

    /// Inconsistent hard pins (one pinned unknown fixed by the equations to another value)
    /// show in the residual; the soft solve still meets every equation.
    #[test]
    fn inconsistent_pins_show_and_soft_pins_still_meet_the_rows() {
        let n = 1200;
        // x_{i+1} − x_i = 1 for i < 10, with x_0 pinned as well as x_10: inconsistent unless
        // the pins differ by 10.
        let mut rows: Vec<Row> = (0..10).map(|i| vec![(i, -1.0), (i + 1, 1.0)]).collect();
        rows.push(vec![(20, 1.0), (21, 1.0)]);
        let c: Vec<f64> = (0..11).map(|i| if i < 10 { 1.0 } else { 0.0 }).collect();
        let x0: Vec<f64> = (0..n)
            .map(|i| if i <= 10 { i as f64 } else { 0.0 })
            .collect();
        let ordering = Ordering::of(&rows, n);
        let solves = PinnedSolves::new(&rows, &c, n, &x0, &ordering);
        let pins = [(0, 0.5), (10, 10.0)];
        let hard = solves.solve(&rows, &c, &pins, None);
        // The pins contradict the chain by 0.5: far above rounding.
        assert!(hard.residual > 1e-3, "{}", hard.residual);
        let soft = solves.solve(&rows, &c, &pins, Some(100.0));
        // Chain of unit steps, entries ≤ 10: rounding-level residual.
        assert!(soft.residual < 1e-12, "{}", soft.residual);
        // The chain moves rigidly; both pins weigh alike, so it splits the difference.
        assert!((soft.x[0] - 0.25).abs() < 1e-3, "{}", soft.x[0]);
    }
}

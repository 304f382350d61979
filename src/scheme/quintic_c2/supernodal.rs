//! Minimum-change solves of the groups beyond the in-house factor ([`super::cholesky`]'s
//! `MAX_FACTOR_ROWS`, `MAX_FACTOR_ENTRIES`): the same normal equations Â Âᵀ y = ĉ − Â·target,
//! factored by faer's supernodal LDLᵀ in an approximate minimum degree order.
//!
//! Why: joint stars (every star with its edge middles and Hessian, `joint_stars`) make one
//! group of the whole curved part of a model; on fandisk 1.57M equations, on a twisted 96 × 12
//! torus 0.67M with nnz(L) 2.5e8. The in-house left-looking factor works one column at a time
//! (memory-bound, and its double-double twin doubles the memory); a supernodal factor does the
//! same elimination in dense blocks.
//!
//! Dependent rows are dropped as [`super::cholesky`] drops them: a pivot below the drop
//! threshold (the rows have unit norm, so Â Âᵀ has a unit diagonal and the threshold is
//! absolute) is replaced by [`DROPPED_PIVOT`], which makes that row's multipliers and its y
//! vanish (faer's dynamic regularization). As there, f64 comes first (drop thresholds
//! [`cholesky::DEPENDENT_PIVOT`], then [`cholesky::RETRY_PIVOT`]), and where its pivots of
//! nearly dependent rows are rounding and the rows are missed, the factor runs again in
//! double-double (faer's `fx128`, rows dropped at [`cholesky::PRECISE_PIVOT`], then at
//! [`PRECISE_RETRY_PIVOT`] if that factor's first correction does not help): the rounded
//! cylinder's joint group needs it (the f64 factors miss its rows by 5.9e-9, the double-double
//! one meets them to 3e-14, as the in-house double-double factor does).
//!
//! Determinism: the factor and its solves run on one thread (`Par::Seq`), so the bits do not
//! depend on the thread count; the dense kernels inside each supernode are what make it fast.

use super::cholesky::{self, UnitRows};
use super::dd::{Dd, Real};
use super::dense::Solution;
use super::sparse::Row;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{fx128, Conj, MatMut, Par, Side};

/// The factor's and the solves' parallelism: one thread, so the bits cannot depend on the
/// thread count. Two threads (faer's `rayon` feature, `Par::rayon(2)`) were measured on the
/// twisted torus's joint group: double-double factor 160 s against 181 s, f64 10.4 s against
/// 9.3 s, the same rank and residual; not worth a second source of nondeterminism.
const PAR: Par = Par::Seq;

/// The pivot a dropped (dependent) row gets: its y is its right-hand side over this, and its
/// column of L the entries over this, both far below the resolution of the others.
pub const DROPPED_PIVOT: f64 = 1e150;

/// Most values a supernodal factor may hold by default ([`solve_near`]'s `max_values`), with
/// the zeros its dense blocks carry: in double-double (16 bytes each) 12.8 GB, on the 24 GB
/// machines we run on. fandisk's joint group: 5.0e8 values (11.6 GB resident in all); on
/// its hull with `flat_net_angle` and `straight_corners`, 7.26e8 (16.5 GB resident).
pub const MAX_VALUES: usize = 800_000_000;

/// The factor's arithmetic: f64, or double-double (faer's `fx128`, a pair hi + lo) for the
/// groups whose f64 factor cannot tell nearly dependent rows from dependent ones (as
/// [`cholesky::Projector::precise`] does for the in-house factor).
pub trait Elem: faer::traits::ComplexField<Real = Self> + Copy {
    /// The value of a double-double sum of Â Âᵀ.
    fn of_dd(d: Dd) -> Self;
    /// The value of an f64.
    fn of_f64(x: f64) -> Self;
    /// As our double-double.
    fn dd(self) -> Dd;
}

impl Elem for f64 {
    fn of_dd(d: Dd) -> f64 {
        d.hi + d.lo
    }
    fn of_f64(x: f64) -> f64 {
        x
    }
    fn dd(self) -> Dd {
        Dd::of(self)
    }
}

impl Elem for fx128 {
    fn of_dd(d: Dd) -> fx128 {
        fx128 { 0: d.hi, 1: d.lo }
    }
    fn of_f64(x: f64) -> fx128 {
        fx128 { 0: x, 1: 0.0 }
    }
    fn dd(self) -> Dd {
        Dd {
            hi: self.0,
            lo: self.1,
        }
    }
}

/// Â Âᵀ of a group, factored in `T` (on its [`Normal`]'s symbolic factorisation).
pub struct Supernodal<'a, T: Elem> {
    symbolic: &'a SymbolicCholesky<usize>,
    values: Vec<T>,
    /// Rows dropped as dependent.
    pub dropped: usize,
}

impl<T: Elem> Supernodal<'_, T> {
    /// Solves Â Âᵀ y = r in `T` (dropped rows get y ≈ 0).
    pub fn solve_wide(&self, r: &[f64]) -> Vec<T> {
        let n = r.len();
        let mut y: Vec<T> = r.iter().map(|&v| T::of_f64(v)).collect();
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<T>(1, PAR));
        let stack = MemStack::new(&mut mem);
        let rhs = MatMut::from_column_major_slice_mut(&mut y, n, 1);
        LdltRef::<usize, T>::new(self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            PAR,
            stack,
        );
        y
    }
}

/// The lower triangle of Â Âᵀ in compressed columns (each column's diagonal first, then its
/// rows in increasing order), from [`cholesky::normal_matrix`]'s diagonal and upper entries.
fn lower_columns(d: &[Dd], off: &[(u32, u32, Dd)]) -> (Vec<usize>, Vec<usize>, Vec<Dd>) {
    let m = d.len();
    let mut ptr = vec![0usize; m + 1];
    for &(i, _, _) in off {
        ptr[i as usize + 1] += 1;
    }
    for i in 0..m {
        ptr[i + 1] += ptr[i] + 1;
    }
    let mut idx = Vec::with_capacity(m + off.len());
    let mut val = Vec::with_capacity(m + off.len());
    // `off` holds each row i's entries (i, k > i) together, k increasing, rows in order.
    let mut e = 0;
    for (i, &di) in d.iter().enumerate() {
        idx.push(i);
        val.push(di);
        while e < off.len() && off[e].0 as usize == i {
            idx.push(off[e].1 as usize);
            val.push(off[e].2);
            e += 1;
        }
        debug_assert_eq!(idx.len(), ptr[i + 1]);
    }
    (ptr, idx, val)
}

/// Â Âᵀ of a group's unit rows (summed in double-double) in compressed lower columns, and its
/// symbolic factorisation in faer's approximate minimum degree order: what every numeric
/// factor of one solve shares, whatever its drop threshold or arithmetic.
pub struct Normal {
    ptr: Vec<usize>,
    idx: Vec<usize>,
    val: Vec<Dd>,
    symbolic: SymbolicCholesky<usize>,
}

impl Normal {
    /// Forms and orders Â Âᵀ of the unit rows `arows` (`n` unknowns); `None` when its factor
    /// would hold more than `max_values` values or faer refuses it.
    #[must_use]
    pub fn of(arows: &[Vec<(u32, f64)>], n: usize, max_values: usize) -> Option<Normal> {
        let m = arows.len();
        let (d, off) = cholesky::normal_matrix::<Dd>(arows, n);
        let (ptr, idx, val) = lower_columns(&d, &off);
        std::mem::drop(off);
        let t = std::time::Instant::now();
        let symbolic = factorize_symbolic_cholesky(
            SymbolicSparseColMatRef::new_checked(m, m, &ptr, None, &idx),
            Side::Lower,
            // Not the in-house minimum degree order: on the twisted 96 × 12 torus's joint group
            // faer's AMD gives 2.4e8 values against 2.9e8, and the f64 factor in 7.5 s against 18.
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .ok()?;
        if std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
            // Opt-in timing on stderr (exploration; results unaffected).
            eprintln!(
                "quintic-c2 supernodal: {m} rows, symbolic {:.2} s, {} values",
                t.elapsed().as_secs_f64(),
                symbolic.len_val()
            );
        }
        (symbolic.len_val() <= max_values).then_some(Normal {
            ptr,
            idx,
            val,
            symbolic,
        })
    }

    /// The numeric factor in `T`, dropping rows whose pivot falls below `threshold`; `None`
    /// when faer refuses it.
    #[must_use]
    pub fn factor<T: Elem>(&self, threshold: f64) -> Option<Supernodal<'_, T>> {
        let m = self.ptr.len() - 1;
        let t = std::time::Instant::now();
        let sym = SymbolicSparseColMatRef::new_checked(m, m, &self.ptr, None, &self.idx);
        let val: Vec<T> = self.val.iter().map(|&v| T::of_dd(v)).collect();
        let symbolic = &self.symbolic;
        let mut values = vec![T::of_f64(0.0); symbolic.len_val()];
        let signs = vec![1i8; m];
        let mut mem =
            MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<T>(PAR, Default::default()));
        let info = symbolic.factorize_numeric_ldlt(
            &mut values,
            SparseColMatRef::new(sym, &val),
            Side::Lower,
            LdltRegularization {
                dynamic_regularization_signs: Some(&signs),
                dynamic_regularization_delta: T::of_f64(DROPPED_PIVOT),
                dynamic_regularization_epsilon: T::of_f64(threshold),
            },
            PAR,
            MemStack::new(&mut mem),
            Default::default(),
        );
        if info.is_err() {
            return None;
        }
        // The dropped rows: pivots set to DROPPED_PIVOT, on the diagonals of the supernodes'
        // blocks.
        let SymbolicCholeskyRaw::Supernodal(raw) = symbolic.raw() else {
            return None;
        };
        let blocks = SupernodalLdltRef::<usize, T>::new(raw, &values);
        let dropped = (0..raw.n_supernodes())
            .map(|s| {
                let v = blocks.supernode(s).val();
                (0..v.ncols())
                    .filter(|&k| v[(k, k)].dd().hi == DROPPED_PIVOT)
                    .count()
            })
            .sum();
        if std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
            eprintln!(
                "quintic-c2 supernodal: numeric {:.2} s, {dropped} dropped",
                t.elapsed().as_secs_f64()
            );
        }
        Some(Supernodal {
            symbolic,
            values,
            dropped,
        })
    }
}

/// A factor with its dropped rows, as [`cholesky::refine_near`] takes them.
fn with_dropped<T: Elem>(f: Supernodal<'_, T>) -> (Supernodal<'_, T>, usize) {
    let dropped = f.dropped;
    (f, dropped)
}

impl cholesky::NormalSolve for Supernodal<'_, f64> {
    fn solve_normal(&self, r: &mut [f64]) {
        r.copy_from_slice(&self.solve_wide(r));
    }
}

impl cholesky::NormalSolve for Supernodal<'_, fx128> {
    fn solve_normal(&self, r: &mut [f64]) {
        let y = self.solve_wide(r);
        for (v, y) in r.iter_mut().zip(y) {
            *v = y.0 + y.1;
        }
    }

    /// y in double-double and Âᵀ y summed in double-double, as the in-house precise factor
    /// does ([`cholesky::add_transposed_precise`] says why).
    fn correct(&self, arows: &[Vec<(u32, f64)>], r: &mut [f64], x: &mut [f64]) {
        let y: Vec<Dd> = self.solve_wide(r).into_iter().map(Elem::dd).collect();
        cholesky::add_transposed_precise(arows, &y, x);
    }

    /// All of them in one solve with as many right-hand sides: a pass over the factor per
    /// solve is what a solve costs (seconds on fandisk's joint group), not its columns.
    fn project(&self, arows: &[Vec<(u32, f64)>], ps: &mut [Vec<f64>]) {
        let m = arows.len();
        let k = ps.len();
        if k == 0 {
            return;
        }
        let mut y: Vec<fx128> = Vec::with_capacity(m * k);
        for p in ps.iter() {
            y.extend(
                cholesky::minus_rows_times(arows, p)
                    .into_iter()
                    .map(fx128::of_f64),
            );
        }
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<fx128>(k, PAR));
        let stack = MemStack::new(&mut mem);
        let rhs = MatMut::from_column_major_slice_mut(&mut y, m, k);
        LdltRef::<usize, fx128>::new(self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            PAR,
            stack,
        );
        for (p, col) in ps.iter_mut().zip(y.chunks(m)) {
            let yd: Vec<Dd> = col.iter().map(|v| v.dd()).collect();
            cholesky::add_transposed_precise(arows, &yd, p);
        }
    }
}

/// [`cholesky::solve_near`] for a group beyond the in-house factor: the x closest to `target`
/// with A x = c, refined until max |A x − c| ≤ `tol` (the same refinement and conjugate
/// gradients): with an f64 factor first, then, if that falls short, a double-double one
/// dropping rows at [`cholesky::PRECISE_PIVOT`] (or [`PRECISE_RETRY_PIVOT`], one factor held
/// at a time); Â Âᵀ is formed and ordered once for all of
/// them ([`Normal`]). `None` when this factor would hold more than `max_values` values
/// ([`MAX_VALUES`] in the solves).
#[must_use]
pub fn solve_near(
    rows: &[Row],
    n: usize,
    c: &[f64],
    target: &[f64],
    tol: f64,
    max_values: usize,
) -> Option<Solution> {
    solve_near_signed(rows, n, c, target, tol, max_values, None, None)
}

/// [`solve_near`], then with `signs` alternating projections between Theorem 2.1's signs and
/// the rows with the same factor ([`cholesky::sign_rounds`]), before the dropped rows are met.
/// `pivot`, if given, is the double-double factor's one drop threshold instead of
/// [`cholesky::PRECISE_PIVOT`] then [`PRECISE_RETRY_PIVOT`] (`[scheme] precise_pivot`).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn solve_near_signed(
    rows: &[Row],
    n: usize,
    c: &[f64],
    target: &[f64],
    tol: f64,
    max_values: usize,
    signs: Option<&cholesky::SignBox>,
    pivot: Option<f64>,
) -> Option<Solution> {
    let unit = UnitRows::new(rows, c);
    let normal = Normal::of(&unit.rows, n, max_values)?;
    let drops = [cholesky::DEPENDENT_PIVOT, cholesky::RETRY_PIVOT];
    let mut best = cholesky::refine_near(&unit, target, tol, &drops, false, signs, |drop| {
        normal.factor::<f64>(drop).map(with_dropped)
    })?;
    if best.0 > tol {
        let precise = cholesky::refine_near(
            &unit,
            target,
            tol,
            &precise_pivots(pivot),
            true,
            signs,
            |drop| normal.factor::<fx128>(drop).map(with_dropped),
        );
        if let Some(p) = precise.filter(|p| p.0 < best.0) {
            best = p;
        }
    }
    let (residual, x, dropped) = best;
    Some(Solution {
        x,
        rank: rows.len() - dropped,
        residual,
    })
}

/// The double-double factor's drop thresholds in turn: [`cholesky::PRECISE_PIVOT`], then
/// [`PRECISE_RETRY_PIVOT`] when that factor's first correction does not help; or the scene's
/// one (`pivot`); or the one `APATCH_PRECISE_PIVOT` names (exploration, before either).
fn precise_pivots(pivot: Option<f64>) -> Vec<f64> {
    match cholesky::positive_env("APATCH_PRECISE_PIVOT").or(pivot) {
        Some(t) => vec![t],
        None => vec![cholesky::PRECISE_PIVOT, PRECISE_RETRY_PIVOT],
    }
}

/// The double-double factor's second drop threshold. Rows within ~1e-6 of the kept rows'
/// span are dropped too (pivots are squared distances) and met afterwards by
/// [`cholesky::meet_dropped`]. fandisk's joint group with snapped β (`face_beta =
/// "snapped"`, session 60) keeps, at 1e-15, pivots whose first correction takes the residual
/// 0.740 → 4.7e20; at 1e-12 it drops 185458 rows and the correction gives 5.1e-9.
pub const PRECISE_RETRY_PIVOT: f64 = 1e-12;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::quintic_c2::cholesky::tests::{sparse_rows, system, times};

    /// Reads a group written by `APATCH_SOLVE_DUMP` (`system::dump_group`'s format): rows, n,
    /// c, target, scale.
    fn read_group_dump(path: &str) -> (Vec<Row>, usize, Vec<f64>, Vec<f64>, f64) {
        let b = std::fs::read(path).expect("GROUP: a group dump");
        let mut at = 0;
        let mut word = || {
            let w: [u8; 8] = b[at..at + 8].try_into().expect("8 bytes");
            at += 8;
            w
        };
        let m = u64::from_le_bytes(word()) as usize;
        let n = u64::from_le_bytes(word()) as usize;
        let scale = f64::from_le_bytes(word());
        let mut rows = Vec::with_capacity(m);
        for _ in 0..m {
            let len = u64::from_le_bytes(word()) as usize;
            let row: Row = (0..len)
                .map(|_| {
                    let j = u64::from_le_bytes(word()) as usize;
                    (j, f64::from_le_bytes(word()))
                })
                .collect();
            rows.push(row);
        }
        let c: Vec<f64> = (0..m).map(|_| f64::from_le_bytes(word())).collect();
        let tgt: Vec<f64> = (0..n).map(|_| f64::from_le_bytes(word())).collect();
        (rows, n, c, tgt, scale)
    }

    /// Exploration: one dumped group solved with double-double factors at each drop threshold
    /// of `DROPS` (the symbolic factor shared): rows dropped, kept pivots per decade, residual
    /// over the group's scale, largest move from the target, rows missed beyond 1e-9 of it.
    #[test]
    #[ignore = "exploration: GROUP=/tmp/dump/group000.bin DROPS=1e-15,1e-17 [F64=1]"]
    fn sweep_group_dump() {
        let path = std::env::var("GROUP").expect("GROUP=<dump>");
        let drops: Vec<f64> = std::env::var("DROPS")
            .unwrap_or_else(|_| "1e-15".into())
            .split(',')
            .map(|v| v.parse().expect("DROPS: numbers"))
            .collect();
        let (rows, n, c, tgt, scale) = read_group_dump(&path);
        eprintln!("{} rows, {n} unknowns, scale {scale:.3e}", rows.len());
        let unit = UnitRows::new(&rows, &c);
        let normal = Normal::of(&unit.rows, n, usize::MAX).expect("factorable");
        let report = |what: &str, got: Option<(f64, Vec<f64>, usize)>, secs: f64| {
            let Some((res, x, dropped)) = got else {
                eprintln!("{what}: no factor");
                return;
            };
            let moved = x
                .iter()
                .zip(&tgt)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let missed = rows
                .iter()
                .zip(&c)
                .filter(|(r, &ci)| {
                    let v: f64 = r.iter().map(|&(j, a)| a * x[j]).sum();
                    (v - ci).abs() > 1e-9 * scale
                })
                .count();
            eprintln!(
                "{what}: dropped {dropped}, residual {res:.3e} ({:.3e} of scale), largest move {moved:.3e}, rows missed {missed}, {secs:.0} s",
                res / scale
            );
        };
        if std::env::var_os("F64").is_some() {
            let t = std::time::Instant::now();
            let got = cholesky::refine_near(
                &unit,
                &tgt,
                1e-13 * scale,
                &[cholesky::DEPENDENT_PIVOT],
                false,
                None,
                |d| normal.factor::<f64>(d).map(with_dropped),
            );
            report("f64 1e-13", got, t.elapsed().as_secs_f64());
        }
        for drop in drops {
            let t = std::time::Instant::now();
            let got = cholesky::refine_near(
                &unit,
                &tgt,
                1e-13 * scale,
                &[drop],
                std::env::var_os("MEET").is_some(),
                None,
                |d| {
                    let f = normal.factor::<fx128>(d)?;
                    let SymbolicCholeskyRaw::Supernodal(raw) = normal.symbolic.raw() else {
                        return None;
                    };
                    let blocks = SupernodalLdltRef::<usize, fx128>::new(raw, &f.values);
                    let mut decades = std::collections::BTreeMap::<i32, usize>::new();
                    for s in 0..raw.n_supernodes() {
                        let v = blocks.supernode(s).val();
                        for k in 0..v.ncols() {
                            let p = v[(k, k)].0;
                            if p != DROPPED_PIVOT {
                                *decades.entry(p.log10().floor() as i32).or_default() += 1;
                            }
                        }
                    }
                    let low: Vec<String> = decades
                        .iter()
                        .filter(|(&e, _)| e < -6)
                        .map(|(e, k)| format!("1e{e}: {k}"))
                        .collect();
                    eprintln!(
                        "drop {d:e}: kept pivots below 1e-6 by decade: {}",
                        low.join(", ")
                    );
                    Some(with_dropped(f))
                },
            );
            report(
                &format!("double-double {drop:e}"),
                got,
                t.elapsed().as_secs_f64(),
            );
        }
    }

    /// Agrees with the dense pivoted QR (an independent factorisation) on random
    /// underdetermined systems with two dependent rows: the same rank (the two rows dropped,
    /// not regularised into the solution) and the same closest solution.
    #[test]
    fn matches_dense_on_rank_deficient_systems() {
        for (m, n, seed) in [
            (30, 50, 12345),
            (120, 200, 7),
            (200, 260, 99),
            (400, 420, 3),
        ] {
            let (a, rows, c, target) = system(m, n, seed);
            let d = crate::scheme::quintic_c2::dense::solve_near(&a, m, n, &c, &target, 1e-11);
            let s = solve_near(&rows, n, &c, &target, 1e-13, MAX_VALUES)
                .expect("small enough to factor");
            assert_eq!(s.rank, d.rank, "rank ({m}×{n})");
            // Consistent system: rounding-level residual, as asked.
            assert!(s.residual <= 1e-13, "{}", s.residual);
            for (x, y) in s.x.iter().zip(&d.x) {
                // Both are the unique closest solution; entries O(1), modest conditioning.
                assert!((x - y).abs() < 1e-9, "{x} vs {y}");
            }
        }
    }

    /// The in-house factor and this one give the same closest solution on a group both can
    /// factor, with more equations than unknowns (consistent, so dependent rows are many).
    #[test]
    fn agrees_with_the_in_house_factor_on_overdetermined_groups() {
        let (m, n) = (300, 240);
        let (_, rows, c, target) = system(m, n, 2024);
        // Overdetermined and random: only consistent if the right-hand side is made so.
        let s =
            solve_near(&rows, n, &c, &target, 1e-13, MAX_VALUES).expect("small enough to factor");
        let h = cholesky::solve_near(&rows, n, &c, &target, 1e-13);
        // 60 dependent rows: in another elimination order a dependent row's pivot, rounding
        // of order 1e-14, can land on either side of the 1e-13 threshold (seen: one row kept
        // here, met to 5e-15 all the same); the solutions must agree regardless.
        assert!(s.rank.abs_diff(h.rank) <= 2, "{} vs {}", s.rank, h.rank);
        assert!(
            s.residual <= 1e-13 && h.residual <= 1e-13,
            "{} {}",
            s.residual,
            h.residual
        );
        for (x, y) in s.x.iter().zip(&h.x) {
            // The same unique solution from two factorisations: agreement to rounding of O(1)
            // entries times a modest condition number.
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
    }

    /// Two rows t apart in angle, a = (1, 0) and b = (cos t, sin t): b lies sin² t from a's
    /// span, the pivot of b after a.
    fn pair(t: f64) -> Vec<Vec<(u32, f64)>> {
        vec![vec![(0, 1.0)], vec![(0, t.cos()), (1, t.sin())]]
    }

    /// [`pair`] as the solves' sparse rows.
    fn pair_rows(t: f64) -> Vec<Row> {
        pair(t)
            .into_iter()
            .map(|r| r.into_iter().map(|(j, a)| (j as usize, a)).collect())
            .collect()
    }

    /// The double-double factor resolves pivots far below f64's rounding: at t = 1e-9 the
    /// pivot is 1e-18 (f64 forms 1 − cos² t at its rounding, 1e-16), kept at a threshold of
    /// 1e-19 and dropped at 1e-17.
    #[test]
    fn double_double_pivots_resolve_distances_below_f64_rounding() {
        let rows = pair(1e-9);
        let normal = Normal::of(&rows, 2, MAX_VALUES).expect("tiny");
        let keep = normal.factor::<fx128>(1e-19).expect("tiny");
        assert_eq!(keep.dropped, 0);
        let drop = normal.factor::<fx128>(1e-17).expect("tiny");
        assert_eq!(drop.dropped, 1);
        // The kept pivot is the true one: solving Â Âᵀ y = e_b gives y_b = 1 / sin² t.
        let y = keep.solve_wide(&[0.0, 1.0]);
        let want = 1.0 / (1e-9_f64.sin() * 1e-9_f64.sin());
        // Double-double carries ~32 digits against a pivot of 1e-18 (relative error ~1e-14).
        assert!(
            (y[1].0 - want).abs() <= 1e-9 * want,
            "{:e} vs {want:e}",
            y[1].0
        );
    }

    /// A row pair 1e-7 apart (pivot 1e-14: below f64's drop threshold, above the double-double
    /// one) with consistent data is met, at the unique solution.
    #[test]
    fn nearly_dependent_rows_are_met_in_double_double() {
        let t = 1e-7_f64;
        let rows = pair_rows(t);
        let c = [1.0, t.cos() + 0.25 * t.sin()];
        let s = solve_near(&rows, 2, &c, &[0.0, 0.0], 1e-13, MAX_VALUES).expect("tiny");
        assert!(s.residual <= 1e-13, "{:e}", s.residual);
        assert_eq!(s.rank, 2);
        // x = (1, 0.25); the pair conditions the solve to ~1e7, so rounding of 1e-16 in the
        // data grows to ~1e-9 in x.
        assert!(
            (s.x[0] - 1.0).abs() < 1e-8 && (s.x[1] - 0.25).abs() < 1e-8,
            "{:?}",
            s.x
        );
    }

    /// A scene's `precise_pivot` is the double-double factor's one threshold: the pair 1e-7
    /// apart (pivot 1e-14) that the default first threshold (1e-15) keeps is dropped at 1e-12
    /// and met afterwards (`cholesky::meet_dropped`), at the same solution.
    #[test]
    fn a_scene_pivot_replaces_the_default_thresholds() {
        let t = 1e-7_f64;
        let rows = pair_rows(t);
        let c = [1.0, t.cos() + 0.25 * t.sin()];
        let solve = |pivot| {
            solve_near_signed(&rows, 2, &c, &[0.0, 0.0], 1e-13, MAX_VALUES, None, pivot)
                .expect("tiny")
        };
        let (kept, dropped) = (solve(None), solve(Some(1e-12)));
        assert_eq!((kept.rank, dropped.rank), (2, 1));
        assert!(dropped.residual <= 1e-13, "{:e}", dropped.residual);
        // x = (1, 0.25), conditioned ~1e7 by the pair (see the test above): 1e-8.
        for x in [&kept.x, &dropped.x] {
            assert!(
                (x[0] - 1.0).abs() < 1e-8 && (x[1] - 0.25).abs() < 1e-8,
                "{x:?}"
            );
        }
    }

    /// Rows a double-double factor drops (off the others' span by ~1e-9, a pivot of ~1e-18,
    /// below `PRECISE_PIVOT`) but whose data are consistent are still met
    /// (`cholesky::meet_dropped`), at the same closest solution as the dense pivoted QR, which
    /// keeps them (its pivots are distances, 1e-9, not their squares).
    #[test]
    fn nearly_dependent_rows_below_the_drop_threshold_are_met() {
        for (m, n, seed) in [(30, 50, 5), (120, 200, 17), (300, 320, 4)] {
            let (mut a, _, _, target) = system(m, n, seed);
            // The last two rows are combinations of rows 0–3: move them 1e-9 off that span.
            let mut s = seed + 1;
            let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
            for i in [m - 2, m - 1] {
                for _ in 0..3 {
                    let j = ((lcg(&mut s) + 1.0) * 0.5 * n as f64) as usize % n;
                    a[i * n + j] += 1e-9 * lcg(&mut s);
                }
            }
            let x0: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
            let c = times(&a, m, n, &x0);
            // Dropping the two rows alone would miss them by ~1e-9 × the move along them (O(1)).
            // The same closest solution: the 1e-9 rows amplify the data's rounding (1e-16) by
            // 1/δ = 1e9 along them, so 1e-7 is their noise and 1e-5 is a wide margin.
            met_as_dense_qr_meets(&a, m, n, &c, &target, 1e-5);
        }
    }

    /// The supernodal solve of A x = c (`m`×`n`, row-major) closest to `target` meets every
    /// row to 1e-13 (what it is asked) and is within `margin` of the dense pivoted QR's
    /// solution, which keeps every row (its pivots are distances, not their squares).
    fn met_as_dense_qr_meets(
        a: &[f64],
        m: usize,
        n: usize,
        c: &[f64],
        target: &[f64],
        margin: f64,
    ) {
        let rows = sparse_rows(a, m, n);
        let s = solve_near(&rows, n, c, target, 1e-13, MAX_VALUES).expect("small");
        assert!(s.residual <= 1e-13, "({m}×{n}) residual {:e}", s.residual);
        let d = crate::scheme::quintic_c2::dense::solve_near(a, m, n, c, target, 1e-13);
        assert_eq!(d.rank, m, "QR keeps every row ({m}×{n})");
        for (x, y) in s.x.iter().zip(&d.x) {
            assert!((x - y).abs() < margin, "({m}×{n}) {x} vs {y}");
        }
    }

    /// Many more nearly dependent rows than one round of `cholesky::meet_dropped` takes
    /// (`MEET_ROWS` = 32), each 1e-9 to 1e-11 off the span of the others and seeing the moves
    /// made for the rest: the rounds keep their earlier directions and fit every row that sees
    /// them, so all are met, at the dense pivoted QR's solution.
    #[test]
    fn many_nearly_dependent_rows_are_met_over_rounds() {
        let (a, m, n, c, target) = near_rows(240, 90, 400, 23);
        // Without the new directions each near row is missed by its δ times the move along it.
        // The data's rounding (1e-16) amplified by 1/δ ≤ 1e11 along the nearest rows is 1e-5;
        // 1e-3 is a margin over that.
        met_as_dense_qr_meets(&a, m, n, &c, &target, 1e-3);
    }

    /// `base` random sparse rows of `n` unknowns and `near` rows each a combination of two of
    /// them plus 1e-9 to 1e-11 off their span, consistent data: (A, m, n, c, target).
    fn near_rows(
        base: usize,
        near: usize,
        n: usize,
        seed: u64,
    ) -> (Vec<f64>, usize, usize, Vec<f64>, Vec<f64>) {
        let mut s = seed;
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let pick = |s: &mut u64, k: usize| ((lcg(s) + 1.0) * 0.5 * k as f64) as usize % k;
        let m = base + near;
        let mut a = vec![0.0; m * n];
        for i in 0..base {
            for _ in 0..6 {
                let j = pick(&mut s, n);
                a[i * n + j] = lcg(&mut s);
            }
        }
        // Each near row: two base rows that share a neighbourhood, plus 1e-9..1e-11 off them.
        for k in 0..near {
            let i = base + k;
            let (r0, r1) = (pick(&mut s, base), pick(&mut s, base));
            let w = lcg(&mut s);
            for j in 0..n {
                a[i * n + j] = a[r0 * n + j] + w * a[r1 * n + j];
            }
            let delta = 10f64.powf(-9.0 - 2.0 * (k as f64 / near as f64));
            for _ in 0..3 {
                let j = pick(&mut s, n);
                a[i * n + j] += delta * lcg(&mut s);
            }
        }
        let x0: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        let target: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        let c = times(&a, m, n, &x0);
        (a, m, n, c, target)
    }

    /// More near rows (300) than `cholesky::meet_dropped` keeps directions for (`MEET_BASIS` =
    /// 160), so no round meets them all: the rows the directions were made for, weighted up
    /// (`MEET_OWN_WEIGHTS`, for fandisk), still take the misses down by more than 10×, and end
    /// above the plain least-squares fit (weight 1) by no more than the 1.7–2.5× measured here.
    #[test]
    fn own_rows_weighted_up_still_lower_misses_the_basis_cannot_meet() {
        for seed in [23, 24] {
            let (a, m, n, c, target) = near_rows(600, 300, 1000, seed);
            let rows = sparse_rows(&a, m, n);
            let unit = UnitRows::new(&rows, &c);
            let normal = Normal::of(&unit.rows, n, MAX_VALUES).expect("small");
            let factor = || {
                normal
                    .factor::<fx128>(cholesky::PRECISE_PIVOT)
                    .map(with_dropped)
            };
            let (f, _) = factor().expect("small");
            let (before, x, _) = cholesky::refine_near(
                &unit,
                &target,
                1e-13,
                &[cholesky::PRECISE_PIVOT],
                false,
                None,
                |_| factor(),
            )
            .expect("small");
            let met = |weights: &[f64]| {
                let mut y = x.clone();
                cholesky::meet_dropped(&unit, &f, &mut y, 1e-13, weights, None).0
            };
            let (plain, own) = (met(&[1.0]), met(&cholesky::MEET_OWN_WEIGHTS));
            eprintln!("seed {seed}: before {before:.2e}, plain {plain:.2e}, weighted {own:.2e}");
            // Both take the misses from ~1e-9 to ~2e-11–6e-11 (what 160 directions allow).
            assert!(own < 0.1 * before, "seed {seed}: {before:e} -> {own:e}");
            // 3×: above the 2.5× measured, far below a weighting that undid the rounds (~1e-9).
            assert!(
                own <= 3.0 * plain,
                "seed {seed}: weighted {own:e}, plain {plain:e}"
            );
        }
    }

    /// Alternating projections between a sign box and the rows, with the group's one factor
    /// (`cholesky::sign_rounds`): where a point meets both (x*, its signed weights 0.5–1.5 on
    /// their side, margin 0.1), the rounds end with every weight on its side and the rows met,
    /// while the plain solve closest to random targets leaves many off.
    #[test]
    fn sign_rounds_reach_the_signs_where_the_rows_allow_them() {
        let (m, n) = (300, 600);
        let SignedSystem {
            a,
            rows,
            c,
            target,
            signed,
        } = signed_system(m, n, 5, 3, 0.5);
        let tol = 1e-12;
        let sb = cholesky::SignBox {
            signed,
            cost: Vec::new(),
            margin: 0.1,
            rounds: 300,
            fit: 0,
            meet_tol: 0.0,
            meet_stall: None,
        };
        let plain = solve_near(&rows, n, &c, &target, tol, MAX_VALUES).expect("small");
        let signed_sol = solve_near_signed(&rows, n, &c, &target, tol, MAX_VALUES, Some(&sb), None)
            .expect("small");
        let (before, after) = (sb.off(&plain.x, 0.0), sb.off(&signed_sol.x, 0.0));
        assert!(before > 20, "the targets leave weights off: {before}");
        assert_eq!(after, 0, "{before} off before the rounds");
        // The last move of every round is onto the rows, refined to `tol`.
        assert!(signed_sol.residual <= tol, "{:e}", signed_sol.residual);
        let r = times(&a, m, n, &signed_sol.x);
        let miss = r
            .iter()
            .zip(&c)
            .fold(0.0_f64, |w, (p, q)| w.max((p - q).abs()));
        // Unit rows of ≤ 8 entries of |a| ≤ 1: the unscaled miss is at most √8 × the unit one.
        assert!(miss <= 3.0 * tol, "{miss:e}");
    }

    /// A test system with signed columns: its dense rows (row-major) and sparse rows, its
    /// right-hand side and targets, and its signed columns with their signs.
    struct SignedSystem {
        a: Vec<f64>,
        rows: Vec<Row>,
        c: Vec<f64>,
        target: Vec<f64>,
        signed: Vec<(usize, f64)>,
    }

    /// A random sparse system (8 entries a row) solved by x* with every `every`-th column
    /// signed (alternately + and −) and x*'s signed weights `lo`..`lo + 1` on their side
    /// (negative `lo`: some off), with random targets: rows, right-hand side, targets, signs.
    fn signed_system(m: usize, n: usize, seed: u64, every: usize, lo: f64) -> SignedSystem {
        let mut s = seed;
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let pick = |s: &mut u64, k: usize| ((lcg(s) + 1.0) * 0.5 * k as f64) as usize % k;
        let mut a = vec![0.0; m * n];
        for i in 0..m {
            for _ in 0..8 {
                let j = pick(&mut s, n);
                a[i * n + j] = lcg(&mut s);
            }
        }
        let signed: Vec<(usize, f64)> = (0..n)
            .step_by(every)
            .map(|j| (j, if j % 2 == 0 { 1.0 } else { -1.0 }))
            .collect();
        let mut star: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        for &(j, sign) in &signed {
            star[j] = sign * (lo + 0.5 + 0.5 * lcg(&mut s));
        }
        let c = times(&a, m, n, &star);
        let target: Vec<f64> = (0..n).map(|_| 2.0 * lcg(&mut s)).collect();
        SignedSystem {
            rows: sparse_rows(&a, m, n),
            a,
            c,
            target,
            signed,
        }
    }

    /// The split sign program (`signsplit::fit`, with the group's one factor) puts every
    /// signed weight on its side where a point of the rows does (x*, margin 0.1), with the
    /// rows still met; and where the rows allow fewer (every column signed, 500 rows on 600
    /// unknowns, x* with a quarter of its weights off), it leaves fewer weights off than as
    /// many rounds of alternating projections (`sign_rounds`): the sign program's point, the
    /// fewest misses rather than a least-squares compromise (measured: 198 off in the plain
    /// solve, 100 after alternating projections, 80 after the fit).
    #[test]
    fn the_split_sign_program_leaves_fewer_weights_off_than_alternating_projections() {
        let (tol, n) = (1e-12, 600);
        // Weights off their sign after the plain solve, alternating projections and the fit
        // (100 rounds each), and the fit's residual.
        let run = |m, seed, every, lo| {
            let sys = signed_system(m, n, seed, every, lo);
            let sb = |rounds, fit| cholesky::SignBox {
                signed: sys.signed.clone(),
                cost: Vec::new(),
                margin: 0.1,
                rounds,
                fit,
                meet_tol: 0.0,
                meet_stall: None,
            };
            let solve = |b: Option<cholesky::SignBox>| {
                let (r, c, t) = (&sys.rows, &sys.c, &sys.target);
                solve_near_signed(r, n, c, t, tol, MAX_VALUES, b.as_ref(), None).expect("small")
            };
            let off = |x: &[f64]| sb(0, 0).off(x, 0.0);
            let (plain, alt, fit) = (
                solve(None),
                solve(Some(sb(100, 0))),
                solve(Some(sb(0, 100))),
            );
            (off(&plain.x), off(&alt.x), off(&fit.x), fit.residual)
        };
        let (before, _, after, residual) = run(300, 5, 3, 0.5);
        assert!(before > 20, "the targets leave weights off: {before}");
        assert_eq!(after, 0, "{before} off before the fit");
        // The fit's move is projected onto the rows' null space; what is left is its rounding.
        assert!(residual <= tol, "{residual:e}");

        let (plain, alt, fit, residual) = run(500, 6, 1, -0.25);
        eprintln!("off: plain {plain}, alternating {alt}, fit {fit}");
        assert!(fit < alt, "{fit} vs {alt}");
        assert!(residual <= tol, "{residual:e}");
    }

    /// A cost on some signed weights' misses (`SignBox::cost`, `joint_sign_boundary`: the
    /// hull's boundary faces) makes the split sign program leave fewer of those off, where the
    /// rows do not allow every sign: the same system as above (every column signed, 500 rows
    /// on 600 unknowns), every other signed weight made costly (10×).
    #[test]
    fn costly_misses_are_left_fewer() {
        let (tol, n) = (1e-12, 600);
        let sys = signed_system(500, n, 6, 1, -0.25);
        let costly: Vec<bool> = (0..sys.signed.len()).map(|i| i % 2 == 0).collect();
        let fit = |cost: Vec<f64>| {
            let sb = cholesky::SignBox {
                signed: sys.signed.clone(),
                cost,
                margin: 0.1,
                rounds: 0,
                fit: 100,
                meet_tol: 0.0,
                meet_stall: None,
            };
            let (r, c, t) = (&sys.rows, &sys.c, &sys.target);
            let x = solve_near_signed(r, n, c, t, tol, MAX_VALUES, Some(&sb), None)
                .expect("small")
                .x;
            let off = |want: bool| {
                sys.signed
                    .iter()
                    .zip(&costly)
                    .filter(|&(&(j, s), &k)| k == want && s * x[j] < 0.0)
                    .count()
            };
            (off(true), off(false))
        };
        let plain = fit(Vec::new());
        let weighed = fit(costly.iter().map(|&k| if k { 10.0 } else { 1.0 }).collect());
        eprintln!("off (costly, the rest): plain {plain:?}, weighed {weighed:?}");
        assert!(weighed.0 < plain.0, "{plain:?} -> {weighed:?}");
    }

    /// `sys`'s rows and right-hand side with 20 near rows appended: every 25th row with one
    /// entry of `delta` added (a random column, from `seed`), its datum consistent with `x0`;
    /// and the seed after those draws.
    fn with_near_rows(
        sys: &SignedSystem,
        x0: &[f64],
        delta: f64,
        seed: u64,
    ) -> (Vec<Row>, Vec<f64>, u64) {
        let n = x0.len();
        let (mut rows, mut c) = (sys.rows.clone(), sys.c.clone());
        let mut seed = seed;
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        for k in 0..20 {
            let i = 25 * k;
            let j = ((lcg(&mut seed) + 1.0) * 0.5 * n as f64) as usize % n;
            let mut row = rows[i].clone();
            row.push((j, delta));
            rows.push(row);
            c.push(c[i] + delta * x0[j]);
        }
        (rows, c, seed)
    }

    /// The signed system of the tests above with 20 rows `delta` off others
    /// ([`with_near_rows`] from its solution): the rows, their right-hand sides, the rows as
    /// unit rows and their normal matrix.
    fn near_fixture(
        tol: f64,
        n: usize,
        delta: f64,
    ) -> (SignedSystem, Vec<Row>, Vec<f64>, UnitRows, Normal) {
        let sys = signed_system(500, n, 6, 1, -0.25);
        let x0 = solve_near(&sys.rows, n, &sys.c, &sys.target, tol, MAX_VALUES)
            .expect("small")
            .x;
        let (rows, c, _) = with_near_rows(&sys, &x0, delta, 43);
        let unit = UnitRows::new(&rows, &c);
        let normal = Normal::of(&unit.rows, n, MAX_VALUES).expect("small");
        (sys, rows, c, unit, normal)
    }

    /// The sign box of 100 rounds of the split sign program (margin 0.1, no boundary cost) on
    /// `sys`, the meet after the fit stopped at `meet_tol`.
    fn fit_box(sys: &SignedSystem, meet_tol: f64) -> cholesky::SignBox {
        cholesky::SignBox {
            signed: sys.signed.clone(),
            cost: Vec::new(),
            margin: 0.1,
            rounds: 0,
            fit: 100,
            meet_tol,
            meet_stall: None,
        }
    }

    /// 100 rounds of the split sign program (margin 0.1) on `near_fixture`'s system, factored
    /// by the double-double factor at its default threshold, the meet after the fit stopped at
    /// `meet_tol`: the sign box and `refine_near`'s (miss, x, rows dropped).
    fn fit_near(
        sys: &SignedSystem,
        unit: &UnitRows,
        normal: &Normal,
        tol: f64,
        meet_tol: f64,
    ) -> (cholesky::SignBox, (f64, Vec<f64>, usize)) {
        let sb = fit_box(sys, meet_tol);
        let drops = [cholesky::PRECISE_PIVOT];
        let got = cholesky::refine_near(unit, &sys.target, tol, &drops, true, Some(&sb), |d| {
            normal.factor::<fx128>(d).map(with_dropped)
        })
        .expect("small");
        (sb, got)
    }

    /// `SignBox::meet_tol` (`joint_meet_tolerance`): the meet after the split sign program
    /// stops once the rows are met to it, and that fit is kept. The signed system of the tests
    /// above with 20 rows 1e-9 off others (dropped by the double-double factor, data
    /// consistent): the fit's move (~1 a weight) makes them missed, so the meet after it has
    /// rows to meet; with the solve's tolerance it meets them all, with 1e-10 it stops between.
    #[test]
    fn the_meet_after_the_fit_stops_at_its_tolerance() {
        let (tol, n, delta) = (1e-13, 600, 1e-9);
        let (sys, _, _, unit, normal) = near_fixture(tol, n, delta);
        let solve = |meet_tol| {
            let (sb, (got, x, dropped)) = fit_near(&sys, &unit, &normal, tol, meet_tol);
            assert_eq!(dropped, 20, "the near rows are the ones dropped");
            (got, sb.off(&x, 1e-12))
        };
        let (full, loose) = (solve(0.0), solve(1e-10));
        eprintln!(
            "full meet: residual {:e}, {} off; to 1e-10: {:e}, {} off",
            full.0, full.1, loose.0, loose.1
        );
        assert!(full.0 <= tol, "{:e}", full.0);
        assert!(loose.0 > tol && loose.0 <= 1e-10, "{:e}", loose.0);
    }

    /// `joint_local_meet`: the fit kept without the factor's meet (`SignBox::meet_tol`
    /// infinite, as the scene key sets it) leaves the near rows missed, and
    /// [`super::super::localmeet::meet`] meets them to the solve's tolerance afterwards,
    /// moving only what they ask (the system of the test above, one region of every unknown).
    #[test]
    fn the_local_meet_meets_what_a_fit_without_its_meet_leaves() {
        let (tol, n, delta) = (1e-13, 600, 1e-9);
        let (sys, rows, c, unit, normal) = near_fixture(tol, n, delta);
        let (_, (got, mut x, _)) = fit_near(&sys, &unit, &normal, tol, f64::INFINITY);
        assert!(
            got > 1e3 * tol,
            "the fit's move reached the near rows: {got:e}"
        );
        let fitted = x.clone();
        // Positions play no part when one region holds every unknown.
        let pos = vec![glam::DVec3::ZERO; n];
        let out = super::super::localmeet::meet(&rows, &c, &mut x, &pos, tol, n, f64::INFINITY);
        let miss = rows
            .iter()
            .zip(&c)
            .map(|(row, c)| (row.iter().map(|&(j, k)| k * x[j]).sum::<f64>() - c).abs())
            .fold(0.0_f64, f64::max);
        eprintln!("fit kept at {got:e}; local meet: {out:?}, rows missed by {miss:e}");
        assert_eq!(out.worst_after, miss, "the miss reported is x's");
        assert!(miss <= tol, "{miss:e}");
        assert!(out.missed_before > 0 && out.missed_after == 0, "{out:?}");
        // The move is the least that meets the rows: the miss over the near rows' distance
        // (1e-9) from the others, at most ~1e2 times the fit's miss of each.
        let moved = x
            .iter()
            .zip(&fitted)
            .fold(0.0_f64, |a, (p, q)| a.max((p - q).abs()));
        assert!(moved > 0.0 && moved <= got / delta * 1e2, "{moved:e}");
    }

    /// A long move whose projection onto the rows' null space was rounded (here: 1e-6 of a
    /// row-space vector added to it) is settled back onto the rows by `signsplit::settle`
    /// (the sign fit's last step), its null-space part kept; a settled move is left as it is.
    #[test]
    fn a_rounded_move_settles_back_onto_the_rows() {
        let (tol, n, m) = (1e-12, 600, 300);
        let sys = signed_system(m, n, 9, 3, 0.5);
        let unit = UnitRows::new(&sys.rows, &sys.c);
        let normal = Normal::of(&unit.rows, n, MAX_VALUES).expect("small");
        let (f, _) = normal
            .factor::<fx128>(cholesky::PRECISE_PIVOT)
            .map(with_dropped)
            .expect("small");
        let x0 = solve_near(&sys.rows, n, &sys.c, &sys.target, tol, MAX_VALUES)
            .expect("small")
            .x;
        let mut r = vec![0.0; m];
        assert!(unit.residual(&x0, &mut r) <= tol);
        // A null-space move of length ~1 per weight, and 1e-6 of Âᵀ w off the null space.
        let mut seed = 31_u64;
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let mut d: Vec<Vec<f64>> = vec![(0..n).map(|_| lcg(&mut seed)).collect()];
        cholesky::NormalSolve::project(&f, &unit.rows, &mut d);
        let d = d.remove(0);
        let mut y: Vec<f64> = x0.iter().zip(&d).map(|(a, b)| a + b).collect();
        for row in &unit.rows {
            let w = 1e-6 * lcg(&mut seed);
            row.iter().for_each(|&(j, a)| y[j as usize] += w * a);
        }
        let before = unit.residual(&y, &mut r);
        assert!(before > 1e-8, "the error is seen: {before:e}");
        let after = super::super::signsplit::settle(&unit, &f, &[], &x0, &mut y, &mut r);
        assert!(after <= tol, "{before:e} -> {after:e}");
        assert_eq!(
            after,
            unit.residual(&y, &mut r),
            "the residual returned is y's"
        );
        // The null-space part is what it was: what settling removed lies in the row space.
        let kept = y
            .iter()
            .zip(&x0)
            .zip(&d)
            .fold(0.0_f64, |a, ((p, q), e)| a.max((p - q - e).abs()));
        eprintln!("settled {before:e} -> {after:e}, null-space part moved by {kept:e}");
        // Π removes the row-space error exactly and leaves d; what is left is the projections'
        // rounding, far below the 1e-6 error removed.
        assert!(kept < 1e-9, "{kept:e}");
        // Settled again: no projection lowers it, so y is left alone.
        let y1 = y.clone();
        let again = super::super::signsplit::settle(&unit, &f, &[], &x0, &mut y, &mut r);
        assert!(again <= after);
        assert!(again < after || y == y1);
    }

    /// The split sign program's moves are orthogonal to the basis it is given, so the rows a
    /// meet made that basis for stay met through the fit (what the fit after the first meet
    /// and `APATCH_FIT_CYCLES`' fits rely on): 20 rows at distance 1e-9 from the kept span (a
    /// kept row plus 1e-9 of one column), missed after a null-space move and met again by
    /// `meet_dropped`, which returns their projections; a fit from there misses them again
    /// without that basis and keeps them met with it (measured: 197 weights off → 74 with
    /// the rows missed by 9.0e-10, → 100 with them met to 7.7e-15).
    #[test]
    fn a_fit_orthogonal_to_the_meets_directions_keeps_its_rows_met() {
        use cholesky::NormalSolve;
        let (tol, n, delta) = (1e-12, 600, 1e-9);
        let sys = signed_system(500, n, 6, 1, -0.25);
        let x0 = solve_near_signed(
            &sys.rows,
            n,
            &sys.c,
            &sys.target,
            tol,
            MAX_VALUES,
            None,
            None,
        )
        .expect("small")
        .x;
        let (rows, c, mut seed) = with_near_rows(&sys, &x0, delta, 41);
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let unit = UnitRows::new(&rows, &c);
        let normal = Normal::of(&unit.rows, n, MAX_VALUES).expect("small");
        let (f, dropped) = normal
            .factor::<fx128>(cholesky::PRECISE_PIVOT)
            .map(with_dropped)
            .expect("small");
        assert_eq!(dropped, 20, "the near rows are the ones dropped");
        let mut r = vec![0.0; rows.len()];
        // A null-space move of ~1 a weight: the kept rows stay met, the near rows see it.
        let mut d: Vec<Vec<f64>> = vec![(0..n).map(|_| lcg(&mut seed)).collect()];
        f.project(&unit.rows, &mut d);
        let mut x: Vec<f64> = x0.iter().zip(&d[0]).map(|(a, b)| a + b).collect();
        let moved = unit.residual(&x, &mut r);
        assert!(moved > 100.0 * tol, "the near rows see the move: {moved:e}");
        let (met, q) =
            cholesky::meet_dropped(&unit, &f, &mut x, tol, &cholesky::MEET_OWN_WEIGHTS, None);
        assert!(met <= tol, "{moved:e} -> {met:e}");
        assert!(!q.is_empty());
        let sb = fit_box(&sys, 0.0);
        let fit = |q: &[Vec<f64>]| {
            let mut y = x.clone();
            let got =
                crate::scheme::quintic_c2::signsplit::fit(&unit, &f, &mut y, q, &sb, f64::INFINITY)
                    .expect("the fit gains signs");
            (got, sb.off(&y, 1e-12))
        };
        let before = sb.off(&x, 1e-12);
        let (open, off_open) = fit(&[]);
        let (kept, off_kept) = fit(&q);
        eprintln!(
            "off {before} -> {off_open} (residual {open:.2e}) without the meet's basis, {off_kept} (residual {kept:.2e}) with it"
        );
        assert!(
            open > 100.0 * tol,
            "without the basis the fit moves the near rows: {open:e}"
        );
        // With it they see only the rounding of the fit's projections (the settled move).
        assert!(kept <= tol, "{kept:e}");
        assert!(off_kept < before, "{before} -> {off_kept}");
    }

    /// A dropped row whose data contradict the kept rows (1e-3 off, at distance 1e-11 from
    /// their span: met only by a move of 1e8) is left missed rather than met by that move.
    #[test]
    fn contradicting_dropped_rows_are_not_met_by_huge_moves() {
        let t = 1e-11_f64;
        let rows = pair_rows(t);
        let c = [1.0, t.cos() + 1e-3];
        let s = solve_near(&rows, 2, &c, &[0.0, 0.0], 1e-13, MAX_VALUES).expect("tiny");
        assert!(s.x.iter().all(|v| v.abs() < 10.0), "{:?}", s.x);
        // The contradiction stays visible in the residual (~1e-3), for the caller to judge.
        assert!(s.residual > 1e-4, "{:e}", s.residual);
    }

    /// The factor in a pool of one thread and in one of two gives the same values to the bit
    /// (`PAR`): a dense-ish random group, whose supernodes are large.
    #[test]
    fn the_factor_is_the_same_on_one_and_two_threads() {
        let (m, n) = (1500, 1600);
        let mut seed = 77_u64;
        let lcg = crate::scheme::quintic_c2::cholesky::tests::lcg;
        let rows: Vec<Vec<(u32, f64)>> = (0..m)
            .map(|_| {
                let mut r: Vec<(u32, f64)> = (0..40)
                    .map(|_| {
                        let j = ((lcg(&mut seed) + 1.0) * 0.5 * n as f64) as u32 % n as u32;
                        (j, lcg(&mut seed))
                    })
                    .collect();
                r.sort_by_key(|t| t.0);
                r.dedup_by_key(|t| t.0);
                let norm = r.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt();
                r.iter_mut().for_each(|t| t.1 /= norm);
                r
            })
            .collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                let normal = Normal::of(&rows, n, MAX_VALUES).expect("small");
                let f = normal.factor::<f64>(1e-13).expect("small");
                let d = normal.factor::<fx128>(1e-15).expect("small");
                let r: Vec<f64> = (0..m).map(|i| (i as f64).sin()).collect();
                let y: Vec<(f64, f64)> = d.solve_wide(&r).iter().map(|v| (v.0, v.1)).collect();
                (f.values.clone(), y)
            })
        };
        let (a, b) = (run(1), run(2));
        assert!(a.0.len() > 100_000, "{} values: too small", a.0.len());
        assert!(a
            .0
            .iter()
            .zip(&b.0)
            .all(|(x, y)| x.to_bits() == y.to_bits()));
        let same = |x: &(f64, f64), y: &(f64, f64)| {
            x.0.to_bits() == y.0.to_bits() && x.1.to_bits() == y.1.to_bits()
        };
        assert!(a.1.iter().zip(&b.1).all(|(x, y)| same(x, y)));
    }
}

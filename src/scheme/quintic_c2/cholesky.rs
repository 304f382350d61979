//! Sparse direct minimum-change solves for the large coupled weight groups: the solution of
//! A x = c closest to a target, x = target + Âᵀ y with (Â Âᵀ) y = ĉ − Â·target (Â, ĉ: the
//! equations scaled to unit norm), by a sparse Cholesky factorisation of Â Âᵀ in a
//! minimum-degree order, followed by iterative refinement.
//!
//! Why: Craig's method ([`super::sparse`]) needs thousands of iterations on the groups the
//! relaxed and the consistent stars couple (the knot: one group of all edge middles with one
//! consistency condition per point), while the factorisation of Â Âᵀ costs little once the
//! local equations are eliminated first, which a minimum-degree order does by itself.
//!
//! Dependent equations (a pivot below [`DEPENDENT_PIVOT`] of its row's unit norm, i.e. the row
//! lies within √1e-13 of the span of the rows eliminated before it) are dropped, as the dense
//! QR's rank test drops them; whether they are met shows in [`Solution::residual`]. Where the
//! f64 factor cannot tell nearly dependent rows from dependent ones (their pivots, squared
//! distances, sink into f64's rounding), the same factorisation runs in double-double
//! ([`Projector::precise`], [`PRECISE_PIVOT`]). Every solve runs in a fixed order (ties broken
//! by index); a factor column with many updates gathers them on two threads, each over half of
//! the accumulator with every update in the same order (`PARALLEL_UPDATES`), and
//! [`Projector::project_units`] runs its projections in parallel, each with the arithmetic it
//! has alone, so the bits do not depend on the thread count.

use super::dd::{Dd, Real};
use super::dense::Solution;
use super::sparse::Row;
use rayon::prelude::*;

/// Squared distance of a unit row from the span of the rows before it below which it is taken
/// as dependent: exact dependencies leave pivots at the rounding of the elimination (≲ 1e-15
/// seen), independent C1/C2 rows stay far above.
pub const DEPENDENT_PIVOT: f64 = 1e-13;

/// Drop threshold of the second factorisation, when the first does not reduce the residual
/// (nearly dependent equations whose pivots are mostly rounding): rows within 3e-5 of the span
/// of the rows before them are dropped; whether they are met shows in the residual.
pub const RETRY_PIVOT: f64 = 1e-9;

/// Rounds of iterative refinement after the first solve.
const REFINE: usize = 4;

/// Most entries a factor of Â Âᵀ may hold ([`Ordering::entries`]). Each entry costs its
/// pattern, two f64 factors and, where f64 falls short, a double-double one: about 100 bytes
/// with the work arrays, so 6e7 is ~6 GB, a quarter of the 24 GB machines we run on. The
/// largest group of a model that passes is fandisk's edge middles (nnz(L) 3.3e6); the group
/// that exceeded memory was fandisk's quintic with every point relaxed (2.27e8). The staged
/// solve hands larger groups to the supernodal factor ([`super::supernodal`]).
pub const MAX_FACTOR_ENTRIES: usize = 60_000_000;

/// Most rows a group may have for this factor to be tried at all: the minimum degree
/// ordering grows faster than its rows (fandisk: 197322 rows 2 s, 1297197 rows 268 s). The
/// staged solve hands larger groups to the supernodal factor ([`super::supernodal`]).
pub const MAX_FACTOR_ROWS: usize = 1_000_000;

/// The Cholesky factor of a sparse symmetric matrix in elimination order, in f64 or, where
/// the normal equations need more digits, in double-double ([`Precise`]).
struct Factor<T: Real = f64> {
    /// Elimination position → node.
    order: Vec<u32>,
    /// L's columns below the diagonal in elimination order, packed: column p's entries are
    /// `start[p]..start[p + 1]` of `rows` (elimination positions, ascending) and `vals`. One
    /// array read front to back (or back to front) by a solve: the repair's time is mostly
    /// these solves, and a vector per column scattered them over the heap.
    start: Vec<usize>,
    rows: Vec<u32>,
    vals: Vec<T>,
    /// Node → diagonal of L (0 for a dropped, dependent node).
    diag: Vec<T>,
}

impl<T: PackedSolve> Factor<T> {
    /// Solves L Lᵀ y = r in place (dependent nodes get y = 0), in the factor's precision.
    fn solve(&self, r: &mut [f64]) {
        let w = self.solve_wide(r);
        for (x, y) in r.iter_mut().zip(w) {
            *x = y.f64();
        }
    }

    /// L Lᵀ y = r solved and returned in the factor's precision (dependent nodes get y = 0).
    fn solve_wide(&self, r: &[f64]) -> Vec<T> {
        let mut y = self.solve_batch::<1>(&[r]);
        y.pop().unwrap_or_default()
    }
}

/// Right-hand sides of [`Factor::solve_wide_many`]'s one pass over L. On three of fandisk's
/// repairs (user time, the setup included): 8 → 16 took 143 s to 118 s, with the same
/// output; 32 gained nothing over 16 (8: 163 s, 16: 139 s, 32: 139 s before L was packed).
const BATCH: usize = 16;

impl<T: PackedSolve> Factor<T> {
    /// [`Factor::solve_wide`] for up to [`BATCH`] right-hand sides in one pass over L (the
    /// solve reads L once from memory for all of them); each gets the same arithmetic, in the
    /// same order, as alone.
    fn solve_wide_many(&self, rs: &[&[f64]]) -> Vec<Vec<T>> {
        self.solve_batch::<BATCH>(rs)
    }

    /// L Lᵀ y = r for up to `B` right-hand sides `rs`, kept side by side per node.
    fn solve_batch<const B: usize>(&self, rs: &[&[f64]]) -> Vec<Vec<T>> {
        #[cfg(target_arch = "x86_64")]
        if T::FUSED && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the processor has FMA, checked just above.
            return unsafe { self.solve_batch_fma::<B>(rs) };
        }
        T::solve_packed::<B>(self, rs)
    }

    /// [`Factor::solve_batch`] compiled with FMA (see [`factor_fma`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "fma")]
    unsafe fn solve_batch_fma<const B: usize>(&self, rs: &[&[f64]]) -> Vec<Vec<T>> {
        T::solve_packed::<B>(self, rs)
    }
}

/// How a factor in a scalar type runs its batched solves ([`Factor::solve_batch`]).
trait PackedSolve: Real {
    /// L Lᵀ y = r for up to `B` right-hand sides `rs`; each gets the arithmetic it gets alone.
    fn solve_packed<const B: usize>(f: &Factor<Self>, rs: &[&[f64]]) -> Vec<Vec<Self>>;
}

impl PackedSolve for f64 {
    #[inline(always)]
    fn solve_packed<const B: usize>(f: &Factor<f64>, rs: &[&[f64]]) -> Vec<Vec<f64>> {
        f.solve_batch_in::<B>(rs)
    }
}

impl PackedSolve for Dd {
    /// In lanes of hi and lo parts ([`Lanes`]), as few as the right-hand sides need: the
    /// double-double products then run side by side in vector registers. Each lane's
    /// operations are [`Dd`]'s, in its order, so the results are its to the bit.
    #[inline(always)]
    fn solve_packed<const B: usize>(f: &Factor<Dd>, rs: &[&[f64]]) -> Vec<Vec<Dd>> {
        assert!(rs.len() <= B, "{} right-hand sides, at most {B}", rs.len());
        match rs.len() {
            0..=1 => f.solve_batch_in::<1>(rs),
            2..=4 => solve_lanes::<4>(f, rs),
            5..=8 => solve_lanes::<8>(f, rs),
            9..=16 => solve_lanes::<16>(f, rs),
            _ => f.solve_batch_in::<B>(rs),
        }
    }
}

/// Up to `L` double-double values, their hi parts side by side and their lo parts side by
/// side (the layout a vector unit adds and multiplies in).
#[derive(Clone, Copy)]
struct Lanes<const L: usize> {
    hi: [f64; L],
    lo: [f64; L],
}

impl<const L: usize> Lanes<L> {
    const ZERO: Lanes<L> = Lanes {
        hi: [0.0; L],
        lo: [0.0; L],
    };

    fn get(&self, k: usize) -> Dd {
        Dd {
            hi: self.hi[k],
            lo: self.lo[k],
        }
    }

    fn set(&mut self, k: usize, x: Dd) {
        self.hi[k] = x.hi;
        self.lo[k] = x.lo;
    }

    /// self[k] −= l · z[k] for every lane: [`Dd`]'s product and difference, step by step.
    #[inline(always)]
    fn sub_product(&mut self, l: Dd, z: &Lanes<L>) {
        for k in 0..L {
            // l · z[k]
            let p = l.hi * z.hi[k];
            let e = l.hi.mul_add(z.hi[k], -p);
            let e = e + (l.hi * z.lo[k] + l.lo * z.hi[k]);
            let ph = p + e;
            let pl = e - (ph - p);
            // self[k] + (−(l · z[k]))
            let (a, b) = (self.hi[k], -ph);
            let s = a + b;
            let bb = s - a;
            let e = (a - (s - bb)) + (b - bb);
            let (c, d) = (self.lo[k], -pl);
            let t = c + d;
            let dd = t - c;
            let f = (c - (t - dd)) + (d - dd);
            let e = e + t;
            let s2 = s + e;
            let e = e - (s2 - s);
            let e = e + f;
            let hi = s2 + e;
            self.lo[k] = e - (hi - s2);
            self.hi[k] = hi;
        }
    }
}

/// [`Factor::solve_batch_in`] for a double-double factor in [`Lanes`] of `L`.
#[inline(always)]
fn solve_lanes<const L: usize>(f: &Factor<Dd>, rs: &[&[f64]]) -> Vec<Vec<Dd>> {
    let b = rs.len();
    assert!(b <= L, "{b} right-hand sides, at most {L}");
    let m = f.diag.len();
    let mut w = vec![Lanes::<L>::ZERO; m];
    for (k, r) in rs.iter().enumerate() {
        for (wi, &v) in w.iter_mut().zip(&f.order) {
            wi.hi[k] = r[v as usize];
        }
    }
    for (p, &v) in f.order.iter().enumerate() {
        let d = f.diag[v as usize];
        if d.f64() == 0.0 {
            w[p] = Lanes::ZERO;
            continue;
        }
        let mut z = w[p];
        for k in 0..b {
            z.set(k, z.get(k) / d);
        }
        w[p] = z;
        let (lo, hi) = (f.start[p], f.start[p + 1]);
        for (&u, &l) in f.rows[lo..hi].iter().zip(&f.vals[lo..hi]) {
            w[u as usize].sub_product(l, &z);
        }
    }
    for (p, &v) in f.order.iter().enumerate().rev() {
        let d = f.diag[v as usize];
        if d.f64() == 0.0 {
            continue;
        }
        let mut s = w[p];
        let (lo, hi) = (f.start[p], f.start[p + 1]);
        for (&u, &l) in f.rows[lo..hi].iter().zip(&f.vals[lo..hi]) {
            s.sub_product(l, &w[u as usize]);
        }
        for k in 0..b {
            w[p].set(k, s.get(k) / d);
        }
    }
    (0..b)
        .map(|k| {
            let mut y = vec![Dd::default(); m];
            for (wi, &v) in w.iter().zip(&f.order) {
                y[v as usize] = wi.get(k);
            }
            y
        })
        .collect()
}

impl<T: Real> Factor<T> {
    #[inline(always)]
    fn solve_batch_in<const B: usize>(&self, rs: &[&[f64]]) -> Vec<Vec<T>> {
        let b = rs.len();
        assert!(b <= B, "{b} right-hand sides, at most {B}");
        let m = self.diag.len();
        // By elimination position.
        let mut w = vec![[T::default(); B]; m];
        for (k, r) in rs.iter().enumerate() {
            for (wi, &v) in w.iter_mut().zip(&self.order) {
                wi[k] = T::of(r[v as usize]);
            }
        }
        for (p, &v) in self.order.iter().enumerate() {
            let d = self.diag[v as usize];
            if d.f64() == 0.0 {
                w[p] = [T::default(); B];
                continue;
            }
            let mut z = w[p];
            for zk in &mut z[..b] {
                *zk = *zk / d;
            }
            w[p] = z;
            let (lo, hi) = (self.start[p], self.start[p + 1]);
            for (&u, &l) in self.rows[lo..hi].iter().zip(&self.vals[lo..hi]) {
                let wu = &mut w[u as usize];
                for k in 0..b {
                    wu[k] -= l * z[k];
                }
            }
        }
        for (p, &v) in self.order.iter().enumerate().rev() {
            let d = self.diag[v as usize];
            if d.f64() == 0.0 {
                continue;
            }
            let mut s = w[p];
            let (lo, hi) = (self.start[p], self.start[p + 1]);
            for (&u, &l) in self.rows[lo..hi].iter().zip(&self.vals[lo..hi]) {
                let wu = &w[u as usize];
                for k in 0..b {
                    s[k] -= l * wu[k];
                }
            }
            for k in 0..b {
                w[p][k] = s[k] / d;
            }
        }
        (0..b)
            .map(|k| {
                let mut y = vec![T::default(); m];
                for (wi, &v) in w.iter().zip(&self.order) {
                    y[v as usize] = wi[k];
                }
                y
            })
            .collect()
    }
}

/// The factor in double-double, for groups whose f64 factor does not meet their rows.
type Precise = Factor<Dd>;

/// Each node's position in the elimination `order`; sorts every column pattern by it.
fn sort_by_position(order: &[u32], pattern: &mut [Vec<u32>]) -> Vec<usize> {
    let mut pos = vec![0usize; order.len()];
    for (k, &v) in order.iter().enumerate() {
        pos[v as usize] = k;
    }
    for p in pattern {
        p.sort_unstable_by_key(|&u| pos[u as usize]);
    }
    pos
}

/// Elimination order, L's column patterns (sorted by elimination position) and each node's
/// position: the symbolic factorisation of Â Âᵀ, which depends only on which columns each row
/// touches. Computed once per group ([`Ordering::of`]) and shared by every solve on rows with
/// the same or fewer entries (both drop thresholds of one solve; the repeated solves of one
/// hole repair, whose pins only move columns to the right-hand side).
pub struct Ordering {
    order: Vec<u32>,
    pattern: Vec<Vec<u32>>,
    pos: Vec<usize>,
}

impl Ordering {
    /// The factor's entries (nnz(L)), known before any value is computed.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.pattern.iter().map(Vec::len).sum()
    }

    /// [`Ordering::of`] when the group is within `(max rows, max factor entries)`
    /// ([`MAX_FACTOR_ROWS`], [`MAX_FACTOR_ENTRIES`]): the rows are counted before the ordering
    /// (which itself grows faster than them), the factor's entries after it. `None` beyond
    /// either: a factor that does not fit in memory would end the process instead of the scene.
    #[must_use]
    pub fn within(
        rows: &[Row],
        n: usize,
        (max_rows, max_entries): (usize, usize),
    ) -> Option<Ordering> {
        if rows.len() > max_rows {
            return None;
        }
        Some(Ordering::of(rows, n)).filter(|o| o.entries() <= max_entries)
    }

    /// The ordering for the rows' structure (`n` unknowns): rows sharing a column are
    /// neighbours, whatever their values (an entry that cancels in one solve may not in the
    /// next).
    #[must_use]
    pub fn of(rows: &[Row], n: usize) -> Ordering {
        let m = rows.len();
        let mut by_col: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (i, r) in rows.iter().enumerate() {
            for &(j, _) in r {
                by_col[j].push(i as u32);
            }
        }
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); m];
        for list in &mut by_col {
            list.dedup();
            for (a, &i) in list.iter().enumerate() {
                for &k in &list[a + 1..] {
                    adj[i as usize].push(k);
                    adj[k as usize].push(i);
                }
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let t = std::time::Instant::now();
        let (order, mut pattern) = super::ordering::quotient_min_degree(adj);
        let pos = sort_by_position(&order, &mut pattern);
        if std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
            // Opt-in timing of the ordering on stderr (exploration; results unaffected).
            let nnz: usize = pattern.iter().map(Vec::len).sum();
            eprintln!(
                "quintic-c2 cholesky: {m} nodes, ordering {:.2} s, nnz(L) {nnz}",
                t.elapsed().as_secs_f64()
            );
        }
        Ordering {
            order,
            pattern,
            pos,
        }
    }
}

/// Factors the symmetric matrix given by its diagonal `d` and strictly off-diagonal entries
/// `off` (each pair once, (i, k, value)) in the order `sym`, dropping pivots below `drop` × the
/// original diagonal. Returns the factor and the number of dropped nodes.
///
/// Left-looking: each column gathers the updates of the columns before it that reach it into
/// one dense accumulator, so the work is the multiply-adds plus one pass over each column's
/// pattern (the right-looking update it replaced scattered the target's whole pattern for every
/// source column: letter P's repair with freed Hessians, 5 min → 101 s).
fn factor<T: Real>(
    d: &[T],
    off: &[(u32, u32, T)],
    drop: f64,
    sym: &Ordering,
) -> (Factor<T>, usize) {
    #[cfg(target_arch = "x86_64")]
    if T::FUSED && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor has FMA, checked just above.
        return unsafe { factor_fma(d, off, drop, sym) };
    }
    factor_in(d, off, drop, sym, PARALLEL_UPDATES)
}

/// [`factor`] compiled with FMA, so that double-double products are one instruction each
/// instead of a call into libm (x86-64's default target has no FMA; the call was 8 % of the
/// nut quintic's `apatch check`, and this 8 % of its time). Fused or not, `mul_add` is
/// correctly rounded and nothing else contracts, so the factor is the same to the bit
/// (the test `fused_factor_is_the_plain_one`).
///
/// Why a twin per function (here, `solve_batch_fma`, `gather_updates_fma`) rather than one
/// generic `with_fma(closure)`: tried in session 37, the compiler kept each closure a function
/// of its own, outside the FMA copy (`objdump -d`: no `vfmadd` in `gather_updates::{closure}`
/// or `solve_batch::{closure}`, against 1 and 28 in the twins), so the products were libm calls
/// again.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn factor_fma<T: Real>(
    d: &[T],
    off: &[(u32, u32, T)],
    drop: f64,
    sym: &Ordering,
) -> (Factor<T>, usize) {
    factor_in(d, off, drop, sym, PARALLEL_UPDATES)
}

/// [`factor`]'s work; columns with at least `parallel` multiply-adds of updates gather them on
/// two threads.
#[inline(always)]
fn factor_in<T: Real>(
    d: &[T],
    off: &[(u32, u32, T)],
    drop: f64,
    sym: &Ordering,
    parallel: usize,
) -> (Factor<T>, usize) {
    let m = d.len();
    let order = sym.order.clone();
    let pattern = &sym.pattern;
    let pos = &sym.pos;
    // A's entries below the diagonal, on each column's pattern.
    let mut vals: Vec<Vec<T>> = pattern
        .iter()
        .map(|p| vec![T::default(); p.len()])
        .collect();
    for &(i, k, a) in off {
        let (v, u) = if pos[i as usize] < pos[k as usize] {
            (i, k)
        } else {
            (k, i)
        };
        let p = &pattern[v as usize];
        let idx = p
            .binary_search_by_key(&pos[u as usize], |&w| pos[w as usize])
            .expect("edge in pattern");
        vals[v as usize][idx] += a;
    }
    let mut diag: Vec<T> = d.to_vec();
    let mut dropped = 0;
    // Each column's pattern as elimination positions (ascending), which index the accumulator.
    let ppos: Vec<Vec<u32>> = pattern
        .iter()
        .map(|p| p.iter().map(|&w| pos[w as usize] as u32).collect())
        .collect();
    // Dense accumulator over positions, zero outside the current column's pattern.
    let mut acc = vec![T::default(); m];
    // For each node, the finished columns whose next entry below the diagonal is that node,
    // with the index of that entry: the columns that update it, each met once.
    let mut links: Vec<Vec<(u32, u32)>> = vec![Vec::new(); m];
    for &v in &order {
        let vi = v as usize;
        let pv = &ppos[vi];
        for (a, &w) in pv.iter().enumerate() {
            acc[w as usize] = vals[vi][a];
        }
        let mut piv = diag[vi];
        // Each update's pivot term, its size, and the updating column's next target (a later
        // column, so the pushes do not touch what the gather below reads).
        let updates = std::mem::take(&mut links[vi]);
        let mut work = 0;
        for &(j, at) in &updates {
            let (pj, next) = (&pattern[j as usize], at as usize + 1);
            let l = vals[j as usize][at as usize];
            piv -= l * l;
            work += pj.len() - next;
            if next < pj.len() {
                links[pj[next] as usize].push((j, next as u32));
            }
        }
        if work >= parallel && pv.len() >= 2 {
            // Two halves of the accumulator (by position), each with every update in the
            // same order: the same arithmetic per entry as on one thread.
            let mid = pv[pv.len() / 2] as usize;
            let (low, high) = acc.split_at_mut(mid);
            let (ppos, vals) = (&ppos, &vals);
            rayon::join(
                || gather_updates(&updates, ppos, vals, low, 0),
                || gather_updates(&updates, ppos, vals, high, mid),
            );
        } else {
            gather_updates(&updates, &ppos, &vals, &mut acc, 0);
        }
        // NaN pivots count as dependent too.
        if piv.f64().is_nan() || piv.f64() <= drop * d[vi].f64().max(f64::MIN_POSITIVE) {
            diag[vi] = T::default();
            for &w in pv {
                acc[w as usize] = T::default();
            }
            vals[vi].iter_mut().for_each(|x| *x = T::default());
            dropped += 1;
            continue;
        }
        let l = piv.root();
        diag[vi] = l;
        for (a, &w) in pv.iter().enumerate() {
            vals[vi][a] = acc[w as usize] / l;
            acc[w as usize] = T::default();
        }
        if let Some(&first) = pattern[vi].first() {
            links[first as usize].push((v, 0));
        }
    }
    let mut start = Vec::with_capacity(m + 1);
    start.push(0);
    let mut rows = Vec::with_capacity(ppos.iter().map(Vec::len).sum());
    let mut packed = Vec::with_capacity(rows.capacity());
    for &v in &order {
        rows.extend_from_slice(&ppos[v as usize]);
        packed.extend_from_slice(&vals[v as usize]);
        start.push(rows.len());
    }
    (
        Factor {
            order,
            start,
            rows,
            vals: packed,
            diag,
        },
        dropped,
    )
}

/// Multiply-adds of one column's updates from which [`factor`] splits them over two threads
/// (a fork costs microseconds; a double-double multiply-add a few nanoseconds).
const PARALLEL_UPDATES: usize = 20_000;

/// The updates `acc[w] −= l_j · l_jw` of one column from the finished columns `updates` (column,
/// index of the entry at the column being formed), for the positions w in `acc`'s window, which
/// starts at position `start`: each entry gets its updates in the order given, so a window's
/// results do not depend on how the accumulator is split.
fn gather_updates<T: Real>(
    updates: &[(u32, u32)],
    ppos: &[Vec<u32>],
    vals: &[Vec<T>],
    acc: &mut [T],
    start: usize,
) {
    #[cfg(target_arch = "x86_64")]
    if T::FUSED && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor has FMA, checked just above.
        return unsafe { gather_updates_fma(updates, ppos, vals, acc, start) };
    }
    gather_updates_in(updates, ppos, vals, acc, start);
}

/// [`gather_updates`] compiled with FMA (see [`factor_fma`]; a thread of `rayon::join` does not
/// run inside the caller's target feature).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn gather_updates_fma<T: Real>(
    updates: &[(u32, u32)],
    ppos: &[Vec<u32>],
    vals: &[Vec<T>],
    acc: &mut [T],
    start: usize,
) {
    gather_updates_in(updates, ppos, vals, acc, start);
}

#[inline(always)]
fn gather_updates_in<T: Real>(
    updates: &[(u32, u32)],
    ppos: &[Vec<u32>],
    vals: &[Vec<T>],
    acc: &mut [T],
    start: usize,
) {
    let end = start + acc.len();
    for &(j, at) in updates {
        let (pj, lj) = (&ppos[j as usize], &vals[j as usize]);
        let at = at as usize;
        let l = lj[at];
        let tail = &pj[at + 1..];
        let from = at + 1 + tail.partition_point(|&w| (w as usize) < start);
        let to = at + 1 + tail.partition_point(|&w| (w as usize) < end);
        for (&w, &lw) in pj[from..to].iter().zip(&lj[from..to]) {
            acc[w as usize - start] -= l * lw;
        }
    }
}

/// The equations scaled to unit rows (duplicate columns merged), as the factorisation, the
/// refinement and [`conjugate_gradients`] use them, with each row's own scale to measure the
/// residual in; also the rows the sign program hands to its solver ([`super::signfit`]).
pub(super) struct UnitRows {
    /// Â: each row over its norm.
    pub(super) rows: Vec<Vec<(u32, f64)>>,
    /// ĉ: each right-hand side over its row's norm.
    pub(super) c: Vec<f64>,
    /// Each row's norm as given.
    scale: Vec<f64>,
}

impl UnitRows {
    pub(super) fn new(rows: &[Row], c: &[f64]) -> UnitRows {
        debug_assert_eq!(rows.len(), c.len());
        let mut unit = Vec::with_capacity(rows.len());
        let mut cs = Vec::with_capacity(rows.len());
        for (r, &ci) in rows.iter().zip(c) {
            let mut merged = super::sparse::merged(r.iter().map(|&(j, a)| (j as u32, a)).collect());
            let s = merged.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt();
            let inv = if s > 0.0 { 1.0 / s } else { 0.0 };
            merged.iter_mut().for_each(|t| t.1 *= inv);
            unit.push(merged);
            cs.push(ci * inv);
        }
        let scale = rows
            .iter()
            .map(|r| r.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt())
            .collect();
        UnitRows {
            rows: unit,
            c: cs,
            scale,
        }
    }

    /// Sets `r` to ĉ − Â x and returns max |A x − c| in the rows' own scale.
    pub(super) fn residual(&self, x: &[f64], r: &mut [f64]) -> f64 {
        self.residual_to(&self.c, x, r)
    }

    /// [`UnitRows::residual`] for the unit right-hand side `c` instead of ĉ.
    fn residual_to(&self, c: &[f64], x: &[f64], r: &mut [f64]) -> f64 {
        for (i, row) in self.rows.iter().enumerate() {
            r[i] = c[i] - row.iter().map(|&(j, a)| a * x[j as usize]).sum::<f64>();
        }
        r.iter()
            .zip(&self.scale)
            .map(|(ri, s)| ri.abs() * s)
            .fold(0.0_f64, f64::max)
    }
}

/// Solves A x = c (rows of A as sparse `rows`, `n` unknowns) for the x closest to `target` in
/// the Euclidean norm, refining until max |A x − c| ≤ `tol` (or [`REFINE`] rounds).
/// [`Solution::rank`] is the number of equations less the dropped dependent ones.
#[must_use]
pub fn solve_near(rows: &[Row], n: usize, c: &[f64], target: &[f64], tol: f64) -> Solution {
    solve_near_ordered(rows, n, c, target, tol, &Ordering::of(rows, n))
}

/// [`solve_near`] in a given `ordering`, one made for these rows or for rows with more
/// entries ([`Ordering::of`]).
#[must_use]
pub fn solve_near_ordered(
    rows: &[Row],
    n: usize,
    c: &[f64],
    target: &[f64],
    tol: f64,
    ordering: &Ordering,
) -> Solution {
    let m = rows.len();
    debug_assert_eq!(ordering.order.len(), m);
    let unit = UnitRows::new(rows, c);
    let (d, off) = normal_matrix::<f64>(&unit.rows, n);
    let drops = [DEPENDENT_PIVOT, RETRY_PIVOT];
    let made = refine_near(&unit, target, tol, &drops, false, None, |drop| {
        Some(factor(&d, &off, drop, ordering))
    });
    let (mut residual, mut x, mut dropped) = made.expect("the in-house factor is always made");
    if residual > tol {
        // Still short: the f64 factor's pivots of nearly dependent rows are rounding. The
        // normal equations in double-double tell dependent rows from independent ones.
        let precise = Projector::precise(rows, n, c, ordering, PRECISE_PIVOT);
        let mut y = target.to_vec();
        let got = precise.meet(&mut y, tol);
        if got < residual {
            (residual, x, dropped) = (got, y, precise.dropped);
        }
    }
    Solution {
        x,
        rank: m - dropped,
        residual,
    }
}

/// A factor of Â Âᵀ: what [`refine_near`] needs of it.
pub(super) trait NormalSolve {
    /// Solves Â Âᵀ y = r in place (dropped, dependent rows get y = 0 or nearly).
    fn solve_normal(&self, r: &mut [f64]);

    /// x += Âᵀ (Â Âᵀ)⁻¹ r (r is overwritten): the least-norm correction towards the rows.
    fn correct(&self, arows: &[Vec<(u32, f64)>], r: &mut [f64], x: &mut [f64]) {
        self.solve_normal(r);
        add_transposed(arows, r, x);
    }

    /// Each p ← Π p, its projection onto the kept rows' null space (p − Âᵀ (Â Âᵀ)⁻¹ Â p).
    fn project(&self, arows: &[Vec<(u32, f64)>], ps: &mut [Vec<f64>]) {
        for p in ps.iter_mut() {
            let mut r = minus_rows_times(arows, p);
            self.correct(arows, &mut r, p);
        }
    }
}

/// −Â p.
pub(super) fn minus_rows_times(arows: &[Vec<(u32, f64)>], p: &[f64]) -> Vec<f64> {
    arows
        .iter()
        .map(|row| -row.iter().map(|&(j, a)| a * p[j as usize]).sum::<f64>())
        .collect()
}

impl NormalSolve for Factor {
    fn solve_normal(&self, r: &mut [f64]) {
        self.solve(r);
    }
}

/// The x closest to `target` with Â x = ĉ (`unit`), from the factors `make` gives for the drop
/// thresholds `drops` in turn (the next only if the last factor's first correction did not
/// help; with how many rows each dropped): iterative refinement with each, then
/// conjugate gradients preconditioned by each, until max |A x − c| ≤ `tol`. Returns the best
/// (residual, x, rows dropped), or `None` when `make` made no factor. In the last solve
/// (`meet`: the dropped rows met afterwards) a factor whose first correction grew the
/// residual is released before the next one is made, so only one is held at a time.
#[allow(clippy::too_many_arguments)]
pub(super) fn refine_near<F: NormalSolve>(
    unit: &UnitRows,
    target: &[f64],
    tol: f64,
    drops: &[f64],
    meet: bool,
    signs: Option<&SignBox>,
    mut make: impl FnMut(f64) -> Option<(F, usize)>,
) -> Option<(f64, Vec<f64>, usize)> {
    let arows = &unit.rows;
    let m = arows.len();
    let residual_of = |x: &[f64], r: &mut [f64]| unit.residual(x, r);
    let mut r = vec![0.0; m];
    let res0 = residual_of(target, &mut r);
    let mut best = (res0, target.to_vec(), 0);
    let mut factors: Vec<(F, usize)> = Vec::new();
    let mut grew = false;
    for &drop in drops {
        if meet && grew {
            // The last solve's factors are the large double-double ones (fandisk's: ~11.6 GB
            // each); one whose first correction grew the residual is no preconditioner
            // either, so it goes before the next is made.
            factors.pop();
        }
        factors.push(make(drop)?);
        let &(ref f, dropped) = factors.last().expect("just pushed");
        let mut x = target.to_vec();
        let mut res = residual_of(&x, &mut r);
        let mut first_step_helped = false;
        for step in 0..=REFINE {
            if res <= tol {
                break;
            }
            f.correct(arows, &mut r, &mut x);
            let before = res;
            res = residual_of(&x, &mut r);
            if std::env::var_os("APATCH_REFINE_TRACE").is_some() {
                // Opt-in report on stderr (exploration; results unaffected).
                eprintln!(
                    "quintic-c2 refine: drop {drop:e}, {dropped} dropped, step {step}: residual {before:.3e} -> {res:.3e}"
                );
            }
            if step == 0 {
                first_step_helped = res < 0.5 * before;
                grew = res > before;
            }
            if res < best.0 {
                best = (res, x.clone(), dropped);
            }
            if res >= before {
                // Refinement stopped helping (an inconsistent dependent row).
                break;
            }
        }
        // An accurate factor removes the consistent part of the residual at once; one that
        // did not (nearly dependent rows kept, their pivots mostly rounding) is retried with
        // the larger drop threshold.
        if res <= tol || first_step_helped {
            break;
        }
    }
    if best.0 > tol {
        // Refinement stalls where the factor is far from Â Âᵀ on nearly dependent rows (their
        // pivots mostly rounding); conjugate gradients with the same factor as preconditioner
        // still converge there, in the rows the factor keeps.
        for (f, dropped) in &factors {
            let mut x = best.1.clone();
            let (got, _) =
                conjugate_gradients(unit, &unit.c, &|z| f.solve_normal(z), &mut x, tol, CG_STALL);
            if got < best.0 {
                best = (got, x, *dropped);
            }
            if best.0 <= tol {
                break;
            }
        }
    }
    if let Some(sb) = signs.filter(|_| meet || best.0 <= tol) {
        // Theorem 2.1's signs by alternating projections with the factor that gave `best`
        // (only where this is the last solve: with the precise factor, or one that met `tol`).
        if let Some((f, _)) = factors.iter().find(|(_, d)| *d == best.2) {
            let mut x = best.1.clone();
            best.0 = sign_rounds(unit, f, &mut x, tol, sb);
            best.1 = x;
        }
    }
    let mut basis = Vec::new();
    // A saved sign fit of this group (exploration, `APATCH_JOINT_FIT_LOAD`): its start stands
    // for the meet before the fit, its fitted values for the fit.
    let loaded = signs
        .filter(|sb| sb.fit > 0 && meet)
        .and_then(|_| std::env::var_os("APATCH_JOINT_FIT_LOAD"))
        .and_then(
            |path| match read_fit(std::path::Path::new(&path), best.1.len()) {
                Ok(v) => Some(v),
                Err(e) => {
                    eprintln!("quintic-c2: saved sign fit not used: {e}");
                    None
                }
            },
        );
    if let Some((x0, _)) = &loaded {
        best = (unit.residual(x0, &mut r), x0.clone(), best.2);
    }
    if meet && best.0 > tol && loaded.is_none() {
        // The rows still missed are dropped ones, nearly dependent on the kept rows: met by a
        // move in the kept rows' null space ([`meet_dropped`]), with the factor that gave `best`.
        if let Some((f, _)) = factors.iter().find(|(_, d)| *d == best.2) {
            let mut x = best.1.clone();
            let got;
            let stall = signs.and_then(|sb| sb.meet_stall);
            (got, basis) = meet_dropped(unit, f, &mut x, tol, &MEET_OWN_WEIGHTS, stall);
            if got < best.0 {
                best = (got, x, best.2);
            }
        }
    }
    if let Some(sb) = signs.filter(|sb| sb.fit > 0 && (meet || best.0 <= tol)) {
        // The sign program inside the group, moving orthogonally to the basis the dropped
        // rows were met with. The other dropped rows see the move (by up to their distance
        // from the kept span, 3.2e-8, times its length), so they are met again after it; a
        // start that met `tol` must still meet it, one that did not may miss by up to 10×
        // more (the check then measures what that does to the jumps).
        if let Some((f, _)) = factors.iter().find(|(_, d)| *d == best.2) {
            let bound = if best.0 <= tol { tol } else { 10.0 * best.0 };
            // Exploration (`APATCH_JOINT_FIT_BOUND`): a fit kept up to another miss, so that
            // `check` can say what a miss beyond the bound does to the jumps.
            let bound = positive_env("APATCH_JOINT_FIT_BOUND").unwrap_or(bound.max(sb.meet_tol));
            let mut x = best.1.clone();
            let loose = if meet { f64::INFINITY } else { bound };
            let was_loaded = loaded.is_some();
            let fitted = match loaded {
                Some((_, xf)) => {
                    // Settled as the fit settles its own move (a fit saved before that was
                    // projected twice).
                    x = xf;
                    Some(super::signsplit::settle(
                        unit, f, &basis, &best.1, &mut x, &mut r,
                    ))
                }
                None => super::signsplit::fit(unit, f, &mut x, &basis, sb, loose),
            };
            if let Some(mut got) = fitted {
                // A fit read from a file is not written back.
                let save = std::env::var_os("APATCH_JOINT_FIT_SAVE").filter(|_| !was_loaded);
                if let Some(path) = save {
                    if let Err(e) = write_fit(std::path::Path::new(&path), &best.1, &x) {
                        eprintln!("quintic-c2: could not save the sign fit: {e:#}");
                    }
                }
                // The meet after the fit stops at the scene's `joint_meet_tolerance` (or, for
                // exploration, `APATCH_MEET_TOL=t`, absolute) where that is looser than the
                // solve's: every row met is a move, and the last rows cost the most signs.
                let meet_tol = positive_env("APATCH_MEET_TOL").unwrap_or(tol.max(sb.meet_tol));
                if meet && got > meet_tol {
                    drop(basis);
                    let weights = meet_weights_override().unwrap_or(MEET_OWN_WEIGHTS.to_vec());
                    let q;
                    (got, q) = meet_dropped(unit, f, &mut x, meet_tol, &weights, None);
                    // Exploration (`APATCH_FIT_CYCLES=n`): the fit and the meet in turns.
                    if let Some(cycles) = positive_env("APATCH_FIT_CYCLES") {
                        got = fit_meet_cycles(
                            unit,
                            f,
                            &mut x,
                            q,
                            got,
                            tol,
                            &weights,
                            sb,
                            cycles as usize,
                            bound,
                        );
                    }
                }
                if got <= bound {
                    best = (got, x, best.2);
                }
            }
        }
    }
    Some(best)
}

/// Rounds of each new fit in [`fit_meet_cycles`] (`APATCH_REFIT_ROUNDS`, default 60): the
/// cycles start from a fitted x, so fewer rounds than the first fit's are asked.
const REFIT_ROUNDS: usize = 60;

/// Exploration (`APATCH_FIT_CYCLES=n`, session 58): after the meet that follows the sign fit,
/// `cycles` turns of a new sign fit from x, its moves orthogonal to the directions `q` the
/// meet just used, and a meet again. A meet given room (`APATCH_MEET_GROWTH`) reaches the
/// rows a weighted fit leaves missed, but its long moves along their projections undo the
/// signs; a fit orthogonal to those projections cannot disturb those rows again (each sees
/// a move only through its projection, which lies in span q), so it may win the signs back
/// while the rows stay met, and the meet after it has only the rows the new move reached.
/// x is left at the turn with the lowest sign cost among those that miss the rows by at most
/// `bound` (the last turn if none does); returns its max |A x − c|. On fandisk (session 58,
/// docs/quintic.md) one turn did not converge: the new fit won the signs back (1433 → 905
/// off) but its move reached near rows outside q (4.67e-11 → 2.25e-8), which the meet after
/// it could again meet only by a long move (refused at 1.03e-10).
#[allow(clippy::too_many_arguments)]
fn fit_meet_cycles<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    x: &mut Vec<f64>,
    mut q: Vec<Vec<f64>>,
    mut got: f64,
    tol: f64,
    weights: &[f64],
    sb: &SignBox,
    cycles: usize,
    bound: f64,
) -> f64 {
    let rounds = positive_env("APATCH_REFIT_ROUNDS").map_or(REFIT_ROUNDS, |v| v as usize);
    let refit = SignBox {
        fit: rounds,
        ..sb.clone()
    };
    let mut best: Option<(f64, f64, Vec<f64>)> =
        (got <= bound).then(|| (sb.off_cost(x, zero_up_to_rounding(x)), got, x.clone()));
    for cycle in 0..cycles {
        let fitted = super::signsplit::fit(unit, f, x, &q, &refit, f64::INFINITY);
        drop(std::mem::take(&mut q));
        (got, q) = meet_dropped(unit, f, x, tol, weights, None);
        let cost = sb.off_cost(x, zero_up_to_rounding(x));
        eprintln!(
            "quintic-c2 fit/meet cycle {cycle}: fit {}, {} off their sign (cost {cost}), residual after the meet {got:.2e} (bound {bound:.2e})",
            fitted.map_or("not taken".to_string(), |r| format!("residual {r:.2e}")),
            sb.off(x, zero_up_to_rounding(x)),
        );
        if got <= bound && best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, got, x.clone()));
        }
    }
    match best {
        Some((_, g, y)) => {
            *x = y;
            g
        }
        None => got,
    }
}

/// The positive finite number the environment variable `name` holds (the exploration
/// overrides' form), or `None` if it is unset or holds anything else.
pub(super) fn positive_env(name: &str) -> Option<f64> {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
}

/// The weights of Q's own rows for the meet after the split sign program, from
/// `APATCH_MEET_WEIGHTS` (exploration: comma-separated, each tried every round, the best move
/// taken; e.g. `1,10`), or `None` if unset or unreadable.
fn meet_weights_override() -> Option<Vec<f64>> {
    let v = std::env::var("APATCH_MEET_WEIGHTS").ok()?;
    let w: Vec<f64> = v
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()?;
    (!w.is_empty() && w.iter().all(|x| x.is_finite() && *x > 0.0)).then_some(w)
}

/// Writes a group's values before and after the split sign program to `path`
/// (exploration: `APATCH_JOINT_FIT_SAVE` names the file, `APATCH_JOINT_FIT_LOAD` reads it
/// back). On fandisk the fit ends ~70 min into the run, and what follows it, the dropped
/// rows' meet, is what a weighted fit needs changed (session 56); from the saved values a
/// run needs only the group's factor (~25 min) to get there. Format: n as u64, then x₀'s and
/// the fitted x's n values, f64 little-endian; written through
/// [`crate::export::write_atomically`], so a file at `path` is whole.
pub(super) fn write_fit(path: &std::path::Path, x0: &[f64], x: &[f64]) -> anyhow::Result<()> {
    debug_assert_eq!(x0.len(), x.len());
    crate::export::write_atomically(path, |out| {
        out.write_all(&(x.len() as u64).to_le_bytes())?;
        for v in x0.iter().chain(x) {
            out.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    })
}

/// Reads what [`write_fit`] wrote, for a group of `n` unknowns: (x₀, fitted x), or what is
/// wrong with the file (unreadable, another group's length, cut short, not finite).
pub(super) fn read_fit(path: &std::path::Path, n: usize) -> Result<(Vec<f64>, Vec<f64>), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let head: [u8; 8] = bytes
        .get(..8)
        .and_then(|b| b.try_into().ok())
        .ok_or_else(|| format!("{}: shorter than its header", path.display()))?;
    let len = u64::from_le_bytes(head);
    if len != n as u64 {
        return Err(format!(
            "{}: a group of {len} unknowns, this one has {n}",
            path.display()
        ));
    }
    if bytes.len() != 8 + 16 * n {
        return Err(format!(
            "{}: {} bytes, {} expected for {n} unknowns",
            path.display(),
            bytes.len(),
            8 + 16 * n
        ));
    }
    let values: Vec<f64> = bytes[8..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("{}: value {i} is not finite", path.display()));
    }
    let fitted = values[n..].to_vec();
    let mut start = values;
    start.truncate(n);
    Ok((start, fitted))
}

/// How far off its sign a weight of x may be and still count as on it: weights this small
/// are zero up to the solves' rounding (1e-12 of x's largest value), for
/// [`SignBox::off`] / [`SignBox::off_cost`] in the sign rounds and fits.
pub(super) fn zero_up_to_rounding(x: &[f64]) -> f64 {
    1e-12 * x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// Theorem 2.1's signs on a group's own weights, for [`sign_rounds`]: each weight of `signed`
/// (column, ±1) is clamped to at least `margin` on its side, for at most `rounds` rounds.
#[derive(Clone, Debug, Default)]
pub struct SignBox {
    /// The group's columns with a sign condition, with that sign (±1).
    pub signed: Vec<(usize, f64)>,
    /// What a miss of each `signed` weight costs the split sign program
    /// ([`super::signsplit::fit`]; empty: 1 each).
    pub cost: Vec<f64>,
    /// How far on its side a clamped weight is put.
    pub margin: f64,
    /// Most rounds of [`sign_rounds`].
    pub rounds: usize,
    /// Rounds of the split sign program after the dropped rows are met
    /// ([`super::signsplit::fit`]; 0 = none).
    pub fit: usize,
    /// The miss (max |A x − c|, the group's data units) to which the meet after the split
    /// sign program meets the dropped rows, if above the solve's tolerance (0: that
    /// tolerance); a fit whose meet reaches it is kept.
    pub meet_tol: f64,
    /// The meet before the fit stops after this many rounds in a row that did not lower its
    /// residual ([`meet_dropped`]; `None`: it runs its rounds out).
    pub meet_stall: Option<usize>,
}

impl SignBox {
    /// Weights of `x` off their sign by more than `tiny`.
    #[must_use]
    pub fn off(&self, x: &[f64], tiny: f64) -> usize {
        self.signed
            .iter()
            .filter(|&&(j, s)| s * x[j] < -tiny)
            .count()
    }

    /// The cost of the weights of `x` off their sign by more than `tiny` (their number when
    /// [`SignBox::cost`] is empty).
    #[must_use]
    pub fn off_cost(&self, x: &[f64], tiny: f64) -> f64 {
        self.signed
            .iter()
            .enumerate()
            .filter(|&(_, &(j, s))| s * x[j] < -tiny)
            .map(|(i, _)| self.cost.get(i).copied().unwrap_or(1.0))
            .sum()
    }

    /// Clamps every signed weight of `x` to at least the margin on its side; how many moved.
    fn clamp(&self, x: &mut [f64]) -> usize {
        let mut moved = 0;
        for &(j, s) in &self.signed {
            if s * x[j] < self.margin {
                x[j] = s * self.margin;
                moved += 1;
            }
        }
        moved
    }
}

/// Alternating projections between the sign box `sb` and the rows (the least-norm move back
/// onto them, refined with the factor `f` as [`refine_near`] does), the last move onto the
/// rows: each round is two Euclidean projections onto convex sets, so the distance to their
/// intersection never grows, and where it is empty (the signs are sufficient, not necessary)
/// the weights still move towards it. What pins do for small groups, with one factor for all
/// rounds instead of one per round: for groups where a factor takes minutes
/// (`QuinticOptions::joint_sign_rounds`). x is left at the round with the fewest weights off
/// their sign among those that meet the rows about as well as x did; returns max |A x − c|.
pub(super) fn sign_rounds<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    x: &mut Vec<f64>,
    tol: f64,
    sb: &SignBox,
) -> f64 {
    let arows = &unit.rows;
    let m = arows.len();
    let mut r = vec![0.0; m];
    let start = unit.residual(x, &mut r);
    // A start that met `tol` must still meet it; one that did not (dropped rows, met after
    // this by [`meet_dropped`]) may miss by a little more.
    let bound = if start <= tol { tol } else { 10.0 * start };
    // Weights this small are zero up to the solves' rounding (as `project`).
    let tiny = zero_up_to_rounding(x);
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    let mut best = (sb.off(x, tiny), start, x.clone());
    let before = best.0;
    let mut y = x.clone();
    for round in 0..sb.rounds {
        let t = std::time::Instant::now();
        let clamped = sb.clamp(&mut y);
        if clamped == 0 {
            break;
        }
        let res = unit.residual(&y, &mut r);
        let res = refine_kept(unit, f, &mut y, &mut r, res, tol);
        let off = sb.off(&y, tiny);
        if trace {
            eprintln!(
                "quintic-c2 sign rounds, round {round}: {clamped} clamped, residual {res:.2e}, {off} off their sign (was {before}), {:.1} s",
                t.elapsed().as_secs_f64()
            );
        }
        if res <= bound && off < best.0 {
            best = (off, res, y.clone());
        }
    }
    *x = best.2;
    best.1
}

/// At most [`REFINE`] corrections of y towards the rows with the factor `f`, each kept only if
/// it lowers max |A y − c| (`res`, with `r` y's residual), until `tol` is met; returns the
/// max, with `r` left y's residual whether or not the last correction was kept. The rounds
/// after ([`meet_dropped`]'s next missed rows, its trace) read r: a factor's `correct` may
/// overwrite the r it is given with (Â Âᵀ)⁻¹ r, so it is given a copy.
fn refine_kept<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    y: &mut Vec<f64>,
    r: &mut Vec<f64>,
    mut res: f64,
    tol: f64,
) -> f64 {
    for _ in 0..REFINE {
        if res <= tol {
            break;
        }
        let mut z = y.clone();
        f.correct(&unit.rows, &mut r.clone(), &mut z);
        let mut rz = vec![0.0; r.len()];
        let next = unit.residual(&z, &mut rz);
        if next >= res {
            break;
        }
        (*y, *r, res) = (z, rz, next);
    }
    res
}

/// Most missed rows [`meet_dropped`] takes in one round (one solve with the factor each).
const MEET_ROWS: usize = 32;
/// Rounds of [`meet_dropped`]: on fandisk's joint group the residual still fell at round 6
/// (5.9e-12 with Q's own rows weighted ×10, [`MEET_OWN_WEIGHTS`]); [`MEET_BASIS`] bounds the
/// memory whatever this is.
const MEET_ROUNDS: usize = 10;
/// Most projections [`meet_dropped`] keeps over its rounds: each is a vector of all the
/// unknowns (fandisk's joint group: 1.83M, so 160 of them are 2.3 GB beside its 11.6 GB
/// double-double factor; 113 of them took its run from 16.7 to 18.1 GB resident).
const MEET_BASIS: usize = 160;
/// Rows [`meet_dropped`] takes in a round: those missed by more than this fraction of the
/// largest miss (and the tolerance), so that each round takes the residual down by about this.
const MEET_FRACTION: f64 = 1e-2;
/// Smallest distance of a missed row from the kept rows' span that [`meet_dropped`] moves
/// along: 1e-12 (a pivot of 1e-24) is far above the double-double projection's rounding
/// (~1e-16 of the row) and far below the rows a drop threshold of 1e-15 drops (≤ 3.2e-8).
const MEET_MIN_DISTANCE: f64 = 1e-12;
/// A unit row sees a unit direction q of the kept rows' null space when |a · q| is above this:
/// a kept row sees only q's rounding (~1e-16 after two projections), a dropped row within
/// [`MEET_MIN_DISTANCE`] of the span sees at most that distance, and rows seeing less than
/// 1e-14 of a move of O(1) miss by less than the tolerances asked (1e-13).
const MEET_SEEN: f64 = 1e-14;
/// Largest move of [`meet_dropped`] per round, in units of the largest |x|: a nearly dependent
/// row whose data disagrees with its neighbours' would otherwise be met by an arbitrarily
/// large move (its miss over its distance).
const MEET_GROWTH: f64 = 10.0;
/// Weight of the rows Q was made for in [`meet_dropped`]'s fit, against the other rows that
/// see Q. In the plain least-squares fit (weight 1) the worst missed rows trade against the
/// ~30000 rows that see the move, and on fandisk's joint group one of them held the residual
/// at 1.23e-11 from round 3 on. Weighted ×10 they are met first while the others still shape
/// the move: 5.9e-12 at round 5 and still falling, moves ≤ 1.9e-2 of |x| (a minimax fit, which
/// meets them exactly, moved by up to 0.5 and worsened every later check). Choosing the weight
/// round by round (the lower residual of 1 and 10, or 10 unless 1 is 2× lower) led back onto
/// the plain fit's path and its 1.23e-11: the ×10 path's round 3 is worse (3.7e-11, not
/// taken), and its rounds 4–5 build on that. Where the basis, not the trade, limits the rounds
/// (more near rows than [`MEET_BASIS`]), the plain fit ends lower (`supernodal`'s tests).
pub(super) const MEET_OWN_WEIGHTS: [f64; 1] = [10.0];

/// Meets the rows a factor dropped but x misses: rows off the kept rows' span by δ (pivot δ²
/// below the drop threshold) are missed by δ times x's distance from the exact solution along
/// them. Each round takes the worst missed rows (at most [`MEET_ROWS`]) and projects them onto
/// the kept rows' null space, p = Π a (a multi-column solve with the factor,
/// [`NormalSolve::project`]); the projections of every round so far (an orthonormal basis Q,
/// at most [`MEET_BASIS`]) span the move. A move dx = Q u leaves every kept row as it was but
/// is seen by every dropped row near the span, not only by the rows it was made for, so u is
/// the least-squares fit of all the rows that see Q ([`MEET_SEEN`]) in their own scale, the
/// rows Q was made for weighted up ([`MEET_OWN_WEIGHTS`]): a round meets its new rows without
/// undoing the earlier rounds' or missing the others more.
/// A few rounds of refinement follow each move (the projections' rounding, amplified by 1/δ);
/// a round that does not lower the residual is not taken, but its rows stay in Q for the next.
/// Returns max |A x − c| (x is left at the best round) and the basis Q.
pub(super) fn meet_dropped<F: NormalSolve>(
    unit: &UnitRows,
    f: &F,
    x: &mut Vec<f64>,
    tol: f64,
    own_weights: &[f64],
    stall: Option<usize>,
) -> (f64, Vec<Vec<f64>>) {
    let arows = &unit.rows;
    let (m, n) = (arows.len(), x.len());
    // Exploration (`APATCH_MEET_GROWTH`): a larger move allowed, for the meet after a
    // weighted sign fit (session 55's refused 2.1).
    let growth = positive_env("APATCH_MEET_GROWTH").unwrap_or(MEET_GROWTH);
    let mut r = vec![0.0; m];
    let mut res = unit.residual(x, &mut r);
    let trace = std::env::var_os("APATCH_SOLVE_TRACE").is_some();
    // Q, the rows whose projections made it, and for each q the rows that see it (a · q).
    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut used = vec![false; m];
    let mut seen: Vec<Vec<(usize, f64)>> = Vec::new();
    // Stop after `stall` rounds in a row that did not lower the residual (fandisk's meet
    // before the fit: four refused rounds of ~6 min, session 66), or as many as
    // `APATCH_MEET_STALL=k` says (exploration, every meet).
    let stall = positive_env("APATCH_MEET_STALL")
        .map(|k| k as usize)
        .or(stall)
        .unwrap_or(usize::MAX);
    let mut stalled = 0;
    for round in 0..MEET_ROUNDS {
        if res <= tol || q.len() >= MEET_BASIS || stalled >= stall {
            break;
        }
        stalled += 1;
        let t = std::time::Instant::now();
        // The worst rows not used yet: those missed by more than a fraction of the largest miss.
        let bar = tol.max(MEET_FRACTION * res);
        let mut missed: Vec<usize> = (0..m)
            .filter(|&i| r[i].abs() * unit.scale[i] > bar && !used[i])
            .collect();
        missed.sort_by(|&a, &b| {
            (r[b].abs() * unit.scale[b])
                .total_cmp(&(r[a].abs() * unit.scale[a]))
                .then(a.cmp(&b))
        });
        let all_missed = missed.len();
        missed.truncate(MEET_ROWS.min(MEET_BASIS - q.len()));
        let mut ps: Vec<Vec<f64>> = missed
            .iter()
            .map(|&i| {
                let mut p = vec![0.0; n];
                for &(j, a) in &arows[i] {
                    p[j as usize] = a;
                }
                p
            })
            .collect();
        // Twice: the first projection's Â p is rounded to ~1e-17 of the row, which is 1e-9 of
        // a projection 1e-8 long; the second removes what that left in the kept span.
        f.project(arows, &mut ps);
        f.project(arows, &mut ps);
        // Extend the orthonormal basis Q (Gram–Schmidt against all of it, twice).
        let mut added = 0;
        let mut nearest = f64::INFINITY;
        for (&i, mut p) in missed.iter().zip(ps) {
            let norm0 = dot(&p, &p).sqrt();
            if norm0 < MEET_MIN_DISTANCE {
                continue;
            }
            for _ in 0..2 {
                for qk in &q {
                    let h = dot(qk, &p);
                    p.iter_mut().zip(qk).for_each(|(v, w)| *v -= h * w);
                }
            }
            let norm = dot(&p, &p).sqrt();
            if norm < 1e-3 * norm0 {
                continue;
            }
            p.iter_mut().for_each(|v| *v /= norm);
            seen.push(
                arows
                    .par_iter()
                    .enumerate()
                    .filter_map(|(i, row)| {
                        let a: f64 = row.iter().map(|&(j, v)| v * p[j as usize]).sum();
                        (a.abs() > MEET_SEEN).then_some((i, a))
                    })
                    .collect(),
            );
            q.push(p);
            used[i] = true;
            added += 1;
            nearest = nearest.min(norm0);
        }
        if added == 0 {
            break;
        }
        // min Σ (w_i s_i)² (a_i · Q u − r_i)² over the rows S that see Q (s_i their scale, w_i
        // the weight of Q's own rows or 1), for each weight given (one but in tests); the move
        // that meets the rows best is taken.
        let mut rows_seen: Vec<usize> = seen.iter().flatten().map(|t| t.0).collect();
        rows_seen.sort_unstable();
        rows_seen.dedup();
        let (k, ms) = (q.len(), rows_seen.len());
        let reach = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let tf = std::time::Instant::now();
        let mut chosen: Option<Move> = None;
        for &weight in own_weights {
            let own = |i: usize| if used[i] { weight } else { 1.0 };
            let mut bt = vec![0.0; k * ms];
            for (col, list) in seen.iter().enumerate() {
                for &(i, a) in list {
                    let s = rows_seen.binary_search(&i).expect("a seen row");
                    bt[col * ms + s] = a * unit.scale[i] * own(i);
                }
            }
            let rhs: Vec<f64> = rows_seen
                .iter()
                .map(|&i| r[i] * unit.scale[i] * own(i))
                .collect();
            let u = if ms >= k {
                super::dense::least_squares(&bt, k, ms, &rhs, 1e-10)
            } else {
                // Fewer rows than directions: the least-norm u that meets them all.
                let mut b = vec![0.0; ms * k];
                for col in 0..k {
                    for s in 0..ms {
                        b[s * k + col] = bt[col * ms + s];
                    }
                }
                super::dense::solve_near(&b, ms, k, &rhs, &vec![0.0; k], 1e-10).x
            };
            let mut y = x.clone();
            for (qk, uk) in q.iter().zip(&u) {
                y.iter_mut().zip(qk).for_each(|(v, w)| *v += uk * w);
            }
            let moved = y
                .iter()
                .zip(x.iter())
                .fold(0.0_f64, |a, (p, q)| a.max((p - q).abs()));
            if moved.is_nan() || moved > growth * reach.max(f64::MIN_POSITIVE) {
                if trace {
                    eprintln!(
                        "quintic-c2 meet dropped, round {round}: weight {weight}: move {moved:.2e} refused"
                    );
                }
                continue;
            }
            let mut ry = vec![0.0; m];
            let got = unit.residual(&y, &mut ry);
            if chosen.as_ref().is_none_or(|c| got < c.got) {
                // What the fit promised on the rows that see Q, in their own scale.
                let fitted = (0..ms).fold(0.0_f64, |a, s| {
                    let e = (0..k).map(|col| bt[col * ms + s] * u[col]).sum::<f64>() - rhs[s];
                    a.max(e.abs() / own(rows_seen[s]))
                });
                chosen = Some(Move {
                    y,
                    ry,
                    got,
                    moved,
                    weight,
                    fitted,
                });
            }
        }
        let fit_time = tf.elapsed().as_secs_f64();
        let Some(Move {
            mut y,
            mut ry,
            mut got,
            moved,
            weight,
            fitted,
        }) = chosen
        else {
            continue;
        };
        let moved_to = got;
        got = refine_kept(unit, f, &mut y, &mut ry, got, tol);
        if trace {
            // What the chosen fit promised on the rows that see Q, what the move gave before
            // the refinement, and the worst row after: one of Q's, one that sees Q, or neither.
            let worst = (0..m)
                .max_by(|&a, &b| {
                    (ry[a].abs() * unit.scale[a]).total_cmp(&(ry[b].abs() * unit.scale[b]))
                })
                .unwrap_or(0);
            let role = if used[worst] {
                "one of Q's rows"
            } else if rows_seen.binary_search(&worst).is_ok() {
                "a row that sees Q"
            } else {
                "a row that does not see Q"
            };
            eprintln!(
                "quintic-c2 meet dropped, round {round}: {all_missed} rows missed, {added} of the worst {} added (nearest {nearest:.1e} off the kept span), {k} directions fitted to the {ms} rows that see them (weight {weight}, fit {fitted:.2e}, {:.1} s), move {moved:.2e}, residual {res:.2e} -> {moved_to:.2e} -> {got:.2e} refined (worst: row {worst}, {role}), {:.1} s",
                missed.len(),
                fit_time,
                t.elapsed().as_secs_f64()
            );
        }
        if got < res {
            (*x, r, res) = (y, ry, got);
            stalled = 0;
        }
    }
    (res, q)
}

/// One candidate move of [`meet_dropped`]: x moved, its residuals and their max, how far it
/// moved, the own rows' weight that gave it and what its fit promised.
struct Move {
    y: Vec<f64>,
    ry: Vec<f64>,
    got: f64,
    moved: f64,
    weight: f64,
    fitted: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One group's equations A x = c factored once (Â Âᵀ, dependent rows dropped at
/// [`DEPENDENT_PIVOT`]), for many minimum-change moves: onto the equations ([`Projector::meet`])
/// or onto their null space ([`Projector::project`], Π v = v − Âᵀ (Â Âᵀ)⁺ Â v). The hole
/// repair's pinned solves are combinations of such projections of the pinned unknowns' unit
/// vectors, so one factor serves every round and weight of a repair
/// (`holes`' `PinnedSolves`).
pub struct Projector {
    unit: UnitRows,
    factor: EitherFactor,
    dropped: usize,
}

/// The unit rows of A x = c and the factor of their Â Âᵀ in `T`, formed and factored in
/// `ordering`, rows below `drop` dropped; with the number dropped.
fn factored<T: Real>(
    rows: &[Row],
    n: usize,
    c: &[f64],
    ordering: &Ordering,
    drop: f64,
) -> (UnitRows, Factor<T>, usize) {
    debug_assert_eq!(ordering.order.len(), rows.len());
    let unit = UnitRows::new(rows, c);
    let (d, off) = normal_matrix::<T>(&unit.rows, n);
    let (factor, dropped) = factor(&d, &off, drop, ordering);
    (unit, factor, dropped)
}

/// A [`Projector`]'s factor, in f64 or double-double.
enum EitherFactor {
    Double(Factor),
    Precise(Precise),
}

impl EitherFactor {
    fn solve(&self, r: &mut [f64]) {
        match self {
            EitherFactor::Double(f) => f.solve(r),
            EitherFactor::Precise(f) => f.solve(r),
        }
    }

    /// [`EitherFactor::solve`] of each of `rs`, [`BATCH`] of them per pass over the factor
    /// (each with the arithmetic it gets alone).
    fn solve_many(&self, rs: &mut [Vec<f64>]) {
        for chunk in rs.chunks_mut(BATCH) {
            let views: Vec<&[f64]> = chunk.iter().map(Vec::as_slice).collect();
            match self {
                EitherFactor::Double(f) => {
                    let ys = f.solve_wide_many(&views);
                    for (r, y) in chunk.iter_mut().zip(ys) {
                        *r = y;
                    }
                }
                EitherFactor::Precise(f) => {
                    let ys = f.solve_wide_many(&views);
                    for (r, y) in chunk.iter_mut().zip(ys) {
                        r.iter_mut().zip(y).for_each(|(ri, yi)| *ri = yi.f64());
                    }
                }
            }
        }
    }

    /// x += Âᵀ (Â Âᵀ)⁻¹ r (r is overwritten): the least-norm correction towards the rows.
    /// In double-double the sum Âᵀ y is formed in double-double too: y is large along nearly
    /// dependent rows (pivots down to [`PRECISE_PIVOT`]) whose terms nearly cancel in Âᵀ y, and
    /// summed in f64 that cancellation left spot's projections of unit vectors 1e-2 off the
    /// null space.
    fn correct(&self, arows: &[Vec<(u32, f64)>], r: &mut [f64], x: &mut [f64]) {
        match self {
            EitherFactor::Double(f) => {
                f.solve(r);
                add_transposed(arows, r, x);
            }
            EitherFactor::Precise(f) => add_transposed_precise(arows, &f.solve_wide(r), x),
        }
    }

    /// [`EitherFactor::correct`] of several (x, r) pairs (at most [`BATCH`]) with one pass
    /// over the factor, each x with the same arithmetic as alone (the rs are left as they are).
    fn correct_many(&self, arows: &[Vec<(u32, f64)>], rs: &[&[f64]], xs: &mut [Vec<f64>]) {
        match self {
            EitherFactor::Double(f) => {
                for (y, x) in f.solve_wide_many(rs).iter().zip(xs) {
                    add_transposed(arows, y, x);
                }
            }
            EitherFactor::Precise(f) => {
                for (y, x) in f.solve_wide_many(rs).iter().zip(xs) {
                    add_transposed_precise(arows, y, x);
                }
            }
        }
    }

    #[cfg(test)]
    fn is_dropped(&self, i: usize) -> bool {
        match self {
            EitherFactor::Double(f) => f.diag[i].f64() == 0.0,
            EitherFactor::Precise(f) => f.diag[i].f64() == 0.0,
        }
    }
}

impl Projector {
    /// Factors the `rows` (over `n` unknowns, right-hand side `c`) in `ordering`, one made
    /// for them ([`Ordering::of`]).
    #[must_use]
    pub fn new(rows: &[Row], n: usize, c: &[f64], ordering: &Ordering) -> Projector {
        let (unit, factor, dropped) = factored::<f64>(rows, n, c, ordering, DEPENDENT_PIVOT);
        Projector {
            unit,
            factor: EitherFactor::Double(factor),
            dropped,
        }
    }

    /// [`Projector::new`] with Â Âᵀ formed and factored in double-double, dropping rows whose
    /// squared distance from the span of the rows before them is below `drop`
    /// ([`PRECISE_PIVOT`] in the repair): for groups whose f64 factor misses their rows
    /// (pivots of nearly dependent rows lost in f64's rounding).
    #[must_use]
    pub fn precise(rows: &[Row], n: usize, c: &[f64], ordering: &Ordering, drop: f64) -> Projector {
        let (unit, factor, dropped) = factored::<Dd>(rows, n, c, ordering, drop);
        Projector {
            unit,
            factor: EitherFactor::Precise(factor),
            dropped,
        }
    }

    /// The rows dropped as dependent (exploration: which rows a move misses).
    #[cfg(test)]
    #[must_use]
    pub fn dropped_rows(&self) -> Vec<usize> {
        (0..self.unit.rows.len())
            .filter(|&i| self.factor.is_dropped(i))
            .collect()
    }

    /// The number of equations less the dependent ones dropped.
    #[must_use]
    pub fn rank(&self) -> usize {
        self.unit.rows.len() - self.dropped
    }

    /// Moves `x` to the closest point (Euclidean) with A x = c, refined until max |A x − c| ≤
    /// `tol`; returns that residual.
    pub fn meet(&self, x: &mut Vec<f64>, tol: f64) -> f64 {
        self.refine(x, &self.unit.c, tol)
    }

    /// Moves `v` to its orthogonal projection onto the null space of A (the closest point with
    /// A v = 0), refined until max |A v| ≤ `tol`; returns that residual.
    pub fn project(&self, v: &mut Vec<f64>, tol: f64) -> f64 {
        self.refine(v, &vec![0.0; self.unit.rows.len()], tol)
    }

    /// The projections Π e_j of the unit vectors of unknowns `js` (of `n`), as
    /// [`Projector::project`] makes them one by one (the same values), with their residuals:
    /// each [`BATCH`] of them is refined and then iterated by conjugate gradients in lock step,
    /// every step's solves sharing one pass over the factor, and the batches run in parallel.
    /// The repair's pinned solves spend most of their time in these projections (profiles of
    /// the nut's repair: 66% in the factor's solves; of fandisk's, 70%, most of it in the
    /// conjugate gradients, which solved one vector at a time before session 51).
    #[must_use]
    pub fn project_units(&self, js: &[usize], n: usize, tol: f64) -> Vec<(Vec<f64>, f64)> {
        let m = self.unit.rows.len();
        let zero = vec![0.0; m];
        js.par_chunks(BATCH)
            .flat_map_iter(|chunk| {
                let mut xs: Vec<Vec<f64>> = chunk
                    .iter()
                    .map(|&j| {
                        let mut v = vec![0.0; n];
                        v[j] = 1.0;
                        v
                    })
                    .collect();
                let mut rs = vec![vec![0.0; m]; chunk.len()];
                let mut res: Vec<f64> = xs
                    .iter()
                    .zip(&mut rs)
                    .map(|(x, r)| self.unit.residual_to(&zero, x, r))
                    .collect();
                // The refinement's steps in lock step: each step's corrections of those above
                // `tol` and still improving share one pass over the factor; a correction that
                // does not lower the residual is undone and ends that one's refinement.
                let mut improving = vec![true; chunk.len()];
                for _ in 0..=REFINE {
                    let active: Vec<usize> = (0..chunk.len())
                        .filter(|&k| improving[k] && res[k] > tol)
                        .collect();
                    if active.is_empty() {
                        break;
                    }
                    let before: Vec<Vec<f64>> = active.iter().map(|&k| xs[k].clone()).collect();
                    let mut ax: Vec<Vec<f64>> =
                        active.iter().map(|&k| std::mem::take(&mut xs[k])).collect();
                    let views: Vec<&[f64]> = active.iter().map(|&k| rs[k].as_slice()).collect();
                    self.factor.correct_many(&self.unit.rows, &views, &mut ax);
                    for ((&k, mut x), old) in active.iter().zip(ax).zip(before) {
                        let now = self.unit.residual_to(&zero, &x, &mut rs[k]);
                        if now.partial_cmp(&res[k]) == Some(std::cmp::Ordering::Less) {
                            res[k] = now;
                        } else {
                            // Refinement stopped helping (NaN-safe): keep the better point.
                            x = old;
                            improving[k] = false;
                        }
                        xs[k] = x;
                    }
                }
                // The refinement's end, conjugate gradients, in lock step for those short
                // of `tol` (most of the repair's time went to their preconditioner solves).
                let short: Vec<usize> = (0..chunk.len()).filter(|&k| res[k] > tol).collect();
                let mut sx: Vec<Vec<f64>> =
                    short.iter().map(|&k| std::mem::take(&mut xs[k])).collect();
                let solve = |zs: &mut [Vec<f64>]| self.factor.solve_many(zs);
                let got =
                    conjugate_gradients_many(&self.unit, &zero, &solve, &mut sx, tol, CG_STALL);
                for ((&k, x), (g, _)) in short.iter().zip(sx).zip(got) {
                    xs[k] = x;
                    res[k] = g.min(res[k]);
                }
                xs.into_iter().zip(res).collect::<Vec<_>>()
            })
            .collect()
    }

    /// Least-norm corrections along Âᵀ y towards Â x = `c`: iterative refinement with the
    /// factor while it lowers the residual, then conjugate gradients preconditioned by it
    /// (as [`solve_near_ordered`] does). Leaves `x` at the best point met.
    fn refine(&self, x: &mut Vec<f64>, c: &[f64], tol: f64) -> f64 {
        let mut r = vec![0.0; self.unit.rows.len()];
        let mut res = self.unit.residual_to(c, x, &mut r);
        for _ in 0..=REFINE {
            if res <= tol {
                return res;
            }
            let before = (res, x.clone());
            self.factor.correct(&self.unit.rows, &mut r, x);
            res = self.unit.residual_to(c, x, &mut r);
            if res.partial_cmp(&before.0) != Some(std::cmp::Ordering::Less) {
                // Refinement stopped helping (NaN-safe): keep the better point.
                (res, *x) = before;
                break;
            }
        }
        self.finish(x, c, tol, res)
    }

    /// The end of [`Projector::refine`]: conjugate gradients where refinement left `x` (its
    /// residual `res`) short of `tol`.
    fn finish(&self, x: &mut Vec<f64>, c: &[f64], tol: f64, mut res: f64) -> f64 {
        if res > tol {
            let solve = |z: &mut [f64]| self.factor.solve(z);
            let (got, _) = conjugate_gradients(&self.unit, c, &solve, x, tol, CG_STALL);
            res = got.min(res);
        }
        res
    }
}

/// Drop threshold of [`Projector::precise`]: rows within √1e-15 ≈ 3e-8 of the span of the
/// rows before them are dependent. Measured on spot's Hessian-pass group of 18506 unknowns
/// (15375 rows): in double-double every pivot lies above 1e-12 or below 1e-18 (478 dropped at
/// any threshold between), and the moves meet every row to 3e-14 of the data; at 1e-22 two
/// rows of pivots ~1e-20 (rows dependent in exact geometry, off the span by their
/// coefficients' rounding) are kept and the moves miss by 2e-3, as the f64 factor's did
/// (its pivots below ~1e-13 are rounding).
pub const PRECISE_PIVOT: f64 = 1e-15;

/// x += Âᵀ y with y and the sum in double-double, x rounded once at the end
/// ([`EitherFactor::correct`] says why).
pub(super) fn add_transposed_precise(arows: &[Vec<(u32, f64)>], y: &[Dd], x: &mut [f64]) {
    let mut acc: Vec<Dd> = x.iter().map(|&v| Dd::of(v)).collect();
    for (row, &yi) in arows.iter().zip(y) {
        if yi.f64() != 0.0 {
            for &(j, a) in row {
                acc[j as usize] += Dd::of(a) * yi;
            }
        }
    }
    for (v, s) in x.iter_mut().zip(acc) {
        *v = s.f64();
    }
}

/// x += Âᵀ y for the unit rows `arows` (rows with y_i = 0 skipped): the least-norm move of the
/// refinement, the projections and conjugate gradients.
fn add_transposed(arows: &[Vec<(u32, f64)>], y: &[f64], x: &mut [f64]) {
    for (row, &yi) in arows.iter().zip(y) {
        if yi != 0.0 {
            for &(j, a) in row {
                x[j as usize] += a * yi;
            }
        }
    }
}

/// Â Âᵀ of the unit rows `arows` over `n` unknowns: its diagonal and its strictly upper
/// entries (row, column, value), the input of [`factor`], summed in `T` (exact products in
/// double-double).
pub(super) fn normal_matrix<T: Real>(
    arows: &[Vec<(u32, f64)>],
    n: usize,
) -> (Vec<T>, Vec<(u32, u32, T)>) {
    let m = arows.len();
    // Rows of each column.
    let mut by_col: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    for (i, r) in arows.iter().enumerate() {
        for &(j, a) in r {
            by_col[j as usize].push((i as u32, a));
        }
    }
    // Â Âᵀ: diagonal and the strictly upper entries (an entry that cancels exactly is kept
    // out).
    let mut d = vec![T::default(); m];
    let mut off: Vec<(u32, u32, T)> = Vec::new();
    let mut acc = vec![T::default(); m];
    let mut seen = vec![false; m];
    let mut touched: Vec<u32> = Vec::new();
    for (i, r) in arows.iter().enumerate() {
        for &(j, a) in r {
            for &(k, b) in &by_col[j as usize] {
                if (k as usize) < i {
                    continue;
                }
                if !seen[k as usize] {
                    seen[k as usize] = true;
                    touched.push(k);
                }
                acc[k as usize] += T::product(a, b);
            }
        }
        touched.sort_unstable();
        for &k in &touched {
            let v = std::mem::take(&mut acc[k as usize]);
            seen[k as usize] = false;
            if k as usize == i {
                d[i] = v;
            } else if v.f64() != 0.0 {
                off.push((i as u32, k, v));
            }
        }
        touched.clear();
    }
    (d, off)
}

/// Iterations of [`conjugate_gradients`] at most.
const CG_ITERATIONS: usize = 60;

/// [`conjugate_gradients`] stops after this many iterations in a row that did not halve its
/// least residual. Measured (a trace of every call on the nut's and the bunny's repairs, ~2900
/// calls): each solve that reached its tolerance did so by iteration 6, its last halving by
/// iteration 5; the rest, mostly inconsistent pinned groups, ran all 60 iterations for nothing.
const CG_STALL: usize = 8;

/// Moves `x` along Âᵀ y, y from preconditioned conjugate gradients on Â Âᵀ y = ĉ − Â x with
/// the factor `f` as preconditioner (the least-norm correction: x stays as close to where it
/// started as the equations allow), until [`UnitRows::residual`] (max |A x − c| in the rows' own
/// scale) is at most `tol`, [`CG_ITERATIONS`] are done or `stall` iterations in a row did not
/// halve the least residual ([`CG_STALL`] in the solves). Leaves `x` at the iterate of least
/// residual and returns that residual and the iterations done.
fn conjugate_gradients(
    unit: &UnitRows,
    c: &[f64],
    f: &dyn Fn(&mut [f64]),
    x: &mut Vec<f64>,
    tol: f64,
    stall: usize,
) -> (f64, usize) {
    let each = |zs: &mut [Vec<f64>]| zs.iter_mut().for_each(|z| f(z));
    let mut xs = [std::mem::take(x)];
    let got = conjugate_gradients_many(unit, c, &each, &mut xs, tol, stall);
    *x = std::mem::take(&mut xs[0]);
    got[0]
}

/// One right-hand side's state in [`conjugate_gradients_many`].
struct Cg {
    /// The recurrence's residual ĉ − Â x.
    r: Vec<f64>,
    /// The least true residual met, and its iterate.
    best: f64,
    best_x: Vec<f64>,
    /// The preconditioned residual, the search direction and r·z.
    z: Vec<f64>,
    p: Vec<f64>,
    rz: f64,
    /// Âᵀ p, Â Âᵀ p and the true residual (buffers).
    dx: Vec<f64>,
    q: Vec<f64>,
    true_r: Vec<f64>,
    stalled: usize,
    iterations: usize,
    done: bool,
}

/// [`conjugate_gradients`] for several starting points `xs` at once, in lock step: each
/// iteration's preconditioner solves of the iterations still going are one call of `f` (the
/// factor then reads L once for up to [`BATCH`] of them, [`EitherFactor::solve_many`]). Each x
/// gets the arithmetic it gets alone; returns each one's least residual and iterations.
fn conjugate_gradients_many(
    unit: &UnitRows,
    c: &[f64],
    f: &dyn Fn(&mut [Vec<f64>]),
    xs: &mut [Vec<f64>],
    tol: f64,
    stall: usize,
) -> Vec<(f64, usize)> {
    let arows = &unit.rows;
    let m = arows.len();
    let mut st: Vec<Cg> = xs
        .iter()
        .map(|x| {
            let mut r = vec![0.0; m];
            let best = unit.residual_to(c, x, &mut r);
            Cg {
                r,
                best,
                best_x: x.clone(),
                z: Vec::new(),
                p: Vec::new(),
                rz: 0.0,
                dx: vec![0.0; x.len()],
                q: vec![0.0; m],
                true_r: vec![0.0; m],
                stalled: 0,
                iterations: 0,
                done: false,
            }
        })
        .collect();
    // The factor as preconditioner, on the rows it keeps (identity on the rows it dropped
    // was tried: on the bunny it left two j-sheets that this repairs): z = f(r) for the
    // states `ks`, in one call.
    let precondition = |st: &mut [Cg], ks: &[usize]| {
        let mut zs: Vec<Vec<f64>> = ks
            .iter()
            .map(|&k| {
                let mut z = std::mem::take(&mut st[k].z);
                z.clear();
                z.extend_from_slice(&st[k].r);
                z
            })
            .collect();
        f(&mut zs);
        for (&k, z) in ks.iter().zip(zs) {
            st[k].z = z;
        }
    };
    let all: Vec<usize> = (0..st.len()).collect();
    precondition(&mut st, &all);
    for s in &mut st {
        s.p.clone_from(&s.z);
        s.rz = s.r.iter().zip(&s.z).map(|(a, b)| a * b).sum();
    }
    for _ in 0..CG_ITERATIONS {
        let mut going = Vec::new();
        for (k, (s, x)) in st.iter_mut().zip(xs.iter_mut()).enumerate() {
            // A non-positive (or NaN) curvature ends the iteration.
            if s.done
                || s.best <= tol
                || s.stalled == stall
                || s.rz.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            {
                s.done = true;
                continue;
            }
            // dx = Âᵀ p, q = Â dx.
            s.dx.iter_mut().for_each(|v| *v = 0.0);
            add_transposed(arows, &s.p, &mut s.dx);
            for (qi, row) in s.q.iter_mut().zip(arows) {
                *qi = row.iter().map(|&(j, a)| a * s.dx[j as usize]).sum();
            }
            let pq: f64 = s.p.iter().zip(&s.q).map(|(a, b)| a * b).sum();
            if pq.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                s.done = true;
                continue;
            }
            let alpha = s.rz / pq;
            s.iterations += 1;
            for (xi, d) in x.iter_mut().zip(&s.dx) {
                *xi += alpha * d;
            }
            for (ri, qi) in s.r.iter_mut().zip(&s.q) {
                *ri -= alpha * qi;
            }
            // The recurrence's residual drifts from the true one: judge by the true one.
            let res = unit.residual_to(c, x, &mut s.true_r);
            s.stalled = if res < 0.5 * s.best { 0 } else { s.stalled + 1 };
            if res < s.best {
                s.best = res;
                s.best_x.clone_from(x);
            }
            going.push(k);
        }
        if going.is_empty() {
            break;
        }
        precondition(&mut st, &going);
        for &k in &going {
            let s = &mut st[k];
            let rz_new: f64 = s.r.iter().zip(&s.z).map(|(a, b)| a * b).sum();
            let beta = rz_new / s.rz;
            s.rz = rz_new;
            for (pi, zi) in s.p.iter_mut().zip(&s.z) {
                *pi = zi + beta * *pi;
            }
        }
    }
    st.into_iter()
        .zip(xs.iter_mut())
        .map(|(s, x)| {
            *x = s.best_x;
            (s.best, s.iterations)
        })
        .collect()
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A stand-in factor of Â Âᵀ = I that multiplies by `gain` (1: exact; 1e3: a first
    /// correction that grows the residual ~1000×), counting how many are alive at once.
    struct Counted {
        gain: f64,
        live: std::rc::Rc<std::cell::Cell<(usize, usize)>>,
    }

    impl NormalSolve for Counted {
        fn solve_normal(&self, r: &mut [f64]) {
            r.iter_mut().for_each(|v| *v *= self.gain);
        }
    }

    impl Drop for Counted {
        fn drop(&mut self) {
            let (now, peak) = self.live.get();
            self.live.set((now - 1, peak));
        }
    }

    /// In the last solve (`meet`) a factor whose first correction grew the residual is gone
    /// before the next drop threshold's factor is made (fandisk's double-double factors are
    /// ~11.6 GB each); elsewhere both stay, as preconditioners for conjugate gradients. Either
    /// way the second, exact factor meets the rows.
    #[test]
    fn a_grown_factor_is_released_before_the_next_in_the_last_solve() {
        // Unit rows x_j = c_j: Â Âᵀ = I.
        let n = 5;
        let rows: Vec<Row> = (0..n).map(|j| vec![(j, 1.0)]).collect();
        let c: Vec<f64> = (0..n).map(|j| 0.25 * j as f64 - 0.5).collect();
        let unit = UnitRows::new(&rows, &c);
        for meet in [true, false] {
            let live = std::rc::Rc::new(std::cell::Cell::new((0, 0)));
            let got = refine_near(
                &unit,
                &vec![0.0; n],
                1e-14,
                &[1.0, 2.0],
                meet,
                None,
                |drop| {
                    let (now, peak) = live.get();
                    live.set((now + 1, peak.max(now + 1)));
                    let gain = if drop == 1.0 { 1e3 } else { 1.0 };
                    let f = Counted {
                        gain,
                        live: live.clone(),
                    };
                    Some((f, 0))
                },
            );
            let (residual, x, _) = got.expect("factors made");
            // The exact factor's one correction leaves only the rounding of c (~1e-16).
            assert!(residual <= 1e-14, "meet {meet}: residual {residual:e}");
            assert_eq!(x, c, "meet {meet}");
            assert_eq!(live.get(), (0, if meet { 1 } else { 2 }), "meet {meet}");
        }
    }

    /// A saved sign fit reads back to the bit (values that are not short decimals, −0.0 and
    /// subnormals among them), and a file of another group's length, one cut short or one
    /// with a NaN is refused with the file named, not read as a fit.
    #[test]
    fn a_saved_sign_fit_reads_back_exactly_and_bad_files_are_refused() {
        let dir = std::env::temp_dir().join(format!("apatch_fit_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("fit.bin");
        let x0: Vec<f64> = (0..7).map(|i| (f64::from(i) * 0.7).sin() / 3.0).collect();
        let mut x = x0.clone();
        x[2] = -0.0;
        x[5] = f64::MIN_POSITIVE / 8.0;
        write_fit(&path, &x0, &x).expect("written");
        assert!(
            !crate::trace::output::temp_path(&path).exists(),
            "the temporary was renamed"
        );
        let (a, b) = read_fit(&path, 7).expect("read back");
        let bits = |v: &[f64]| v.iter().map(|t| t.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&x0));
        assert_eq!(bits(&b), bits(&x));
        let e = read_fit(&path, 6).expect_err("another group");
        assert!(e.contains("fit.bin") && e.contains("7 unknowns"), "{e}");
        let bytes = std::fs::read(&path).expect("bytes");
        std::fs::write(&path, &bytes[..bytes.len() - 8]).expect("cut");
        let e = read_fit(&path, 7).expect_err("cut short");
        assert!(e.contains("bytes"), "{e}");
        x[3] = f64::NAN;
        write_fit(&path, &x0, &x).expect("written");
        let e = read_fit(&path, 7).expect_err("a NaN");
        assert!(e.contains("value 10 is not finite"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A seeded uniform number in [−1, 1) (the random systems of these and `pinned`'s tests).
    pub(in crate::scheme::quintic_c2) fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    /// Random sparse system with dependent rows, seeded: the dense rows, the sparse rows and
    /// the right-hand side of a consistent system.
    pub(in crate::scheme::quintic_c2) fn system(
        m: usize,
        n: usize,
        seed: u64,
    ) -> (Vec<f64>, Vec<Row>, Vec<f64>, Vec<f64>) {
        let mut s = seed;
        let mut a = vec![0.0; m * n];
        for i in 0..m - 2 {
            for _ in 0..6 {
                let j = ((lcg(&mut s) + 1.0) * 0.5 * n as f64) as usize % n;
                a[i * n + j] = lcg(&mut s);
            }
        }
        for j in 0..n {
            a[(m - 2) * n + j] = a[j] + 2.0 * a[n + j];
            a[(m - 1) * n + j] = a[2 * n + j] - a[3 * n + j];
        }
        let x0: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        let c = times(&a, m, n, &x0);
        let target: Vec<f64> = (0..n).map(|_| lcg(&mut s)).collect();
        let rows = sparse_rows(&a, m, n);
        (a, rows, c, target)
    }

    /// A x for the `m`×`n` row-major A: the right-hand side that makes x a solution.
    pub(in crate::scheme::quintic_c2) fn times(
        a: &[f64],
        m: usize,
        n: usize,
        x: &[f64],
    ) -> Vec<f64> {
        (0..m)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect()
    }

    /// The nonzeros of the `m`×`n` row-major A as sparse rows.
    pub(in crate::scheme::quintic_c2) fn sparse_rows(a: &[f64], m: usize, n: usize) -> Vec<Row> {
        (0..m)
            .map(|i| {
                (0..n)
                    .filter(|&j| a[i * n + j] != 0.0)
                    .map(|j| (j, a[i * n + j]))
                    .collect()
            })
            .collect()
    }

    /// Agrees with the dense pivoted QR (an independent factorisation) on random
    /// underdetermined systems with two dependent rows: same rank, same closest solution.
    #[test]
    fn matches_dense_on_rank_deficient_systems() {
        for (m, n, seed) in [(30, 50, 12345), (120, 200, 7), (200, 260, 99)] {
            let (a, rows, c, target) = system(m, n, seed);
            let d = crate::scheme::quintic_c2::dense::solve_near(&a, m, n, &c, &target, 1e-11);
            let s = solve_near(&rows, n, &c, &target, 1e-13);
            assert_eq!(s.rank, d.rank, "rank ({m}×{n})");
            // Consistent system: rounding-level residual, as asked.
            assert!(s.residual <= 1e-13, "{}", s.residual);
            for (x, y) in s.x.iter().zip(&d.x) {
                // Both are the unique closest solution; entries O(1), modest conditioning.
                assert!((x - y).abs() < 1e-9, "{x} vs {y}");
            }
        }
    }

    /// Conjugate gradients with a poor preconditioner (the factor of Â Âᵀ's diagonal alone,
    /// the identity for unit rows) still reach the closest solution the dense pivoted QR finds,
    /// on a consistent system with two dependent rows (30 rows: CG ends in at most 30 steps
    /// in exact arithmetic, and [`CG_ITERATIONS`] allows 60).
    #[test]
    fn conjugate_gradients_reach_the_closest_solution() {
        let (m, n) = (30, 50);
        let (a, rows, c, target) = system(m, n, 12345);
        let dense = crate::scheme::quintic_c2::dense::solve_near(&a, m, n, &c, &target, 1e-11);
        let unit = UnitRows::new(&rows, &c);
        let ordering = Ordering::of(&rows, n);
        let (f, dropped) = factor(&vec![1.0; m], &[], DEPENDENT_PIVOT, &ordering);
        assert_eq!(dropped, 0);
        let mut x = target.clone();
        // No stall stop: with this preconditioner the largest residual need not halve for
        // many steps in a row (CG minimises another norm).
        let (res, _) = conjugate_gradients(
            &unit,
            &unit.c,
            &|z| f.solve(z),
            &mut x,
            1e-12,
            CG_ITERATIONS,
        );
        // Consistent system, entries O(1): rounding-level residual is reachable.
        assert!(res <= 1e-12, "{res}");
        for (u, v) in x.iter().zip(&dense.x) {
            // Both the unique closest solution; CG's rounding on a modestly conditioned system.
            assert!((u - v).abs() < 1e-8, "{u} vs {v}");
        }
    }

    /// [`conjugate_gradients_many`] gives each starting point what [`conjugate_gradients`]
    /// gives it alone, bit for bit (same iterate, residual and iterations), with the
    /// iterations ending at different steps: [`BATCH`] + 3 starts (two batches of the factor's
    /// solves), on a consistent system with the identity as preconditioner (many iterations)
    /// and on an inconsistent one with the exact factor (stalls).
    #[test]
    fn conjugate_gradients_in_lock_step_are_the_single_ones() {
        let (m, n) = (40, 60);
        // Iterations per (case, start): they must differ somewhere (the consistent case: starts
        // at different distances; the inconsistent one stalls at the same step everywhere).
        let mut counts = std::collections::HashSet::new();
        for (inconsistent, seed) in [(false, 5), (true, 3)] {
            let (_, rows, mut c, target) = system(m, n, seed);
            if inconsistent {
                c[39] += 0.5;
            }
            let unit = UnitRows::new(&rows, &c);
            let ordering = Ordering::of(&rows, n);
            let (f, _) = if inconsistent {
                let (d, off) = normal_matrix::<f64>(&unit.rows, n);
                factor(&d, &off, DEPENDENT_PIVOT, &ordering)
            } else {
                factor(&vec![1.0; m], &[], DEPENDENT_PIVOT, &ordering)
            };
            let f = EitherFactor::Double(f);
            // Without the factor the largest residual need not halve for many steps in a row
            // (as in `conjugate_gradients_reach_the_closest_solution`): no stall stop there.
            let stall = if inconsistent {
                CG_STALL
            } else {
                CG_ITERATIONS
            };
            let mut seed = 99u64;
            let starts: Vec<Vec<f64>> = (0..BATCH as i32 + 3)
                .map(|k| {
                    // Starts at different distances: their iterations end at different steps.
                    let scale = 10f64.powi(k % 4 - 2);
                    target.iter().map(|t| t + scale * lcg(&mut seed)).collect()
                })
                .collect();
            let mut many = starts.clone();
            let got = conjugate_gradients_many(
                &unit,
                &unit.c,
                &|zs: &mut [Vec<f64>]| f.solve_many(zs),
                &mut many,
                1e-12,
                stall,
            );
            for ((start, x), (res, it)) in starts.iter().zip(&many).zip(&got) {
                let mut one = start.clone();
                let (r1, i1) =
                    conjugate_gradients(&unit, &unit.c, &|z| f.solve(z), &mut one, 1e-12, stall);
                assert_eq!((res.to_bits(), *it), (r1.to_bits(), i1));
                assert!(x.iter().zip(&one).all(|(a, b)| a.to_bits() == b.to_bits()));
                counts.insert(*it);
            }
        }
        assert!(counts.len() > 2 && !counts.contains(&0), "{counts:?}");
    }

    /// On an inconsistent system (one dependent row contradicted by 0.5) no iterate meets the
    /// rows: with the exact factor as preconditioner CG stops after [`CG_STALL`] iterations
    /// without a halving instead of running all [`CG_ITERATIONS`], and keeps its best iterate.
    #[test]
    fn conjugate_gradients_stop_when_they_stall() {
        let (m, n) = (40, 60);
        let (_, rows, mut c, target) = system(m, n, 3);
        c[39] += 0.5;
        let unit = UnitRows::new(&rows, &c);
        let ordering = Ordering::of(&rows, n);
        let s = solve_near(&rows, n, &c, &target, 1e-13);
        let mut x = s.x.clone();
        let (d, off) = normal_matrix::<f64>(&unit.rows, n);
        let (f, _) = factor(&d, &off, DEPENDENT_PIVOT, &ordering);
        let (res, iterations) =
            conjugate_gradients(&unit, &unit.c, &|z| f.solve(z), &mut x, 1e-13, CG_STALL);
        assert!(iterations <= CG_STALL + 1, "{iterations}");
        // Never worse than where it started; the contradiction (0.5) stays far above rounding.
        assert!(res <= s.residual && res > 1e-3, "{res} vs {}", s.residual);
    }

    /// [`refine_kept`] leaves r the residual of the y it returns, also when its last correction
    /// did not help and was not kept: on an inconsistent system (one dependent row contradicted
    /// by 0.5) refinement with the f64 factor stops helping at once, and that factor's
    /// `correct` overwrites the r it is handed with (Â Âᵀ)⁻¹ r.
    #[test]
    fn refinement_leaves_the_residual_of_what_it_returns() {
        let (m, n) = (40, 60);
        let (_, rows, mut c, target) = system(m, n, 3);
        c[39] += 0.5;
        let unit = UnitRows::new(&rows, &c);
        let ordering = Ordering::of(&rows, n);
        let (d, off) = normal_matrix::<f64>(&unit.rows, n);
        let (f, dropped) = factor(&d, &off, DEPENDENT_PIVOT, &ordering);
        assert!(dropped >= 1, "the dependent row is dropped");
        let mut y = target.clone();
        let mut r = vec![0.0; m];
        let start = unit.residual(&y, &mut r);
        // tol 0: never met, so every step is tried until one does not help.
        let got = refine_kept(&unit, &f, &mut y, &mut r, start, 0.0);
        let mut fresh = vec![0.0; m];
        let again = unit.residual(&y, &mut fresh);
        // The same y and the same arithmetic: equal to the bit.
        assert_eq!(got.to_bits(), again.to_bits());
        assert_eq!(r, fresh);
        // The contradiction stays (0.5 against rows of norm 1), and some step helped.
        assert!(got > 1e-3 && got <= start, "{got} from {start}");
    }

    /// The double-double factor resolves a squared distance far below f64's rounding: row b
    /// = (cos t, sin t) at angle t = 1e-9 from row a = (1, 0) is sin² t ≈ 1e-18 from a's span
    /// (exactly b₁² for the rows as stored, since |b|² − (a·b)² = b₀² + b₁² − b₀²). f64 forms
    /// Â Âᵀ's entries and the pivot 1 − cos² t at its rounding (1e-16), so its pivot is
    /// noise, and the drop decision with it.
    #[test]
    fn precise_pivots_resolve_distances_below_f64_rounding() {
        let t = 1e-9_f64;
        let rows: Vec<Vec<(u32, f64)>> = vec![vec![(0, 1.0)], vec![(0, t.cos()), (1, t.sin())]];
        let ordering = Ordering {
            order: vec![0, 1],
            pattern: vec![vec![1], vec![]],
            pos: vec![0, 1],
        };
        let true_pivot = t.sin() * t.sin();
        let (d, off) = normal_matrix::<Dd>(&rows, 2);
        let (f, dropped) = factor(&d, &off, 0.0, &ordering);
        assert_eq!(dropped, 0);
        let piv = f.diag[1] * f.diag[1];
        // Double-double carries ~32 digits: the pivot's error is ~1e-32 against 1e-18.
        assert!(
            (piv.f64() - true_pivot).abs() <= 1e-9 * true_pivot,
            "{piv:?} vs {true_pivot:e}"
        );
        let (d, off) = normal_matrix::<f64>(&rows, 2);
        let (f, _) = factor(&d, &off, 0.0, &ordering);
        let piv = f.diag[1] * f.diag[1];
        // What the precise factor is for: f64's pivot is off by orders of magnitude (it is
        // 1 − cos² t with cos t = 1 − 5e-19 rounded to 1).
        assert!((piv - true_pivot).abs() > 0.5 * true_pivot, "{piv:e}");
    }

    /// The double-double factor and solve compiled with FMA give the plain build's numbers to
    /// the bit (`mul_add` is correctly rounded either way): on a random rank-deficient system,
    /// every entry of L and every solved value. Skipped where the processor has no FMA.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn fused_factor_is_the_plain_one() {
        if !std::arch::is_x86_feature_detected!("fma") {
            eprintln!("skipped: no FMA on this processor");
            return;
        }
        let (_, rows, c, _) = system(200, 260, 31);
        let ordering = Ordering::of(&rows, 260);
        let unit = UnitRows::new(&rows, &c);
        let (d, off) = normal_matrix::<Dd>(&unit.rows, 260);
        let (plain, dropped) = factor_in(&d, &off, PRECISE_PIVOT, &ordering, usize::MAX);
        // SAFETY: FMA checked above.
        let (fused, dropped_fused) = unsafe { factor_fma(&d, &off, PRECISE_PIVOT, &ordering) };
        assert_eq!(dropped, dropped_fused);
        assert!(dropped >= 2, "the two dependent rows, {dropped}");
        assert_eq!(plain.diag, fused.diag);
        assert_eq!((&plain.rows, &plain.vals), (&fused.rows, &fused.vals));
        let r: &[f64] = &unit.c;
        let y = plain.solve_batch_in::<1>(&[r]);
        // SAFETY: FMA checked above.
        let y_fused = unsafe { plain.solve_batch_fma::<1>(&[r]) };
        assert_eq!(y, y_fused);
        // The products do round differently from plain f64 ones (else the test shows nothing).
        assert!(plain.diag.iter().any(|x| x.lo != 0.0));
    }

    /// Columns whose updates are gathered on two threads get the same factor, to the bit, as on
    /// one, in both precisions: every column split (threshold 0) against none.
    #[test]
    fn split_updates_give_the_serial_factor() {
        let (_, rows, c, _) = system(200, 260, 77);
        let ordering = Ordering::of(&rows, 260);
        let unit = UnitRows::new(&rows, &c);
        let (d, off) = normal_matrix::<Dd>(&unit.rows, 260);
        let (serial, dropped) = factor_in(&d, &off, PRECISE_PIVOT, &ordering, usize::MAX);
        let (split, dropped_split) = factor_in(&d, &off, PRECISE_PIVOT, &ordering, 0);
        assert_eq!(dropped, dropped_split);
        assert_eq!(serial.diag, split.diag);
        assert_eq!((&serial.rows, &serial.vals), (&split.rows, &split.vals));
        let (d, off) = normal_matrix::<f64>(&unit.rows, 260);
        let (serial, _) = factor_in(&d, &off, DEPENDENT_PIVOT, &ordering, usize::MAX);
        let (split, _) = factor_in(&d, &off, DEPENDENT_PIVOT, &ordering, 0);
        assert_eq!(serial.diag, split.diag);
        assert_eq!((&serial.rows, &serial.vals), (&split.rows, &split.vals));
        // Fill: some columns have updates to split.
        assert!(ordering.entries() > 260, "{}", ordering.entries());
    }

    /// The double-double solve in [`Lanes`] gives what the solve side by side per node gives,
    /// bit for bit, for every number of right-hand sides up to [`BATCH`] (each lane count
    /// 1, 4, 8, 16 and its partly filled cases), on a rank-deficient system (dropped nodes).
    #[test]
    fn double_double_lanes_are_the_plain_solve() {
        let (m, n) = (60, 90);
        let (_, rows, c, _) = system(m, n, 4242);
        let ordering = Ordering::of(&rows, n);
        let unit = UnitRows::new(&rows, &c);
        let (d, off) = normal_matrix::<Dd>(&unit.rows, n);
        let (f, dropped) = factor(&d, &off, PRECISE_PIVOT, &ordering);
        assert!(dropped > 0, "the system should be rank deficient");
        let mut seed = 7u64;
        let rs: Vec<Vec<f64>> = (0..BATCH)
            .map(|_| (0..m).map(|_| lcg(&mut seed)).collect())
            .collect();
        for b in 1..=BATCH {
            let views: Vec<&[f64]> = rs[..b].iter().map(Vec::as_slice).collect();
            let lanes = f.solve_wide_many(&views);
            let plain = f.solve_batch_in::<BATCH>(&views);
            let bits = |v: &[Vec<Dd>]| {
                v.iter()
                    .flatten()
                    .map(|x| (x.hi.to_bits(), x.lo.to_bits()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&lanes), bits(&plain), "{b} right-hand sides");
            // Not all zero: the solve did something.
            assert!(lanes.iter().flatten().any(|x| x.lo != 0.0));
        }
    }

    /// [`Projector::project_units`] (batched, parallel) gives the projections
    /// [`Projector::project`] gives one by one, bit for bit, in both precisions: 19 unknowns,
    /// so the last batch is partial; a rank-deficient system, so some rows are dropped.
    #[test]
    fn batched_projections_are_the_single_ones() {
        let (m, n) = (60, 90);
        let (_, rows, c, _) = system(m, n, 4242);
        let ordering = Ordering::of(&rows, n);
        let js: Vec<usize> = (0..19).map(|k| (k * 7 + 3) % n).collect();
        for p in [
            Projector::new(&rows, n, &c, &ordering),
            Projector::precise(&rows, n, &c, &ordering, PRECISE_PIVOT),
        ] {
            for (&j, (v, res)) in js.iter().zip(p.project_units(&js, n, 1e-13)) {
                let mut e = vec![0.0; n];
                e[j] = 1.0;
                let one = p.project(&mut e, 1e-13);
                assert_eq!(res.to_bits(), one.to_bits(), "column {j}");
                assert!(
                    v.iter().zip(&e).all(|(a, b)| a.to_bits() == b.to_bits()),
                    "column {j}"
                );
                // A real projection: unit vector moved into the null space.
                assert!(res <= 1e-13 && v[j] < 1.0, "column {j}: {res:e}, {}", v[j]);
            }
        }
    }

    /// [`Projector::precise`] agrees with the dense pivoted QR on random rank-deficient
    /// systems as the f64 solve does (same rank, same closest solution), and meets a row
    /// pair 1e-6 apart in angle, whose f64 pivot (1e-12) sits 10× above f64's drop threshold
    /// and within its rounding's reach of it.
    #[test]
    fn precise_projector_matches_dense() {
        for (m, n, seed) in [(30, 50, 12345), (120, 200, 7)] {
            let (mut a, mut rows, mut c, target) = system(m, n, seed);
            // Row 4 turned 1e-6 off row 5 (both independent of the rest), consistent data.
            let t = 1e-6_f64;
            let b: Row = rows[5]
                .iter()
                .map(|&(j, v)| (j, v * t.cos()))
                .chain([(n - 1, t.sin())])
                .collect();
            for j in 0..n {
                a[4 * n + j] = 0.0;
            }
            for &(j, v) in &b {
                a[4 * n + j] += v;
            }
            rows[4] = (0..n)
                .filter(|&j| a[4 * n + j] != 0.0)
                .map(|j| (j, a[4 * n + j]))
                .collect();
            c[4] = c[5] * t.cos() + t.sin() * 0.25;
            let d = crate::scheme::quintic_c2::dense::solve_near(&a, m, n, &c, &target, 1e-11);
            let ordering = Ordering::of(&rows, n);
            let p = Projector::precise(&rows, n, &c, &ordering, PRECISE_PIVOT);
            let mut x = target.clone();
            let res = p.meet(&mut x, 1e-13);
            assert_eq!(p.rank(), d.rank, "rank ({m}×{n})");
            // Consistent system: rounding-level residual, as asked.
            assert!(res <= 1e-13, "{res}");
            for (u, v) in x.iter().zip(&d.x) {
                // Both the unique closest solution; the 1e-6 pair conditions it to ~1e6, so
                // rounding of 1e-16 grows to ~1e-10 in x.
                assert!((u - v).abs() < 1e-8, "{u} vs {v}");
            }
        }
    }

    /// One least-norm correction of [`Projector::precise`] meets a residual along the
    /// nearly null direction of two rows 1e-7 apart in angle (pivot 1e-14, kept: above
    /// [`PRECISE_PIVOT`]) in one step: y = (Â Âᵀ)⁻¹ r is ~1e14 there and Âᵀ y ~1e7, so the
    /// sum of Âᵀ y must cancel 7 digits. Summed in f64 it missed by ~1e-2; where Â Âᵀ is worse
    /// conditioned than its pivots show (spot's 13462-unknown repair group) such misses did
    /// not shrink under refinement and the projections of unit vectors missed the rows by 1e-2.
    #[test]
    fn precise_correction_cancels_in_double_double() {
        let n = 6;
        let t = 1e-7_f64;
        let u = [0.6, 0.0, 0.8, 0.0, 0.0, 0.0];
        let mut w: Vec<f64> = u.iter().map(|x| x * t.cos()).collect();
        w[1] = t.sin();
        let rows: Vec<Row> = [u.to_vec(), w]
            .iter()
            .map(|r| {
                r.iter()
                    .copied()
                    .enumerate()
                    .filter(|t| t.1 != 0.0)
                    .collect()
            })
            .collect();
        let c = [0.0, 0.0];
        let p = Projector::precise(&rows, n, &c, &Ordering::of(&rows, n), PRECISE_PIVOT);
        assert_eq!(p.rank(), 2);
        let want = [1.0, -1.0];
        let mut r = want.to_vec();
        let mut x = vec![0.0; n];
        p.factor.correct(&p.unit.rows, &mut r, &mut x);
        for (row, want) in p.unit.rows.iter().zip(want) {
            let got: f64 = row.iter().map(|&(j, a)| a * x[j as usize]).sum();
            // x ~ 1e7 (the least-norm move along e_1); its rounding, 1e7 × 1e-16 = 1e-9,
            // times the unit rows' entries, is what the product can miss.
            assert!((got - want).abs() < 1e-8, "{got} vs {want}");
        }
    }

    /// An inconsistent dependent row shows in the residual (not hidden by the drop).
    #[test]
    fn inconsistent_dependent_row_shows() {
        let (_, rows, mut c, target) = system(40, 60, 3);
        c[39] += 0.5;
        let s = solve_near(&rows, 60, &c, &target, 1e-13);
        // The contradiction is 0.5 on one row: far above rounding.
        assert!(s.residual > 1e-3, "{}", s.residual);
    }

    /// A long chain (a banded system whose minimum-degree order must not fill in): the closest
    /// solution of x_{i+1} − x_i = 1 to the target 0 is the centred ramp, known in closed form.
    #[test]
    fn chain_closest_solution() {
        let n = 5000;
        let rows: Vec<Row> = (0..n - 1).map(|i| vec![(i, -1.0), (i + 1, 1.0)]).collect();
        let c = vec![1.0; n - 1];
        let s = solve_near(&rows, n, &c, &vec![0.0; n], 1e-12);
        let mid = (n - 1) as f64 / 2.0;
        for (i, x) in s.x.iter().enumerate() {
            // Closed form x_i = i − (n−1)/2; entries up to 2500, rounding ~1e-12 relative.
            assert!((x - (i as f64 - mid)).abs() < 1e-8, "{i}: {x}");
        }
        assert_eq!(s.rank, n - 1);
    }
}

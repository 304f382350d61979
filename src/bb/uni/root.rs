//! The first root of a univariate Bernstein polynomial on an interval.
//!
//! # Policy (what counts as a root)
//! With s = max|ck| and the tolerance τ = [`TOUCH_TOL`]·s, [`first_root_in`] returns the
//! smallest t in [lo, hi] such that
//! - f changes sign at t, or f(t) is exactly 0 (roots at 0 and 1 included), or
//! - f *touches* zero at t: |f| ≤ τ around a point where f is not monotone (a tangency or
//!   double root that rounding may have lifted slightly above zero or pushed slightly below).
//!
//! So tangential touches are **reported**, whichever side rounding puts them on: at the
//! touching point (the extremum of f), or at the first of the two roots rounding split it into
//! (≈ √(rounding/|f″|) ≈ 1e-8 before it). Where f stays within τ of zero over a stretch (roots of
//! high multiplicity), the first point of that stretch is reported. An identically zero
//! polynomial (s = 0), an empty slice, or non-finite coefficients give `None`.
//!
//! # Algorithm
//! 1. Early exit: all coefficients > τ or all < −τ (convex hull property): no root.
//! 2. Isolation by subdivision at the midpoint, left half first; an interval whose coefficients
//!    have exactly one sign variation holds exactly one root (Descartes' rule of signs for the
//!    Bernstein basis), which is polished by Newton's method safeguarded by bisection inside
//!    the sign bracket. Intervals where f is monotone (all control-polygon slopes beyond ±τ)
//!    and whose ends share a sign are dropped.
//! 3. Intervals narrower than 2⁻³⁰ of [0, 1] that survive are touches (or their root is
//!    polished, if their ends differ in sign): Newton on f′ of the whole polynomial refines
//!    the touch to the nearby extremum, and a sign change between the two is bisected.
//!
//! Simple roots come out to a few ulps (Newton stops once in its quadratic phase). The search
//! is monomorphised for each length 1..=16, so its loops unroll and nothing allocates.
//!
//! # Continuing after a rejected root
//! An exact root at `lo` is reported again: to look past a root r, call
//! `first_root_in(c, r + δ, hi)` with some δ > 0 suited to the caller's scale.

use super::STACK_LEN;

/// Relative tolerance τ/max|ck| under which a coefficient counts as touching zero. Rounding in
/// a restricted segment polynomial is a few ulps of the largest weight; 1e-13 leaves ~500×
/// headroom over that. A touch is detected within √(τ/|f″|) of it, then refined.
pub const TOUCH_TOL: f64 = 1e-13;

/// Width (relative to [0, 1]) below which an unresolved interval is reported as a touch.
const LEAF_WIDTH: f64 = 1.0 / (1u64 << 30) as f64;

/// Cap on subdivisions per call (a degenerate polynomial cannot make the search run away).
const MAX_SPLITS: usize = 4096;

/// Newton iterations at most in the polish (bisection guarantees ≥ 1 bit per two steps).
const MAX_POLISH: usize = 100;

/// The smallest root of f in [0, 1] under the policy of this module; no heap allocation.
///
/// # Panics
/// When `c` has more than [`STACK_LEN`] coefficients.
#[inline]
#[must_use]
pub fn first_root(c: &[f64]) -> Option<f64> {
    first_root_in(c, 0.0, 1.0)
}

/// The smallest root of f in [lo, hi] ⊂ [0, 1] (the interval is clamped to [0, 1]; `None`
/// when lo > hi or either is NaN). Used to continue the search after rejecting a root.
///
/// # Panics
/// When `c` has more than [`STACK_LEN`] coefficients.
#[must_use]
pub fn first_root_in(c: &[f64], lo: f64, hi: f64) -> Option<f64> {
    first_root_in_tol(c, lo, hi, 0.0)
}

/// [`first_root_in`] where a value within `zero` of 0 at an end of [lo, hi] also counts as a
/// root there (at `lo` always; at `hi` when no earlier root exists). `zero` is on the caller's
/// scale: a ray tracer passes a rounding bound from the patch's largest weight, so that a root
/// exactly on a face shared by two tetrahedra cannot slip through both neighbours, and a
/// segment so short that all its coefficients are rounding noise (a ray through a mesh vertex)
/// still reports its root. With `zero` = 0 this is [`first_root_in`]; an identically zero
/// polynomial gives `Some(lo)` when `zero` > 0.
///
/// # Panics
/// When `c` has more than [`STACK_LEN`] coefficients.
#[must_use]
pub fn first_root_in_tol(c: &[f64], lo: f64, hi: f64, zero: f64) -> Option<f64> {
    macro_rules! dispatch {
        ($($n:literal)*) => {
            match c.len() {
                0 => None,
                $($n => first_root_fixed::<$n>(c.try_into().expect("length checked"), lo, hi, zero),)*
                len => panic!("first_root supports at most {STACK_LEN} coefficients, got {len}"),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

/// [`first_root_in`] for exactly N coefficients: every loop has a constant trip count.
#[inline]
fn first_root_fixed<const N: usize>(c: &[f64; N], lo: f64, hi: f64, zero: f64) -> Option<f64> {
    if lo.is_nan() || hi.is_nan() {
        return None;
    }
    let (lo, hi) = (lo.max(0.0), hi.min(1.0));
    if lo > hi {
        return None;
    }
    let mut scale: f64 = 0.0;
    for &x in c {
        scale = scale.max(x.abs());
    }
    if scale == 0.0 && zero > 0.0 {
        return Some(lo);
    }
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let tol = TOUCH_TOL * scale;
    if lo == hi {
        let (f, _) = eval_d(c, lo);
        return (f.abs() <= tol.max(zero)).then_some(lo);
    }
    // Coefficients on [lo, hi]: split at hi, then the left part at lo/hi.
    let b = if lo == 0.0 && hi == 1.0 {
        *c
    } else {
        let (left, _) = split(c, hi);
        split(&left, lo / hi).1
    };
    if zero > 0.0 && b[0].abs() <= zero {
        return Some(lo);
    }
    let root = if excluded(&b, tol) {
        None
    } else {
        Search {
            tol,
            splits: 0,
            top: &b,
            top_a: lo,
            top_w: hi - lo,
        }
        .search(&b, lo, hi - lo)
    };
    root.or_else(|| (zero > 0.0 && b[N - 1].abs() <= zero).then_some(hi))
}

/// (f(t), f′(t)) by de Casteljau on exactly N coefficients.
#[inline(always)]
fn eval_d<const N: usize>(c: &[f64; N], t: f64) -> (f64, f64) {
    if N == 1 {
        return (c[0], 0.0);
    }
    let mut b = *c;
    let s = 1.0 - t;
    for r in (2..N).rev() {
        for i in 0..r {
            b[i] = s * b[i] + t * b[i + 1];
        }
    }
    (s * b[0] + t * b[1], (N - 1) as f64 * (b[1] - b[0]))
}

/// De Casteljau subdivision at t into the pieces on [0, t] and [t, 1].
#[inline(always)]
fn split<const N: usize>(c: &[f64; N], t: f64) -> ([f64; N], [f64; N]) {
    let mut right = *c;
    let mut left = *c;
    let s = 1.0 - t;
    for r in 1..N {
        for i in 0..N - r {
            right[i] = s * right[i] + t * right[i + 1];
        }
        left[r] = right[0];
    }
    (left, right)
}

/// True when every coefficient is beyond τ on the same side: no root, no touch.
#[inline(always)]
fn excluded<const N: usize>(b: &[f64; N], tol: f64) -> bool {
    let (mut mn, mut mx) = (f64::INFINITY, f64::NEG_INFINITY);
    for &x in b {
        mn = mn.min(x);
        mx = mx.max(x);
    }
    mn > tol || mx < -tol
}

/// Number of sign changes in the sequence, exact zeros skipped.
#[inline(always)]
fn variations<const N: usize>(b: &[f64; N]) -> usize {
    let mut v = 0;
    let mut last = 0.0;
    for &x in b {
        if x != 0.0 {
            if last != 0.0 && (x > 0.0) != (last > 0.0) {
                v += 1;
            }
            last = x;
        }
    }
    v
}

/// True when every control-polygon slope b_{i+1} − b_i is beyond τ on the same side.
#[inline(always)]
fn monotone<const N: usize>(b: &[f64; N], tol: f64) -> bool {
    let (mut up, mut down) = (true, true);
    for i in 0..N - 1 {
        let d = b[i + 1] - b[i];
        up &= d > tol;
        down &= d < -tol;
    }
    up || down
}

struct Search<'a, const N: usize> {
    tol: f64,
    splits: usize,
    /// The whole polynomial on [top_a, top_a + top_w] (for refining touches).
    top: &'a [f64; N],
    top_a: f64,
    top_w: f64,
}

/// How far (in the whole interval's parameter) a touch leaf may be from the extremum it is
/// refined to: the stretch where |f| ≤ τ around a tangency is √(τ/|f″|) wide, 3e-4 even for
/// |f″| = 1e-6·max|c|.
const TOUCH_WINDOW: f64 = 1e-2;

impl<const N: usize> Search<'_, N> {
    /// First root of the polynomial with coefficients `b` on [a, a+w] (global parameter).
    fn search(&mut self, b: &[f64; N], a: f64, w: f64) -> Option<f64> {
        let n = N - 1;
        if b[0] == 0.0 {
            return Some(a);
        }
        let v = variations(b);
        if v == 1 && b[n] != 0.0 {
            return Some(a + w * polish(b));
        }
        if v == 0 {
            if b[n] == 0.0 {
                return Some(a + w);
            }
            if monotone(b, self.tol) {
                return None;
            }
        }
        if w <= LEAF_WIDTH || self.splits >= MAX_SPLITS {
            // A touch, or a cluster of roots narrower than the leaf width.
            if b[n] != 0.0 && (b[0] > 0.0) != (b[n] > 0.0) {
                return Some(a + w * polish(b));
            }
            return Some(self.touch(a + 0.5 * w));
        }
        self.splits += 1;
        let (left, right) = split(b, 0.5);
        let h = 0.5 * w;
        if !excluded(&left, self.tol) {
            if let Some(t) = self.search(&left, a, h) {
                return Some(t);
            }
        }
        if !excluded(&right, self.tol) {
            return self.search(&right, a + h, h);
        }
        None
    }
}

impl<const N: usize> Search<'_, N> {
    /// Refines a touch leaf at global `t`: Newton on f′ of the whole polynomial finds the
    /// nearby extremum; a sign change between the leaf and the extremum is bisected to the
    /// first root, otherwise the extremum is the touching point (when |f| ≤ τ there). Falls
    /// back to `t` when the refinement does not settle within [`TOUCH_WINDOW`].
    fn touch(&self, t: f64) -> f64 {
        if N < 3 {
            return t;
        }
        let to_global = |u: f64| self.top_a + u * self.top_w;
        let u0 = (t - self.top_a) / self.top_w;
        let (f0, _, _) = eval_d2(self.top, u0);
        let mut u = u0;
        let mut settled = false;
        for _ in 0..40 {
            let (_, d1, d2) = eval_d2(self.top, u);
            if d2 == 0.0 {
                break;
            }
            let step = d1 / d2;
            u -= step;
            if !((u - u0).abs() <= TOUCH_WINDOW && (0.0..=1.0).contains(&u)) {
                return t;
            }
            if step.abs() <= 4.0 * f64::EPSILON * u.abs().max(1e-3) {
                settled = true;
                break;
            }
        }
        if !settled {
            return t;
        }
        let (fe, _, _) = eval_d2(self.top, u);
        if fe == 0.0 {
            return to_global(u);
        }
        if f0 != 0.0 && (fe > 0.0) != (f0 > 0.0) {
            // A genuine crossing between the leaf and the extremum: bisect to it.
            let (mut lo, mut hi) = (u0.min(u), u0.max(u));
            let lo_positive = eval_d2(self.top, lo).0 > 0.0;
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if (eval_d2(self.top, mid).0 > 0.0) == lo_positive {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return to_global(0.5 * (lo + hi));
        }
        if fe.abs() <= self.tol {
            return to_global(u);
        }
        t
    }
}

/// (f, f′, f″) at t by de Casteljau down to the quadratic level (N ≥ 3).
#[inline]
fn eval_d2<const N: usize>(c: &[f64; N], t: f64) -> (f64, f64, f64) {
    let n = (N - 1) as f64;
    let mut b = *c;
    let s = 1.0 - t;
    for r in (3..N).rev() {
        for i in 0..r {
            b[i] = s * b[i] + t * b[i + 1];
        }
    }
    let (b0, b1, b2) = (b[0], b[1], b[2]);
    let f = s * s * b0 + 2.0 * s * t * b1 + t * t * b2;
    let d1 = n * (s * (b1 - b0) + t * (b2 - b1));
    let d2 = n * (n - 1.0) * (b0 - 2.0 * b1 + b2);
    (f, d1, d2)
}

/// Below this Newton correction (in the interval's own parameter) the iteration has reached
/// its quadratic phase: the error after the step is ~|f″/f′|·step² ≲ 1e-18·|f″/f′|.
const NEWTON_DONE: f64 = 1e-9;

/// The root in (0, 1) of a polynomial whose first and last coefficients are non-zero with
/// opposite signs: Newton from the control polygon's first crossing, kept inside the sign
/// bracket; a bisection replaces any step that leaves the bracket or that would not halve the
/// step before last (the `rtsafe` safeguard).
#[inline]
fn polish<const N: usize>(b: &[f64; N]) -> f64 {
    let n = N - 1;
    let positive_at_lo = b[0] > 0.0;
    // Start at the control polygon's first crossing of zero.
    let mut u = 0.5;
    for i in 0..n {
        if (b[i] > 0.0) != (b[i + 1] > 0.0) || b[i + 1] == 0.0 {
            u = (i as f64 + b[i] / (b[i] - b[i + 1])) / n as f64;
            break;
        }
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let (mut dx, mut dx_old) = (1.0_f64, 1.0_f64);
    let mut newton_steps = 0;
    for _ in 0..MAX_POLISH {
        let (f, df) = eval_d(b, u);
        if f == 0.0 {
            return u;
        }
        if (f > 0.0) == positive_at_lo {
            lo = u;
        } else {
            hi = u;
        }
        let step = f / df;
        if step.abs() <= 2.0 * f64::EPSILON * u {
            // Converged: the correction is below the resolution of u.
            return u;
        }
        let newton = u - step;
        if !(newton > lo && newton < hi) || (2.0 * f).abs() > (dx_old * df).abs() {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            u = lo + dx;
            newton_steps = 0;
        } else {
            dx_old = dx;
            dx = step;
            u = newton;
            newton_steps += 1;
            // Two successive Newton steps, the last one tiny: quadratic convergence.
            if newton_steps >= 2 && step.abs() <= NEWTON_DONE {
                return u;
            }
        }
        if hi - lo <= 2.0 * f64::EPSILON * hi {
            return u;
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::super::multiply;
    use super::*;

    /// Bernstein coefficients of Π (t − r).
    fn from_roots(roots: &[f64]) -> Vec<f64> {
        roots
            .iter()
            .fold(vec![1.0], |acc, &r| multiply(&acc, &[-r, 1.0 - r]))
    }

    /// Simple roots are polished to a few ulps.
    const SIMPLE: f64 = 1e-14;
    /// Tangencies are refined to the extremum (or to the first of two roots rounding split
    /// them into): √(rounding/|f″|) ≈ √(1e-15) ≈ 3e-8.
    const TOUCH: f64 = 1e-7;

    #[test]
    fn simple_roots() {
        let r = first_root(&[-0.3, 0.7]).unwrap();
        assert!((r - 0.3).abs() < SIMPLE);
        assert_eq!(first_root(&[1.0, 2.0, 0.5]), None);
        let c = from_roots(&[0.8, 0.2, 0.5]);
        assert!((first_root(&c).unwrap() - 0.2).abs() < SIMPLE);
        assert!((first_root_in(&c, 0.2 + 1e-9, 1.0).unwrap() - 0.5).abs() < SIMPLE);
        assert!((first_root_in(&c, 0.6, 0.9).unwrap() - 0.8).abs() < SIMPLE);
        assert_eq!(first_root_in(&c, 0.55, 0.75), None);
    }

    #[test]
    fn identically_zero_and_empty() {
        assert_eq!(first_root(&[0.0, 0.0, 0.0]), None);
        assert_eq!(first_root(&[]), None);
        assert_eq!(first_root(&[0.0, f64::NAN]), None);
    }

    #[test]
    fn roots_at_the_ends() {
        assert_eq!(first_root(&from_roots(&[0.0, 0.6])), Some(0.0));
        assert_eq!(first_root(&from_roots(&[1.0, 1.5])), Some(1.0));
        assert_eq!(first_root(&[2.0, 1.0, 0.0]), Some(1.0));
        // Double root at 0 (touch at the start).
        assert_eq!(first_root(&from_roots(&[0.0, 0.0, 0.7])), Some(0.0));
    }

    #[test]
    fn tangencies_are_reported() {
        for &r in &[0.5, 1.0 / 3.0, 0.123_456_7, 0.9] {
            for sign in [1.0, -1.0] {
                let c: Vec<f64> = from_roots(&[r, r, 1.7]).iter().map(|x| sign * x).collect();
                let t = first_root(&c).unwrap_or_else(|| panic!("touch at {r} missed"));
                assert!((t - r).abs() < TOUCH, "touch at {r}: got {t}");
            }
        }
        // Lifted clearly off zero: no root.
        let mut c = from_roots(&[0.4, 0.4]);
        for x in &mut c {
            *x += 1e-6;
        }
        assert_eq!(first_root(&c), None);
        // Two close simple roots: the first one.
        let c = from_roots(&[0.4 - 1e-4, 0.4 + 1e-4]);
        assert!((first_root(&c).unwrap() - (0.4 - 1e-4)).abs() < 1e-12);
    }

    #[test]
    fn extreme_scales() {
        let base = from_roots(&[0.3, 0.7, 1.4]);
        for &k in &[1e-12, 1e-6, 1e6, 1e12] {
            let c: Vec<f64> = base.iter().map(|x| k * x).collect();
            assert!((first_root(&c).unwrap() - 0.3).abs() < SIMPLE, "scale {k}");
        }
        // Coefficients spanning 1e-12..1e12 in one polynomial: the root is near 1e-24.
        let c = [1e-12, -1e12, 1e12];
        let t = first_root(&c).unwrap();
        let f = super::super::eval(&c, t);
        // |f| must be at rounding level of the largest coefficient.
        assert!(t < 1e-20 && f.abs() < 1e-3, "t={t} f={f}");
        let c = [1e12, 1e-12, -1e-12];
        let t = first_root(&c).unwrap();
        assert!(t > 0.99 && t <= 1.0, "t={t}");
    }

    #[test]
    fn high_multiplicity() {
        // (t − 0.5)^7: f stays within τ of 0 on |t − 0.5| < τ^(1/7) ≈ 0.014.
        let c = from_roots(&[0.5; 7]);
        let t = first_root(&c).unwrap();
        assert!((t - 0.5).abs() < 0.02, "t={t}");
    }

    #[test]
    fn end_values_within_the_callers_zero_are_roots() {
        // g = (t − 0.3)(t + 0.5) + 1e-12 is positive and increasing on [0.3, 0.5]: only its
        // rounding-sized value at the start makes a root, when the caller's zero admits it.
        let mut c = from_roots(&[0.3, -0.5]);
        for x in &mut c {
            *x += 1e-12;
        }
        assert_eq!(first_root_in(&c, 0.3, 0.5), None);
        assert_eq!(first_root_in_tol(&c, 0.3, 0.5, 1e-11), Some(0.3));
        // h = −(t − 0.3)(t + 0.5) + 1e-12 on [0.1, 0.3]: the same at the end.
        let h: Vec<f64> = from_roots(&[0.3, -0.5]).iter().map(|x| 1e-12 - x).collect();
        assert_eq!(first_root_in_tol(&h, 0.1, 0.3, 1e-11), Some(0.3));
        assert_eq!(first_root_in_tol(&h, 0.1, 0.3, 1e-13), None);
        // ... but only when nothing precedes it.
        let c2 = from_roots(&[0.2, 0.3]);
        let r = first_root_in_tol(&c2, 0.0, 0.3 - 1e-15, 1e-11).unwrap();
        // The simple root at 0.2 comes first (polished to a few ulps).
        assert!((r - 0.2).abs() < SIMPLE, "{r}");
        // All coefficients rounding noise (a segment through a vertex): a root at lo.
        assert_eq!(
            first_root_in_tol(&[1e-17, -2e-17, 1e-17], 0.0, 1.0, 1e-15),
            Some(0.0)
        );
        assert_eq!(first_root_in_tol(&[0.0, 0.0], 0.25, 1.0, 1e-15), Some(0.25));
        // zero = 0 is the plain finder.
        assert_eq!(
            first_root_in_tol(&c, 0.3, 0.5, 0.0),
            first_root_in(&c, 0.3, 0.5)
        );
    }
}

//! The first root of a univariate Bernstein polynomial on an interval.
//!
//! # Policy (what counts as a root)
//! With s = max|ck| and the tolerance τ = [`TOUCH_TOL`]·s, [`first_root_in`] returns the
//! smallest t in [lo, hi] such that
//! - f changes sign at t, or f(t) is exactly 0 (roots at 0 and 1 included), or
//! - f *touches* zero at t: |f| ≤ τ around a point where f is not monotone (a tangency or
//!   double root that rounding may have lifted slightly above zero or pushed slightly below).
//!
//! So tangential touches are **reported** (at the touching point, to within ≈ √(τ/|f″|) in t),
//! whichever side rounding puts them on. Where f stays within τ of zero over a stretch (roots of
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
//! 3. Intervals narrower than 2⁻³⁰ of [0, 1] that survive are touches: their midpoint is
//!    reported (or their root, if their ends differ in sign).

use super::{eval_with_derivative, subdivide_into, STACK_LEN};

/// Relative tolerance τ/max|ck| under which a coefficient counts as touching zero. Rounding in
/// a restricted segment polynomial is a few ulps of the largest weight; 1e-13 leaves ~500×
/// headroom over that while placing tangencies to ≈ 3e-7 of the interval.
pub const TOUCH_TOL: f64 = 1e-13;

/// Width (relative to [0, 1]) below which an unresolved interval is reported as a touch.
const LEAF_WIDTH: f64 = 1.0 / (1u64 << 30) as f64;

/// Cap on subdivisions per call (a degenerate polynomial cannot make the search run away).
const MAX_SPLITS: usize = 4096;

/// Newton iterations at most in the polish (bisection guarantees ≥ 1 bit per two steps).
const MAX_POLISH: usize = 100;

/// The smallest root of f in [0, 1] under the policy of this module; no heap allocation for
/// up to [`STACK_LEN`] coefficients.
#[inline]
#[must_use]
pub fn first_root(c: &[f64]) -> Option<f64> {
    first_root_in(c, 0.0, 1.0)
}

/// The smallest root of f in [lo, hi] ⊂ [0, 1] (the interval is clamped to [0, 1]; `None`
/// when lo > hi or either is NaN). Used to continue the search after rejecting a root.
///
/// # Panics
/// When `c` has more than 64 coefficients.
#[must_use]
pub fn first_root_in(c: &[f64], lo: f64, hi: f64) -> Option<f64> {
    let len = c.len();
    if len == 0 || lo.is_nan() || hi.is_nan() || lo > hi {
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
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let tol = TOUCH_TOL * scale;
    if len <= STACK_LEN {
        first_root_fixed::<STACK_LEN>(c, lo, hi, tol)
    } else {
        assert!(
            len <= 64,
            "first_root supports at most 64 coefficients, got {len}"
        );
        first_root_fixed::<64>(c, lo, hi, tol)
    }
}

#[inline]
fn first_root_fixed<const N: usize>(c: &[f64], lo: f64, hi: f64, tol: f64) -> Option<f64> {
    let len = c.len();
    if lo == 0.0 && hi == 1.0 {
        if excluded(c, tol) {
            return None;
        }
        let mut ctx = Search { tol, splits: 0 };
        return ctx.search::<N>(c, 0.0, 1.0);
    }
    if lo == hi {
        let (f, _) = eval_with_derivative(c, lo);
        return (f.abs() <= tol).then_some(lo);
    }
    // Coefficients on [lo, hi]: split at hi, then the left part at lo/hi.
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    let mut part = [0.0; N];
    subdivide_into(c, hi, &mut left, &mut right);
    subdivide_into(&left[..len], lo / hi, &mut right, &mut part);
    let b = &part[..len];
    if excluded(b, tol) {
        return None;
    }
    let mut ctx = Search { tol, splits: 0 };
    ctx.search::<N>(b, lo, hi - lo)
}

/// True when every coefficient is beyond τ on the same side: no root, no touch.
#[inline]
fn excluded(b: &[f64], tol: f64) -> bool {
    let (mut mn, mut mx) = (f64::INFINITY, f64::NEG_INFINITY);
    for &x in b {
        mn = mn.min(x);
        mx = mx.max(x);
    }
    mn > tol || mx < -tol
}

/// Number of sign changes in the sequence, exact zeros skipped.
#[inline]
fn variations(b: &[f64]) -> usize {
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
#[inline]
fn monotone(b: &[f64], tol: f64) -> bool {
    let (mut up, mut down) = (true, true);
    for w in b.windows(2) {
        let d = w[1] - w[0];
        up &= d > tol;
        down &= d < -tol;
    }
    up || down
}

struct Search {
    tol: f64,
    splits: usize,
}

impl Search {
    /// First root of the polynomial with coefficients `b` on [a, a+w] (global parameter).
    fn search<const N: usize>(&mut self, b: &[f64], a: f64, w: f64) -> Option<f64> {
        let n = b.len() - 1;
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
            return Some(a + 0.5 * w);
        }
        self.splits += 1;
        let mut left = [0.0; N];
        let mut right = [0.0; N];
        subdivide_into(b, 0.5, &mut left, &mut right);
        let h = 0.5 * w;
        if !excluded(&left[..=n], self.tol) {
            if let Some(t) = self.search::<N>(&left[..=n], a, h) {
                return Some(t);
            }
        }
        if !excluded(&right[..=n], self.tol) {
            return self.search::<N>(&right[..=n], a + h, h);
        }
        None
    }
}

/// The root in (0, 1) of a polynomial whose first and last coefficients are non-zero with
/// opposite signs: Newton from the control polygon's first crossing, kept inside the sign
/// bracket; a bisection replaces any step that leaves the bracket or that would not halve the
/// step before last (the `rtsafe` safeguard).
fn polish(b: &[f64]) -> f64 {
    let n = b.len() - 1;
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
    for _ in 0..MAX_POLISH {
        let (f, df) = eval_with_derivative(b, u);
        if f == 0.0 {
            return u;
        }
        if (f > 0.0) == positive_at_lo {
            lo = u;
        } else {
            hi = u;
        }
        let newton = u - f / df;
        if !(newton > lo && newton < hi) || (2.0 * f).abs() > (dx_old * df).abs() {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            u = lo + dx;
        } else {
            dx_old = dx;
            dx = u - newton;
            u = newton;
        }
        if dx.abs() <= 2.0 * f64::EPSILON * u || hi - lo <= 2.0 * f64::EPSILON * hi {
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
    /// Tangencies are placed to √(τ/|f″|) ≈ √(1e-13) ≈ 3e-7 (policy of the module).
    const TOUCH: f64 = 1e-6;

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
}

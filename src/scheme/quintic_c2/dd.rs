//! Double-double numbers (an unevaluated sum hi + lo of two f64, about 32 significant digits)
//! for the factorisation of Â Âᵀ where f64 is not enough: the normal equations square A's
//! condition number, so rows 1e-8 from the span of the others (A's κ ≈ 1e8) leave pivots of
//! 1e-16, all rounding in f64 ([`super::cholesky`]'s precise factor).
//!
//! Error-free transformations: Knuth's two-sum and the product's rounding error by a fused
//! multiply-add. Only what the factorisation needs: +, −, ×, ÷ and √.

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// hi + lo with |lo| ≤ ulp(hi)/2.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

/// a + b as hi + lo exactly (Knuth).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a + b as hi + lo exactly, for |a| ≥ |b| (or a = 0).
#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// a · b as hi + lo exactly (the rounding error of the product by a fused multiply-add).
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Add for Dd {
    type Output = Dd;
    #[inline]
    fn add(self, b: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, b: Dd) -> Dd {
        self + (-b)
    }
}

impl AddAssign for Dd {
    #[inline]
    fn add_assign(&mut self, b: Dd) {
        *self = *self + b;
    }
}

impl SubAssign for Dd {
    #[inline]
    fn sub_assign(&mut self, b: Dd) {
        *self = *self - b;
    }
}

impl Mul for Dd {
    type Output = Dd;
    #[inline]
    fn mul(self, b: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

impl Div for Dd {
    type Output = Dd;
    #[inline]
    fn div(self, b: Dd) -> Dd {
        // Long division: q1 = a/b in f64, then the remainder's quotient.
        let q1 = self.hi / b.hi;
        let r = self - b * Dd::of(q1);
        let q2 = r.hi / b.hi;
        let r = r - b * Dd::of(q2);
        let q3 = r.hi / b.hi;
        let (hi, lo) = quick_two_sum(q1, q2);
        Dd { hi, lo } + Dd::of(q3)
    }
}

/// The scalars [`super::cholesky`]'s factor runs in: f64, or [`Dd`] where f64 is not enough.
pub trait Real:
    Copy
    + Send
    + Sync
    + Default
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + AddAssign
    + SubAssign
{
    /// Whether the arithmetic uses `mul_add`, so that code running in it pays for FMA
    /// instructions ([`super::cholesky`] compiles its factor and solve with them where the
    /// processor has them).
    const FUSED: bool;
    /// a · b of two f64 (exact for [`Dd`]).
    fn product(a: f64, b: f64) -> Self;
    fn of(x: f64) -> Self;
    /// The nearest f64.
    fn f64(self) -> f64;
    fn root(self) -> Self;
}

impl Real for f64 {
    const FUSED: bool = false;
    #[inline]
    fn product(a: f64, b: f64) -> f64 {
        a * b
    }
    #[inline]
    fn of(x: f64) -> f64 {
        x
    }
    #[inline]
    fn f64(self) -> f64 {
        self
    }
    #[inline]
    fn root(self) -> f64 {
        self.sqrt()
    }
}

impl Real for Dd {
    const FUSED: bool = true;
    #[inline]
    fn product(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_prod(a, b);
        Dd { hi, lo }
    }
    #[inline]
    fn of(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }
    #[inline]
    fn f64(self) -> f64 {
        self.hi + self.lo
    }
    fn root(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd::of(self.hi.sqrt());
        }
        // One Newton step from the f64 root: √a ≈ s + (a − s²) / (2s).
        let s = self.hi.sqrt();
        let e = self - Dd::product(s, s);
        let (hi, lo) = quick_two_sum(s, e.hi / (2.0 * s));
        Dd { hi, lo }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (1 + 2⁻³⁰)² − 1 − 2⁻²⁹ is 2⁻⁶⁰ exactly: f64 rounds the square to 1 + 2⁻²⁹ and gives 0,
    /// the double-double product and differences keep it exactly.
    #[test]
    fn products_keep_what_f64_rounds_away() {
        let a = 1.0 + 2f64.powi(-30);
        let small = 2f64.powi(-60);
        let sq = Dd::product(a, a) - Dd::of(1.0) - Dd::of(2f64.powi(-29));
        assert_eq!(sq.f64(), small);
        assert_eq!(a * a - 1.0 - 2f64.powi(-29), 0.0);
    }

    /// Division and square root invert multiplication to ~1e-31 relative (double-double's
    /// precision, 2⁻¹⁰⁴ ≈ 5e-32, with a few roundings).
    #[test]
    fn division_and_root_invert_products() {
        let third = Dd::of(1.0) / Dd::of(3.0);
        let back = third * Dd::of(3.0) - Dd::of(1.0);
        assert!(back.f64().abs() < 1e-31, "{back:?}");
        let two = Dd::of(2.0);
        let r = two.root();
        let back = r * r - two;
        assert!(back.f64().abs() < 1e-31, "{back:?}");
        // Not just the f64 root.
        assert!(r.lo != 0.0);
    }
}

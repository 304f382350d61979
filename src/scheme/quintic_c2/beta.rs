//! β of a shared face: the barycentric coordinates, in tetrahedron A, of the vertex of B
//! opposite the face, which carry the C1 and C2 conditions (2.8), (2.9) from A's weights to
//! B's ([`super::system`]).
//!
//! The hull builds some of them exactly by construction: the point s of an edge tetrahedron
//! pair is the midpoint of the two apexes (Def. 3.6 (5)(ii)), so across the pair's shared face
//! β = (0, 0, −1, 2), the collinear case (2.10), (2.11). Stored in f64 the midpoint is off the
//! apexes' line by its rounding, and β computed from the stored points has components of
//! ~1e-14 where the construction has zeros (fandisk: on 29753 of its 31334 faces between edge
//! tetrahedra), so those faces' equations couple weights the scheme keeps apart, and the
//! joint group's rows come out nearly dependent (~1e-11 off the kept rows' span), which its
//! sign fit and the meet after it fight over.
//!
//! Three β, the scene's choice (`[scheme] face_beta`, [`FaceBeta`]): the f64 barycentric map
//! ([`crate::bb::Tet::bary`], the default, as the rows always were), [`exact`] (double-double
//! from the stored points) and [`snapped`] (that with the construction's zeros and integers
//! restored). What they do is in docs/quintic.md, "β of the shared faces, exact and snapped
//! (session 60)" and "Snapped β as a scene key; … (session 61)".

use super::dd::{Dd, Real as _};
use glam::DVec3;

/// Components of β below this fraction of its largest |component| are a construction's zero
/// left in by the stored points' rounding ([`snapped`]); the rows then change by less than
/// 1e-12 of their largest coefficient, far under the 1e-9 (gradient) and 1e-7 (Hessian) that
/// `apatch check` allows the jumps.
pub const SNAP: f64 = 1e-12;

/// Which β the C1/C2 rows carry (`[scheme] face_beta`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FaceBeta {
    /// The f64 barycentric map and f64 products (`"f64"`, the default; the rows before
    /// session 61, bit for bit).
    #[default]
    F64,
    /// [`exact`], coefficients formed in double-double and rounded once (`"exact"`).
    Exact,
    /// [`snapped`] [`exact`], coefficients as for `Exact` (`"snapped"`): the edge tetrahedron
    /// pairs' rows exactly collinear.
    Snapped,
}

impl FaceBeta {
    /// The scene key's names, in the order the error message lists them.
    pub const NAMES: [&'static str; 3] = ["f64", "exact", "snapped"];

    /// The modes [`Self::NAMES`] name, in the same order.
    const MODES: [FaceBeta; 3] = [FaceBeta::F64, FaceBeta::Exact, FaceBeta::Snapped];

    /// The mode a scene key's value names, `None` for any other string.
    #[must_use]
    pub fn named(name: &str) -> Option<FaceBeta> {
        let at = Self::NAMES.iter().position(|&n| n == name)?;
        Some(Self::MODES[at])
    }

    /// `self`, unless the exploration override `APATCH_FACE_BETA` names another mode (to
    /// compare the three on a scene without editing it; a resumed complex must be resumed
    /// with the rows it was solved with).
    #[must_use]
    pub fn or_env(self) -> FaceBeta {
        std::env::var("APATCH_FACE_BETA")
            .ok()
            .and_then(|v| FaceBeta::named(&v))
            .unwrap_or(self)
    }
}

/// β of `p` in the tetrahedron `tet` for a face's conditions, as `mode` asks.
#[must_use]
pub fn of_face(tet: &crate::bb::Tet, p: DVec3, mode: FaceBeta) -> [Dd; 4] {
    match mode {
        FaceBeta::F64 => tet.bary(p).map(Dd::of),
        FaceBeta::Exact => exact(tet.v, p),
        FaceBeta::Snapped => snapped(exact(tet.v, p)),
    }
}

/// The barycentric coordinates of `p` in the tetrahedron `v`, computed in double-double from
/// the f64 coordinates as stored (relative error ~1e-30 times the tetrahedron's condition).
#[must_use]
pub fn exact(v: [DVec3; 4], p: DVec3) -> [Dd; 4] {
    let diff = |a: DVec3, b: DVec3| {
        [
            Dd::of(a.x) - Dd::of(b.x),
            Dd::of(a.y) - Dd::of(b.y),
            Dd::of(a.z) - Dd::of(b.z),
        ]
    };
    let det = |a: [Dd; 3], b: [Dd; 3], c: [Dd; 3]| {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
    };
    let (e0, e1, e2, q) = (
        diff(v[0], v[3]),
        diff(v[1], v[3]),
        diff(v[2], v[3]),
        diff(p, v[3]),
    );
    let volume = det(e0, e1, e2);
    let b0 = det(q, e1, e2) / volume;
    let b1 = det(e0, q, e2) / volume;
    let b2 = det(e0, e1, q) / volume;
    [b0, b1, b2, Dd::of(1.0) - b0 - b1 - b2]
}

/// `beta` with its components below [`SNAP`] of the largest set to zero; when that leaves
/// components within [`SNAP`] of integers summing to one, those integers, else the last
/// nonzero one made up to a sum of one.
#[must_use]
pub fn snapped(beta: [Dd; 4]) -> [Dd; 4] {
    let big = beta.iter().fold(0.0_f64, |m, b| m.max(b.f64().abs()));
    let tol = SNAP * big;
    let mut out = beta;
    let mut zeroed = false;
    for b in &mut out {
        if b.f64() != 0.0 && b.f64().abs() <= tol {
            *b = Dd::of(0.0);
            zeroed = true;
        }
    }
    if !zeroed {
        return beta;
    }
    let nonzero: Vec<usize> = (0..4).filter(|&k| out[k].f64() != 0.0).collect();
    let near_integers = nonzero
        .iter()
        .all(|&k| (out[k].f64() - out[k].f64().round()).abs() <= tol);
    let integer_sum: f64 = nonzero.iter().map(|&k| out[k].f64().round()).sum();
    if near_integers && integer_sum == 1.0 {
        for &k in &nonzero {
            out[k] = Dd::of(out[k].f64().round());
        }
    } else if let Some((&last, rest)) = nonzero.split_last() {
        let mut sum = Dd::of(0.0);
        for &k in rest {
            sum += out[k];
        }
        out[last] = Dd::of(1.0) - sum;
    }
    out
}

/// The coefficient r!/γ! · β^γ of a condition (2.8), (2.9): in f64 as before session 61 for
/// [`FaceBeta::F64`], else formed in double-double and rounded once.
#[must_use]
pub fn coefficient(beta: &[Dd; 4], gamma: [u8; 4], mode: FaceBeta) -> f64 {
    if mode == FaceBeta::F64 {
        // The f64 products the rows were formed with before session 60, bit for bit.
        let mut coef = crate::bb::rational::multinomial(gamma);
        for k in 0..4 {
            coef *= beta[k].f64().powi(i32::from(gamma[k]));
        }
        return coef;
    }
    let mut c = Dd::of(crate::bb::rational::multinomial(gamma));
    for (b, &g) in beta.iter().zip(&gamma) {
        for _ in 0..g {
            c = c * *b;
        }
    }
    c.f64()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tet() -> [DVec3; 4] {
        [
            DVec3::new(0.1, -0.3, 0.2),
            DVec3::new(2.0, 0.1, -0.4),
            DVec3::new(0.3, 1.7, 0.5),
            DVec3::new(-0.2, 0.4, 1.9),
        ]
    }

    #[test]
    fn exact_barycentrics_rebuild_the_point_to_double_double() {
        let v = tet();
        let p = DVec3::new(0.37, 0.81, -1.3);
        let b = exact(v, p);
        // Σ β_k v_k − p in double-double, per coordinate: the f64 map leaves ~1e-16 here;
        // Cramer's rule in double-double on exact differences leaves rounding of ~1e-31
        // (times the entries' size, O(1)), so 1e-28 has three digits of room.
        for axis in 0..3 {
            let mut s = Dd::of(0.0) - Dd::of(p[axis]);
            for k in 0..4 {
                s += b[k] * Dd::of(v[k][axis]);
            }
            assert!(s.f64().abs() < 1e-28, "axis {axis}: {:e}", s.f64());
        }
        let sum = b.iter().fold(Dd::of(0.0), |s, x| s + *x);
        assert!((sum.f64() - 1.0).abs() < 1e-30, "sum {:e}", sum.f64());
        // Against the f64 map: the same numbers to its accuracy (cond ~10 here, so 1e-14).
        let f = crate::bb::Tet::new(v).unwrap().bary(p);
        for k in 0..4 {
            assert!(
                (b[k].f64() - f[k]).abs() < 1e-14,
                "{k}: {:e} vs {:e}",
                b[k].f64(),
                f[k]
            );
        }
    }

    #[test]
    fn a_rounded_midpoint_snaps_to_the_collinear_case() {
        // An edge tetrahedron [p_i, p_j, q0, s] and its partner's apex q1, s the stored
        // midpoint of q0 and q1 (Def. 3.6 (5)(ii)); coordinates that do not round-trip, so s
        // is off the line by its rounding.
        let (pi, pj) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.7, -0.1, 0.35));
        let (q0, q1) = (DVec3::new(0.41, 0.47, 0.9), DVec3::new(0.43, 0.13, -0.3));
        let s = 0.5 * (q0 + q1);
        let v = [pi, pj, q0, s];
        let raw = exact(v, q1);
        let off = raw[0].f64().abs().max(raw[1].f64().abs());
        // The stored points are not exactly collinear, so the exact β has off-line
        // components (if this ever rounds exactly, pick other coordinates: the test needs them).
        assert!(off > 0.0 && off < 1e-14, "off-line components {off:e}");
        let b = snapped(raw).map(|x| x.f64());
        assert_eq!(b, [0.0, 0.0, -1.0, 2.0]);
    }

    #[test]
    fn general_barycentrics_are_left_alone() {
        let v = tet();
        for p in [DVec3::new(0.37, 0.81, -1.3), DVec3::new(0.5, 0.5, 0.5)] {
            let b = exact(v, p);
            assert_eq!(snapped(b), b);
        }
        // A component that is small but well above SNAP of the largest stays.
        let b = [Dd::of(1e-9), Dd::of(0.3), Dd::of(0.7 - 1e-9), Dd::of(0.0)];
        assert_eq!(snapped(b), b);
    }

    #[test]
    fn a_snapped_ratio_keeps_its_sum() {
        // s at 0.3 of the way from q0 to q1: β = (0, 0, −7/3, 10/3), not integers; the tiny
        // components go and the sum stays one to double-double.
        let third = 1.0 / 3.0;
        let b = [
            Dd::of(3e-16),
            Dd::of(-2e-16),
            Dd::of(-7.0 * third),
            Dd::of(1.0 + 7.0 * third),
        ];
        let s = snapped(b);
        assert_eq!((s[0].f64(), s[1].f64()), (0.0, 0.0));
        assert_eq!(s[2], b[2]);
        let sum = s.iter().fold(Dd::of(0.0), |a, x| a + *x);
        assert!((sum.f64() - 1.0).abs() < 1e-30);
    }

    #[test]
    fn coefficients_are_the_multinomial_products() {
        let b = [Dd::of(0.5), Dd::of(-1.5), Dd::of(3.0), Dd::of(-1.0)];
        // 2!/(1! 1!) · 0.5 · (−1.5) = −1.5; 2!/2! · 3² = 9; 1 · (−1) = −1 (all exact in f64).
        assert_eq!(coefficient(&b, [1, 1, 0, 0], FaceBeta::Exact), -1.5);
        assert_eq!(coefficient(&b, [0, 0, 2, 0], FaceBeta::Exact), 9.0);
        assert_eq!(coefficient(&b, [0, 0, 0, 1], FaceBeta::Exact), -1.0);
    }
}

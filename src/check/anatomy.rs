//! Why a boundary face is crossed: which of its Bernstein coefficients stand against the sign
//! the data give it, and what fixes them.
//!
//! A boundary face with a corner p on the surface (an interpolated vertex, a point of T) has F = 0
//! at p, and its coefficients next to p are set by p's jet: the ones with p at multiplicity
//! n − 1 (the number 1 weights, n_p·(x − p)/n) by the normal and the hull's geometry, those at
//! n − 2 (number 2, for a C2 scheme) by the normal and the Hessian. The number 1 weights give
//! the face the only sign it can keep near p; where every coefficient has that sign the face is
//! not crossed (the Bernstein basis is positive), so a crossed face has a coefficient against it.
//! The one most against it, by its distance from the nearest point of T, says what a repair must
//! move: the normals or the hull (order 1), a jet's Hessian (order 2 in a C2 complex), or the
//! weights the scheme solves for (the stars, edge middles and late weights).

use super::faces::{point_key, PointKey};
use crate::bb::multi_indices;
use crate::complex::Patch;
use std::collections::HashSet;

/// What holds a crossed face's coefficient most against the face's sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum HeldBy {
    /// No corner of the face is on the surface, or the coefficients next to them are all zero:
    /// no sign is given, and none is judged.
    Unsigned,
    /// A number 1 weight: the normal at a point of T and the direction of the face's edge from
    /// it (the hull's geometry). No weight the scheme solves for changes it.
    Normal,
    /// A number 2 weight of a C2 complex: the jet's Hessian at a point of T.
    Hessian,
    /// A weight the scheme solves for beyond the jets.
    Weights,
}

impl HeldBy {
    /// The name in reports and in the `--holes` file.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            HeldBy::Unsigned => "unsigned",
            HeldBy::Normal => "normal",
            HeldBy::Hessian => "hessian",
            HeldBy::Weights => "weights",
        }
    }
}

/// The anatomy of one crossed face.
#[derive(Clone, Debug, PartialEq)]
pub struct Anatomy {
    /// The sign the face's number 1 weights give it (+1, −1; 0 when [`HeldBy::Unsigned`]); on
    /// a face in a tangent plane (all of them zero), the sign of the next order's sum.
    pub sign: i8,
    /// The patch-local multi-index of the coefficient most against that sign.
    pub index: [u8; 4],
    /// That coefficient times the sign, over the face's largest |coefficient| (negative when it
    /// is against the sign; 0 when unsigned).
    pub share: f64,
    /// Its distance from the nearest corner on the surface: n minus its largest multiplicity at
    /// such a corner (n when no corner is on the surface).
    pub order: u8,
    /// What fixes it.
    pub held_by: HeldBy,
}

/// The anatomy of the face of `patch` opposite its local vertex `opp`: `surface` holds the
/// [`point_key`]s of the complex's interpolated vertices (the schemes copy them into the
/// tetrahedra's corners, so a corner on the surface is bit for bit one of them), `continuity` the complex's promise (its
/// jets are of that order). `zero`: coefficients at or below this fraction of the face's
/// largest count as zero.
#[must_use]
pub fn anatomy(
    patch: &Patch,
    opp: usize,
    surface: &HashSet<PointKey>,
    continuity: u8,
    zero: f64,
) -> Anatomy {
    let n = patch.degree;
    let on_surface: Vec<bool> = (0..4)
        .map(|k| k != opp && surface.contains(&point_key(patch.tet[k])))
        .collect();
    let face: Vec<([u8; 4], f64)> = multi_indices(usize::from(n))
        .into_iter()
        .zip(patch.weights.iter().copied())
        .filter(|(l, _)| l[opp] == 0)
        .collect();
    let largest = face.iter().fold(0.0_f64, |m, c| m.max(c.1.abs()));
    let order = |l: &[u8; 4]| {
        n - (0..4)
            .filter(|&k| on_surface[k])
            .map(|k| l[k])
            .max()
            .unwrap_or(0)
    };
    // The number 1 weights share one sign on every face the tangent planes keep on one side;
    // their sum carries it (and is zero only when all are). On a face in a tangent plane they
    // are all zero and the next order's sum gives the sign F leaves the corners with.
    let unsigned = Anatomy {
        sign: 0,
        index: [0; 4],
        share: 0.0,
        order: n,
        held_by: HeldBy::Unsigned,
    };
    if largest == 0.0 || !on_surface.iter().any(|&s| s) {
        return unsigned;
    }
    let Some(first) = (1..n)
        .map(|k| {
            face.iter()
                .filter(|(l, _)| order(l) == k)
                .map(|c| c.1)
                .sum::<f64>()
        })
        .find(|s| s.abs() > zero * largest)
    else {
        return unsigned;
    };
    let sign = if first > 0.0 { 1 } else { -1 };
    let Some(&(index, w)) = face
        .iter()
        .min_by(|a, b| (f64::from(sign) * a.1).total_cmp(&(f64::from(sign) * b.1)))
    else {
        return unsigned;
    };
    let order = order(&index);
    let held_by = match order {
        0 | 1 => HeldBy::Normal,
        2 if continuity >= 2 => HeldBy::Hessian,
        _ => HeldBy::Weights,
    };
    Anatomy {
        sign,
        index,
        share: f64::from(sign) * w / largest,
        order,
        held_by,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bb::index_of;

    /// A degree-5 face tetrahedron over the triangle p0 p1 p2 (on the surface, z = −0.1) with
    /// apex p3 and F = z + 0.1: its weights are the corners' heights blended, so the base face
    /// (opposite 3) has every coefficient 0 and the faces through the apex one-signed ones.
    fn plane_patch(apex_z: f64) -> Patch {
        let tet = [
            [0.0, 0.0, -0.1],
            [1.0, 0.0, -0.1],
            [0.0, 1.0, -0.1],
            [0.3, 0.3, apex_z],
        ];
        let heights: Vec<f64> = tet.iter().map(|p| p[2] + 0.1).collect();
        let weights = multi_indices(5)
            .into_iter()
            .map(|l| (0..4).map(|k| f64::from(l[k]) * heights[k]).sum::<f64>() / 5.0)
            .collect();
        Patch {
            tet,
            degree: 5,
            weights,
            rational: Vec::new(),
            sheet: crate::complex::SheetRule::Any,
            role: crate::complex::Role::Face,
            element: 0,
            jvertex: Some(3),
            jedge: None,
        }
    }

    fn surface_of(p: &Patch, ks: &[usize]) -> HashSet<PointKey> {
        ks.iter().map(|&k| point_key(p.tet[k])).collect()
    }

    /// On the face [p0 p1 p3] of a linear F (corners p0, p1 on the surface) every coefficient
    /// has the apex's sign: the number 1 weights toward p3 give +1 and the face's least
    /// coefficient (0, on the edge p0 p1) is not against it.
    #[test]
    fn a_one_signed_face_has_nothing_against_its_sign() {
        let p = plane_patch(0.5);
        let s = surface_of(&p, &[0, 1, 2]);
        let a = anatomy(&p, 2, &s, 2, 1e-12);
        assert_eq!(a.sign, 1);
        // 1e-15: the edge p0 p1's weights are sums of zero heights.
        assert!(a.share.abs() < 1e-15, "{a:?}");
    }

    /// Each weight moved against the sign is named with what fixes it: one next to a corner
    /// on the surface at multiplicity 3 is a Hessian's (C2) or the solved weights' (C1), one at
    /// multiplicity 4 the normal's, and one at the apex the solved weights'.
    #[test]
    fn the_weight_most_against_the_sign_names_what_holds_it() {
        let s_of = |p: &Patch| surface_of(p, &[0, 1, 2]);
        let cases: [([u8; 4], u8, HeldBy, u8); 5] = [
            ([3, 0, 0, 2], 2, HeldBy::Hessian, 2),
            ([3, 0, 0, 2], 1, HeldBy::Weights, 2),
            ([3, 1, 0, 1], 2, HeldBy::Hessian, 2),
            ([1, 1, 0, 3], 2, HeldBy::Weights, 4),
            ([0, 0, 0, 5], 2, HeldBy::Weights, 5),
        ];
        for (l, continuity, held, order) in cases {
            let mut p = plane_patch(0.5);
            p.weights[index_of(l)] = -0.3;
            let a = anatomy(&p, 2, &s_of(&p), continuity, 1e-12);
            assert_eq!(
                (a.sign, a.index, a.held_by, a.order),
                (1, l, held, order),
                "{l:?}"
            );
            let largest = p
                .weights
                .iter()
                .zip(multi_indices(5))
                .filter(|(_, m)| m[2] == 0)
                .fold(0.0_f64, |m, (w, _)| m.max(w.abs()));
            // 1e-15: one division of the same two numbers.
            assert!((a.share + 0.3 / largest).abs() < 1e-15, "{a:?}");
        }
        // A number 1 weight against the others: their sum keeps the sign, and the normal holds it.
        let mut p = plane_patch(0.5);
        let l = [4, 0, 0, 1];
        p.weights[index_of(l)] = -0.01;
        let a = anatomy(&p, 2, &s_of(&p), 2, 1e-12);
        assert_eq!((a.sign, a.index, a.held_by), (1, l, HeldBy::Normal));
    }

    /// Without a corner on the surface (or with every number 1 weight zero, the base face of
    /// the plane) no sign is given.
    #[test]
    fn faces_without_a_signed_corner_are_unsigned() {
        let p = plane_patch(0.5);
        let a = anatomy(&p, 2, &HashSet::new(), 2, 1e-12);
        assert_eq!(a.held_by, HeldBy::Unsigned);
        let a = anatomy(&p, 3, &surface_of(&p, &[0, 1, 2]), 2, 1e-12);
        assert_eq!(a.held_by, HeldBy::Unsigned);
    }

    /// A face in the corners' tangent plane (the apex on the base's plane: every number 1
    /// weight zero) takes its sign from the next order.
    #[test]
    fn a_face_in_the_tangent_plane_takes_the_next_orders_sign() {
        let mut p = plane_patch(-0.1);
        let s = surface_of(&p, &[0, 1, 2]);
        p.weights[index_of([3, 0, 0, 2])] = 0.2;
        p.weights[index_of([2, 0, 0, 3])] = -0.1;
        let a = anatomy(&p, 2, &s, 2, 1e-12);
        assert_eq!(
            (a.sign, a.index, a.order, a.held_by),
            (1, [2, 0, 0, 3], 3, HeldBy::Weights)
        );
        p.weights[index_of([3, 0, 0, 2])] = -0.2;
        let a = anatomy(&p, 2, &s, 2, 1e-12);
        assert_eq!(a.sign, -1);
    }

    /// An inner apex (below the base) gives the face the negative sign.
    #[test]
    fn the_sign_follows_the_apex_side() {
        let p = plane_patch(-0.6);
        let a = anatomy(&p, 2, &surface_of(&p, &[0, 1, 2]), 2, 1e-12);
        assert_eq!(a.sign, -1);
    }
}

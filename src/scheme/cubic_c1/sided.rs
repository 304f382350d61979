//! Single or double sided: Definition 3.6 (4) of the 1994 paper builds one face tetrahedron on
//! a convex triangle of T and an L-U pair (one tetrahedron on each side) on a non-convex one.
//!
//! Why it matters: the weights of a face tetrahedron on its base triangle are fixed by the data
//! (a_3e_k = 0, number 1: a_2e_k+e_l = (p_l − p_k)·∇F(p_k)/3, number 2 from those). On a convex
//! triangle they share the sign of its side (≤ 0 outside, ≥ 0 inside: F keeps one sign on the
//! base, Theorem 2.1). When an edge of the triangle is convex the other way (Definition 3.1: the
//! edge runs above the tangent planes of an outer-only triangle), its two number 1 weights have
//! the opposite sign, F on the base changes sign, and with nothing on the other side the surface
//! ends at the base: a hole (`apatch check`'s "holes"). No free weight can change that; the
//! triangle needs the partner tetrahedron on its other side, as the paper prescribes.
//!
//! The inner hull (`hull::inner`, Algorithm 1 step (5)) decides single or double sided from the
//! pseudo-centroid's tangent plane alone, so on the 12×8 quad torus 24 triangles (a
//! pseudo-centroid and two centroids of neighbouring faces where the torus turns from convex to
//! saddle) have one apex but an edge convex the other way. [`complete_lu_pairs`] adds the
//! missing partner apexes before the cubic scheme runs.
//!
//! Where the partner apex q' goes: the existing apex q mirrored in the triangle's plane (a
//! tetrahedron of the same shape on the other side), then moved further away from the plane
//! until q' lies strictly on the partner's side of the three tangent planes at the triangle's
//! vertices: the number 1 weights a_2e_k+e_q' = (q' − p_k)·∇F(p_k)/3 of the partner's free faces
//! (the faces [p_k p_l q'] with no edge tetrahedron beyond them) then have the partner side's
//! sign, like the base weights of its convex edges.

use crate::hull::simplicial::{Side, SimplicialHull};
use glam::DVec3;

/// Relative tolerance for Definition 3.1's products (p_l − p_k)·n_k / |p_l − p_k|: zero-convex
/// (coplanar) edges give round-off of the coordinates (≈1e-16); the torus's wrong-way edges
/// give 0.1.
pub const CONVEXITY_TOL: f64 = 1e-9;

/// How far beyond the tangent planes the partner apex is put: this fraction of its distance to
/// the triangle's vertex.
pub const TANGENT_MARGIN: f64 = 0.05;

fn sign(side: Side) -> f64 {
    match side {
        Side::Outer => 1.0,
        Side::Inner => -1.0,
    }
}

fn other(side: Side) -> Side {
    match side {
        Side::Outer => Side::Inner,
        Side::Inner => Side::Outer,
    }
}

/// True when the triangle `t` of `hull` is convex for `side` (Definition 3.2 read with the sign
/// of the side): every product σ·(p_l − p_k)·n_k ≤ tolerance, i.e. every number 1 weight of its
/// base has the side's sign (σ = +1 outside).
#[must_use]
pub fn convex_for(hull: &SimplicialHull, t: usize, side: Side) -> bool {
    let tri = hull.triangles[t].map(|v| v as usize);
    let s = sign(side);
    (0..3).all(|k| {
        (0..3).filter(|&l| l != k).all(|l| {
            let d = hull.points[tri[l]] - hull.points[tri[k]];
            s * d.dot(hull.normals[tri[k]]) <= CONVEXITY_TOL * d.length()
        })
    })
}

/// The partner apex for triangle `t`, whose only apex `q` is on side `side` (see the module
/// documentation); `None` when the triangle is degenerate or a vertex normal lies in its plane.
#[must_use]
pub fn partner_apex(hull: &SimplicialHull, t: usize, side: Side, q: DVec3) -> Option<DVec3> {
    let tri = hull.triangles[t].map(|v| hull.points[v as usize]);
    let normals = hull.triangles[t].map(|v| hull.normals[v as usize]);
    let m = (tri[1] - tri[0]).cross(tri[2] - tri[0]).try_normalize()?;
    // The partner's side as a direction: −σ·m (m points to the outer side).
    let away = -sign(side) * m;
    let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
    let height = (q - centroid).dot(m).abs();
    let mut p = q - 2.0 * (q - centroid).dot(m) * m;
    if height <= 0.0 {
        return None;
    }
    // Move along `away` until every (p − p_k)·(σ'·n_k) ≥ margin·|p − p_k| (σ' = −σ).
    for _ in 0..3 {
        let mut step = 0.0f64;
        for (pk, nk) in tri.iter().zip(&normals) {
            let n_away = -sign(side) * *nk;
            let rate = away.dot(n_away);
            if rate <= 1e-3 {
                return None;
            }
            let need = TANGENT_MARGIN * (p - *pk).length() - (p - *pk).dot(n_away);
            step = step.max(need / rate);
        }
        if step <= 0.0 {
            return Some(p);
        }
        p += step * away;
    }
    Some(p)
}

/// `hull` with a partner apex on every single-sided triangle that is not convex for its side
/// ([`convex_for`]), and the triangles changed. (A triangle convex for the other side only would
/// be single sided there by Definition 3.6; it gets the partner too and keeps its apex, whose
/// tetrahedron then has F of the side's sign on its base.)
#[must_use]
pub fn complete_lu_pairs(hull: &SimplicialHull) -> (SimplicialHull, Vec<usize>) {
    let mut out = hull.clone();
    let mut changed = Vec::new();
    for t in 0..hull.triangles.len() {
        let sides = hull.apexes[t];
        let (side, q) = match sides {
            [Some(q), None] => (Side::Outer, q),
            [None, Some(q)] => (Side::Inner, q),
            _ => continue,
        };
        if convex_for(hull, t, side) {
            continue;
        }
        if let Some(p) = partner_apex(hull, t, side, q) {
            out.apexes[t][other(side) as usize] = Some(p);
            changed.push(t);
        }
    }
    (out, changed)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;

    /// One triangle [0 1 2] of the points 0, x, y in z = 0 (element 0) with the outer apex
    /// (0.3, 0.3, 0.5) and `inner_apex` as its partner; normal z at point 0 and normals tilted by
    /// `tilt` at the points 1 and 2 (towards each other when positive: the edge [1 2] runs above
    /// their tangent planes). Also the fixture of [`super::super::tangent`]'s tests.
    pub(crate) fn tilted_triangle(tilt: f64, inner_apex: Option<DVec3>) -> SimplicialHull {
        SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![
                DVec3::Z,
                DVec3::new(-tilt, tilt, 1.0).normalize(),
                DVec3::new(tilt, -tilt, 1.0).normalize(),
            ],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[Some(DVec3::new(0.3, 0.3, 0.5)), inner_apex]],
            element: vec![0],
        }
    }

    /// The single-sided triangle (outer apex only) with normals tilted by `tilt`.
    fn hull(tilt: f64) -> SimplicialHull {
        tilted_triangle(tilt, None)
    }

    #[test]
    fn convex_triangle_keeps_one_apex() {
        // tilt −0.3: the edge [1 2] runs below both tangent planes (positively convex).
        for tilt in [0.0, -0.3] {
            let h = hull(tilt);
            assert!(convex_for(&h, 0, Side::Outer));
            let (out, changed) = complete_lu_pairs(&h);
            assert!(changed.is_empty());
            assert_eq!(out.apexes, h.apexes);
        }
    }

    #[test]
    fn nonconvex_triangle_gets_a_partner_beyond_the_tangent_planes() {
        let h = hull(0.3);
        assert!(!convex_for(&h, 0, Side::Outer));
        // Seen from the inner side every edge runs the right way.
        assert!(convex_for(&h, 0, Side::Inner));
        let (out, changed) = complete_lu_pairs(&h);
        assert_eq!(changed, vec![0]);
        assert_eq!(out.apexes[0][0], h.apexes[0][0]);
        let q = out.apexes[0][1].expect("partner apex");
        // Inner side of z = 0, at least as deep as the mirrored apex.
        assert!(q.z <= -0.5 + 1e-12, "{q}");
        for (p, n) in h.points.iter().zip(&h.normals) {
            // Beyond every tangent plane by the margin (up to the last iteration's rounding).
            let d = (q - *p).dot(*n);
            assert!(d <= -(TANGENT_MARGIN - 1e-9) * (q - *p).length(), "{q} {d}");
        }
    }
}

//! Apexes beyond the tangent planes of their triangle's points, on their own side.
//!
//! Definition 3.5 asks of an L-U pair only that the tangent plane at each of its triangle's
//! points p_k cut *one* of the two face tetrahedra (`hull::inner::verify` checks exactly that).
//! The cubic scheme needs more. Its number 1 weights toward an apex q on side σ,
//! a_2e_k+e_q = (q − p_k)·∇F(p_k)/3, are fixed by the data; on the faces [p_k q s] of the edge
//! tetrahedra that no other tetrahedron shares (boundary faces of the hull), and on the free
//! side faces [p_k p_l q] of an L-U pair's tetrahedron, F starts at p_k with these slopes.
//! When σ·(q − p_k)·n_k < 0 the apex lies on the other side of p_k's tangent plane, F takes the
//! sign −σ on that face next to p_k while its weights of levels ≥ 2 have the sign σ (Theorem
//! 2.1's sign conditions): the surface leaves the hull through the face (a hole, `apatch check`'s
//! "holes"). No free weight can change a number 1 weight; only the apex can move.
//!
//! [`contain_tangents`] moves every such apex along σ·m (m the triangle's outer unit normal),
//! away from its triangle, by the least step that puts it on its side of all three tangent planes
//! with the margin [`TANGENT_MARGIN`] × |q − p_k|. Then σ(s − p_k)·n_k ≥ 0 too for the midpoint s
//! of two such apexes (the edge tetrahedra's fourth point), so every face [p_k q s] starts with
//! slopes of the sign σ. Apexes already on their side (up to [`TANGENT_TOL`], which keeps the
//! step (3) apexes that lie *on* a tangent plane in place) are not moved.

use crate::hull::simplicial::{Side, SimplicialHull};
use glam::DVec3;

/// Relative slope σ(q − p_k)·n_k / |q − p_k| below which an apex counts as beyond a tangent
/// plane: apexes put on a tangent plane by construction (Algorithm 1's step (3) apex V lies on
/// the planes of its centroids) give round-off of the coordinates (≈1e-16).
pub const TANGENT_TOL: f64 = 1e-9;

/// Relative slope a moved apex gets at its worst point of the triangle: room above round-off so
/// that the faces' number 1 weights are certifiably of the side's sign.
pub const TANGENT_MARGIN: f64 = 0.02;

/// Smallest m·n_k for which moving along the triangle's normal raises the slope at p_k: the
/// slope of a point far along the normal tends to m·n_k, so it must clear [`TANGENT_MARGIN`]
/// well (normals nearly in the triangle's plane are left alone: the step would be unbounded).
pub const MIN_RATE: f64 = 2.0 * TANGENT_MARGIN;

/// Largest move, relative to the triangle's longest edge. A longer needle would reach over
/// its neighbours' tetrahedra (spot and bunny need at most 0.1 and 0.29; mpi_poly's nearly
/// coplanar corners asked for 6e5).
pub const MAX_LIFT: f64 = 1.0;

fn sign(side: Side) -> f64 {
    match side {
        Side::Outer => 1.0,
        Side::Inner => -1.0,
    }
}

/// The smallest relative slope σ(q − p_k)·n_k / |q − p_k| of apex `q` of triangle `t` on `side`.
#[must_use]
pub fn worst_slope(hull: &SimplicialHull, t: usize, side: Side, q: DVec3) -> f64 {
    let s = sign(side);
    hull.triangles[t]
        .iter()
        .map(|&v| {
            let (p, n) = (hull.points[v as usize], hull.normals[v as usize]);
            let d = q - p;
            s * d.dot(n) / d.length().max(f64::MIN_POSITIVE)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The apex `q` of triangle `t` on `side`, moved along σ·m until every slope is at least
/// [`TANGENT_MARGIN`] (up to 1e-6 relative). Where σ·m raises some slope by less than
/// [`MIN_RATE`] (a vertex normal nearly in the triangle's plane, or tilted away from m), it
/// moves instead along the direction d with d·n_k = σ at all three points (every slope rises
/// alike), when d points to the apex's side; `None` when neither direction has the rate or the
/// move would exceed [`MAX_LIFT`].
#[must_use]
pub fn contained_apex(hull: &SimplicialHull, t: usize, side: Side, q: DVec3) -> Option<DVec3> {
    let tri = hull.triangles[t].map(|v| hull.points[v as usize]);
    let normals = hull.triangles[t].map(|v| hull.normals[v as usize]);
    let m = (tri[1] - tri[0]).cross(tri[2] - tri[0]).try_normalize()?;
    let longest = (0..3)
        .map(|k| (tri[k] - tri[(k + 1) % 3]).length())
        .fold(0.0, f64::max);
    let s = sign(side);
    let mut away = s * m;
    if normals.iter().any(|n| away.dot(*n) * s <= MIN_RATE) {
        // The direction raising every slope alike: d · n_k = σ for all three points (mpi_poly
        // cleaned, corner 71: a normal at −0.05 to the triangle's).
        let nm = glam::DMat3::from_cols(normals[0], normals[1], normals[2]).transpose();
        if nm.determinant().abs() > 1e-6 {
            let d = nm.inverse() * DVec3::splat(s);
            if let Some(d) = d.try_normalize() {
                if d.dot(s * m) > 0.0 {
                    away = d;
                }
            }
        }
    }
    let mut p = q;
    // The margin grows with |p − p_k| as p moves: a few rounds reach it (each round's shortfall
    // shrinks by the factor TANGENT_MARGIN / rate ≤ 1/2).
    for _ in 0..30 {
        let mut step = 0.0f64;
        for (pk, nk) in tri.iter().zip(&normals) {
            let rate = s * away.dot(*nk);
            let need = TANGENT_MARGIN * (p - *pk).length() - s * (p - *pk).dot(*nk);
            if need <= 0.0 {
                // Met; the final check sees it if later steps (rate < 0) undo it.
                continue;
            }
            if rate <= MIN_RATE {
                return None;
            }
            step = step.max(need / rate);
        }
        if step <= 1e-6 * TANGENT_MARGIN * longest {
            break;
        }
        p += step * away;
        if (p - q).length() > MAX_LIFT * longest {
            return None;
        }
    }
    (worst_slope(hull, t, side, p) >= TANGENT_MARGIN - 1e-6).then_some(p)
}

/// True when triangle `t`'s base is not one-signed for `side` and the apex is an L-U pair's:
/// some base point p_l lies beyond another's tangent plane on the side's sign,
/// σ(p_l − p_k)·n_k > 0 (a concave edge of T under the apex: number 1 weights of the base with
/// the apex's sign). With the apex on all three tangent planes (Algorithm 1's step (3) apex V
/// of a trihedral corner) the face tetrahedron's level-1 weights toward the apex are only the
/// edge blossoms, and where those have the other sign the lines from the apex to the base
/// points near the surface cross it twice whatever the apex weights (mpi_poly cleaned: corner
/// 71, whose faces 6 and 7 meet at a 41° groove).
fn mixed_base(hull: &SimplicialHull, t: usize, side: Side) -> bool {
    if hull.apexes[t].iter().any(Option::is_none) {
        return false;
    }
    let s = sign(side);
    let tri = hull.triangles[t];
    (0..3).any(|k| {
        let (pk, nk) = (hull.points[tri[k] as usize], hull.normals[tri[k] as usize]);
        (0..3).filter(|&l| l != k).any(|l| {
            let d = hull.points[tri[l] as usize] - pk;
            s * d.dot(nk) > TANGENT_TOL * d.length()
        })
    })
}

/// `hull` with every apex that lies beyond one of its triangle's tangent planes (slope below
/// −[`TANGENT_TOL`]), or on them over a base that is not one-signed ([`mixed_base`]), moved by
/// [`contained_apex`], the (triangle, side) pairs moved, and how many such apexes could not be
/// moved.
#[must_use]
pub fn contain_tangents(hull: &SimplicialHull) -> (SimplicialHull, Vec<(usize, Side)>, usize) {
    contain_tangents_with(hull, 0.0)
}

/// [`contain_tangents`] that also moves every apex whose worst slope is below `clearance` (> 0)
/// though on its side, to the margin [`TANGENT_MARGIN`]. The quintic needs it where apexes lie
/// *on* a point's tangent plane: Algorithm 1 puts step (3) and (5)(i) apexes on the
/// polyhedron's edges, so on a flat face the boundary faces [p q s] of the edge tetrahedra next
/// to its points lie in the surface's own plane, their number 1 and 2 weights vanish, and the
/// star weights (λ_p = 2), which the C2 conditions fix far from the data, decide on which side
/// the surface leaves p (mpi_poly: most edge-tetrahedron holes). `clearance` 0 is
/// [`contain_tangents`] exactly.
#[must_use]
pub fn contain_tangents_with(
    hull: &SimplicialHull,
    clearance: f64,
) -> (SimplicialHull, Vec<(usize, Side)>, usize) {
    let mut out = hull.clone();
    let mut moved = Vec::new();
    let mut stuck = 0;
    for t in 0..hull.triangles.len() {
        for side in Side::BOTH {
            let Some(q) = hull.apexes[t][side as usize] else {
                continue;
            };
            let slope = worst_slope(hull, t, side, q);
            let beyond = slope < -TANGENT_TOL;
            let on_mixed = slope <= TANGENT_TOL && mixed_base(hull, t, side);
            if !beyond && !on_mixed && (clearance <= 0.0 || slope >= clearance) {
                continue;
            }
            match contained_apex(hull, t, side, q) {
                Some(p) => {
                    out.apexes[t][side as usize] = Some(p);
                    moved.push((t, side));
                }
                None => stuck += 1,
            }
        }
    }
    (out, moved, stuck)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One triangle in z = 0, normals tilted towards each other at the points 1 and 2, an
    /// L-U pair whose inner apex lies just below the plane: above the tangent planes at 1 and 2.
    fn hull(inner_apex: DVec3) -> SimplicialHull {
        super::super::sided::tests::tilted_triangle(0.4, Some(inner_apex))
    }

    /// The shallow inner apex is beyond the tangent planes (its slopes are checked
    /// independently, by the dot products); after the move every slope is at least the margin,
    /// it moved straight down (along −m), and the outer apex, already above its planes, stayed.
    #[test]
    fn shallow_apex_is_moved_below_the_tangent_planes() {
        let q = DVec3::new(0.3, 0.3, -0.05);
        let h = hull(q);
        // The premise: (q − p_1)·n_1 > 0, the inner apex is on the outer side of p_1's plane.
        assert!((q - h.points[1]).dot(h.normals[1]) > 0.0);
        let (out, moved, stuck) = contain_tangents(&h);
        assert_eq!((moved, stuck), (vec![(0, Side::Inner)], 0));
        assert_eq!(out.apexes[0][0], h.apexes[0][0]);
        let p = out.apexes[0][1].expect("apex");
        // Along −z only (exact: the step is a multiple of (0, 0, −1)).
        assert_eq!((p.x, p.y), (q.x, q.y));
        assert!(p.z < q.z);
        for (pk, nk) in h.points.iter().zip(&h.normals) {
            let slope = -(p - *pk).dot(*nk) / (p - *pk).length();
            // The margin, up to the last round's growth of |p − p_k| (1e-6 relative).
            assert!(slope >= TANGENT_MARGIN - 1e-6, "{slope}");
        }
    }

    /// A normal nearly in the triangle's plane (m·n = 0.01 at point 1, below [`MIN_RATE`]):
    /// the slope there can hardly be raised by moving along m, so the apex is left where it was
    /// (counted as stuck) instead of moved a long way.
    #[test]
    fn apex_over_a_grazing_normal_is_stuck() {
        let mut h = hull(DVec3::new(0.3, 0.3, -0.05));
        h.normals[1] = DVec3::new(-1.0, 0.3, 0.01).normalize();
        // The premise: the apex is beyond that tangent plane ((q − p_1)·n_1 > 0 on the inner
        // side) and m·n_1 < MIN_RATE.
        assert!((DVec3::new(0.3, 0.3, -0.05) - h.points[1]).dot(h.normals[1]) > 0.0);
        assert!(h.normals[1].z < MIN_RATE);
        let (out, moved, stuck) = contain_tangents(&h);
        assert!(moved.is_empty() && stuck == 1);
        assert_eq!(out.apexes, h.apexes);
    }

    /// An L-U pair's outer apex on all three tangent planes (as Algorithm 1's apex V of a
    /// trihedral corner is) over a base with a concave edge (p_1 beyond p_0's tangent plane on
    /// the outer side): moved off the planes to the margin (slopes checked by the dot products).
    /// The same apex over a single-sided triangle stays where it is.
    #[test]
    fn on_plane_apex_over_a_mixed_base_is_moved() {
        let q = DVec3::new(0.3, 0.3, 0.5);
        let mut h = hull(DVec3::new(0.3, 0.3, -2.0));
        h.apexes[0][0] = Some(q);
        // Each normal orthogonal to q − p_k.
        h.normals = vec![
            DVec3::new(1.0, -5.0 / 3.0, 0.4).normalize(),
            DVec3::new(0.0, -5.0, 3.0).normalize(),
            DVec3::new(-0.5, 0.0, 0.3).normalize(),
        ];
        for k in 0..3 {
            assert!((q - h.points[k]).dot(h.normals[k]).abs() < 1e-12);
        }
        assert!((h.points[1] - h.points[0]).dot(h.normals[0]) > 0.0);
        let (out, moved, stuck) = contain_tangents(&h);
        assert_eq!((moved, stuck), (vec![(0, Side::Outer)], 0));
        assert_eq!(out.apexes[0][1], h.apexes[0][1]);
        let p = out.apexes[0][0].expect("apex");
        for (pk, nk) in h.points.iter().zip(&h.normals) {
            let slope = (p - *pk).dot(*nk) / (p - *pk).length();
            // The margin, up to the last round's growth of |p − p_k| (1e-6 relative).
            assert!(slope >= TANGENT_MARGIN - 1e-6, "{slope}");
        }
        let mut single = h.clone();
        single.apexes[0][1] = None;
        let (out, moved, stuck) = contain_tangents(&single);
        assert!(moved.is_empty() && stuck == 0);
        assert_eq!(out.apexes, single.apexes);
    }

    /// An outer apex on its side of every tangent plane but on one of them (slope 0 at p_0, as
    /// Algorithm 1's apexes on the polyhedron's edges are on a flat face's plane), over a
    /// single-sided triangle: [`contain_tangents`] leaves it, a clearance above its worst slope
    /// moves it to the margin (slopes checked by the dot products), and a clearance below it
    /// changes nothing.
    #[test]
    fn apex_on_a_tangent_plane_is_cleared_on_request() {
        let mut h = hull(DVec3::new(0.3, 0.3, -2.0));
        h.apexes[0][1] = None;
        let q = h.apexes[0][0].expect("outer apex");
        // Turn n_0 about the triangle's plane until q − p_0 lies in p_0's tangent plane,
        // keeping n_0 towards the outer side (+z).
        let d = (q - h.points[0]).normalize();
        let n0 = (DVec3::Z - d * d.z).normalize();
        h.normals[0] = n0;
        assert!((q - h.points[0]).dot(n0).abs() < 1e-12 && n0.z > 0.0);
        let worst = worst_slope(&h, 0, Side::Outer, q);
        assert!(worst.abs() < 1e-12, "{worst}");
        let (out, moved, _) = contain_tangents(&h);
        assert!(moved.is_empty());
        assert_eq!(out.apexes, h.apexes);
        let (out, moved, stuck) = contain_tangents_with(&h, 0.01);
        assert_eq!((moved, stuck), (vec![(0, Side::Outer)], 0));
        let p = out.apexes[0][0].expect("apex");
        for (pk, nk) in h.points.iter().zip(&h.normals) {
            let slope = (p - *pk).dot(*nk) / (p - *pk).length();
            // The margin, up to the last round's growth of |p − p_k| (1e-6 relative).
            assert!(slope >= TANGENT_MARGIN - 1e-6, "{slope}");
        }
        let (out, moved, _) = contain_tangents_with(&h, -0.5);
        assert!(moved.is_empty());
        assert_eq!(out.apexes, h.apexes);
        // Just below the plane by round-off (slope −1e-11, within TANGENT_TOL): clearance 0 is
        // the old rule exactly, which leaves it.
        let mut low = h.clone();
        low.apexes[0][0] = Some(q - 1e-11 * (q - h.points[0]).length() * n0);
        let worst = worst_slope(&low, 0, Side::Outer, low.apexes[0][0].unwrap());
        assert!(worst < 0.0 && worst > -TANGENT_TOL, "{worst}");
        for clearance in [0.0, -0.5] {
            let (out, moved, _) = contain_tangents_with(&low, clearance);
            assert!(moved.is_empty(), "{clearance}");
            assert_eq!(out.apexes, low.apexes);
        }
    }

    /// A deep inner apex already on its side of every tangent plane is left alone.
    #[test]
    fn contained_apex_stays() {
        let h = hull(DVec3::new(0.3, 0.3, -2.0));
        let (out, moved, stuck) = contain_tangents(&h);
        assert!(moved.is_empty() && stuck == 0);
        assert_eq!(out.apexes, h.apexes);
    }
}

//! Edge tetrahedra thick enough for C2 (beyond the paper).
//!
//! The edge tetrahedra `[p_i p_j q s]` over an edge of T join the apexes `q0`, `q1` of the two
//! face tetrahedra on one side. Where those apexes and the edge are nearly coplanar (an L-U
//! partner added by [`crate::scheme::cubic_c1::sided::complete_lu_pairs`] or an apex moved by
//! the apex search next to a fold of T, both near the fold's bisecting plane) the edge
//! tetrahedra are slivers. The C2 conditions hold exactly in BB form, but the patch's world
//! Hessian carries the rounding of its f64 weights times (L / h)², h its smallest height:
//! spot_control_cage's two slivers, h / L ≈ 1e-4, gave a Hessian jump of 1.9e-7 (the check
//! allows 1e-7) where every other face jumps by less than 1e-9.
//!
//! [`thicken`] moves such apexes apart, each away from the plane that bisects the fold at the
//! edge towards its own triangle (the rotation that opens the edge tetrahedra), by the least of
//! a few steps that makes the pair's relative volume reach [`EDGE_MIN_VOLUME`], and keeps a
//! move only when no face tetrahedron the moved apexes belong to becomes thinner than
//! [`FACE_MIN_VOLUME`] (or than it was), no base vertex's tangent plane changes sides with
//! respect to a moved apex unless to the apex's own side (Definition 3.5 and Theorem 2.1's signs
//! are kept or gained, never lost), and the hull's verification finds no more violations than
//! before.

use crate::hull::inner::degenerate::relative_volume;
use crate::hull::inner::verify::verify;
use crate::hull::inner::wedge::inward_directions;
use crate::hull::simplicial::{HullEdge, Side, SimplicialHull};
use glam::DVec3;

/// Relative volume 6V / L³ (L the longest edge) below which an edge tetrahedron is thickened.
/// spot_control_cage's two slivers that broke the Hessian bound lie below it; of the other
/// shipped quintic scenes the thinnest is the nut's, 7.4e-4 (the ignored survey
/// `edge_sliver_survey` in `tests/quintic_c2.rs`), so they are unchanged. The pending fandisk
/// (13 below, down to 2.9e-6) and mpi_poly (2, 6.7e-5) have some.
pub const EDGE_MIN_VOLUME: f64 = 1e-4;

/// Relative volume a moved apex's face tetrahedra keep at least ([`crate::hull::inner::verify::C2_MIN_VOLUME`]).
pub const FACE_MIN_VOLUME: f64 = crate::hull::inner::verify::C2_MIN_VOLUME;

/// Distances, in edge lengths, that the moved apexes are given from the bisecting plane, tried
/// in turn (the least that reaches [`EDGE_MIN_VOLUME`] is kept). The hull's own wedge margin is
/// 0.005 ([`crate::hull::inner::wedge::WEDGE_MARGIN`]).
const STEPS: [f64; 5] = [0.01, 0.02, 0.04, 0.08, 0.16];

/// One edge whose edge tetrahedra were thin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sliver {
    /// The edge's two points of T.
    pub edge: [u32; 2],
    /// The side of T its edge tetrahedra lie on.
    pub side: Side,
    /// The smaller relative volume of its pair before.
    pub before: f64,
    /// After (equal to `before` when no move was kept).
    pub after: f64,
}

/// The smaller relative volume |6V| / L³ of the pair of edge tetrahedra `[p_i p_j q s]`, s the
/// apexes' midpoint (the quintic's [`crate::hull::simplicial::EdgePoint::Midpoint`]).
#[must_use]
pub fn pair_volume(pi: DVec3, pj: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let s = 0.5 * (q0 + q1);
    relative_volume(pi, pj, q0, s)
        .abs()
        .min(relative_volume(pi, pj, q1, s).abs())
}

/// Every edge of T and side whose edge tetrahedra have a relative volume below `bound`, with
/// that volume.
#[must_use]
pub fn thin_edges(hull: &SimplicialHull, bound: f64) -> Vec<(usize, Side, f64)> {
    let Ok(edges) = hull.edges() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (e, edge) in edges.iter().enumerate() {
        for side in Side::BOTH {
            if let Some((q0, q1)) = apex_pair(hull, edge, side) {
                let (pi, pj) = ends(hull, edge);
                let v = pair_volume(pi, pj, q0, q1);
                if v < bound {
                    out.push((e, side, v));
                }
            }
        }
    }
    out
}

fn ends(hull: &SimplicialHull, e: &HullEdge) -> (DVec3, DVec3) {
    (hull.points[e.v[0] as usize], hull.points[e.v[1] as usize])
}

fn apex_pair(hull: &SimplicialHull, e: &HullEdge, side: Side) -> Option<(DVec3, DVec3)> {
    if e.faces[1] == u32::MAX {
        return None;
    }
    let [fa, fb] = e.faces.map(|f| f as usize);
    Some((
        hull.apexes[fa][side as usize]?,
        hull.apexes[fb][side as usize]?,
    ))
}

/// The unit normal of the plane through the edge that bisects the fold between its two
/// triangles, pointing to the first triangle's side (`None` for a degenerate edge or triangle,
/// or two triangles folded onto each other).
fn bisector_normal(hull: &SimplicialHull, e: &HullEdge) -> Option<DVec3> {
    let [ua, ub] = inward_directions(hull, e)?;
    (ua - ub).try_normalize()
}

/// Signs of n_k · (q − p_k) at the base vertices of triangle `t` for apex `q`.
fn plane_signs(hull: &SimplicialHull, t: usize, q: DVec3) -> [i8; 3] {
    hull.triangles[t].map(|k| {
        let d = hull.normals[k as usize].dot(q - hull.points[k as usize]);
        if d > 0.0 {
            1
        } else if d < 0.0 {
            -1
        } else {
            0
        }
    })
}

/// Whether apex `q` may replace triangle `t`'s apex on `side`: its face tetrahedron stays on
/// that side with a relative volume of at least [`FACE_MIN_VOLUME`] (or, where it was thinner,
/// at least what it had: flat nets' tetrahedra are) and no base vertex's tangent plane changes
/// side except to put the apex on the side it should be on (outer apexes above the plane,
/// inner below: Theorem 2.1's sign of the number 1 weight toward it).
fn acceptable(hull: &SimplicialHull, t: usize, side: Side, q: DVec3) -> bool {
    let Some(old) = hull.apexes[t][side as usize] else {
        return false;
    };
    let [a, b, c] = hull.triangles[t].map(|k| hull.points[k as usize]);
    let sigma = if side == Side::Outer { 1.0 } else { -1.0 };
    let floor = FACE_MIN_VOLUME.min(sigma * relative_volume(a, b, c, old));
    let want = if side == Side::Outer { 1 } else { -1 };
    let kept = plane_signs(hull, t, q)
        .iter()
        .zip(plane_signs(hull, t, old))
        .all(|(&now, was)| now == was || now == want);
    sigma * relative_volume(a, b, c, q) >= floor.max(0.0) && kept
}

/// Thickens the edge tetrahedra below [`EDGE_MIN_VOLUME`] (module docs). Returns the hull with
/// the moved apexes and every thin edge found, with its volume before and after.
#[must_use]
pub fn thicken(hull: &SimplicialHull) -> (SimplicialHull, Vec<Sliver>) {
    let mut out = hull.clone();
    let thin = thin_edges(hull, EDGE_MIN_VOLUME);
    if thin.is_empty() {
        return (out, Vec::new());
    }
    let edges = hull.edges().expect("thin_edges found edges");
    let mut violations = verify(&out).len();
    let mut log = Vec::with_capacity(thin.len());
    for (e, side, before) in thin {
        let edge = &edges[e];
        let mut sliver = Sliver {
            edge: edge.v,
            side,
            before,
            after: before,
        };
        let (Some(bn), Some((q0, q1))) = (bisector_normal(&out, edge), apex_pair(&out, edge, side))
        else {
            log.push(sliver);
            continue;
        };
        let (pi, pj) = ends(&out, edge);
        let elen = (pj - pi).length();
        let [fa, fb] = edge.faces.map(|f| f as usize);
        let trace = std::env::var_os("APATCH_SLIVER_TRACE").is_some();
        if trace {
            eprintln!(
                "sliver: edge {:?} ({pi}, {pj}) side {side:?} volume {before:.1e}, triangles {fa} {fb}, apexes {q0} {q1}, signs {:?} {:?}",
                edge.v,
                plane_signs(&out, fa, q0),
                plane_signs(&out, fb, q1)
            );
        }
        for step in STEPS {
            let d = step * elen;
            // Each apex at least d from the bisecting plane, on its own triangle's side.
            let a = q0 + (d - bn.dot(q0 - pi)).max(0.0) * bn;
            let b = q1 - (d + bn.dot(q1 - pi)).max(0.0) * bn;
            let v = pair_volume(pi, pj, a, b);
            let ok = [acceptable(&out, fa, side, a), acceptable(&out, fb, side, b)];
            if v < EDGE_MIN_VOLUME || ok.contains(&false) {
                if trace {
                    eprintln!("  step {step}: volume {v:.1e}, acceptable {ok:?}");
                }
                continue;
            }
            let mut trial = out.clone();
            trial.apexes[fa][side as usize] = Some(a);
            trial.apexes[fb][side as usize] = Some(b);
            let n = verify(&trial).len();
            if trace {
                eprintln!("  step {step}: volume {v:.1e}, violations {violations} -> {n}");
            }
            if n <= violations {
                violations = n;
                out = trial;
                sliver.after = v;
                break;
            }
        }
        log.push(sliver);
    }
    (out, log)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;

    /// Two triangles along the edge from the origin to x, rising from it at ±`half` radians
    /// from +z (a valley open towards +z, its bisecting plane y = 0), each with an outer apex
    /// at height 0.5 and `offset` off the bisecting plane on its own side.
    fn valley(half: f64, offset: f64) -> SimplicialHull {
        let (s, c) = half.sin_cos();
        let pa = DVec3::new(0.5, -s, c);
        let pb = DVec3::new(0.5, s, c);
        let points = vec![DVec3::ZERO, DVec3::X, pa, pb];
        // Outer normals: the sides facing +z.
        let na = DVec3::new(0.0, c, s);
        let nb = DVec3::new(0.0, -c, s);
        let orient = |t: [u32; 3], n: DVec3| {
            let [a, b, c] = t.map(|k| points[k as usize]);
            if (b - a).cross(c - a).dot(n) > 0.0 {
                t
            } else {
                [t[0], t[2], t[1]]
            }
        };
        SimplicialHull {
            normals: vec![DVec3::Z, DVec3::Z, na, nb],
            origins: vec![PointOrigin::Other; 4],
            triangles: vec![orient([0, 1, 2], na), orient([0, 1, 3], nb)],
            apexes: vec![
                [Some(DVec3::new(0.4, -offset, 0.5)), None],
                [Some(DVec3::new(0.6, offset, 0.5)), None],
            ],
            element: vec![0, 1],
            points,
        }
    }

    /// Apexes 1e-6 off the bisecting plane make sliver edge tetrahedra; they are moved apart to
    /// the bound, each on its own side, and their face tetrahedra stay on their side and thick.
    #[test]
    fn sliver_pair_is_opened() {
        let hull = valley(50f64.to_radians(), 1e-6);
        let thin = thin_edges(&hull, EDGE_MIN_VOLUME);
        assert_eq!(thin.len(), 1, "{thin:?}");
        let (moved, log) = thicken(&hull);
        assert_eq!(log.len(), 1);
        assert!(log[0].before < 1e-5, "{log:?}");
        assert!(log[0].after >= EDGE_MIN_VOLUME, "{log:?}");
        assert!(thin_edges(&moved, EDGE_MIN_VOLUME).is_empty());
        let [qa, qb] = [0, 1].map(|t| moved.apexes[t][0].unwrap());
        assert!(qa.y < 0.0 && qb.y > 0.0, "{qa} {qb}");
        for t in 0..2 {
            let [a, b, c] = moved.triangles[t].map(|k| moved.points[k as usize]);
            let q = moved.apexes[t][0].unwrap();
            assert!(relative_volume(a, b, c, q) >= FACE_MIN_VOLUME);
        }
    }

    /// Thick pairs are left exactly as they were.
    #[test]
    fn thick_pairs_are_untouched() {
        let hull = valley(50f64.to_radians(), 0.1);
        assert!(thin_edges(&hull, EDGE_MIN_VOLUME).is_empty());
        let (moved, log) = thicken(&hull);
        assert!(log.is_empty());
        assert_eq!(moved.apexes, hull.apexes);
    }
}

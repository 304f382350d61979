//! Apexes kept inside their wedge at the folds of T (beyond the paper; needed at strong folds).
//!
//! Two triangles of T sharing an edge and a side both have a face tetrahedron there. Where T
//! folds into a valley on that side, the two tetrahedra lean towards each other; when an apex
//! crosses the plane that bisects the dihedral angle at the shared edge, its tetrahedron enters
//! the neighbour's (and the edge tetrahedra between them) — the nut's overlaps along its ~45°
//! valleys of T, with apexes over the base that lean along the mean vertex normal.
//!
//! [`keep_in_wedges`] moves every such apex the least distance (Dykstra's alternating
//! projections onto the half-spaces, which converge to the nearest point of their intersection)
//! to a point that lies, by a margin, on its own triangle's side of every such bisecting plane,
//! over its base if possible, at least [`super::sides::MIN_HEIGHT`] high, and still on the far side of the
//! tangent plane at every base vertex whose plane it crosses now (Definition 3.5 stays true).
//! Apexes that are already inside their wedges are not touched, nor apexes for which no such
//! point is found, nor the apexes of trihedral corners (step (3), (3')).

use crate::hull::simplicial::{HullEdge, PointOrigin, SimplicialHull};
use glam::DVec3;

/// Distance an apex keeps from a bisecting plane, relative to the shared edge's length: enough
/// that the edge tetrahedra between two apexes at their planes keep a volume (0 left 22
/// degenerate ones on the nut), small enough that the apexes still fit over their bases at the
/// nut's 50–80° valleys (nut violations: 60 for margins 0.0005–0.01, 399 at 0.02, 411 at 0.05).
pub const WEDGE_MARGIN: f64 = 0.005;

/// A half-space a·q ≥ b.
type HalfSpace = (DVec3, f64);

/// The unit directions, perpendicular to the interior edge `e` of T, from the edge into each of
/// its two triangles (towards their third points), in the order of `e.faces`; `None` for a
/// degenerate edge or triangle. Their difference is the normal of the plane bisecting the fold.
#[must_use]
pub fn inward_directions(hull: &SimplicialHull, e: &HullEdge) -> Option<[DVec3; 2]> {
    let (p, q) = (hull.points[e.v[0] as usize], hull.points[e.v[1] as usize]);
    let dir = (q - p).try_normalize()?;
    let inward = |t: u32| -> Option<DVec3> {
        let o = hull.triangles[t as usize]
            .iter()
            .find(|&&i| i != e.v[0] && i != e.v[1])?;
        let d = hull.points[*o as usize] - p;
        (d - d.dot(dir) * dir).try_normalize()
    };
    Some([inward(e.faces[0])?, inward(e.faces[1])?])
}

/// Moves apexes that lie beyond the bisecting plane of a fold of T back into their wedge (module
/// docs). Returns the number of apexes moved.
#[allow(clippy::needless_range_loop)] // t and side index apexes, wedges and step5 alike
pub fn keep_in_wedges(hull: &mut SimplicialHull) -> usize {
    let Ok(edges) = hull.edges() else {
        return 0;
    };
    // Per triangle and side, the wedge half-spaces from its shared-side edges.
    let nt = hull.triangles.len();
    let mut wedge: Vec<[Vec<HalfSpace>; 2]> = vec![[Vec::new(), Vec::new()]; nt];
    for e in &edges {
        if e.faces[1] == u32::MAX {
            continue;
        }
        let [fa, fb] = e.faces.map(|f| f as usize);
        let Some([ua, ub]) = inward_directions(hull, e) else {
            continue;
        };
        let (p, q) = (hull.points[e.v[0] as usize], hull.points[e.v[1] as usize]);
        let elen = (q - p).length();
        // T does not fold here (coplanar triangles: flat regions, guard nets, whose apexes
        // `guardnet` places on purpose): no wedge.
        if ua.dot(ub) < -1.0 + 1e-9 {
            continue;
        }
        let Some(bn) = (ua - ub).try_normalize() else {
            continue;
        };
        for side in 0..2 {
            if hull.apexes[fa][side].is_some() && hull.apexes[fb][side].is_some() {
                let m = WEDGE_MARGIN * elen;
                wedge[fa][side].push((bn, bn.dot(p) + m));
                wedge[fb][side].push((-bn, -bn.dot(p) + m));
            }
        }
    }
    let mut moved = 0;
    for t in 0..nt {
        // Only step (5) triangles (with a pseudo-centroid), as in `sides::settle`: a trihedral
        // corner's apex V and the hallway pair of step (3') lie in face planes on purpose.
        let step5 = hull.triangles[t]
            .iter()
            .any(|&i| matches!(hull.origins[i as usize], PointOrigin::PseudoCentroid { .. }));
        if !step5 {
            continue;
        }
        for side in 0..2 {
            let Some(q0) = hull.apexes[t][side] else {
                continue;
            };
            if wedge[t][side].iter().all(|&(a, b)| a.dot(q0) >= b) {
                continue;
            }
            // First over the base; where the wedges and the tangent planes leave no room there
            // (the nut's corner-guard triangles at its 50–80° valleys), anywhere inside them:
            // the wedges of its shared-side edges still keep the apex beside its own triangle.
            // The move must not lose tangent containment (Definition 3.5, as `verify` judges
            // it) at a base vertex where this tetrahedron has it and its partner does not.
            let keeps = |q: DVec3| {
                (0..3).all(|k| {
                    !contains_at(hull, t, q0, k)
                        || contains_at(hull, t, q, k)
                        || hull.apexes[t][1 - side].is_some_and(|p| contains_at(hull, t, p, k))
                })
            };
            let found = [true, false].into_iter().find_map(|over_base| {
                let mut spaces = wedge[t][side].clone();
                spaces.extend(apex_spaces(hull, t, side, q0, over_base));
                nearest_point(q0, &spaces).filter(|&q| keeps(q))
            });
            if let Some(q) = found {
                hull.apexes[t][side] = Some(q);
                moved += 1;
            }
        }
    }
    moved
}

/// The half-spaces that keep an apex valid: on its side at least [`super::sides::MIN_HEIGHT`]
/// times the longest edge, beyond each base vertex's tangent plane that `q0` is beyond now while
/// the base does not meet that plane, and (when `over_base`) over the base.
fn apex_spaces(
    hull: &SimplicialHull,
    t: usize,
    side: usize,
    q0: DVec3,
    over_base: bool,
) -> Vec<HalfSpace> {
    let tri = hull.triangles[t];
    let base = tri.map(|i| hull.points[i as usize]);
    let sigma = if side == 0 { 1.0 } else { -1.0 };
    let Some(nn) = (base[1] - base[0]).cross(base[2] - base[0]).try_normalize() else {
        return Vec::new();
    };
    let len = (0..3)
        .map(|k| (base[(k + 1) % 3] - base[k]).length())
        .fold(0.0, f64::max);
    let mut out = vec![(
        sigma * nn,
        sigma * nn.dot(base[0]) + super::sides::MIN_HEIGHT * len,
    )];
    for k in (0..3).filter(|_| over_base) {
        let (a, b) = (base[k], base[(k + 1) % 3]);
        // In-plane inward normal of edge ab (the base is counter-clockwise round nn).
        let m = nn.cross(b - a);
        out.push((m, m.dot(a)));
    }
    for k in 0..3 {
        let (p, n) = (base[k], hull.normals[tri[k] as usize]);
        let vals = [n.dot(base[(k + 1) % 3] - p), n.dot(base[(k + 2) % 3] - p)];
        let tol = 1e-12 * len;
        let (lo, hi) = (vals[0].min(vals[1]), vals[0].max(vals[1]));
        if lo <= tol && hi >= -tol {
            continue; // the base meets the tangent plane already
        }
        let want = if hi < 0.0 { 1.0 } else { -1.0 };
        if want * n.dot(q0 - p) > 0.0 {
            let target = 0.05 * lo.abs().min(hi.abs());
            out.push((want * n, want * n.dot(p) + target));
        }
    }
    out
}

/// Whether the face tetrahedron of triangle `t` with apex `q` is tangent-containing at its base
/// vertex `k`, by `verify`'s rule and tolerance.
fn contains_at(hull: &SimplicialHull, t: usize, q: DVec3, k: usize) -> bool {
    let tri = hull.triangles[t];
    let base = tri.map(|i| hull.points[i as usize]);
    let tet = [base[0], base[1], base[2], q];
    let mut longest: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            longest = longest.max((tet[i] - tet[j]).length());
        }
    }
    let tol = super::verify::PLANE_TOL * longest;
    let (pk, nk) = (base[k], hull.normals[tri[k] as usize]);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in tet.iter().filter(|&&x| x != pk) {
        let v = nk.dot(*x - pk);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    lo <= tol && hi >= -tol
}

/// The point of the intersection of `spaces` nearest to `q0` (Dykstra's algorithm), or `None`
/// when the iteration does not reach a point inside all of them (to rounding).
fn nearest_point(q0: DVec3, spaces: &[HalfSpace]) -> Option<DVec3> {
    let mut x = q0;
    let mut incr = vec![DVec3::ZERO; spaces.len()];
    for _ in 0..2000 {
        for (i, &(a, b)) in spaces.iter().enumerate() {
            let y = x + incr[i];
            let aa = a.length_squared();
            let viol = b - a.dot(y);
            let z = if viol > 0.0 && aa > 0.0 {
                y + (viol / aa) * a
            } else {
                y
            };
            incr[i] = y - z;
            x = z;
        }
        let worst = spaces
            .iter()
            .map(|&(a, b)| (b - a.dot(x)) / a.length().max(1e-300))
            .fold(f64::NEG_INFINITY, f64::max);
        if worst <= 1e-12 * (1.0 + x.length()) {
            return Some(x);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles folded into a 90° valley with outer apexes leaning across the bisecting
    /// plane: the leaning apex comes back inside its wedge by the margin, stays over its base
    /// and above MIN_HEIGHT; the other apex is untouched.
    #[test]
    fn leaning_apex_returns_to_its_wedge() {
        // Edge along y from (0,0,0) to (0,1,0); triangle A in the plane z = 0 (x < 0 side is
        // not used: A spans x ∈ [0, 1]), B rising in the plane x = 0 towards +z: a valley on
        // the outer (+z / +x) side.
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(0.0, 0.5, 1.0),
        ];
        let mut hull = SimplicialHull {
            points: p.to_vec(),
            normals: vec![DVec3::new(1.0, 0.0, 1.0).normalize(); 4],
            origins: vec![
                PointOrigin::PseudoCentroid { vertex: 0 },
                PointOrigin::Other,
                PointOrigin::Other,
                PointOrigin::Other,
            ],
            // A = [0, 2, 1] has normal +z... (2−0)×(1−0) = (1,.5,0)×(0,1,0) = (0,0,1).
            // B = [0, 1, 3]: (1−0)×(3−0) = (0,1,0)×(0,.5,1) = (1,0,0).
            triangles: vec![[0, 2, 1], [0, 1, 3]],
            apexes: vec![
                // A's apex leans over x < 0.3 towards B, crossing the bisector x = z.
                [Some(DVec3::new(0.3, 0.5, 0.6)), None],
                [Some(DVec3::new(0.3, 0.5, 0.5)), None],
            ],
            element: vec![0, 1],
        };
        let moved = keep_in_wedges(&mut hull);
        assert_eq!(moved, 1);
        let q = hull.apexes[0][0].unwrap();
        // A's side of the bisector x = z is x > z; margin 0.02 of the edge (length 1) along the
        // unit normal (1, 0, −1)/√2; Dykstra stops within 1e-12.
        assert!((q.x - q.z) / 2f64.sqrt() >= WEDGE_MARGIN - 1e-9, "{q}");
        assert!(q.z >= super::super::sides::MIN_HEIGHT - 1e-9, "{q}");
        assert!(q.x >= -1e-9 && q.x <= 1.0, "{q}");
        assert_eq!(hull.apexes[1][0], Some(DVec3::new(0.3, 0.5, 0.5)));
    }
}

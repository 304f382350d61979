//! No degenerate face tetrahedra: the last step of the inner hull.
//!
//! Why: Algorithm 1's apexes come from intersections of lines and planes (step (5): the
//! projection of the midpoint M onto π_{C_0}, the lines through C_0). Where a corner is nearly
//! flat (nearly coplanar faces round a pseudo-centroid, fandisk's flat regions) those
//! intersections are nearly parallel and the apex lands far away: fandisk's hull triangle 12397
//! (a triangle of size 0.06) got an inner apex 9.6 away, a face tetrahedron of relative volume
//! −4e-13 that stopped the cubic scheme ("face tetrahedron … is degenerate") and crossed most
//! of the model. [`sides::settle`](super::sides::settle) rebuilds such triangles over their
//! base only when it finds a height within [`MAX_HEIGHT`](super::sides::MAX_HEIGHT) that makes
//! the required sides tangent-containing, and keeps Algorithm 1's apexes otherwise.
//!
//! [`repair`] finds every face tetrahedron whose relative volume 6V / L³ (L its longest edge)
//! is below [`DEGENERATE_VOLUME`] — the bound `verify` uses — or whose apex lies more than
//! [`FAR_APEX`] base lengths away, and replaces its apex by one over
//! the base ([`sides::apexes_over_base`](super::sides::apexes_over_base)): on the same sides, or
//! else as an L-U pair (one apex on each side), which is tangent-containing wherever the base
//! meets its vertices' tangent planes from either side. A triangle that still has no
//! non-degenerate tetrahedron (a sliver base, or no height within the bound) is an error naming
//! the hull triangle, the input element it was built for and that element's line: degenerate
//! tetrahedra are never handed to a scheme.

use super::sides::apexes_over_base;
use super::verify::DEGENERATE_VOLUME;
use crate::error::{Error, Result};
use crate::hull::simplicial::{Side, SimplicialHull};
use glam::DVec3;

/// Relative volume 6V / L³ of the tetrahedron (a, b, c, q), L its longest edge; signed
/// (positive when q lies on the side of (a, b, c)'s counter-clockwise normal).
#[must_use]
pub fn relative_volume(a: DVec3, b: DVec3, c: DVec3, q: DVec3) -> f64 {
    let pts = [a, b, c, q];
    let mut l: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.max((pts[i] - pts[j]).length());
        }
    }
    if l == 0.0 {
        return 0.0;
    }
    (b - a).cross(c - a).dot(q - a) / (l * l * l)
}

/// Largest distance of an apex from its base's centroid, in longest base edges, before
/// [`repair`] rebuilds it over the base. Algorithm 1's apexes lie within about one base length
/// (a trihedral corner's V, the projections of step (5)); one several base lengths away comes
/// from a nearly parallel intersection (mpi_poly's hull triangle 35, base edges ≈ 5, had its
/// outer apex 345 away) and crosses its neighbours' tetrahedra. No triangle of the passing
/// paper1994 hulls comes near 4.
pub const FAR_APEX: f64 = 4.0;

/// True when the apex of triangle `t` on `side` lies more than [`FAR_APEX`] longest base edges
/// from the base's centroid.
#[must_use]
pub fn is_far(hull: &SimplicialHull, t: usize, side: Side) -> bool {
    hull.face_tet(t, side).is_some_and(|[a, b, c, q]| {
        let len = (b - a).length().max((c - b).length()).max((a - c).length());
        (q - (a + b + c) / 3.0).length() > FAR_APEX * len
    })
}

/// True when the face tetrahedron of triangle `t` on `side` is degenerate in `verify`'s sense
/// (relative volume below [`DEGENERATE_VOLUME`] in magnitude).
#[must_use]
pub fn is_degenerate(hull: &SimplicialHull, t: usize, side: Side) -> bool {
    hull.face_tet(t, side)
        .is_some_and(|[a, b, c, q]| relative_volume(a, b, c, q).abs() < DEGENERATE_VOLUME)
}

/// Replaces degenerate face-tetrahedron apexes of `hull` (module documentation) and returns the
/// number of triangles changed. `vertex_lines[v]` is the line of input vertex v (for errors;
/// 0 or missing when unknown).
///
/// # Errors
/// A triangle of T whose face tetrahedra cannot be made non-degenerate, naming the hull
/// triangle, its input element and the element's line.
pub fn repair(hull: &mut SimplicialHull, vertex_lines: &[u32]) -> Result<usize> {
    let mut changed = 0;
    for t in 0..hull.triangles.len() {
        let degenerate: Vec<Side> = Side::BOTH
            .into_iter()
            .filter(|&s| is_degenerate(hull, t, s))
            .collect();
        let bad: Vec<Side> = Side::BOTH
            .into_iter()
            .filter(|&s| degenerate.contains(&s) || is_far(hull, t, s))
            .collect();
        if bad.is_empty() {
            continue;
        }
        let base = hull.triangles[t].map(|i| hull.points[i as usize]);
        let normals = hull.triangles[t].map(|i| hull.normals[i as usize]);
        let sides = [hull.apexes[t][0].is_some(), hull.apexes[t][1].is_some()];
        let fresh = apexes_over_base(base, normals, sides)
            .or_else(|| apexes_over_base(base, normals, [true, true]));
        let ok = fresh.filter(|apexes| {
            apexes
                .iter()
                .flatten()
                .all(|&q| relative_volume(base[0], base[1], base[2], q).abs() >= DEGENERATE_VOLUME)
        });
        let Some(apexes) = ok else {
            if degenerate.is_empty() {
                continue; // far but thick: kept as built
            }
            let element = hull.element[t];
            let line = vertex_lines.get(element as usize).copied().unwrap_or(0);
            let [a, b, c] = base;
            return Err(Error::Invalid(format!(
                "inner hull: the {:?} face tetrahedron of hull triangle {t} (built for input vertex {element}, line {line}) is degenerate (relative volume {:.2e}) and no apex over its base (area {:.3e}) is tangent-containing; the corner there is too flat or too thin for the 1994 hull",
                degenerate[0],
                hull.face_tet(t, degenerate[0])
                    .map_or(0.0, |[a, b, c, q]| relative_volume(a, b, c, q)),
                0.5 * (b - a).cross(c - a).length(),
            )));
        };
        // Keep the sides that were fine; fill the rest (replaced, or new for an L-U pair).
        for s in Side::BOTH {
            let i = s as usize;
            if hull.apexes[t][i].is_none() || bad.contains(&s) {
                hull.apexes[t][i] = apexes[i];
            }
        }
        changed += 1;
    }
    Ok(changed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;

    /// A unit right triangle with an inner apex 1e4 away sideways (what a nearly parallel
    /// intersection gives): degenerate by verify's bound; repaired, the apex lies over the
    /// base on the same side, and every face tetrahedron is tangent-containing and thick.
    #[test]
    fn far_apex_is_replaced_over_the_base() {
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z; 3],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[None, Some(DVec3::new(1e4, 0.3, -0.5))]],
            element: vec![7],
        };
        assert!(is_degenerate(&hull, 0, Side::Inner));
        assert_eq!(repair(&mut hull, &[]).unwrap(), 1);
        assert!(hull.apexes[0][0].is_none());
        let q = hull.apexes[0][1].unwrap();
        // Over the closed base and below it (inner side), at least MIN_HEIGHT (0.08) deep.
        assert!(q.x >= 0.0 && q.y >= 0.0 && q.x + q.y <= 1.0 && q.z <= -0.08 + 1e-12);
        assert!(!is_degenerate(&hull, 0, Side::Inner));
        assert!(crate::hull::inner::verify(&hull)
            .iter()
            .all(|v| v.kind != crate::hull::inner::ViolationKind::Degenerate));
    }

    /// A sliver base (three nearly collinear points) has no thick tetrahedron at all: the
    /// repair is an error naming the triangle, the input vertex and its line.
    #[test]
    fn sliver_base_is_a_clear_error() {
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1e-12, 0.0)],
            normals: vec![DVec3::Z; 3],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[Some(DVec3::new(0.5, 0.0, 1e-12)), None]],
            element: vec![3],
        };
        let e = repair(&mut hull, &[10, 11, 12, 13])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("hull triangle 0") && e.contains("input vertex 3") && e.contains("line 13"),
            "{e}"
        );
    }

    /// Thick tetrahedra are left alone.
    #[test]
    fn thick_tetrahedra_are_kept() {
        let q = DVec3::new(0.3, 0.3, 0.5);
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z; 3],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[Some(q), None]],
            element: vec![0],
        };
        assert_eq!(repair(&mut hull, &[]).unwrap(), 0);
        assert_eq!(hull.apexes[0], [Some(q), None]);
    }

    /// A thick but far apex (straight above, 100 base lengths up: relative volume ≈ 1e-4, not
    /// degenerate) is brought down over the base, within [`FAR_APEX`] base lengths.
    #[test]
    fn far_thick_apex_is_brought_over_the_base() {
        let far = DVec3::new(0.3, 0.3, 100.0);
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z; 3],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[Some(far), None]],
            element: vec![0],
        };
        assert!(!is_degenerate(&hull, 0, Side::Outer) && is_far(&hull, 0, Side::Outer));
        assert_eq!(repair(&mut hull, &[]).unwrap(), 1);
        let q = hull.apexes[0][0].unwrap();
        // The longest base edge is √2; the centroid is (1/3, 1/3, 0).
        let g = DVec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0);
        assert!(q.z > 0.0 && (q - g).length() <= FAR_APEX * 2f64.sqrt());
        assert!(hull.apexes[0][1].is_none());
    }
}

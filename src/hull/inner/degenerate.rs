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

/// True when the tangent plane at every base vertex (normal `normals[k]`) leaves neither all
/// of the other three points of (base, q) strictly on one side (Definition 3.5, no tolerance).
fn tangent_containing(base: [DVec3; 3], normals: [DVec3; 3], q: DVec3) -> bool {
    (0..3).all(|k| {
        let vals = [base[(k + 1) % 3], base[(k + 2) % 3], q].map(|x| normals[k].dot(x - base[k]));
        let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        lo <= 0.0 && hi >= 0.0
    })
}

/// Grid steps per unit of the longest base edge in [`apex_beside_base`]'s search.
const BESIDE_STEPS: usize = 20;

/// An apex on `side` of the triangle `base` that need not lie over it: the point nearest the
/// base's centroid g, on a grid of heights (0.08 to 1 longest edge L, as over the base) and
/// offsets in the base's plane (up to 1.5 L each way, steps of L / [`BESIDE_STEPS`]), that makes
/// the tetrahedron tangent-containing and thick. For triangles whose vertex normal lies nearly
/// in the base's plane (mpi_poly's hull triangle 35 at a pseudo-centroid: n·N = 0.03) no apex
/// over the base within L reaches that vertex's tangent plane, but one beside the base does
/// (0.47 L from g there); Algorithm 1 put it 40 L away. `None` when the grid has none.
#[must_use]
pub fn apex_beside_base(base: [DVec3; 3], normals: [DVec3; 3], side: Side) -> Option<DVec3> {
    let [a, b, c] = base;
    let n = (b - a).cross(c - a).try_normalize()?;
    let len = (b - a).length().max((c - b).length()).max((a - c).length());
    let g = (a + b + c) / 3.0;
    let u = (b - a).normalize();
    let v = n.cross(u);
    let sigma = if side == Side::Outer { 1.0 } else { -1.0 };
    let step = len / BESIDE_STEPS as f64;
    let reach = (1.5 * BESIDE_STEPS as f64) as i64;
    let mut best: Option<(f64, DVec3)> = None;
    for ih in 0..=BESIDE_STEPS {
        let h = (0.08 + 0.92 * ih as f64 / BESIDE_STEPS as f64) * len;
        for i in -reach..=reach {
            for j in -reach..=reach {
                let q = g + sigma * h * n + (i as f64 * step) * u + (j as f64 * step) * v;
                let r = (q - g).length();
                if best.is_some_and(|(d, _)| d <= r) {
                    continue;
                }
                if relative_volume(a, b, c, q).abs() >= DEGENERATE_VOLUME
                    && tangent_containing(base, normals, q)
                {
                    best = Some((r, q));
                }
            }
        }
    }
    best.map(|(_, q)| q)
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
    repair_below(hull, vertex_lines, DEGENERATE_VOLUME)
}

/// True when the face tetrahedron of triangle `t` on `side` has a relative volume below
/// `bound` in magnitude: its apex does not stand off its base.
#[must_use]
pub fn is_flat(hull: &SimplicialHull, t: usize, side: Side, bound: f64) -> bool {
    hull.face_tet(t, side)
        .is_some_and(|[a, b, c, q]| relative_volume(a, b, c, q).abs() < bound)
}

/// [`repair`] with its own bound: face tetrahedra with a relative volume below `min_volume`
/// (at least [`DEGENERATE_VOLUME`]) are rebuilt over their base too, and rebuilt apexes reach
/// it. The quintic's bound ([`super::verify::C2_MIN_VOLUME`]): the nut's nearly flat trihedral
/// corner (input vertex 445, three faces 1.5e-6 rad apart, just beyond
/// [`super::coplanar::NORMAL_TOL`], so not merged) gets step (3)'s triangle C_1C_2C_3 with the
/// apex V in (almost) its plane and a second apex on an edge of the same plane: an L-U pair of
/// relative volumes 7e-8 and 2e-8, above verify's bound and kept by [`repair`]. A flat
/// tetrahedron whose rebuilt apexes cannot reach `min_volume` keeps its apexes when it is not
/// degenerate in verify's sense.
///
/// # Errors
/// As [`repair`].
pub fn repair_below(
    hull: &mut SimplicialHull,
    vertex_lines: &[u32],
    min_volume: f64,
) -> Result<usize> {
    let min_volume = min_volume.max(DEGENERATE_VOLUME);
    let mut changed = 0;
    for t in 0..hull.triangles.len() {
        let degenerate: Vec<Side> = Side::BOTH
            .into_iter()
            .filter(|&s| is_degenerate(hull, t, s))
            .collect();
        let bad: Vec<Side> = Side::BOTH
            .into_iter()
            .filter(|&s| is_flat(hull, t, s, min_volume) || is_far(hull, t, s))
            .collect();
        if bad.is_empty() {
            continue;
        }
        let base = hull.triangles[t].map(|i| hull.points[i as usize]);
        let normals = hull.triangles[t].map(|i| hull.normals[i as usize]);
        let sides = [hull.apexes[t][0].is_some(), hull.apexes[t][1].is_some()];
        let fresh = apexes_over_base(base, normals, sides)
            .or_else(|| apexes_over_base(base, normals, [true, true]))
            .or_else(|| {
                // Beside the base: each side that is there, nearest the base's centroid.
                let mut out = [None, None];
                for s in Side::BOTH {
                    if sides[s as usize] {
                        out[s as usize] = Some(apex_beside_base(base, normals, s)?);
                    }
                }
                Some(out)
            });
        let thick = |apexes: &[Option<DVec3>; 2], bound: f64| {
            apexes
                .iter()
                .flatten()
                .all(|&q| relative_volume(base[0], base[1], base[2], q).abs() >= bound)
        };
        // Rebuilt apexes reach the bound asked for; a tetrahedron degenerate in verify's sense
        // takes any that is not.
        let ok = fresh.filter(|a| {
            thick(a, min_volume) || (!degenerate.is_empty() && thick(a, DEGENERATE_VOLUME))
        });
        let Some(apexes) = ok else {
            if degenerate.is_empty() {
                continue; // far or flat but not degenerate: kept as built
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

    /// An L-U pair over a flat base whose apexes lie 5e-8 of its size off the base's plane (the
    /// nut's nearly flat trihedral corner, all normals the plane's): not degenerate by verify's
    /// bound, so [`repair`] keeps it; [`repair_below`] with the quintic's bound rebuilds both
    /// apexes over the base, each tetrahedron at least that thick and tangent-containing.
    #[test]
    fn flat_pair_stands_off_its_base_under_the_c2_bound() {
        use crate::hull::inner::verify::C2_MIN_VOLUME;
        let flat = [
            Some(DVec3::new(0.3, 0.3, 5e-8)),
            Some(DVec3::new(0.2, 0.4, -5e-8)),
        ];
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![DVec3::Z; 3],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![flat],
            element: vec![0],
        };
        assert_eq!(repair(&mut hull, &[]).unwrap(), 0);
        assert_eq!(hull.apexes[0], flat);
        assert_eq!(repair_below(&mut hull, &[], C2_MIN_VOLUME).unwrap(), 1);
        let [a, b, c] = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let [o, i] = hull.apexes[0].map(Option::unwrap);
        // Outer above, inner below the plane z = 0, both at least the bound thick.
        assert!(o.z > 0.0 && i.z < 0.0, "{o} {i}");
        for q in [o, i] {
            assert!(relative_volume(a, b, c, q).abs() >= C2_MIN_VOLUME, "{q}");
            assert!(tangent_containing([a, b, c], [DVec3::Z; 3], q));
        }
        // Rebuilt once, they stay.
        let kept = hull.apexes[0];
        assert_eq!(repair_below(&mut hull, &[], C2_MIN_VOLUME).unwrap(), 0);
        assert_eq!(hull.apexes[0], kept);
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

    /// A vertex normal nearly in the base's plane (n·N = 0.03 at p_0, pointing away from the
    /// other two vertices): Algorithm 1's kind of answer is an apex 30 up; no apex over the
    /// base within one base length is tangent-containing at p_0, so the repair puts it beside
    /// the base (behind p_0). Checked with `verify`'s per-tetrahedron conditions, and the apex is near.
    #[test]
    fn normal_in_the_base_plane_gets_an_apex_beside_the_base() {
        let n0 = DVec3::new(-1.0, -1.0, 0.03).normalize();
        let mut hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: vec![n0, DVec3::Z, DVec3::Z],
            origins: vec![PointOrigin::Other; 3],
            triangles: vec![[0, 1, 2]],
            apexes: vec![[Some(DVec3::new(0.0, 0.0, 30.0)), None]],
            element: vec![0],
        };
        // One triangle is no closed T: only the per-tetrahedron conditions count here.
        use crate::hull::inner::ViolationKind::{Degenerate, NotTangentContaining, WrongSide};
        let local = |hull: &SimplicialHull| {
            crate::hull::inner::verify(hull)
                .into_iter()
                .filter(|v| matches!(v.kind, Degenerate | NotTangentContaining | WrongSide))
                .collect::<Vec<_>>()
        };
        // The far apex is tangent-containing (it is what Algorithm 1 gives), but far.
        assert!(local(&hull).is_empty());
        assert!(is_far(&hull, 0, Side::Outer));
        assert_eq!(repair(&mut hull, &[]).unwrap(), 1);
        let q = hull.apexes[0][0].unwrap();
        assert!(hull.apexes[0][1].is_none());
        assert!(q.z > 0.0 && !is_far(&hull, 0, Side::Outer), "{q}");
        let v = local(&hull);
        assert!(v.is_empty(), "{v:?}");
        // Behind p_0 (the side its normal points to), not over the base.
        assert!(n0.dot(q) >= 0.0 && q.x + q.y < 0.0, "{q}");
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

//! "Above face" vertex normals (§4 restriction (ii), Appendix C).
//!
//! Algorithm 1 needs n_V · n_f > 0 for every face f around a non-trihedral vertex V (Lemma A.2:
//! then the faces' projections onto V's tangent plane do not overlap). Appendix C reaches this by
//! re-meshing the corner; we first try the cheaper remedy of changing the normal: if a direction
//! above all the faces exists, the given normal is rotated towards the direction that is most
//! above them (the max–min of n · n_f over the unit sphere) just far enough to clear a margin.
//! Only when no such direction exists (the faces wrap round more than a hemisphere) does the
//! corner need Appendix C's re-meshing, which [`super::remesh`] does before the hull.

use glam::DVec3;

/// Smallest accepted min_f n · n_f: about 0.06° above the flattest face. Below it the projection
/// of Lemma A.2 is numerically meaningless and the pseudo-centroid's tets degenerate.
pub const ABOVE_MARGIN: f64 = 1e-3;

/// min over `faces` of n · n_f.
#[must_use]
pub fn clearance(n: DVec3, faces: &[DVec3]) -> f64 {
    faces
        .iter()
        .map(|f| n.dot(*f))
        .fold(f64::INFINITY, f64::min)
}

/// The unit direction maximising min_f n · n_f (exact: the optimum is balanced between one, two
/// or three of the unit face normals, and every such candidate is tried).
#[must_use]
pub fn most_above(faces: &[DVec3]) -> DVec3 {
    let mut best = faces.iter().sum::<DVec3>().normalize_or_zero();
    let mut best_c = clearance(best, faces);
    let mut consider = |n: DVec3| {
        if let Some(n) = n.try_normalize() {
            let c = clearance(n, faces);
            if c > best_c {
                best_c = c;
                best = n;
            }
        }
    };
    let k = faces.len();
    for i in 0..k {
        consider(faces[i]);
        for j in i + 1..k {
            consider(faces[i] + faces[j]);
            for l in j + 1..k {
                let n = (faces[j] - faces[i]).cross(faces[l] - faces[i]);
                consider(n);
                consider(-n);
            }
        }
    }
    best
}

/// A normal above all `faces` (unit normals) with clearance ≥ [`ABOVE_MARGIN`]: `given` itself
/// when it qualifies, else `given` rotated towards [`most_above`] by the smallest step that
/// reaches half of the best clearance (bisection on the blend). `None` when no direction
/// qualifies.
#[must_use]
pub fn make_above(given: DVec3, faces: &[DVec3]) -> Option<DVec3> {
    if clearance(given, faces) >= ABOVE_MARGIN {
        return Some(given);
    }
    let target = most_above(faces);
    if clearance(target, faces) < ABOVE_MARGIN {
        return None;
    }
    let blend = |t: f64| ((1.0 - t) * given + t * target).normalize_or_zero();
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        // Half the best clearance: well inside the feasible cone, so the corner stays
        // separable and its tetrahedra stay thick.
        if clearance(blend(mid), faces) >= 0.5 * clearance(target, faces) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let n = blend(hi);
    (clearance(n, faces) >= ABOVE_MARGIN).then_some(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four faces of a square pyramid, with a normal tilted below one face: the result is above
    /// all of them; the symmetric optimum is the axis.
    #[test]
    fn pyramid_normal_is_repaired() {
        let faces: Vec<DVec3> = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y]
            .iter()
            .map(|&d| (d + DVec3::Z).normalize())
            .collect();
        let opt = most_above(&faces);
        // The axis, up to rounding of normalise().
        assert!((opt - DVec3::Z).length() < 1e-12);
        let bad = (DVec3::Z + 1.5 * DVec3::X).normalize();
        assert!(clearance(bad, &faces) < 0.0);
        let fixed = make_above(bad, &faces).unwrap();
        assert!(clearance(fixed, &faces) >= ABOVE_MARGIN);
        // Faces all round the equator: no direction is above all of them.
        let wrap = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
        assert!(make_above(DVec3::Z, &wrap).is_none());
    }
}

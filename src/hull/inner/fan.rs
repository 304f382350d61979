//! Pseudo-centroids inside the kernel of their fan (beyond the paper; needed at strong folds).
//!
//! Algorithm 1 step (4) puts the pseudo-centroid C_0 on V's normal line, C_0 = αV + (1−α)V̄,
//! and T gets the fan C_0C_iC_{i+1} round it. Seen along n_V (C_0's normal), that fan is a
//! proper umbrella only when C_0 lies in the kernel of the polygon of the face centroids
//! C_1 … C_k projected onto C_0's tangent plane π. On coarse models with strong folds it does
//! not: at the top-inner ring of the 5×5 quad torus the two upper faces' centroids project to
//! a chord that passes *between* V and the torus's axis (five major steps of 72°), and along the
//! nut's sharp ridges likewise; the triangle C_0C_iC_{i+1} then faces against n_V (T folds back
//! on itself by ~155–178°), its face tetrahedra point into the neighbouring triangles' ones and
//! the hull overlaps (torus_quad: every Intersecting violation involves such a fan).
//!
//! The cut position is a free quantity of the construction (§7: how far a corner is cut), so
//! [`place_pseudo_centroid`] moves C_0 — parallel to π, at the paper's depth or a few other
//! depths along n_V — to the nearest point where every fan triangle's projection onto π is at
//! least [`FAN_MARGIN`] times its projected base long in height *and* every edge C_0C_i of T
//! stays convex (Lemma 4.1). Where the paper's C_0 already is such a point (every test
//! polyhedron but the coarse tori, all but 15 fans of the nut) it stays. Where no point is (the
//! 10 fans of torus_quad's top and bottom inner rings: a point inside the kernel is above the
//! steep inner faces' planes or below the outer faces' centroids), the paper's C_0 stays and the
//! hull keeps its overlaps there.

use glam::{DVec2, DVec3};

/// Smallest height of a fan triangle's projection onto π (the distance of C_0's projection from
/// the projected base C_iC_{i+1}), relative to the projected base's length. Small: only fans
/// that are nearly edge-on or folded over move (the 12×8 quad torus has 0.12 at its flattest
/// fan, the nut 15 fans below it, all folded over).
pub const FAN_MARGIN: f64 = 0.03;

/// Distance C_0 keeps from the plane of every face round V when it is slid (relative to the
/// ring's size): on that plane (the nearest point of the convex region often is) the fan
/// triangles C_0C_iC_{i+1} through a flat face's points are coplanar with that face's triangles
/// across edges C_0C_i that are not zero convex (C_0's normal is V's, not the face's), and the
/// cubic scheme's flat-edge equations there have no solution (the 1994 paper's Appendix B
/// (5'')(iii) displaces such a point; the nut's flat faces had a C¹ jump of 1.45).
pub const PLANE_MARGIN: f64 = 0.01;

/// Cut depths tried, as multiples f of t* in C_0 = V + f t* n (the paper's is f = 1 − α), when
/// the paper's C_0 does not give an umbrella: shallower and deeper cuts, and points just
/// outside the corner (f < 0), each with its own tangent plane π.
const DEPTHS: [f64; 16] = [
    0.1, 0.25, 0.35, 0.5, 0.65, 0.8, 0.95, 1.1, 1.25, 1.5, 2.0, 2.5, 3.0, -0.1, -0.25, -0.5,
];

/// A half-plane w·p ≥ c of π's coordinates.
type HalfPlane = (DVec2, f64);

/// The pseudo-centroid of a separable vertex V (normal `n`, unit) with face centroids `ring`
/// (C_1 … C_k, counter-clockwise round `n`) and face normals `normals`, for the cut
/// C_0 = V + (1−α) t* n of step (4).
///
/// Returns the paper's C_0 when its fan is an umbrella with margin: every fan triangle's
/// projection onto π at least [`FAN_MARGIN`] times its projected base high. Otherwise the
/// nearest point (over the depths of `DEPTHS`, sliding parallel to each π) where that holds
/// *and* every edge C_0C_i of T is convex (Lemma 4.1: C_0 lies on the side of face i's plane
/// that C_i lies on of π, at least [`PLANE_MARGIN`] times the ring's size off the plane). When none exists, the paper's C_0.
#[must_use]
pub fn place_pseudo_centroid(
    v: DVec3,
    n: DVec3,
    t_star: f64,
    alpha: f64,
    ring: &[DVec3],
    normals: &[DVec3],
) -> DVec3 {
    let paper = v + (1.0 - alpha) * t_star * n;
    let k = ring.len();
    if k < 3 || normals.len() != k {
        return paper;
    }
    let u = n.any_orthonormal_vector();
    let w = n.cross(u);
    let flat2 = |x: DVec3| DVec2::new(x.dot(u), x.dot(w));
    let scale = ring.iter().map(|&p| (p - v).length()).fold(0.0, f64::max);
    let fan_planes = |c0: DVec3| -> (Vec<DVec2>, Vec<HalfPlane>) {
        let flat: Vec<DVec2> = ring.iter().map(|&p| flat2(p - c0)).collect();
        let planes = (0..k)
            .map(|i| {
                let (p, q) = (flat[i], flat[(i + 1) % k]);
                let e = q - p;
                let wv = DVec2::new(-e.y, e.x);
                (wv, wv.dot(p) + FAN_MARGIN * e.length_squared())
            })
            .collect();
        (flat, planes)
    };
    if fan_planes(paper).1.iter().all(|&(_, c)| c <= 0.0) {
        return paper;
    }
    let mut best: Option<(f64, DVec3)> = None;
    for f in DEPTHS {
        let c0 = v + f * t_star * n;
        let (flat, mut planes) = fan_planes(c0);
        let mut ok = true;
        for i in 0..k {
            // Edge C_0C_i: a = (C_i − C_0)·n has sign σ; keep b = (C_0 − C_i)·n_i of sign σ.
            let a = (ring[i] - c0).dot(n);
            if a.abs() <= 1e-6 * scale {
                ok = false; // C_i on π: the edge's class would hang on rounding
                break;
            }
            let sigma = a.signum();
            let ni = normals[i];
            // Strictly convex by PLANE_MARGIN: C_0 on face i's plane would make the fan
            // triangles coplanar with face i's across a nonzero-convex edge (App. B (5'')(iii)).
            planes.push((
                sigma * flat2(ni),
                -sigma * (c0 - ring[i]).dot(ni) + PLANE_MARGIN * scale,
            ));
        }
        if !ok {
            continue;
        }
        if let Some(region) = clip(&planes, &flat) {
            let p = nearest_to_origin(&region);
            let q = c0 + p.x * u + p.y * w;
            let d = (q - paper).length();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, q));
            }
        }
    }
    best.map_or(paper, |(_, q)| q)
}

/// The intersection of the half-planes, inside a box round `pts` and the origin; `None` when it
/// has no interior (fewer than three corners).
fn clip(planes: &[HalfPlane], pts: &[DVec2]) -> Option<Vec<DVec2>> {
    let (lo, hi) = pts.iter().fold((DVec2::ZERO, DVec2::ZERO), |(a, b), &p| {
        (a.min(p), b.max(p))
    });
    let pad = (hi - lo).max_element().max(1e-300);
    let (lo, hi) = (lo - DVec2::splat(pad), hi + DVec2::splat(pad));
    let mut region = vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    for &(wv, c) in planes {
        let f = |p: DVec2| wv.dot(p) - c;
        let mut next = Vec::with_capacity(region.len() + 1);
        for j in 0..region.len() {
            let (p, q) = (region[j], region[(j + 1) % region.len()]);
            let (fp, fq) = (f(p), f(q));
            if fp >= 0.0 {
                next.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                next.push(p + (q - p) * (fp / (fp - fq)));
            }
        }
        region = next;
        if region.len() < 3 {
            return None;
        }
    }
    Some(region)
}

/// The point of the convex polygon `poly` nearest to the origin (the origin itself when inside).
fn nearest_to_origin(poly: &[DVec2]) -> DVec2 {
    let m = poly.len();
    let inside = (0..m).all(|j| (poly[(j + 1) % m] - poly[j]).perp_dot(-poly[j]) >= 0.0);
    if inside {
        return DVec2::ZERO;
    }
    let mut best = poly[0];
    for j in 0..m {
        let (a, b) = (poly[j], poly[(j + 1) % m]);
        let e = b - a;
        let t = if e.length_squared() > 0.0 {
            (-a.dot(e) / e.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let p = a + t * e;
        if p.length_squared() < best.length_squared() {
            best = p;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square fan round V keeps the paper's C_0; a fan whose centroids all lie to one side of
    /// V (V outside the kernel) slides C_0 within π to where every projected triangle is at
    /// least FAN_MARGIN of its base high, and every edge C_0C_i stays convex.
    #[test]
    fn pseudo_centroid_moves_into_shrunk_kernel() {
        let n = DVec3::Z;
        // Faces tilted 30° down and away from their centroid direction: a convex corner.
        let dirs = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
        let tilt = |d: DVec3| (d * 0.5 + DVec3::Z * 0.75f64.sqrt()).normalize();
        let normals = dirs.map(tilt);
        // Centroids in the face planes through V = 0, below π.
        let ring = dirs.map(|d| {
            let nd = tilt(d);
            let p = d;
            p - nd.dot(p) * nd
        });
        let t_star = ring.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
        let c = place_pseudo_centroid(DVec3::ZERO, n, t_star, 0.5, &ring, &normals);
        assert_eq!(c, 0.5 * t_star * n);
        // Shift the centroids of the fan sideways (as on the coarse torus): V's projection
        // leaves the kernel.
        let shift = DVec3::new(0.9, 0.0, 0.0);
        let moved = ring.map(|p| p + shift);
        let normals2 = normals;
        let t2 = moved.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
        let c = place_pseudo_centroid(DVec3::ZERO, n, t2, 0.5, &moved, &normals2);
        for i in 0..4 {
            let (a, b) = (moved[i].truncate(), moved[(i + 1) % 4].truncate());
            let e = b - a;
            let h = e.perp_dot(c.truncate() - a) / e.length();
            // Rounding of the clipping only (1e-12).
            assert!(h >= FAN_MARGIN * e.length() - 1e-12, "{i}: {h}");
            // Edge C_0C_i convex: a and b of one sign (both ≤ 0 here), b at least PLANE_MARGIN
            // of the ring's size off face i's plane, up to rounding.
            let av = (moved[i] - c).dot(n);
            let bv = (c - moved[i]).dot(normals2[i]);
            let scale = moved.iter().map(|p| p.length()).fold(0.0, f64::max);
            assert!(
                av < 0.0 && bv <= -PLANE_MARGIN * scale + 1e-12,
                "{i}: a {av} b {bv}"
            );
        }
    }
}

//! Face-tetrahedron sides from the convexity of T's edges (Definitions 3.1, 3.2, 3.4), and
//! apexes over the base for dense triangle meshes.
//!
//! Why: the cubic (and quintic) scheme fixes F on every edge [p_i p_j] of T from the Hermite
//! data alone: F(p_i) = F(p_j) = 0 with slopes ∇F(p_i)·(p_j − p_i) and ∇F(p_j)·(p_j − p_i).
//! So the sign of F along the edge, and with it the side of T the surface takes near that
//! edge, is a property of the edge (Definition 3.1): negatively convex ((p_j − p_i)·n_i < 0 or
//! (p_i − p_j)·n_j < 0) puts the surface on the outer side, positively convex on the inner
//! side, nonconvex on both, zero convex on neither. A triangle therefore needs a face
//! tetrahedron on every side one of its edges asks for (Definition 3.2/3.4: a face with edges of
//! both kinds is nonconvex and gets an L-U pair), and then the two triangles at every edge share
//! that edge's side and are joined by edge tetrahedra (Def. 3.6 (5)(ii)).
//!
//! Algorithm 1's steps (5)(i)–(iii) choose the sides from the position of T_0 and T_1 against
//! C_0's tangent plane instead. On dense meshes (small dihedral angles, C_0 close to V) that
//! disagrees with the edge classes: a convex corner V with one valley edge gives its triangle
//! only an outer tetrahedron while the neighbour at V' gives only an inner one. There, and where
//! an apex does not lie over its base (the projection of the midpoint M onto π_{C_0}, step (5)(ii),
//! falls on the chord C_1C_2 and gives slivers that overlap the tetrahedra at V'), [`settle`]
//! replaces the triangle's apexes by points over its base: the centroid g of the triangle moved
//! along its unit normal ±N by the least height that makes the tetrahedron (or the L-U pair)
//! tangent-containing (Definition 3.5) at each of its vertices, and at least [`MIN_HEIGHT`]
//! times the longest edge.

use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use crate::mesh::convexity::{edge_convexity_1994, Convexity};
use glam::DVec3;

/// Smallest apex height over the base, relative to the triangle's longest edge: thick enough
/// that barycentric coordinates keep their digits (verify's degeneracy bound is 1e-8 in
/// volume), thin enough to stay clear of the neighbours' tetrahedra at T's small dihedral
/// angles.
pub const MIN_HEIGHT: f64 = 0.08;

/// Largest apex height over the base, relative to the longest edge; a triangle needing more
/// keeps Algorithm 1's apexes.
pub const MAX_HEIGHT: f64 = 1.0;

/// Smallest barycentric coordinate the projection of an apex onto its base's plane may have
/// before the triangle is rebuilt here (0: the apex lies over the closed base triangle).
pub const OVER_BASE: f64 = 0.0;

/// What [`settle`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SideCounts {
    /// Triangles that lacked a side one of their edges asks for.
    pub missing_side: usize,
    /// Triangles whose apex did not lie over the base.
    pub off_base: usize,
    /// Triangles whose apexes were replaced.
    pub rebuilt: usize,
    /// Triangles flagged but left as they were (no apex height up to [`MAX_HEIGHT`] works).
    pub kept: usize,
}

/// The sides (`[outer, inner]`) a surface crossing the edge (p_a, p_b) of T with normals n_a,
/// n_b takes near it (Definition 3.1; see the module docs).
#[must_use]
pub fn edge_sides(pa: DVec3, na: DVec3, pb: DVec3, nb: DVec3) -> [bool; 2] {
    match edge_convexity_1994(pa, na, pb, nb) {
        Convexity::Negative => [true, false],
        Convexity::Positive => [false, true],
        Convexity::Nonconvex => [true, true],
        Convexity::Zero => [false, false],
    }
}

/// Barycentric coordinates of the projection of q onto the plane of (a, b, c).
fn bary(a: DVec3, b: DVec3, c: DVec3, q: DVec3) -> [f64; 3] {
    let m = (b - a).cross(c - a);
    let m2 = m.length_squared();
    let l1 = (c - b).cross(q - b).dot(m) / m2;
    let l2 = (a - c).cross(q - c).dot(m) / m2;
    [l1, l2, 1.0 - l1 - l2]
}

/// Apexes over the base for `required` sides of the triangle `base` with vertex normals
/// `normals`, or `None` when some vertex's tangent plane cannot be met within [`MAX_HEIGHT`].
///
/// The apexes rise from the base's centroid along the mean of the three vertex normals (two of
/// which the neighbour across each edge shares, so neighbouring apexes rise nearly in parallel
/// and their midpoints s stay over the shared edge even where T folds), or along the base's
/// normal where that mean is more than 60° off it or would leave the apex outside the base.
#[must_use]
pub fn apexes_over_base(
    base: [DVec3; 3],
    normals: [DVec3; 3],
    required: [bool; 2],
) -> Option<[Option<DVec3>; 2]> {
    let [a, b, c] = base;
    let nn = (b - a).cross(c - a).try_normalize()?;
    let mean = (normals[0] + normals[1] + normals[2]).normalize_or_zero();
    if mean.dot(nn) >= 0.5 {
        if let Some(out) = apexes_along(base, normals, required, mean) {
            let over = out
                .iter()
                .flatten()
                .all(|&q| bary(a, b, c, q).iter().all(|&l| l >= 0.0));
            if over {
                return Some(out);
            }
        }
    }
    apexes_along(base, normals, required, nn)
}

/// [`apexes_over_base`] along the unit direction `up` (with up · N > 0).
fn apexes_along(
    base: [DVec3; 3],
    normals: [DVec3; 3],
    required: [bool; 2],
    up: DVec3,
) -> Option<[Option<DVec3>; 2]> {
    let [a, b, c] = base;
    let g = (a + b + c) / 3.0;
    let len = (b - a).length().max((c - b).length()).max((a - c).length());
    // Distance along +up (outer) or −up (inner) per side.
    let mut h = [MIN_HEIGHT * len; 2];
    for k in 0..3 {
        let (p, n) = (base[k], normals[k]);
        let vals = [n.dot(base[(k + 1) % 3] - p), n.dot(base[(k + 2) % 3] - p)];
        // Rounding of the coordinates: the base vertices lie on the tangent plane up to this.
        let tol = 1e-12 * len;
        let (lo, hi) = (vals[0].min(vals[1]), vals[0].max(vals[1]));
        if lo <= tol && hi >= -tol {
            continue; // the base already meets the tangent plane
        }
        // An apex must reach the other side: sign wanted for n·(q − p).
        let want = if hi < 0.0 { 1.0 } else { -1.0 };
        let g0 = want * n.dot(g - p);
        // q = g ± h·up gives want·n·(q − p) = g0 ± h·want·n·up; reach a margin of 5% of the
        // base's depth so the plane cuts the tetrahedron cleanly. Of the sides that can, take
        // the one that has to rise least beyond its height so far.
        let target = 0.05 * lo.abs().min(hi.abs());
        let mut best: Option<(usize, f64)> = None;
        for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
            if !required[side] {
                continue;
            }
            let rate = sign * want * n.dot(up);
            let need = if g0 >= target {
                0.0
            } else if rate > 1e-9 {
                (target - g0) / rate
            } else {
                continue;
            };
            let extra = (need - h[side]).max(0.0);
            if best.is_none_or(|(s, x)| extra < (x - h[s]).max(0.0)) {
                best = Some((side, need));
            }
        }
        let (side, need) = best?;
        h[side] = h[side].max(need);
    }
    let mut out = [None, None];
    for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
        if required[side] {
            if h[side] > MAX_HEIGHT * len {
                return None;
            }
            out[side] = Some(g + sign * h[side] * up);
        }
    }
    Some(out)
}

/// Gives every triangle of `hull` the face tetrahedra its edges ask for, rebuilding the
/// apexes over the base where a side is missing or an apex is not over its base (module docs).
/// Triangles all of whose edges are zero convex (coplanar groups, Appendix B) keep theirs.
pub fn settle(hull: &mut SimplicialHull) -> SideCounts {
    let mut counts = SideCounts::default();
    let Ok(edges) = hull.edges() else {
        return counts;
    };
    let mut required = vec![[false; 2]; hull.triangles.len()];
    for e in &edges {
        let [a, b] = e.v.map(|i| i as usize);
        let sides = edge_sides(
            hull.points[a],
            hull.normals[a],
            hull.points[b],
            hull.normals[b],
        );
        for f in e.faces {
            if let Some(r) = required.get_mut(f as usize) {
                r[0] |= sides[0];
                r[1] |= sides[1];
            }
        }
    }
    for (t, &req) in required.iter().enumerate() {
        if !req[0] && !req[1] {
            continue;
        }
        let base = hull.triangles[t].map(|i| hull.points[i as usize]);
        let missing = (0..2).any(|s| req[s] && hull.apexes[t][s].is_none());
        // Only step (5) triangles (with a pseudo-centroid): a trihedral corner's apex V and the
        // hallway pair of step (3') need not lie over the base and are valid as built.
        let step5 = hull.triangles[t]
            .iter()
            .any(|&i| matches!(hull.origins[i as usize], PointOrigin::PseudoCentroid { .. }));
        let off = step5
            && hull.apexes[t].iter().flatten().any(|&q| {
                bary(base[0], base[1], base[2], q)
                    .iter()
                    .any(|&l| l < OVER_BASE)
            });
        if !missing && !off && !step5 {
            continue;
        }
        counts.missing_side += usize::from(missing);
        counts.off_base += usize::from(off && !missing);
        let normals = hull.triangles[t].map(|i| hull.normals[i as usize]);
        match apexes_over_base(base, normals, req) {
            Some(apexes) => {
                hull.apexes[t] = apexes;
                counts.rebuilt += 1;
            }
            None => counts.kept += 1,
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat triangle with normals tilted outwards at every vertex (a convex cap): each
    /// vertex's tangent plane leaves the other two below it, so the outer apex must rise above
    /// all three planes; checked against the planes directly.
    #[test]
    fn convex_cap_apex_clears_every_tangent_plane() {
        let base = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let g = (base[0] + base[1] + base[2]) / 3.0;
        let normals = base.map(|p| (p - g + 2.0 * DVec3::Z).normalize());
        let apexes = apexes_over_base(base, normals, [true, false]).unwrap();
        let q = apexes[0].unwrap();
        assert!(apexes[1].is_none());
        for k in 0..3 {
            // Above the tangent plane at p_k, while the other two base vertices are below.
            assert!(normals[k].dot(q - base[k]) > 0.0);
            assert!(normals[k].dot(base[(k + 1) % 3] - base[k]) < 0.0);
        }
        // Over the base: its projection lies in the triangle.
        assert!(bary(base[0], base[1], base[2], q).iter().all(|&l| l > 0.0));
    }

    /// A saddle-like triangle needing both sides gets one apex on each side.
    #[test]
    fn both_sides_give_an_lu_pair() {
        let base = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let apexes = apexes_over_base(base, [DVec3::Z; 3], [true, true]).unwrap();
        assert!(apexes[0].unwrap().z > 0.0 && apexes[1].unwrap().z < 0.0);
    }
}

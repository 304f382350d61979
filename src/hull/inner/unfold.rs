//! Folded-back edges of T between two pseudo-centroids: the diagonal flip.
//!
//! Why: Algorithm 1 step (5) joins the pseudo-centroid C_0 of a non-trihedral vertex V to the
//! centroids C_1, C_2 of the two faces at every edge e = VV'. When V' is non-trihedral too, the
//! edge C_1C_2 of T is shared by the triangles [C_0C_1C_2] of V and [C_0'C_2C_1] of V', a quad
//! C_0 C_1 C_0' C_2 whose diagonal C_1C_2 crosses e. Where e is short against the faces (the
//! double torus's waist has edges ten times shorter than their neighbours, between saddle
//! vertices whose normals differ by 70°), C_0 and C_0' lie close to the middle of C_1C_2 on
//! different sides, and the two triangles fold back onto each other (their normals ~140°
//! apart). Their face tetrahedra then overlap, and the edge tetrahedra between them are
//! inverted: no placement of apexes satisfies Definition 3.6 (5)(i) there.
//!
//! The other diagonal C_0C_0' runs along e, and the triangles [C_0 C_1 C_0'], [C_0' C_2 C_0]
//! are nearly coplanar with their neighbours. [`flip_folds`] makes that flip where it turns a
//! fold of more than 90° into a milder one without creating a sharper fold at the quad's other
//! edges, and only when the new edge is convex (Definition 3.1, Lemma 4.1). The new triangles
//! get face tetrahedra over their bases on the sides their edges ask for
//! ([`sides::apexes_over_base`]); [`sides::settle`] then treats them like every step (5)
//! triangle. T keeps its points, its genus and its orientation.

use super::sides::{apexes_over_base, edge_sides};
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use crate::mesh::convexity::{edge_convexity_1994, Convexity};
use glam::DVec3;
use std::collections::{HashMap, HashSet};

/// Cosine of the angle between two triangles' normals below which their shared edge counts as
/// folded back (the triangles turn by more than 90°).
pub const FOLD_COS: f64 = 0.0;

/// Unit normal of the triangle `tri` of `hull`, or `None` when it is degenerate.
fn unit_normal(hull: &SimplicialHull, tri: [u32; 3]) -> Option<DVec3> {
    let [a, b, c] = tri.map(|i| hull.points[i as usize]);
    (b - a).cross(c - a).try_normalize()
}

/// `tri` rotated so that it starts with the directed edge (a, b), with its third point.
fn third(tri: [u32; 3], a: u32, b: u32) -> Option<u32> {
    (0..3)
        .find(|&k| tri[k] == a && tri[(k + 1) % 3] == b)
        .map(|k| tri[(k + 2) % 3])
}

/// Sides (`[outer, inner]`) the edges of `tri` ask for (Definition 3.1).
fn required_sides(hull: &SimplicialHull, tri: [u32; 3]) -> [bool; 2] {
    let mut req = [false; 2];
    for k in 0..3 {
        let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
        let s = edge_sides(
            hull.points[a],
            hull.normals[a],
            hull.points[b],
            hull.normals[b],
        );
        req[0] |= s[0];
        req[1] |= s[1];
    }
    req
}

/// Shallower cuts tried for the pseudo-centroids C_0 = V + λ (C_0 − V) at the ends of a
/// flipped diagonal, in order, when their present places make it nonconvex: λ moves C_0 along
/// V's normal towards V, which keeps it between V and V̄ (Algorithm 1 step (4): a larger α), so
/// its own step (5) edges stay convex.
pub const CUTS: [(f64, f64); 9] = [
    (1.0, 1.0),
    (0.5, 1.0),
    (1.0, 0.5),
    (0.5, 0.5),
    (0.25, 1.0),
    (1.0, 0.25),
    (0.25, 0.5),
    (0.5, 0.25),
    (0.25, 0.25),
];

/// Flips every edge of T that folds back between a pseudo-centroid pair (module docs), one at a
/// time, sharpest first, until none qualifies. `positions` are the polyhedron's vertices (the V
/// of every pseudo-centroid). Returns the number of flips.
pub fn flip_folds(hull: &mut SimplicialHull, positions: &[DVec3]) -> usize {
    let mut flips = 0;
    // Each flip raises the worst fold round the quad, so the loop ends; the bound only guards
    // against cycling through equal folds.
    for _ in 0..hull.triangles.len() {
        if !flip_one(hull, positions) {
            break;
        }
        flips += 1;
    }
    flips
}

/// Edge → the (up to two) triangles holding it.
fn edge_faces(hull: &SimplicialHull) -> HashMap<(u32, u32), Vec<usize>> {
    let mut map: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, tri) in hull.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            map.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    map
}

/// Over the edges of every triangle that uses one of `pts`: the smallest cosine between the
/// normals of an edge's two triangles, the number of edges folded back (that cosine below
/// [`FOLD_COS`]) and the number of nonconvex edges (Definition 3.1).
fn local_quality(hull: &SimplicialHull, pts: [u32; 2]) -> (f64, usize, usize) {
    let map = edge_faces(hull);
    let mut seen = HashSet::new();
    let mut worst = f64::INFINITY;
    let mut nonconvex = 0;
    let mut folded = 0;
    for tri in hull
        .triangles
        .iter()
        .filter(|t| pts.iter().any(|p| t.contains(p)))
    {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            if !seen.insert(key) {
                continue;
            }
            let (pa, pb) = (hull.points[a as usize], hull.points[b as usize]);
            let (na, nb) = (hull.normals[a as usize], hull.normals[b as usize]);
            if edge_convexity_1994(pa, na, pb, nb) == Convexity::Nonconvex {
                nonconvex += 1;
            }
            if let [f, g] = map[&key][..] {
                match (
                    unit_normal(hull, hull.triangles[f]),
                    unit_normal(hull, hull.triangles[g]),
                ) {
                    (Some(m), Some(n)) => {
                        worst = worst.min(m.dot(n));
                        folded += usize::from(m.dot(n) < FOLD_COS);
                    }
                    _ => worst = f64::NEG_INFINITY,
                }
            }
        }
    }
    (worst, folded, nonconvex)
}

/// The vertex V of a pseudo-centroid point, if `i` is one.
fn corner_of(hull: &SimplicialHull, positions: &[DVec3], i: u32) -> Option<DVec3> {
    match hull.origins[i as usize] {
        PointOrigin::PseudoCentroid { vertex } => positions.get(vertex as usize).copied(),
        _ => None,
    }
}

/// A fold between pseudo-centroids: its cosine, the two triangles, the edge (v0, v1) and the
/// third points c (of the first triangle) and d.
type Fold = (f64, usize, usize, u32, u32, u32, u32);

/// Finds the sharpest fold that a flip (with the first of [`CUTS`] that works) improves, and
/// makes it; false when there is none.
fn flip_one(hull: &mut SimplicialHull, positions: &[DVec3]) -> bool {
    let Ok(edges) = hull.edges() else {
        return false;
    };
    let present: HashSet<(u32, u32)> = edges
        .iter()
        .map(|e| (e.v[0].min(e.v[1]), e.v[0].max(e.v[1])))
        .collect();
    // Folds between pseudo-centroid pairs, sharpest first.
    let mut folds: Vec<Fold> = Vec::new();
    for e in &edges {
        if e.faces[1] == u32::MAX {
            continue;
        }
        let [f0, f1] = e.faces.map(|f| f as usize);
        let [v0, v1] = e.v;
        let (Some(c), Some(d)) = (
            third(hull.triangles[f0], v0, v1),
            third(hull.triangles[f1], v1, v0),
        ) else {
            continue;
        };
        if corner_of(hull, positions, c).is_none()
            || corner_of(hull, positions, d).is_none()
            || c == d
            || present.contains(&(c.min(d), c.max(d)))
        {
            continue;
        }
        let (Some(n0), Some(n1)) = (
            unit_normal(hull, hull.triangles[f0]),
            unit_normal(hull, hull.triangles[f1]),
        ) else {
            continue;
        };
        let before = n0.dot(n1);
        if before < FOLD_COS {
            folds.push((before, f0, f1, v0, v1, c, d));
        }
    }
    folds.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, f0, f1, v0, v1, c, d) in folds {
        let (before_worst, before_folded, before_bad) = local_quality(hull, [c, d]);
        let old = (
            hull.points[c as usize],
            hull.points[d as usize],
            hull.triangles[f0],
            hull.triangles[f1],
        );
        let (vc, vd) = (
            corner_of(hull, positions, c).expect("checked"),
            corner_of(hull, positions, d).expect("checked"),
        );
        // The quad runs v1, c, v0, d; the new triangles share the diagonal (c, d).
        hull.triangles[f0] = [c, v0, d];
        hull.triangles[f1] = [d, v1, c];
        for (lc, ld) in CUTS {
            hull.points[c as usize] = vc + lc * (old.0 - vc);
            hull.points[d as usize] = vd + ld * (old.1 - vd);
            let (worst, folded, bad) = local_quality(hull, [c, d]);
            // No new nonconvex edge (Lemma 4.1); fewer folds round c and d, or as many and
            // the worst one milder.
            let better = folded < before_folded || folded == before_folded && worst > before_worst;
            if bad > before_bad || !better {
                continue;
            }
            if let Some(()) = place_apexes(hull, [c, d], [f0, f1]) {
                return true;
            }
        }
        hull.points[c as usize] = old.0;
        hull.points[d as usize] = old.1;
        hull.triangles[f0] = old.2;
        hull.triangles[f1] = old.3;
    }
    false
}

/// Gives the triangles `new` (which must get them) and every other triangle that uses one of
/// `pts` (where they exist; [`sides::settle`] revisits those) face tetrahedra over their bases
/// on the sides their edges ask for (the outer side when they ask for none). `None`, changing
/// nothing, when one of `new` has no such apexes.
fn place_apexes(hull: &mut SimplicialHull, pts: [u32; 2], new: [usize; 2]) -> Option<()> {
    let mut out = Vec::new();
    for (t, tri) in hull.triangles.iter().enumerate() {
        if !pts.iter().any(|p| tri.contains(p)) {
            continue;
        }
        let base = tri.map(|i| hull.points[i as usize]);
        let normals = tri.map(|i| hull.normals[i as usize]);
        let req = required_sides(hull, *tri);
        let req = if req[0] || req[1] { req } else { [true, false] };
        match apexes_over_base(base, normals, req) {
            Some(a) => out.push((t, a)),
            None if new.contains(&t) => return None,
            None => {}
        }
    }
    for (t, a) in out {
        hull.apexes[t] = a;
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad of two triangles folded back 150° along their diagonal (v0, v1), whose other
    /// two corners are pseudo-centroids, inside a ring of four flat neighbours: the flip makes
    /// (c, d) the diagonal, the two new triangles nearly coplanar, every edge of the quad is
    /// still shared by exactly two triangles running opposite ways, and the apexes lie on
    /// the sides the edges ask for.
    #[test]
    fn folded_quad_is_flipped() {
        // v0 = (−1, 0, 0), v1 = (1, 0, 0); c, d close to the middle of v0v1, on either side
        // in y, raised so that [v0 v1 c] and [v1 v0 d] fold back onto each other.
        let pts = vec![
            DVec3::new(-1.0, 0.0, 0.0),  // 0 v0
            DVec3::new(1.0, 0.0, 0.0),   // 1 v1
            DVec3::new(0.0, 0.05, 0.2),  // 2 c
            DVec3::new(0.0, -0.05, 0.2), // 3 d
            DVec3::new(0.0, 1.0, 0.0),   // 4 outer ring
            DVec3::new(0.0, -1.0, 0.0),  // 5
        ];
        let n = pts.len();
        let mut origins = vec![PointOrigin::Other; n];
        origins[2] = PointOrigin::PseudoCentroid { vertex: 0 };
        origins[3] = PointOrigin::PseudoCentroid { vertex: 1 };
        // Quad v1, c, v0, d plus a fan to 4 (over c's side) and 5 (over d's side), closed
        // by two back triangles [0 4 1]... kept open: the flip only needs the neighbours.
        let triangles = vec![
            [0, 1, 2], // f0: v0 → v1, third c
            [1, 0, 3], // f1: v1 → v0, third d
            [2, 1, 4], // across (v1, c)
            [0, 2, 4], // across (c, v0)
            [3, 0, 5], // across (v0, d)
            [1, 3, 5], // across (d, v1)
        ];
        let mut hull = SimplicialHull {
            points: pts,
            normals: vec![DVec3::Z; n],
            origins,
            apexes: vec![[Some(DVec3::new(0.0, 0.0, 1.0)), None]; triangles.len()],
            element: vec![0; triangles.len()],
            triangles,
        };
        // The polyhedron's vertices of the two pseudo-centroids: just above them.
        let corners = [DVec3::new(0.0, 0.05, 0.25), DVec3::new(0.0, -0.05, 0.25)];
        let before = unit_normal(&hull, [0, 1, 2])
            .unwrap()
            .dot(unit_normal(&hull, [1, 0, 3]).unwrap());
        assert!(before < FOLD_COS, "{before}");
        assert_eq!(flip_folds(&mut hull, &corners), 1);
        assert_eq!(hull.triangles[0], [2, 0, 3]);
        assert_eq!(hull.triangles[1], [3, 1, 2]);
        let after = unit_normal(&hull, hull.triangles[0])
            .unwrap()
            .dot(unit_normal(&hull, hull.triangles[1]).unwrap());
        // Both new triangles lie in planes through the x = 0 line tilted by at most atan(0.2/1):
        // their normals are within 2·11.4° of each other.
        assert!(after > 0.9, "{after}");
        for e in hull.edges().unwrap() {
            if e.faces[1] != u32::MAX {
                let t1 = hull.triangles[e.faces[1] as usize];
                assert!((0..3).any(|k| t1[k] == e.v[1] && t1[(k + 1) % 3] == e.v[0]));
            }
        }
        for t in 0..2 {
            let tri = hull.triangles[t];
            let [a, b, c] = tri.map(|i| hull.points[i as usize]);
            let req = required_sides(&hull, tri);
            for (side, sign) in [(0, 1.0), (1, -1.0)] {
                assert_eq!(
                    hull.apexes[t][side].is_some(),
                    req[side] || (side == 0 && !req[1])
                );
                if let Some(q) = hull.apexes[t][side] {
                    assert!(sign * (b - a).cross(c - a).dot(q - a) > 0.0);
                }
            }
        }
        // Nothing folds back any more.
        assert_eq!(flip_folds(&mut hull, &corners), 0);
    }
}

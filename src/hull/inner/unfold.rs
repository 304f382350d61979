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
use std::collections::HashSet;

/// Cosine of the angle between two triangles' normals below which their shared edge counts as
/// folded back (the triangles turn by more than 90°).
pub const FOLD_COS: f64 = 0.0;

/// Unit normal of the triangle `tri` of `hull`, or `None` when it is degenerate.
pub(super) fn unit_normal(hull: &SimplicialHull, tri: [u32; 3]) -> Option<DVec3> {
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
pub(super) fn required_sides(hull: &SimplicialHull, tri: [u32; 3]) -> [bool; 2] {
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

/// Flips every edge of T that folds back between a pseudo-centroid pair (module docs), sharpest
/// first, in passes until one flips nothing. `positions` are the polyhedron's vertices (the V
/// of every pseudo-centroid). Returns the number of flips.
pub fn flip_folds(hull: &mut SimplicialHull, positions: &[DVec3]) -> usize {
    let mut incident = incidence(hull);
    let mut flips = 0;
    // Each flip lowers the folds round its quad, so passes end; the bound only guards against
    // cycling through equal folds.
    for _ in 0..8 {
        let done = flip_pass(hull, positions, &mut incident);
        flips += done;
        if done == 0 {
            break;
        }
    }
    flips
}

/// For each point of T, the triangles that use it.
pub(super) fn incidence(hull: &SimplicialHull) -> Vec<Vec<usize>> {
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); hull.points.len()];
    for (t, tri) in hull.triangles.iter().enumerate() {
        for &i in tri {
            if let Some(list) = incident.get_mut(i as usize) {
                list.push(t);
            }
        }
    }
    incident
}

/// The triangles holding the undirected edge (a, b).
fn faces_of(incident: &[Vec<usize>], hull: &SimplicialHull, a: u32, b: u32) -> Vec<usize> {
    incident[a as usize]
        .iter()
        .copied()
        .filter(|&t| hull.triangles[t].contains(&b))
        .collect()
}

/// Over the edges of every triangle that uses one of `pts`: the smallest cosine between the
/// normals of an edge's two triangles, the number of edges folded back (that cosine below
/// [`FOLD_COS`]) and the number of nonconvex edges (Definition 3.1).
pub(super) fn local_quality(
    hull: &SimplicialHull,
    incident: &[Vec<usize>],
    pts: [u32; 2],
) -> (f64, usize, usize) {
    let mut seen = HashSet::new();
    let mut worst = f64::INFINITY;
    let mut nonconvex = 0;
    let mut folded = 0;
    let tris: HashSet<usize> = pts
        .iter()
        .flat_map(|&p| incident[p as usize].iter().copied())
        .collect();
    for &t in &tris {
        let tri = hull.triangles[t];
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
            if let [f, g] = faces_of(incident, hull, a, b)[..] {
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

/// The quad of T round an edge whose flip would join two pseudo-centroids.
#[derive(Clone, Copy, Debug)]
pub(super) struct Quad {
    /// The edge's points (v0, v1).
    pub v: [u32; 2],
    /// The triangle holding the directed edge (v0, v1), then the one holding (v1, v0).
    pub f: [usize; 2],
    /// The third point of `f[0]` (a pseudo-centroid).
    pub c: u32,
    /// The third point of `f[1]` (a pseudo-centroid).
    pub d: u32,
    /// The polyhedron's vertex V of c.
    pub vc: DVec3,
    /// The polyhedron's vertex V of d.
    pub vd: DVec3,
}

/// The quad round the edge `[v0, v1]` of T as it is now, when both its other corners are
/// pseudo-centroids not yet joined by an edge; `None` otherwise.
pub(super) fn pseudo_centroid_quad(
    hull: &SimplicialHull,
    incident: &[Vec<usize>],
    positions: &[DVec3],
    [v0, v1]: [u32; 2],
) -> Option<Quad> {
    let [fa, fb] = faces_of(incident, hull, v0, v1)[..] else {
        return None;
    };
    let (f0, f1) = if third(hull.triangles[fa], v0, v1).is_some() {
        (fa, fb)
    } else {
        (fb, fa)
    };
    let c = third(hull.triangles[f0], v0, v1)?;
    let d = third(hull.triangles[f1], v1, v0)?;
    let (vc, vd) = (
        corner_of(hull, positions, c)?,
        corner_of(hull, positions, d)?,
    );
    if c == d || !faces_of(incident, hull, c, d).is_empty() {
        return None; // the other diagonal is an edge already
    }
    Some(Quad {
        v: [v0, v1],
        f: [f0, f1],
        c,
        d,
        vc,
        vd,
    })
}

impl Quad {
    /// Flips the quad's diagonal to (c, d) and moves c and d along their cut lines, C_0 = V +
    /// λ (C_0 − V) for each (λ_c, λ_d) of `cuts` in order, until `accept` takes the hull as it
    /// then is (placing apexes as it needs). Where none is taken, the points and triangles are
    /// put back as they were. Returns whether the flip was made.
    pub(super) fn try_flip(
        &self,
        hull: &mut SimplicialHull,
        incident: &mut [Vec<usize>],
        cuts: impl IntoIterator<Item = (f64, f64)>,
        mut accept: impl FnMut(&mut SimplicialHull, &[Vec<usize>]) -> bool,
    ) -> bool {
        let Quad {
            v: [v0, v1],
            f: [f0, f1],
            c,
            d,
            vc,
            vd,
        } = *self;
        let old = (
            hull.points[c as usize],
            hull.points[d as usize],
            hull.triangles[f0],
            hull.triangles[f1],
        );
        // The quad runs v1, c, v0, d; the new triangles share the diagonal (c, d).
        set_triangle(hull, incident, f0, [c, v0, d]);
        set_triangle(hull, incident, f1, [d, v1, c]);
        for (lc, ld) in cuts {
            hull.points[c as usize] = vc + lc * (old.0 - vc);
            hull.points[d as usize] = vd + ld * (old.1 - vd);
            if accept(hull, incident) {
                return true;
            }
        }
        hull.points[c as usize] = old.0;
        hull.points[d as usize] = old.1;
        set_triangle(hull, incident, f0, old.2);
        set_triangle(hull, incident, f1, old.3);
        false
    }
}

/// Replaces triangle `t` by `new`, keeping `incident` up to date.
fn set_triangle(hull: &mut SimplicialHull, incident: &mut [Vec<usize>], t: usize, new: [u32; 3]) {
    for &i in &hull.triangles[t] {
        incident[i as usize].retain(|&x| x != t);
    }
    hull.triangles[t] = new;
    for &i in &new {
        incident[i as usize].push(t);
    }
}

/// One pass: every fold between pseudo-centroids, sharpest first, is flipped (with the first of
/// [`CUTS`] that works) if that still improves it. Returns the number of flips.
fn flip_pass(hull: &mut SimplicialHull, positions: &[DVec3], incident: &mut [Vec<usize>]) -> usize {
    let Ok(edges) = hull.edges() else {
        return 0;
    };
    // Folds between pseudo-centroid pairs: (cosine, the edge), sharpest first.
    let mut folds: Vec<(f64, [u32; 2])> = Vec::new();
    for e in &edges {
        if e.faces[1] == u32::MAX {
            continue;
        }
        let [f0, f1] = e.faces.map(|f| f as usize);
        let (Some(n0), Some(n1)) = (
            unit_normal(hull, hull.triangles[f0]),
            unit_normal(hull, hull.triangles[f1]),
        ) else {
            continue;
        };
        if n0.dot(n1) < FOLD_COS {
            folds.push((n0.dot(n1), e.v));
        }
    }
    folds.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut flips = 0;
    for (_, [v0, v1]) in folds {
        // The edge as it is now (earlier flips may have removed it).
        let Some(quad) = pseudo_centroid_quad(hull, incident, positions, [v0, v1]) else {
            continue;
        };
        let [f0, f1] = quad.f;
        let (Some(n0), Some(n1)) = (
            unit_normal(hull, hull.triangles[f0]),
            unit_normal(hull, hull.triangles[f1]),
        ) else {
            continue;
        };
        if n0.dot(n1) >= FOLD_COS {
            continue;
        }
        let (c, d) = (quad.c, quad.d);
        let (before_worst, before_folded, before_bad) = local_quality(hull, incident, [c, d]);
        let flipped = quad.try_flip(hull, incident, CUTS, |hull, incident| {
            let (worst, folded, bad) = local_quality(hull, incident, [c, d]);
            // No new nonconvex edge (Lemma 4.1); fewer folds round c and d, or as many and
            // the worst one milder.
            let better = folded < before_folded || folded == before_folded && worst > before_worst;
            bad <= before_bad && better && place_apexes(hull, incident, [c, d], [f0, f1]).is_some()
        });
        flips += usize::from(flipped);
    }
    flips
}

/// Gives the triangles `new` (which must get them) and every other triangle that uses one of
/// `pts` (where they exist; [`sides::settle`] revisits those) face tetrahedra over their bases
/// on the sides their edges ask for (the outer side when they ask for none). `None`, changing
/// nothing, when one of `new` has no such apexes.
pub(super) fn place_apexes(
    hull: &mut SimplicialHull,
    incident: &[Vec<usize>],
    pts: [u32; 2],
    new: [usize; 2],
) -> Option<()> {
    let mut out = Vec::new();
    let tris: HashSet<usize> = pts
        .iter()
        .flat_map(|&p| incident[p as usize].iter().copied())
        .collect();
    for t in tris {
        let tri = hull.triangles[t];
        let base = tri.map(|i| hull.points[i as usize]);
        let normals = tri.map(|i| hull.normals[i as usize]);
        let req = required_sides(hull, tri);
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

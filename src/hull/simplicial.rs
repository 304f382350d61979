//! The smoothable simplicial hull Σ = (T, S_f, S_e) of Definition 3.6 (Bajaj, Chen, Xu 1994):
//! the plain-data contract between the inner hull construction (`hull::inner`, §4–5) and the
//! polynomial schemes built on it (`scheme::cubic_c1`, `scheme::quintic_c2`, §6).
//!
//! T is an edge-convex triangulation whose vertices carry the point and normal data the surface
//! interpolates (centroids, corner guards, pseudo-centroids). Every triangle of T has one face
//! tetrahedron (convex face, single sided) or an L-U pair, one on each side (non-convex face).
//! Between two face tetrahedra on the same side of an edge of T sits a pair of edge tetrahedra
//! `[p_i p_j q_l s]`, `[p_i p_j q_n s]` with `s = (q_l + q_n)/2` (Def. 3.6 (5)(ii)); those are
//! derived here, not stored, so every hull builder gets them the same way.

use crate::bb::Tet;
use glam::DVec3;
use std::collections::HashMap;

/// Which side of a triangle of T a face tetrahedron lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// On the side the triangle's normal (counter-clockwise orientation) points to: outside.
    Outer = 0,
    /// On the opposite side: inside.
    Inner = 1,
}

impl Side {
    /// Both sides, outer first.
    pub const BOTH: [Side; 2] = [Side::Outer, Side::Inner];
}

/// Where a vertex of T comes from in the input polyhedron, for reports and shape control.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointOrigin {
    /// Centroid of polygon `face` (convex face).
    Centroid {
        /// Input polygon index.
        face: u32,
    },
    /// A corner guard of non-convex polygon `face` (§5).
    CornerGuard {
        /// Input polygon index.
        face: u32,
    },
    /// Pseudo-centroid C_0 of non-trihedral input vertex `vertex` (Algorithm 1 step (4)).
    PseudoCentroid {
        /// Input vertex index.
        vertex: u32,
    },
    /// Anything else (test hulls, interpolated points of §7.2).
    Other,
}

/// A smoothable simplicial hull: T with point normals and the apexes of its face tetrahedra.
#[derive(Clone, Debug, Default)]
pub struct SimplicialHull {
    /// Vertices of T: the points the surface passes through.
    pub points: Vec<DVec3>,
    /// Unit normal of the surface at each point (the direction of ∇f there).
    pub normals: Vec<DVec3>,
    /// Where each point comes from.
    pub origins: Vec<PointOrigin>,
    /// Triangles of T, counter-clockwise seen from outside the polyhedron.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the apex of its face tetrahedron on each side (`[outer, inner]`, indexed by
    /// [`Side`]); at least one is present, both for an L-U pair.
    pub apexes: Vec<[Option<DVec3>; 2]>,
    /// Per triangle, the input polyhedron element it was built for (vertex for step (3)/(4)
    /// triangles, edge for step (5') triangles), for reports.
    pub element: Vec<u32>,
}

/// Where the point s shared by a pair of edge tetrahedra `[p_i p_j q0 s]`, `[p_i p_j q1 s]`
/// lies. Definition 3.6 (5)(ii) and the scheme's (6.12) put s on the line of the two apexes,
/// s = μ1 q0 + μ2 q1; on such a line the vertex-star systems of appendices D and E can be
/// singular for every point (see `docs/quintic.md`, issue 8), so the quintic scheme may move
/// s off it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum EdgePoint {
    /// s = (q0 + q1)/2, on the apexes' line (the default, Def. 3.6 (5)(ii)).
    #[default]
    Midpoint,
    /// s = m + t·(m − e) with m = (q0 + q1)/2 and e = (p_i + p_j)/2 the edge's midpoint: off
    /// the apexes' line in the plane through e and the line (away from T for t > 0, toward
    /// the edge for −1 < t < 0).
    Lift(f64),
    /// s = (1 − μ) q0 + μ q1 with this μ (q0 the apex of the edge's first triangle): on the
    /// apexes' line but not at its middle.
    Ratio(f64),
    /// s on the apexes' line at the ratio that keeps C1/C2 extrapolation smallest
    /// ([`balanced_ratio`]): needle triangles of T and small triangles beside large ones put
    /// the midpoint far outside a face tetrahedron's frame.
    Balanced,
}

impl EdgePoint {
    /// The point s for apexes `q0`, `q1` over the edge [`pi` `pj`].
    #[must_use]
    pub fn place(self, q0: DVec3, q1: DVec3, pi: DVec3, pj: DVec3) -> DVec3 {
        let m = 0.5 * (q0 + q1);
        match self {
            EdgePoint::Midpoint => m,
            EdgePoint::Lift(t) => m + t * (m - 0.5 * (pi + pj)),
            EdgePoint::Ratio(mu) => (1.0 - mu) * q0 + mu * q1,
            // Without the face tetrahedra the balanced point is the midpoint;
            // `edge_tets_with` places it with them.
            EdgePoint::Balanced => m,
        }
    }
}

/// An edge of T with the triangles on both sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HullEdge {
    /// The two points of T, as they run in `triangles[faces[0]]`.
    pub v: [u32; 2],
    /// The triangles sharing the edge; `faces[1] == u32::MAX` on a boundary of T.
    pub faces: [u32; 2],
}

/// One edge tetrahedron of S_e: `[p_i p_j q s]` with q the apex of `face`'s tetrahedron on `side`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeTet {
    /// Index into [`SimplicialHull::edges`].
    pub edge: u32,
    /// The triangle whose face tetrahedron this edge tetrahedron is glued to.
    pub face: u32,
    /// The side both face tetrahedra lie on.
    pub side: Side,
    /// `[p_i, p_j, q, s]`, with s the midpoint of the two apexes.
    pub tet: [DVec3; 4],
}

impl SimplicialHull {
    /// The points of T joined to each point by an edge of T, each once, in the order the
    /// triangles first name them (callers that sum over neighbours rely on that order).
    #[must_use]
    pub fn point_neighbours(&self) -> Vec<Vec<u32>> {
        let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); self.points.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3]);
                if !nbrs[a].contains(&b) {
                    nbrs[a].push(b);
                }
                let (a, b) = (t[(k + 1) % 3] as usize, t[k]);
                if !nbrs[a].contains(&b) {
                    nbrs[a].push(b);
                }
            }
        }
        nbrs
    }

    /// The face tetrahedron `[p_i p_j p_k q]` of `triangle` on `side`, if built.
    #[must_use]
    pub fn face_tet(&self, triangle: usize, side: Side) -> Option<[DVec3; 4]> {
        let [a, b, c] = self.triangles[triangle];
        self.apexes[triangle][side as usize].map(|q| {
            [
                self.points[a as usize],
                self.points[b as usize],
                self.points[c as usize],
                q,
            ]
        })
    }

    /// The edges of T in first-seen order. Errors name the edge when more than two triangles
    /// share it (T must be a manifold).
    pub fn edges(&self) -> Result<Vec<HullEdge>, String> {
        let mut map: HashMap<(u32, u32), usize> = HashMap::new();
        let mut edges: Vec<HullEdge> = Vec::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                match map.get(&key) {
                    None => {
                        map.insert(key, edges.len());
                        edges.push(HullEdge {
                            v: [a, b],
                            faces: [t as u32, u32::MAX],
                        });
                    }
                    Some(&e) if edges[e].faces[1] == u32::MAX => edges[e].faces[1] = t as u32,
                    Some(_) => {
                        let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
                        return Err(format!(
                            "hull edge ({a}, {b}), from {pa} to {pb}, is shared by more than two triangles"
                        ));
                    }
                }
            }
        }
        Ok(edges)
    }

    /// The edge tetrahedra S_e: for every interior edge of T and every side on which both
    /// adjacent triangles have a face tetrahedron, the pair glued to them.
    pub fn edge_tets(&self) -> Result<Vec<EdgeTet>, String> {
        self.edge_tets_with(EdgePoint::Midpoint)
    }

    /// [`SimplicialHull::edge_tets`] with the shared point s of each pair placed by `rule`
    /// ([`EdgePoint::Midpoint`] gives exactly `edge_tets`).
    pub fn edge_tets_with(&self, rule: EdgePoint) -> Result<Vec<EdgeTet>, String> {
        let edges = self.edges()?;
        let mut out = Vec::new();
        for (e, edge) in edges.iter().enumerate() {
            let [f0, f1] = edge.faces;
            if f1 == u32::MAX {
                continue;
            }
            for side in Side::BOTH {
                let (Some(q0), Some(q1)) = (
                    self.apexes[f0 as usize][side as usize],
                    self.apexes[f1 as usize][side as usize],
                ) else {
                    continue;
                };
                let pi = self.points[edge.v[0] as usize];
                let pj = self.points[edge.v[1] as usize];
                let s = if rule == EdgePoint::Balanced {
                    let face = |f: u32, q: DVec3| {
                        let [a, b, c] = self.triangles[f as usize].map(|i| self.points[i as usize]);
                        [a, b, c, q]
                    };
                    let mu = balanced_ratio(&face(f0, q0), &face(f1, q1));
                    (1.0 - mu) * q0 + mu * q1
                } else {
                    rule.place(q0, q1, pi, pj)
                };
                for (face, q) in [(f0, q0), (f1, q1)] {
                    out.push(EdgeTet {
                        edge: e as u32,
                        face,
                        side,
                        tet: [pi, pj, q, s],
                    });
                }
            }
        }
        Ok(out)
    }
}

/// Nearest [`balanced_ratio`] gets to either apex: the thinner edge tetrahedron keeps at least
/// this share of the pair's volume.
pub const BALANCE_MIN_RATIO: f64 = 0.1;

/// Sum of |barycentric coordinates| of `x` in the tetrahedron `t`: how far a polynomial on `t`
/// is extrapolated to reach `x` (C1 conditions across a face multiply weights by up to this,
/// C2 by its square).
#[must_use]
pub fn extrapolation(t: &Tet, x: DVec3) -> f64 {
    t.bary(x).iter().map(|l| l.abs()).sum()
}

/// The largest extrapolation the C1/C2 faces of an edge tetrahedron pair make with s at ratio
/// `mu` on the apexes' line: s in either face tetrahedron `a` (apex `a.v[3]`) or `b`, and each
/// apex in the other edge tetrahedron's frame ((2 − μ)/μ and (1 + μ)/(1 − μ), 3 at the
/// midpoint). What [`balanced_ratio`] makes least.
#[must_use]
pub fn pair_extrapolation(a: &Tet, b: &Tet, mu: f64) -> f64 {
    let s = (1.0 - mu) * a.v[3] + mu * b.v[3];
    extrapolation(a, s)
        .max(extrapolation(b, s))
        .max((2.0 - mu) / mu)
        .max((1.0 + mu) / (1.0 - mu))
}

/// The ratio μ of s = (1 − μ) q0 + μ q1 for the edge tetrahedra glued to the face tetrahedra
/// `a` (apex q0 = `a[3]`) and `b` (apex q1 = `b[3]`) over one edge of T that makes
/// [`pair_extrapolation`] least. Each of its terms is convex in μ, so their maximum is, and a
/// golden-section search over [[`BALANCE_MIN_RATIO`], 1 − [`BALANCE_MIN_RATIO`]] finds it. The
/// pair's union [p_i p_j q0 q1] does not depend on μ, so the hull's tetrahedra keep their
/// overlaps and gaps (none) whatever it is. Where the midpoint is within 1% of the best it is
/// kept, so well-shaped pairs are unchanged; so is a degenerate face tetrahedron's.
#[must_use]
pub fn balanced_ratio(a: &[DVec3; 4], b: &[DVec3; 4]) -> f64 {
    let (Some(a), Some(b)) = (Tet::new(*a), Tet::new(*b)) else {
        return 0.5;
    };
    let cost = |mu: f64| pair_extrapolation(&a, &b, mu);
    let (mut lo, mut hi) = (BALANCE_MIN_RATIO, 1.0 - BALANCE_MIN_RATIO);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (cost(x1), cost(x2));
    for _ in 0..60 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = cost(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = cost(x2);
        }
    }
    let best = 0.5 * (lo + hi);
    if cost(0.5) <= 1.01 * cost(best) {
        0.5
    } else {
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles sharing an edge, both with outer apexes: one edge-tetrahedron pair whose
    /// shared point is the apexes' midpoint.
    #[test]
    fn edge_tets_pair_on_shared_side() {
        let hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
            normals: vec![DVec3::Z; 4],
            origins: vec![PointOrigin::Other; 4],
            triangles: vec![[0, 1, 2], [2, 1, 3]],
            apexes: vec![
                [Some(DVec3::new(0.3, 0.3, 1.0)), None],
                [
                    Some(DVec3::new(0.7, 0.7, 2.0)),
                    Some(DVec3::new(0.7, 0.7, -1.0)),
                ],
            ],
            element: vec![0, 1],
        };
        let edges = hull.edges().unwrap();
        assert_eq!(edges.len(), 5);
        let et = hull.edge_tets().unwrap();
        assert_eq!(et.len(), 2);
        assert!(et.iter().all(|t| t.side == Side::Outer));
        assert_eq!(et[0].tet[3], DVec3::new(0.5, 0.5, 1.5));
        assert_eq!(et[0].tet[2], DVec3::new(0.3, 0.3, 1.0));
        assert_eq!(et[1].tet[2], DVec3::new(0.7, 0.7, 2.0));
        // The placements of s: the midpoint is `edge_tets`; a ratio on the apexes' line from
        // the first triangle's apex; a lift away from the edge's midpoint (0.5, 0.5, 0).
        let mid = hull.edge_tets_with(EdgePoint::Midpoint).unwrap();
        assert_eq!(mid, et);
        let r = hull.edge_tets_with(EdgePoint::Ratio(0.25)).unwrap();
        // Rounding of 0.75·0.3 + 0.25·0.7.
        assert!(r[0].tet[3].distance(DVec3::new(0.4, 0.4, 1.25)) < 1e-15);
        let l = hull.edge_tets_with(EdgePoint::Lift(1.0)).unwrap();
        assert_eq!(l[1].tet[3], DVec3::new(0.5, 0.5, 3.0));
    }

    /// Three triangles on one edge: the error names the edge by its points and where they are
    /// (hull point indices alone cannot be found in the model).
    #[test]
    fn non_manifold_edge_is_named_with_its_points() {
        let hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_Y],
            normals: vec![DVec3::Z; 5],
            origins: vec![PointOrigin::Other; 5],
            triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
            apexes: vec![[None, None]; 3],
            element: vec![0; 3],
        };
        let e = hull.edges().unwrap_err();
        assert!(
            e.contains("(0, 1)") && e.contains("[0, 0, 0]") && e.contains("[1, 0, 0]"),
            "{e}"
        );
    }

    /// The face tetrahedra over the edge [(0,0,0) (1,0,0)] of a triangle whose third point is
    /// `h` off the edge's line and of its mirror image across the edge, a flat fold, with
    /// apexes 0.3 above their centroids.
    fn pair(h0: f64, h1: f64) -> ([DVec3; 4], [DVec3; 4]) {
        let (pi, pj) = (DVec3::ZERO, DVec3::X);
        let k0 = DVec3::new(0.4, h0, 0.0);
        let k1 = DVec3::new(0.6, -h1, 0.0);
        let q0 = (pi + pj + k0) / 3.0 + DVec3::new(0.0, 0.0, 0.3);
        let q1 = (pi + pj + k1) / 3.0 + DVec3::new(0.0, 0.0, 0.3);
        ([pi, pj, k0, q0], [pj, pi, k1, q1])
    }

    /// [`pair_extrapolation`] of the pair at ratio `mu`.
    fn cost(a: &[DVec3; 4], b: &[DVec3; 4], mu: f64) -> f64 {
        pair_extrapolation(&Tet::new(*a).unwrap(), &Tet::new(*b).unwrap(), mu)
    }

    /// Mirror-image face tetrahedra keep the midpoint exactly: their pair is already balanced.
    #[test]
    fn balanced_ratio_keeps_the_midpoint_of_a_symmetric_pair() {
        let (a, b) = pair(0.8, 0.8);
        assert_eq!(balanced_ratio(&a, &b), 0.5);
    }

    /// A needle (third point 0.01 off the edge) beside a thick triangle: the midpoint lies far
    /// outside the needle's face tetrahedron (cost 28, its C2 factor ~800), the balanced point
    /// moves towards the needle's apex, and its cost is the least on a fine grid of ratios
    /// (brute force, independent of the golden-section search) to 1%.
    #[test]
    fn balanced_ratio_moves_s_towards_a_needle() {
        let (a, b) = pair(0.01, 0.8);
        let mid = cost(&a, &b, 0.5);
        assert!(mid > 20.0, "midpoint cost {mid}");
        let mu = balanced_ratio(&a, &b);
        assert!((BALANCE_MIN_RATIO..0.5).contains(&mu), "μ = {mu}");
        let best = (1..1000)
            .map(|k| f64::from(k) / 1000.0)
            .filter(|m| (BALANCE_MIN_RATIO..=1.0 - BALANCE_MIN_RATIO).contains(m))
            .map(|m| cost(&a, &b, m))
            .fold(f64::INFINITY, f64::min);
        let got = cost(&a, &b, mu);
        // The grid's step (1e-3 in μ) changes a cost of ~20 by < 1%.
        assert!(got <= 1.01 * best, "balanced {got}, grid best {best}");
        assert!(got < 0.5 * mid, "balanced {got}, midpoint {mid}");
        // The pair's union is [p_i p_j q0 q1] wherever s lies on the apexes' line.
        let vol = |t: [DVec3; 4]| (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0]).abs() / 6.0;
        let s = (1.0 - mu) * a[3] + mu * b[3];
        let union = vol([a[0], a[1], a[3], b[3]]);
        let parts = vol([a[0], a[1], a[3], s]) + vol([a[0], a[1], b[3], s]);
        // Rounding of two triple products of O(1) vectors.
        assert!((parts - union).abs() < 1e-14, "{parts} vs {union}");
    }

    /// `edge_tets_with(Balanced)` places s on the apexes' line at `balanced_ratio`.
    #[test]
    fn balanced_edge_tets_use_the_ratio() {
        let hull = SimplicialHull {
            points: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.4, 0.01, 0.0),
                DVec3::new(0.6, -0.8, 0.0),
            ],
            normals: vec![DVec3::Z; 4],
            origins: vec![PointOrigin::Other; 4],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
            apexes: vec![
                [Some(DVec3::new(1.4 / 3.0, 0.01 / 3.0, 0.3)), None],
                [Some(DVec3::new(1.6 / 3.0, -0.8 / 3.0, 0.3)), None],
            ],
            element: vec![0, 1],
        };
        let et = hull.edge_tets_with(EdgePoint::Balanced).unwrap();
        assert_eq!(et.len(), 2);
        let (a, b) = (
            hull.face_tet(0, Side::Outer).unwrap(),
            hull.face_tet(1, Side::Outer).unwrap(),
        );
        let mu = balanced_ratio(&a, &b);
        let s = (1.0 - mu) * a[3] + mu * b[3];
        assert!(mu < 0.5);
        assert_eq!(et[0].tet[3], s);
        assert_eq!(et[1].tet[3], s);
    }
}

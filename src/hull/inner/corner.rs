//! Algorithm 1, steps (3)–(5), and Algorithm 2's step (3'): the triangles of T and the face tetrahedra built for one vertex V
//! of the (convex-faced) polyhedron.
//!
//! Reconstruction of the missing figures 4.3–4.5, as implemented:
//! - step (3), trihedral V: T gets the triangle of the three face centroids C_1C_2C_3 (in the
//!   counter-clockwise order of the faces round V), apex V. The tangent plane of every C_i is its
//!   face plane, which contains V, so the tetrahedron is tangent-containing.
//! - step (3') of Algorithm 2 (the hallway corner, Figure 5.7), trihedral V with a reflex angle
//!   in one face f_1 (so the edge e_1 not in f_1 is a concave edge of the polyhedron): when e_1
//!   crosses the plane of the guards' triangle at X before its midpoint M, a second apex
//!   T_0 = (X + M)/2 on e_1 gives the L-U pair [G_1G_2G_3V], [G_1G_2G_3T_0]. Beyond the paper:
//!   the outer apex V is later moved in f_1's plane away from f_1 ([`spread_hallway_apexes`]),
//!   since with V itself the edge tetrahedra across e_1 (midpoint s = M) are inverted.
//! - step (4), otherwise: t_i = n_V·(C_i − V). V is separable when all t_i have one sign; then
//!   V̄ = V + t* n_V with |t*| = min |t_i| and the pseudo-centroid C_0 = αV + (1−α)V̄ (normal
//!   n_V); unseparable V gives C_0 = V. T gets the fan C_0C_iC_{i+1}, one triangle per edge
//!   e = VV' between faces f_i and f_{i+1}.
//! - step (5), per edge e: X is where e meets C_0's tangent plane π (clamped to [V, V + 0.4e]);
//!   T_0 the midpoint of X and M (the midpoint of e), so T_0 lies on e strictly on V's side of
//!   M; T_1 the projection of M onto π along n_V. With s_i = n_V·(C_i − C_0):
//!   (i) s_1 s_2 ≥ 0 and T_0 across π from C_1, C_2: apex T_0;
//!   (ii) s_1 s_2 ≥ 0, T_0 on their side, T_0 and T_1 on one side of the triangle: apex T_1;
//!   (iii) as (ii) but on different sides: the L-U pair T_0, T_1;
//!   (iv) s_1 s_2 < 0 (only at unseparable V): T_0 and T_1 are moved along ±n_V off π (T_0
//!   up for a ridge, down for a valley, by 5% of |e|) and form an L-U pair; should both still
//!   be on one side of the triangle, T_1 is pushed across it along the triangle's normal.
//!   Which side of the triangle (outer or inner) each apex is on follows from its position.

use super::InnerOptions;
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use glam::DVec3;

/// How each triangle's face tetrahedra were chosen (Algorithm 1 steps (3), (5)(i)–(iv)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaseCounts {
    /// Step (3): trihedral vertices.
    pub trihedral: usize,
    /// Step (5)(i): apex T_0 on the edge.
    pub case_i: usize,
    /// Step (5)(ii): apex T_1 on the tangent plane of C_0.
    pub case_ii: usize,
    /// Step (5)(iii): L-U pair T_0, T_1.
    pub case_iii: usize,
    /// Step (5)(iv): L-U pair with moved T_0, T_1.
    pub case_iv: usize,
    /// Step (3'): hallway corners (trihedral with a reflex face angle), L-U pair V, T_0.
    pub hallway: usize,
    /// Trihedral saddle corners whose edges of T ask for the side V is not on: an L-U pair
    /// from V and apexes over the base (`saddle_apex`).
    pub saddle: usize,
}

/// One vertex's data for steps (3)–(5).
pub struct Corner<'a> {
    /// The input vertex index.
    pub vertex: u32,
    /// Its position.
    pub v: DVec3,
    /// Its unit ("above face") normal.
    pub n: DVec3,
    /// Its neighbours in counter-clockwise order seen from outside; the edge to `ring[i + 1]`
    /// lies between `faces[i]` and `faces[i + 1]` (cyclically).
    pub ring: &'a [DVec3],
    /// The faces round it (indices of T points: their centroids / corner guards).
    pub faces: &'a [u32],
    /// The face (index into `faces`) in which the corner at V is reflex (angle > π), if any:
    /// with three faces that is the hallway corner of Algorithm 2 step (3').
    pub reflex: Option<usize>,
}

/// An outer apex of a hallway corner (step (3')) that may be moved in its face's plane, away
/// from the face, when an edge tetrahedron's midpoint would otherwise fall on the wrong side of
/// T ([`spread_hallway_apexes`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HallwayApex {
    /// The triangle of T.
    pub triangle: usize,
    /// Unit direction in the reflex face's plane, bisecting the corner's convex (outer) angle.
    pub dir: DVec3,
    /// Longest move allowed (three quarters of the shorter polygon edge at V).
    pub limit: f64,
}

/// Orientation of q against the triangle (a, b, c): > 0 on its outer (counter-clockwise normal)
/// side.
fn orient(a: DVec3, b: DVec3, c: DVec3, q: DVec3) -> f64 {
    (b - a).cross(c - a).dot(q - a)
}

/// Pushes `apex` as the face tetrahedron of the last triangle on the side it lies on.
fn set_apex(slot: &mut [Option<DVec3>; 2], tri: [DVec3; 3], apex: DVec3) {
    let side = usize::from(orient(tri[0], tri[1], tri[2], apex) <= 0.0);
    slot[side] = Some(apex);
}

/// Where a trihedral saddle's apex on V's side lies between V (0) and the apex over the base
/// (1) (`saddle_apex`). Measured on double_torus_poly's waist: 0.1 to 0.6 give a valid hull,
/// 0 (V itself: its tetrahedron reaches across the polyhedron edge VV' into the neighbour's)
/// and 0.75 (deep under the base: the two mirror-image saddles' tetrahedra meet) do not.
pub const SADDLE_BLEND: f64 = 0.35;

/// A trihedral saddle corner (one reflex face angle with V on the inner side of the guards'
/// triangle, so not Algorithm 2's hallway (3'); or edges of both convexity classes) has edges
/// of T asking for the side V is not on (Definition 3.1; see [`super::sides`]), so it needs an
/// L-U pair (Def. 3.6 (4)(ii)). The missing side gets the apex over the base of
/// [`super::sides::apexes_over_base`]; V's side keeps a point between V and that function's
/// apex on the same side ([`SADDLE_BLEND`]). Both lie in the region where the pair is
/// tangent-containing (Definition 3.5): for each base vertex, the other two base vertices are
/// on opposite sides of its tangent plane (the plane cuts the base), or both on one side and
/// then V (in all three face planes) and the apex over the base (which reaches the plane) are on
/// or across it, and so is every point between them. Left to [`super::sides::settle`], both
/// apexes were replaced by apexes over the base, 0.73 of the longest edge deep on
/// double_torus_poly's waist, and the inner ones of the two mirror-image saddles there
/// overlapped; with V itself, its tetrahedron overlapped the neighbour's across the edge VV'.
/// Where no apex over the base exists, the missing side gets a low one (the centroid moved
/// by [`super::sides::MIN_HEIGHT`] times the longest edge) and V stays.
fn saddle_apex(
    slot: &mut [Option<DVec3>; 2],
    v: DVec3,
    base: [DVec3; 3],
    normals: [DVec3; 3],
    counts: &mut CaseCounts,
) {
    let mut req = [false; 2];
    for k in 0..3 {
        let s =
            super::sides::edge_sides(base[k], normals[k], base[(k + 1) % 3], normals[(k + 1) % 3]);
        req[0] |= s[0];
        req[1] |= s[1];
    }
    let Some(own) = (0..2).find(|&s| slot[s] == Some(v)) else {
        return; // V is not an apex (a hallway pair replaced it): nothing to blend
    };
    let other = 1 - own;
    if !req[other] || slot[other].is_some() {
        return;
    }
    req[own] = true;
    counts.saddle += 1;
    if let Some(over) = super::sides::apexes_over_base(base, normals, req) {
        if let (Some(q_own), Some(q_other)) = (over[own], over[other]) {
            slot[own] = Some(v + SADDLE_BLEND * (q_own - v));
            slot[other] = Some(q_other);
            return;
        }
    }
    let [a, b, c] = base;
    let Some(nn) = (b - a).cross(c - a).try_normalize() else {
        return;
    };
    let len = (b - a).length().max((c - b).length()).max((a - c).length());
    let sign = if other == 0 { 1.0 } else { -1.0 };
    slot[other] = Some((a + b + c) / 3.0 + sign * super::sides::MIN_HEIGHT * len * nn);
}

/// Longest move along −e of an apex that [`build_corner`] brings to V's side of the plane Π
/// through C_1, C_2 and M (Lemma 4.3), relative to |e|. Where Π nearly contains e (C_1, C_2
/// and e almost coplanar: a diagonal of a planar-split polygon, spot_control_cage's udder
/// saddles 12/121) the rate along −e is tiny and the unclamped move sent an apex 0.93 away
/// from V over a triangle 0.21 long (edge tetrahedra overlapping the whole corner's). Beyond
/// 0.5|e| the apex is past V, where the move no longer serves Lemma 4.3. On every scene of
/// `scenes/paper1994` the clamped apexes are rebuilt later ([`super::sides::settle`]) and the
/// hulls are bit-identical with and without the clamp.
pub const KEEP_SIDE_REACH: f64 = 0.5;

/// Offset δ along n_V of the pseudo-centroid C_0 = V + δ n_V of an unseparable vertex (the paper
/// puts C_0 = V). The edge C_0G_i of T is convex (Definition 3.1) when
/// (C_0 − G_i)·n_{G_i} has the sign of t_i = (G_i − V)·n_V or is zero; with C_0 = V the first
/// factor is zero only for planar faces, and a non-planar input face (double_torus_poly's
/// five-gons, ~1e-7 off their plane) can give it the wrong sign. Each face bounds δ on one
/// side (n_V·n_{G_i} > 0 for "above face" normals); δ is 0 when that interval holds 0 (the
/// paper's C_0 = V), else its middle (the middle of the overlap of the bounds when it is
/// empty), or twice the one bound there is. |δ| stays of the
/// order of the non-planarity, far below min |t_i|, so the second factor keeps its sign.
fn unseparable_offset(v: DVec3, n: DVec3, pts: &[DVec3], nrm: &[DVec3], t: &[f64]) -> f64 {
    // δ ≥ lo from faces with t_i > 0, δ ≤ hi from faces with t_i < 0.
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for ((&g, &ng), &ti) in pts.iter().zip(nrm).zip(t) {
        let cos = n.dot(ng);
        if cos <= 1e-6 {
            continue; // not above this face: no bound from it (Appendix C's business)
        }
        let bound = -ng.dot(v - g) / cos;
        if ti > 0.0 {
            lo = lo.max(bound);
        } else if ti < 0.0 {
            hi = hi.min(bound);
        }
    }
    let limit = 1e-3 * t.iter().fold(f64::INFINITY, |m, x| m.min(x.abs()));
    let delta = if lo <= 0.0 && hi >= 0.0 {
        0.0 // C_0 = V already gives convex edges: the paper's choice
    } else if lo.is_finite() && hi.is_finite() {
        0.5 * (lo + hi)
    } else if lo > 0.0 {
        2.0 * lo // clears the binding face by its own offset
    } else {
        2.0 * hi
    };
    delta.clamp(-limit, limit)
}

/// Runs steps (3)–(5) for `c`, appending to `hull` (whose first points are the face centroids
/// and guards with their normals). Returns whether the vertex was separable (step (4)).
pub fn build_corner(
    hull: &mut SimplicialHull,
    c: &Corner,
    options: &InnerOptions,
    counts: &mut CaseCounts,
    hallway: &mut Vec<HallwayApex>,
) -> bool {
    let k = c.faces.len();
    let pts: Vec<DVec3> = c.faces.iter().map(|&f| hull.points[f as usize]).collect();
    let nrm: Vec<DVec3> = c.faces.iter().map(|&f| hull.normals[f as usize]).collect();
    if k == 3 {
        let tri = [c.faces[0], c.faces[1], c.faces[2]];
        let mut slot = [None, None];
        let base = [pts[0], pts[1], pts[2]];
        set_apex(&mut slot, base, c.v);
        if let Some(r) = c.reflex {
            // Step (3'): the edge e_1 not in the reflex face runs from V through the plane of
            // the guards' triangle; the polyhedron near e_1 lies beyond it, so a second face
            // tetrahedron with apex T_0 on e_1, between that crossing X and the midpoint M,
            // forms an L-U pair with [G_1G_2G_3V].
            let d = c.ring[(r + 2) % 3] - c.v;
            let m = (base[1] - base[0]).cross(base[2] - base[0]);
            let o_v = orient(base[0], base[1], base[2], c.v);
            let rate = m.dot(d);
            let u = if rate.abs() > 1e-12 * m.length() * d.length() {
                -o_v / rate
            } else {
                f64::INFINITY
            };
            if o_v > 0.0 && u > 0.0 && u < 0.5 {
                set_apex(&mut slot, base, c.v + 0.5 * (u + 0.5) * d);
                let (a, b) = (c.ring[r] - c.v, c.ring[(r + 1) % 3] - c.v);
                if let Some(dir) = (a.normalize_or_zero() + b.normalize_or_zero()).try_normalize() {
                    hallway.push(HallwayApex {
                        triangle: hull.triangles.len(),
                        dir,
                        limit: 0.75 * a.length().min(b.length()),
                    });
                }
                counts.hallway += 1;
            }
        }
        saddle_apex(&mut slot, c.v, base, [nrm[0], nrm[1], nrm[2]], counts);
        hull.triangles.push(tri);
        hull.apexes.push(slot);
        hull.element.push(c.vertex);
        counts.trihedral += 1;
        return true;
    }
    let n = c.n;
    let t: Vec<f64> = pts.iter().map(|&x| n.dot(x - c.v)).collect();
    let separable = t.iter().all(|&x| x > 0.0) || t.iter().all(|&x| x < 0.0);
    let c0 = if separable {
        let t_star = t
            .iter()
            .copied()
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .expect("k > 3 faces");
        // Beyond the paper (`fan`): C_0 slides (or cuts deeper) until its fan is an umbrella.
        super::fan::place_pseudo_centroid(c.v, n, t_star, options.alpha, &pts, &nrm)
    } else {
        c.v + unseparable_offset(c.v, n, &pts, &nrm, &t) * n
    };
    let i0 = hull.points.len() as u32;
    hull.points.push(c0);
    hull.normals.push(n);
    hull.origins
        .push(PointOrigin::PseudoCentroid { vertex: c.vertex });
    for i in 0..k {
        let (g1, g2) = (c.faces[i], c.faces[(i + 1) % k]);
        let (c1, c2) = (pts[i], pts[(i + 1) % k]);
        let w = c.ring[(i + 1) % k];
        let d = w - c.v;
        let m = c.v + 0.5 * d;
        // Where e meets π (u along e), clamped so T_0 stays strictly before M.
        let nd = n.dot(d);
        let u = if nd.abs() > 1e-12 * d.length() {
            (n.dot(c0 - c.v) / nd).clamp(0.0, 0.4)
        } else {
            0.4
        };
        let mut t0 = c.v + 0.5 * (u + 0.5) * d;
        let mut t1 = m - n.dot(m - c0) * n;
        let (s1, s2) = (n.dot(c1 - c0), n.dot(c2 - c0));
        let tri = [c0, c1, c2];
        let mut slot = [None, None];
        // Lemma 4.3: the plane Π through C_1, C_2 and M separates this vertex's tetrahedron
        // from the one built at V' over the same edge C_1C_2, if every apex lies on V's side
        // at least as far as the point 0.45e (T_0 does by construction). Apexes are moved
        // there along −e.
        let mut pi_n = (c1 - m).cross(c2 - m).normalize_or_zero();
        if pi_n.dot(c.v - m) < 0.0 {
            pi_n = -pi_n;
        }
        let g_min = pi_n.dot(c.v + 0.45 * d - m);
        // Along −e: keeps the distances to both face planes (e lies in them), so tangency at
        // C_1 and C_2 is unchanged.
        let along = -d.normalize_or_zero();
        let keep_side = |q: DVec3| -> DVec3 {
            let gq = pi_n.dot(q - m);
            let rate = pi_n.dot(along);
            if g_min > 0.0 && gq < g_min && rate > 1e-9 {
                q + ((g_min - gq) / rate).min(KEEP_SIDE_REACH * d.length()) * along
            } else {
                q
            }
        };
        t1 = keep_side(t1);
        if s1 * s2 >= 0.0 {
            let s = if s1 != 0.0 { s1 } else { s2 };
            let st0 = n.dot(t0 - c0);
            // The side the polyhedron's corner lies on: outer when the centroids are below
            // C_0's tangent plane (a convex corner), inner otherwise.
            let up = if s <= 0.0 { n } else { -n };
            let mm = (c1 - c0).cross(c2 - c0);
            let want = if s <= 0.0 { 1.0 } else { -1.0 };
            let margin = 0.05 * d.length() * mm.length();
            // Moves q until it is on the corner's side of the triangle: along `up` when that
            // gets there (n_V is above every face, so q rises over C_0's tangent plane and both
            // face planes and stays tangent-containing), else parallel to π (keeping the
            // tangency at C_0).
            let w = if want * mm.dot(up) > 0.2 * mm.length() {
                up
            } else {
                (want * mm - want * mm.dot(up) * up).normalize_or_zero()
            };
            let rate = want * mm.dot(w);
            let to_corner_side = |q: DVec3| -> DVec3 {
                let o = orient(c0, c1, c2, q) * want;
                if o < margin && rate > 1e-12 * mm.length() {
                    keep_side(q + (margin - o) / rate * w)
                } else {
                    q
                }
            };
            if st0 * s <= 0.0 {
                if separable {
                    t0 = to_corner_side(t0);
                }
                if !separable {
                    // C_0 = V lies in both face planes, as does T_0: lift T_0 off them (away
                    // from the triangle) so the edge tetrahedra over VC_i are not flat.
                    let mm = (c1 - c0).cross(c2 - c0);
                    let side = orient(c0, c1, c2, t0).signum();
                    t0 += 0.05 * d.length() * side * mm.normalize_or_zero();
                }
                set_apex(&mut slot, tri, t0);
                counts.case_i += 1;
            } else {
                if !separable {
                    // As in case (i): T_0 on e lies in both face planes, as do C_0 = V and the
                    // centroids, so the edge tetrahedra over VC_i between two such apexes would
                    // be flat; lift T_0 away from the triangle.
                    let side = orient(c0, c1, c2, t0).signum();
                    t0 += 0.05 * d.length() * side * mm.normalize_or_zero();
                }
                let o0 = orient(c0, c1, c2, t0);
                // T_1 must lie on the corner's side of the triangle unless T_0 already does.
                if o0 * want <= 0.0 {
                    t1 = to_corner_side(t1);
                }
                let o1 = orient(c0, c1, c2, t1);
                if o0 * o1 >= 0.0 {
                    set_apex(&mut slot, tri, t1);
                    counts.case_ii += 1;
                } else {
                    set_apex(&mut slot, tri, t0);
                    set_apex(&mut slot, tri, t1);
                    counts.case_iii += 1;
                }
            }
        } else {
            // Case (iv): e is a ridge when f_{i+1}'s centroid lies below f_i's plane.
            let n1 = nrm[i];
            let ridge = n1.dot(c2 - c1) <= 0.0;
            let up = if ridge { n } else { -n };
            let shift = 0.05 * d.length();
            let h0 = up.dot(t0 - c0);
            if h0 < shift {
                t0 += (shift - h0) * up;
            } else if !separable {
                // T_0 is still on e, in both face planes with C_0 = V: lift it off them as in
                // cases (i)–(iii), away from the triangle.
                let mm = (c1 - c0).cross(c2 - c0);
                let side = orient(c0, c1, c2, t0).signum();
                t0 += shift * side * mm.normalize_or_zero();
            }
            t1 = keep_side(t1 - shift * up);
            let o0 = orient(c0, c1, c2, t0);
            let mut o1 = orient(c0, c1, c2, t1);
            if o0 * o1 >= 0.0 {
                let m = (c1 - c0).cross(c2 - c0);
                let mn = m.normalize_or_zero();
                // Push T_1 across the triangle to the far side from T_0, by the same margin.
                let dist = o1 / m.length();
                let target = if o0 >= 0.0 { -shift } else { shift };
                t1 += (target - dist) * mn;
                o1 = orient(c0, c1, c2, t1);
            }
            debug_assert!(o0 * o1 <= 0.0 || o0 == 0.0);
            set_apex(&mut slot, tri, t0);
            set_apex(&mut slot, tri, t1);
            counts.case_iv += 1;
        }
        hull.triangles.push([i0, g1, g2]);
        hull.apexes.push(slot);
        hull.element.push(c.vertex);
    }
    separable
}

/// Smallest distance of an edge tetrahedron's midpoint s from the planes of its two triangles,
/// relative to the edge of T, that [`spread_hallway_apexes`] establishes.
pub const MIDPOINT_MARGIN: f64 = 0.05;

/// The outer apexes V of hallway corners (step (3')) make the outer edge tetrahedra over the
/// edge G_2G_3 (across e_1) and their neighbours degenerate or inverted: the midpoint s of two
/// apexes on the polyhedron's concave edge lies on T's inner side there. Each such apex is moved
/// in its reflex face's plane, out of the face (the tangent plane at G_1 still contains it, so
/// the tetrahedron stays tangent-containing), just far enough that every outer midpoint s over
/// its triangle's edges lies [`MIDPOINT_MARGIN`] on the outer side of both triangles.
pub fn spread_hallway_apexes(hull: &mut SimplicialHull, hallway: &[HallwayApex]) {
    if hallway.is_empty() {
        return;
    }
    let Ok(edges) = hull.edges() else {
        return;
    };
    let mut movable = vec![None; hull.triangles.len()];
    for h in hallway {
        movable[h.triangle] = Some(*h);
    }
    let mut moved = vec![0.0f64; hull.triangles.len()];
    let outer = crate::hull::simplicial::Side::Outer as usize;
    let unit_normal = |hull: &SimplicialHull, t: usize| {
        let [a, b, c] = hull.triangles[t].map(|i| hull.points[i as usize]);
        ((b - a).cross(c - a).normalize_or_zero(), a)
    };
    for _ in 0..4 {
        for e in &edges {
            let [fa, fb] = e.faces.map(|f| f as usize);
            if e.faces[1] == u32::MAX || (movable[fa].is_none() && movable[fb].is_none()) {
                continue;
            }
            let (Some(qa), Some(qb)) = (hull.apexes[fa][outer], hull.apexes[fb][outer]) else {
                continue;
            };
            let len = (hull.points[e.v[1] as usize] - hull.points[e.v[0] as usize]).length();
            let target = MIDPOINT_MARGIN * len;
            let s = 0.5 * (qa + qb);
            let ds = 0.5
                * (movable[fa].map_or(DVec3::ZERO, |h| h.dir)
                    + movable[fb].map_or(DVec3::ZERO, |h| h.dir));
            let mut lambda: f64 = 0.0;
            let mut ok = true;
            for t in [fa, fb] {
                let (n, p) = unit_normal(hull, t);
                let dist = n.dot(s - p);
                if dist < target {
                    let rate = n.dot(ds);
                    if rate > 1e-9 {
                        lambda = lambda.max((target - dist) / rate);
                    } else {
                        ok = false;
                    }
                }
            }
            if !ok || lambda <= 0.0 {
                continue;
            }
            for t in [fa, fb] {
                if let Some(h) = movable[t] {
                    let step = lambda.min(h.limit - moved[t]).max(0.0);
                    moved[t] += step;
                    if let Some(q) = hull.apexes[t][outer].as_mut() {
                        *q += step * h.dir;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::convexity::{edge_convexity_1994, Convexity};

    /// An unseparable vertex (centroids above and below its tangent plane) whose faces are off
    /// their planes by ~1e-7, as non-planar input polygons are: with C_0 = V the edge to the
    /// first guard is nonconvex (Definition 3.1); with the offset of `unseparable_offset` both
    /// edges are convex, and the offset stays of the order of the non-planarity.
    #[test]
    fn unseparable_offset_makes_edges_convex() {
        let v = DVec3::ZERO;
        let n = DVec3::Z;
        let ng = DVec3::new(-0.3, 0.0, 1.0).normalize();
        // Face 0 above V's tangent plane, its guard 1e-7 off the plane through V; face 1
        // below, 1e-6 off on the other side.
        let g = [
            DVec3::new(1.0, 0.0, 0.3) + 1e-7 * ng,
            DVec3::new(-1.0, 0.0, -0.3) + 1e-6 * ng,
        ];
        let nrm = [ng, ng];
        let t = [n.dot(g[0] - v), n.dot(g[1] - v)];
        assert!(t[0] > 0.0 && t[1] < 0.0);
        let class = |c0: DVec3, k: usize| edge_convexity_1994(c0, n, g[k], nrm[k]);
        assert_eq!(class(v, 0), Convexity::Nonconvex);
        let delta = unseparable_offset(v, n, &g, &nrm, &t);
        // Bounded by the two faces' offsets over n·n_G (≈ 0.96).
        assert!(delta > 0.0 && delta < 1.1e-6, "{delta}");
        let c0 = v + delta * n;
        assert_eq!(class(c0, 0), Convexity::Positive);
        assert_eq!(class(c0, 1), Convexity::Negative);
    }
}

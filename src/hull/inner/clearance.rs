//! Apexes on their own side of every base vertex's tangent plane.
//!
//! Why: the 1994 schemes interpolate at every point p of T with ∇F ∥ n_p, so on a face
//! [p q s] of an edge tetrahedron (q an apex of a face tetrahedron over a triangle at p, s the
//! midpoint of two such apexes) F vanishes at p to first order only along the tangent plane's
//! trace. Those faces are boundary faces of the hull (nothing lies beyond them); if q, and with
//! it s, lies across p's tangent plane from the side its tetrahedron is on, that trace runs
//! into the face and the surface leaves the hull through it: `apatch check`'s holes (all 36 of
//! double_torus_poly's after its hull verified were edge-tetrahedron faces next to such apexes,
//! at its waist's trihedral saddles and their neighbours). Definition 3.5 does not ask for
//! this (a tangent plane cutting the tetrahedron anywhere is enough), and the hull builders
//! can leave it: an apex over the base reaching one vertex's tangent plane can sink below
//! another's.
//!
//! [`lift_apexes`] moves every apex that lies below a base vertex's tangent plane (beyond the
//! non-planarity the input may have, [`crate::mesh::PLANARITY_TOL`]) until it clears all three
//! planes by [`CLEARANCE`] times the longest edge, staying on its side of the triangle: by the
//! shortest of three moves, along the triangle's normal, straight across the plane it is
//! furthest below, or between the two ([`move_over`]). Why the shortest: a triangle that
//! stands almost edge-on to a base vertex's tangent plane crosses it slowly along its normal
//! (mpi_poly's step (5') cell over edge 73–83, from needle face 44's plane x = 6 to face 26:
//! the normal crosses x = 6 at a rate of 0.14, so the apex rose 4.5 over a base 3.4 long and
//! its tetrahedron overlapped 56 times; straight across, it moves 0.6). Then every apex of an L-U pair is on its own side of every tangent plane,
//! which keeps the pair tangent-containing (Definition 3.5): at a vertex whose plane does not
//! cut the base, the other two base vertices are on one side and the apex of the other side is
//! across it. Apexes already on or above all three planes (the trihedral corners' V lies in
//! all three) are left alone; `verify` judges the moved ones like any other. Apexes below a
//! plane by less than the input's non-planarity but beyond rounding are nudged over all three
//! by a hair ([`NUDGE_HEIGHT`]), so the cubic scheme does not move them by its margin
//! (`scheme::cubic_c1::tangent`).

use super::degenerate::relative_volume;
use super::verify::DEGENERATE_VOLUME;
use crate::hull::simplicial::{HullEdge, SimplicialHull};
use glam::DVec3;

/// Clearance of a lifted apex over its base vertices' tangent planes, relative to the
/// triangle's longest edge.
pub const CLEARANCE: f64 = 0.02;

/// Smallest cosine between the triangle's normal and a base vertex's normal for which lifting
/// along the triangle's normal is tried (the plane is then crossed at a useful rate).
const MIN_RATE: f64 = 0.05;

/// Lifts the apexes below a base vertex's tangent plane (module docs), within
/// [`super::sides::MAX_HEIGHT`] times the longest edge over the base. Returns how many moved.
pub fn lift_apexes(hull: &mut SimplicialHull) -> usize {
    let mut moved = 0;
    // T's edges, built at the first nudge only (most hulls have none).
    let mut edges: Option<Vec<HullEdge>> = None;
    for t in 0..hull.triangles.len() {
        let tri = hull.triangles[t];
        let p = tri.map(|i| hull.points[i as usize]);
        let n = tri.map(|i| hull.normals[i as usize]);
        let Some(nn) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
            continue;
        };
        let len = (p[1] - p[0])
            .length()
            .max((p[2] - p[1]).length())
            .max((p[0] - p[2]).length());
        let g = (p[0] + p[1] + p[2]) / 3.0;
        for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
            let Some(q) = hull.apexes[t][side] else {
                continue;
            };
            if let Some(lifted) = lift(q, p, n, sign * nn, len, g) {
                hull.apexes[t][side] = Some(lifted);
                moved += 1;
            } else if let Some(nudged) = nudge(q, p, n, sign * nn, len, g) {
                let edges = edges.get_or_insert_with(|| hull.edges().unwrap_or_default());
                if keeps_edge_tets(hull, edges, t, side, nudged) {
                    hull.apexes[t][side] = Some(nudged);
                    moved += 1;
                }
            }
        }
    }
    moved
}

/// True when the edge tetrahedra [p_i p_j q s] that triangle `t`'s apex on `side` would form
/// at `q` with each neighbour's apex on that side (s their midpoint, as
/// [`SimplicialHull::edge_tets`] builds them) all keep a relative volume of at least
/// [`DEGENERATE_VOLUME`] (the bound `verify` holds them to). Why: a nudge is a hair, but on
/// mpi_poly's needle face 44 it flattened the edge tetrahedra at edge (66, 60) to −9e-9;
/// such a nudge is not made (`degenerate::repair` rebuilds face tetrahedra only).
fn keeps_edge_tets(
    hull: &SimplicialHull,
    edges: &[HullEdge],
    t: usize,
    side: usize,
    q: DVec3,
) -> bool {
    edges
        .iter()
        .filter(|e| e.faces[1] != u32::MAX && e.faces.contains(&(t as u32)))
        .all(|e| {
            let other = if e.faces[0] as usize == t {
                e.faces[1]
            } else {
                e.faces[0]
            };
            let Some(q1) = hull.apexes[other as usize][side] else {
                return true;
            };
            let s = 0.5 * (q + q1);
            let [pi, pj] = e.v.map(|i| hull.points[i as usize]);
            [q, q1]
                .iter()
                .all(|&x| relative_volume(pi, pj, x, s).abs() >= DEGENERATE_VOLUME)
        })
}

/// The apex `q` moved until it clears the tangent planes of `p` (normals `n`) on its side by
/// [`CLEARANCE`] times `len`, staying on its side of the triangle (`up`: the triangle's unit
/// normal towards q) by the same margin; `None` when it needs no move or none works. Tried
/// directions, the first that works: `up` (straight away from the base), then straight across
/// the plane it is furthest below, then halfway between the two.
fn lift(q: DVec3, p: [DVec3; 3], n: [DVec3; 3], up: DVec3, len: f64, g: DVec3) -> Option<DVec3> {
    let side = up.dot(n[0] + n[1] + n[2]).signum();
    // Height of x over each tangent plane on q's side (the side whose normal agrees with `up`).
    let h = |k: usize, x: DVec3| side * n[k].dot(x - p[k]);
    if (0..3).all(|k| h(k, q) >= -crate::mesh::PLANARITY_TOL * len) {
        return None;
    }
    move_over(q, p, n, up, len, g, CLEARANCE * len)
}

/// Relative slope σ(q − p_k)·n_k / |q − p_k| below which [`nudge`] moves an apex: the cubic
/// scheme's `tangent::TANGENT_TOL` (apexes beyond it are moved there, by a margin of 0.02).
pub const NUDGE_TOL: f64 = 1e-9;

/// Height over the tangent planes a nudged apex gets, relative to the triangle's longest edge:
/// far above the scheme's tolerance, far below anything `verify` or the patches see.
pub const NUDGE_HEIGHT: f64 = 1e-6;

/// An apex below a base vertex's tangent plane by no more than the input's non-planarity (which
/// [`lift`] leaves alone) but beyond rounding (relative slope below [`NUDGE_TOL`]), moved the
/// least step over all three planes by [`NUDGE_HEIGHT`]. Why: mpi_poly's faces are planar to
/// 8e-5 only, so a trihedral corner's apex V lay 1e-4 beyond the plane of a guard 10 away; the
/// cubic scheme then moved it by its margin 0.02 × the distance (0.56 at vertex 77) and the
/// moved tetrahedra overlapped their neighbours (raw hull 295 violations, the scheme's 396;
/// nudged, both 282). `None` when no move is needed or none works.
fn nudge(q: DVec3, p: [DVec3; 3], n: [DVec3; 3], up: DVec3, len: f64, g: DVec3) -> Option<DVec3> {
    let side = up.dot(n[0] + n[1] + n[2]).signum();
    let below = (0..3).any(|k| {
        let d = q - p[k];
        side * n[k].dot(d) < -NUDGE_TOL * d.length()
    });
    if !below {
        return None;
    }
    move_over(q, p, n, up, len, g, NUDGE_HEIGHT * len)
}

/// The apex `q` moved by the least step along `up`, across the plane it is furthest below, or
/// between the two (whichever of the three moves least), until it clears every tangent plane
/// by `target` and stays on its side of the triangle within [`super::sides::MAX_HEIGHT`];
/// `None` when no direction works.
fn move_over(
    q: DVec3,
    p: [DVec3; 3],
    n: [DVec3; 3],
    up: DVec3,
    len: f64,
    g: DVec3,
    target: f64,
) -> Option<DVec3> {
    let side = up.dot(n[0] + n[1] + n[2]).signum();
    let h = |k: usize, x: DVec3| side * n[k].dot(x - p[k]);
    let worst = (0..3)
        .min_by(|&a, &b| h(a, q).total_cmp(&h(b, q)))
        .expect("three vertices");
    let across = side * n[worst];
    let mut best: Option<(f64, DVec3)> = None;
    for dir in [up, across, (up + across).normalize_or_zero()] {
        // λ ≥ 0 with every height h_k + λ r_k ≥ target and the side up·(x − g) ≥ target.
        let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
        let mut constraints: Vec<(f64, f64)> =
            (0..3).map(|k| (h(k, q), side * n[k].dot(dir))).collect();
        constraints.push((up.dot(q - g), up.dot(dir)));
        let mut ok = true;
        for (value, rate) in constraints {
            if value >= target && rate >= 0.0 {
                continue;
            }
            if rate.abs() < MIN_RATE * dir.length().max(1e-300) {
                if value < target {
                    ok = false;
                }
                continue;
            }
            let bound = (target - value) / rate;
            if rate > 0.0 {
                lo = lo.max(bound);
            } else {
                hi = hi.min(bound);
            }
        }
        if !ok || lo > hi {
            continue;
        }
        let lifted = q + lo * dir;
        if (lifted - g).length() <= super::sides::MAX_HEIGHT * len {
            let step = (lifted - q).length();
            if best.is_none_or(|(b, _)| step < b) {
                best = Some((step, lifted));
            }
        }
    }
    best.map(|(_, x)| x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat triangle whose vertex normals lean outwards (a convex cap) with its outer apex
    /// dropped below one vertex's tangent plane: the lift brings it over all three planes by
    /// the clearance, measured directly, moving no further than straight up would; an apex
    /// already above all three stays.
    #[test]
    fn apex_below_a_tangent_plane_is_lifted_over_all_three() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let g = (p[0] + p[1] + p[2]) / 3.0;
        let n = p.map(|x| (x - g + 2.0 * DVec3::Z).normalize());
        let len = 2f64.sqrt();
        // Near vertex 1's side, low: below the plane tilted towards +x at vertex 1.
        let q = DVec3::new(0.6, 0.2, 0.05);
        assert!(n[1].dot(q - p[1]) < 0.0);
        let lifted = lift(q, p, n, DVec3::Z, len, g).expect("lifted");
        for k in 0..3 {
            // Rounding of the step: far below the clearance.
            assert!(n[k].dot(lifted - p[k]) >= CLEARANCE * len - 1e-12);
        }
        // Straight up works here, by the largest (target − h_k) / n_k·z over the planes; the
        // lift moves no further than that (it takes the shortest move; rounding ~1e-12).
        let up_step = (0..3)
            .map(|k| (CLEARANCE * len - n[k].dot(q - p[k])) / n[k].z)
            .fold(0.0, f64::max);
        assert!(up_step > 0.0);
        assert!((lifted - q).length() <= up_step + 1e-12);
        assert!(lift(lifted, p, n, DVec3::Z, len, g).is_none());
    }

    /// A vertex normal that stands almost in the triangle's plane (the triangle edge-on to that
    /// tangent plane): the normal `up` crosses the plane at a rate of 0.44 only, so lifting
    /// along it moves the apex (target + depth) / 0.44; straight across the plane moves it
    /// (target + depth) / 1. The lift takes the shorter move, measured against both.
    #[test]
    fn apex_below_a_steep_plane_takes_the_shortest_move() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let g = (p[0] + p[1] + p[2]) / 3.0;
        let n = [DVec3::Z, DVec3::Z, DVec3::new(-0.9, 0.0, 0.44).normalize()];
        let len = 2f64.sqrt();
        let target = CLEARANCE * len;
        let q = g + 0.3 * DVec3::Z;
        let depth = -n[2].dot(q - p[2]);
        assert!(depth > 0.1, "q lies {depth} below vertex 2's plane");
        let lifted = lift(q, p, n, DVec3::Z, len, g).expect("lifted");
        for k in 0..3 {
            // Rounding of the step: far below the clearance.
            assert!(n[k].dot(lifted - p[k]) >= target - 1e-12);
        }
        let along_up = (target + depth) / n[2].z;
        let across = target + depth;
        let step = (lifted - q).length();
        // Rounding of the step (coordinates ~1): the moves differ by 0.25.
        assert!((step - across).abs() < 1e-12, "{step} vs {across}");
        assert!(step < along_up - 0.2, "{step} vs {along_up}");
    }

    /// A trihedral-like apex 1e-5 below one vertex's tangent plane (within the planarity
    /// tolerance, so `lift` leaves it) is nudged over all three planes by a hair, and moves
    /// far less than the clearance would move it.
    #[test]
    fn apex_a_hair_below_a_plane_is_nudged() {
        let p = [DVec3::ZERO, DVec3::X * 10.0, DVec3::Y * 10.0];
        let g = (p[0] + p[1] + p[2]) / 3.0;
        // Vertex 2's plane tilts: −0.1x + z = 0 through p_2, so q = (3, 3, 0.3) lies on it and
        // 0.3 over the other two.
        let n = [DVec3::Z, DVec3::Z, (DVec3::Z - 0.1 * DVec3::X).normalize()];
        let len = 200f64.sqrt();
        let q = DVec3::new(3.0, 3.0, 0.3) - n[2] * 1e-5;
        assert!(n[2].dot(q - p[2]) < -1e-6);
        assert!(lift(q, p, n, DVec3::Z, len, g).is_none());
        let nudged = nudge(q, p, n, DVec3::Z, len, g).expect("nudged");
        for k in 0..3 {
            // Rounding of the step (coordinates ~10): far below the nudge height 1.4e-5.
            assert!(n[k].dot(nudged - p[k]) >= NUDGE_HEIGHT * len - 1e-12);
        }
        // A hair: well under a thousandth of the edge (the clearance would be 0.28).
        assert!((nudged - q).length() < 1e-3);
        assert!(nudge(nudged, p, n, DVec3::Z, len, g).is_none());
    }
}

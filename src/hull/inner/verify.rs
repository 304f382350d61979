//! Checks that a [`SimplicialHull`] is smoothable: Definition 3.6 with Lemmas 4.1–4.3, plus the
//! global conditions a closed surface needs. Works on any hull (inner, fixtures, hand-made).
//!
//! Checked, each violation naming the triangle (and its input element) or point:
//! - shape: per-triangle arrays of equal length, indices in range, finite points, unit normals,
//!   at least one apex per triangle;
//! - T is a closed, consistently oriented 2-manifold (every edge in two triangles, running
//!   opposite ways; every point's link one cycle); [`euler_characteristic`] gives its genus;
//! - Lemma 4.1: every edge of T is convex (Definition 3.1 with T's normals);
//! - Lemma 4.2: every face tetrahedron (or one of an L-U pair) is tangent-containing at each of
//!   its three triangle vertices (Definition 3.5: the tangent plane there does not leave the
//!   other three tetrahedron vertices strictly on one side);
//! - L-U pairs have one apex on each side, and single apexes lie on their recorded side;
//! - no degenerate face or edge tetrahedron;
//! - Lemma 4.3 and Def. 3.6 (5)(i): no two tetrahedra of S_f ∪ S_e overlap (separating-axis
//!   test; touching along shared faces, edges or vertices is allowed);
//! - every edge of T has edge tetrahedra on at least one side (else the hull is not contiguous
//!   there and no C1 surface can cross the edge).

use crate::hull::simplicial::{Side, SimplicialHull};
use crate::mesh::convexity::{edge_convexity_1994, Convexity};
use glam::DVec3;
use std::collections::HashMap;

/// Relative volume 6V / L³ (L the longest edge) below which a tetrahedron counts as degenerate:
/// barycentric coordinates in it would keep fewer than 8 of f64's 16 significant digits, below
/// what the schemes' continuity checks resolve. (A regular tetrahedron has 0.118.)
pub const DEGENERATE_VOLUME: f64 = 1e-8;

/// Smallest relative volume 6V / L³ the hull gives a face tetrahedron for the quintic C2 scheme
/// ([`super::InnerOptions::min_volume`] under `type = "quintic-c2"`; the cubic keeps
/// [`DEGENERATE_VOLUME`]). The C1 rows across a side face of a face tetrahedron A carry the
/// barycentrics of the neighbour's opposite vertex in A, about L³ / 6V; the C2 rows of degree 5
/// carry their squares. A sliver of 1e-8 (the nut's nearly flat trihedral corner, input vertex
/// 445) puts 1e10–1e11 into those rows; at 1e-3 they stay below 1e6 and the C2 data of the
/// sliver's neighbourhood are not decided by rounding. Every passing quintic scene's flattest
/// face tetrahedron is above 7e-3 (double_torus_poly 7.5e-3; measured), so they are unchanged;
/// the nut's flattest after its sliver is 2.9e-3.
pub const C2_MIN_VOLUME: f64 = 1e-3;

/// Overlap depth, relative to the smaller tetrahedron's longest edge, above which two
/// tetrahedra intersect. Shared faces, edges and vertices touch with depth 0 up to rounding of
/// the coordinates (≈1e-15); a real overlap is a visible fraction of a tetrahedron.
pub const OVERLAP_DEPTH: f64 = 1e-7;

/// Tangent-containment tolerance relative to the tetrahedron's longest edge. The tangent plane
/// at a centroid or corner guard is its polygon's plane, and the construction puts apexes on
/// polygon edges (steps (3), (5)(i)); input polygons are accepted up to
/// [`crate::mesh::PLANARITY_TOL`] of non-planarity, so such apexes may lie that far off it.
pub const PLANE_TOL: f64 = crate::mesh::PLANARITY_TOL;

/// What is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ViolationKind {
    /// Inconsistent arrays, bad indices, non-finite or non-unit data, a triangle with no apex.
    Malformed,
    /// T is not a closed 2-manifold (edge in ≠ 2 triangles, a point's link not one cycle).
    NotManifold,
    /// Two triangles run the same way along their shared edge.
    Orientation,
    /// An edge of T is nonconvex (Definition 3.1; Lemma 4.1).
    EdgeNonconvex,
    /// A face tetrahedron (or L-U pair) is not tangent-containing (Definition 3.5; Lemma 4.2).
    NotTangentContaining,
    /// An apex lies on the wrong side of its triangle, or an L-U pair is one-sided.
    WrongSide,
    /// A face or edge tetrahedron has (nearly) zero volume.
    Degenerate,
    /// Two tetrahedra of the hull overlap (Lemma 4.3; Definition 3.6 (5)(i)).
    Intersecting,
    /// An edge of T has no edge tetrahedra on either side.
    NoEdgeTetrahedra,
}

/// One violated condition, with a message naming the triangle, element or point.
#[derive(Clone, Debug, PartialEq)]
pub struct HullViolation {
    /// Which condition.
    pub kind: ViolationKind,
    /// The triangle of T concerned, if one.
    pub triangle: Option<u32>,
    /// Human-readable detail.
    pub message: String,
}

/// V − E + F of T over the points its triangles use (2 − 2g for a closed orientable surface of
/// genus g). `None` when T is not a manifold.
#[must_use]
pub fn euler_characteristic(hull: &SimplicialHull) -> Option<i64> {
    let edges = hull.edges().ok()?;
    let mut used = vec![false; hull.points.len()];
    for t in &hull.triangles {
        for &i in t {
            *used.get_mut(i as usize)? = true;
        }
    }
    let v = used.iter().filter(|&&u| u).count() as i64;
    Some(v - edges.len() as i64 + hull.triangles.len() as i64)
}

/// Checks `hull` (see the module documentation). Empty when it is a smoothable hull.
#[must_use]
pub fn verify(hull: &SimplicialHull) -> Vec<HullViolation> {
    let nt = hull.triangles.len();
    let np = hull.points.len();
    let mut out = Sink(Vec::new());
    if hull.apexes.len() != nt
        || hull.element.len() != nt
        || hull.normals.len() != np
        || hull.origins.len() != np
    {
        out.push(
            ViolationKind::Malformed,
            None,
            format!(
                "array lengths differ: {np} points, {} normals, {} origins, {nt} triangles, {} apex slots, {} elements",
                hull.normals.len(),
                hull.origins.len(),
                hull.apexes.len(),
                hull.element.len()
            ),
        );
        return out.0;
    }
    let name = |t: usize| format!("triangle {t} (element {})", hull.element[t]);
    let mut malformed = false;
    for (i, (p, n)) in hull.points.iter().zip(&hull.normals).enumerate() {
        // Unit normals: |n| − 1 within 1e-9 allows any normalised f64 vector.
        if !p.is_finite() || !n.is_finite() || (n.length() - 1.0).abs() > 1e-9 {
            out.push(
                ViolationKind::Malformed,
                None,
                format!("point {i}: {p} with normal {n} (need finite point, unit normal)"),
            );
            malformed = true;
        }
    }
    for (t, tri) in hull.triangles.iter().enumerate() {
        if tri.iter().any(|&i| i as usize >= np)
            || tri[0] == tri[1]
            || tri[1] == tri[2]
            || tri[0] == tri[2]
        {
            out.push(
                ViolationKind::Malformed,
                Some(t),
                format!("{}: bad indices {tri:?}", name(t)),
            );
            malformed = true;
        } else if hull.apexes[t].iter().all(Option::is_none) {
            out.push(
                ViolationKind::Malformed,
                Some(t),
                format!("{}: no face tetrahedron", name(t)),
            );
        } else if hull.apexes[t].iter().flatten().any(|q| !q.is_finite()) {
            out.push(
                ViolationKind::Malformed,
                Some(t),
                format!("{}: non-finite apex", name(t)),
            );
            malformed = true;
        }
    }
    if malformed {
        return out.0;
    }
    let pt = |i: u32| hull.points[i as usize];

    // Manifold and orientation.
    let edges = match hull.edges() {
        Ok(e) => e,
        Err(m) => {
            out.push(ViolationKind::NotManifold, None, m);
            return out.0;
        }
    };
    for e in &edges {
        let [a, b] = e.v;
        if e.faces[1] == u32::MAX {
            out.push(
                ViolationKind::NotManifold,
                Some(e.faces[0] as usize),
                format!(
                    "edge ({a}, {b}) of {} is a boundary of T",
                    name(e.faces[0] as usize)
                ),
            );
            continue;
        }
        let t1 = hull.triangles[e.faces[1] as usize];
        let same_way = (0..3).any(|k| t1[k] == a && t1[(k + 1) % 3] == b);
        if same_way {
            out.push(
                ViolationKind::Orientation,
                Some(e.faces[1] as usize),
                format!(
                    "{} and {} run the same way along edge ({a}, {b})",
                    name(e.faces[0] as usize),
                    name(e.faces[1] as usize)
                ),
            );
        }
        // Lemma 4.1.
        let (pa, pb) = (pt(a), pt(b));
        let (na, nb) = (hull.normals[a as usize], hull.normals[b as usize]);
        if edge_convexity_1994(pa, na, pb, nb) == Convexity::Nonconvex {
            out.push(
                ViolationKind::EdgeNonconvex,
                Some(e.faces[0] as usize),
                format!(
                    "edge ({a}, {b}) between {} and {} is nonconvex: (p_b − p_a)·n_a = {:.3e}, (p_a − p_b)·n_b = {:.3e}",
                    name(e.faces[0] as usize),
                    name(e.faces[1] as usize),
                    (pb - pa).dot(na),
                    (pa - pb).dot(nb)
                ),
            );
        }
        let joined = Side::BOTH.iter().any(|&s| {
            hull.apexes[e.faces[0] as usize][s as usize].is_some()
                && hull.apexes[e.faces[1] as usize][s as usize].is_some()
        });
        if !joined {
            out.push(
                ViolationKind::NoEdgeTetrahedra,
                Some(e.faces[0] as usize),
                format!(
                    "edge ({a}, {b}): {} and {} have face tetrahedra on opposite sides only",
                    name(e.faces[0] as usize),
                    name(e.faces[1] as usize)
                ),
            );
        }
    }
    // Links: at every point the triangles form one cycle.
    let mut link: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for tri in &hull.triangles {
        for k in 0..3 {
            link.entry(tri[k])
                .or_default()
                .push((tri[(k + 1) % 3], tri[(k + 2) % 3]));
        }
    }
    let mut keys: Vec<u32> = link.keys().copied().collect();
    keys.sort_unstable();
    for p in keys {
        let l = &link[&p];
        let next: HashMap<u32, u32> = l.iter().copied().collect();
        let mut cur = l[0].0;
        let mut steps = 0;
        while let Some(&n) = next.get(&cur) {
            cur = n;
            steps += 1;
            if cur == l[0].0 || steps > l.len() {
                break;
            }
        }
        if next.len() != l.len() || steps != l.len() || cur != l[0].0 {
            out.push(
                ViolationKind::NotManifold,
                None,
                format!("point {p}: its {} triangles do not form one fan", l.len()),
            );
        }
    }

    // Per triangle: sidedness, tangent containment (Lemma 4.2), degeneracy.
    for (t, tri) in hull.triangles.iter().enumerate() {
        let base = tri.map(pt);
        let slots = hull.apexes[t];
        let tets: Vec<(Side, [DVec3; 4])> = Side::BOTH
            .iter()
            .filter_map(|&s| slots[s as usize].map(|q| (s, [base[0], base[1], base[2], q])))
            .collect();
        for &(side, tet) in &tets {
            let l = longest_edge(&tet);
            let o = (base[1] - base[0])
                .cross(base[2] - base[0])
                .dot(tet[3] - base[0]);
            let rel = o / (l * l * l);
            if rel.abs() < DEGENERATE_VOLUME {
                out.push(
                    ViolationKind::Degenerate,
                    Some(t),
                    format!(
                        "{}: {side:?} face tetrahedron has relative volume {rel:.2e}",
                        name(t)
                    ),
                );
            } else if (rel > 0.0) != (side == Side::Outer) {
                out.push(
                    ViolationKind::WrongSide,
                    Some(t),
                    format!("{}: the {side:?} apex lies on the other side", name(t)),
                );
            }
        }
        for k in 0..3 {
            let (pk, nk) = (base[k], hull.normals[tri[k] as usize]);
            if !tets.iter().any(|(_, tet)| tangent_contains(tet, pk, nk)) {
                out.push(
                    ViolationKind::NotTangentContaining,
                    Some(t),
                    format!(
                        "{}: the tangent plane at point {} misses its face tetrahedra",
                        name(t),
                        tri[k]
                    ),
                );
            }
        }
    }

    // Edge tetrahedra: degeneracy; then all pairs for overlaps.
    let edge_tets = match hull.edge_tets() {
        Ok(e) => e,
        Err(m) => {
            out.push(ViolationKind::NotManifold, None, m);
            return out.0;
        }
    };
    let mut all: Vec<([DVec3; 4], String)> = Vec::new();
    for (t, slots) in hull.apexes.iter().enumerate() {
        for s in Side::BOTH {
            if slots[s as usize].is_some() {
                let tet = hull.face_tet(t, s).expect("apex present");
                all.push((tet, format!("{s:?} face tetrahedron of {}", name(t))));
            }
        }
    }
    for et in &edge_tets {
        let l = longest_edge(&et.tet);
        let rel = tet_volume6(&et.tet) / (l * l * l);
        let label = format!(
            "{:?} edge tetrahedron at edge ({}, {}) beside {}",
            et.side,
            edges[et.edge as usize].v[0],
            edges[et.edge as usize].v[1],
            name(et.face as usize)
        );
        if rel.abs() < DEGENERATE_VOLUME {
            out.push(
                ViolationKind::Degenerate,
                Some(et.face as usize),
                format!("{label}: relative volume {rel:.2e}"),
            );
        }
        all.push((et.tet, label));
    }
    for (i, j, depth) in overlapping_pairs(&all.iter().map(|(t, _)| *t).collect::<Vec<_>>()) {
        out.push(
            ViolationKind::Intersecting,
            None,
            format!("{} overlaps {} (depth {depth:.2e})", all[i].1, all[j].1),
        );
    }
    out.0
}

/// Collects violations.
struct Sink(Vec<HullViolation>);

impl Sink {
    fn push(&mut self, kind: ViolationKind, triangle: Option<usize>, message: String) {
        self.0.push(HullViolation {
            kind,
            triangle: triangle.map(|t| t as u32),
            message,
        });
    }
}

/// Definition 3.5 at the vertex `pk` (normal `nk`) of `tet`: its tangent plane does not leave
/// the other vertices strictly on one side (within [`PLANE_TOL`] of the longest edge).
pub(super) fn tangent_contains(tet: &[DVec3; 4], pk: DVec3, nk: DVec3) -> bool {
    let tol = PLANE_TOL * longest_edge(tet);
    let (lo, hi) = tet
        .iter()
        .filter(|&&x| x != pk)
        .map(|&x| nk.dot(x - pk))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    lo <= tol && hi >= -tol
}

/// Longest edge of a tetrahedron.
pub(super) fn longest_edge(t: &[DVec3; 4]) -> f64 {
    let mut l: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.max((t[i] - t[j]).length());
        }
    }
    l
}

/// Six times the signed volume.
fn tet_volume6(t: &[DVec3; 4]) -> f64 {
    (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0])
}

/// Pairs of tetrahedra whose interiors overlap by more than [`OVERLAP_DEPTH`], with the depth
/// (relative to the smaller one's longest edge), sorted. Grid of bounding boxes (cells of the
/// mean box size, each pair tested once, in the cell holding the lower corner of the
/// intersection of its boxes), cells in parallel, then the separating-axis test, which stops at
/// the first axis that already separates (touching neighbours, most pairs, stop at their shared
/// face's normal): the same pairs and depths as the full test ([`sat_depth`]), near-linear in
/// the number of tetrahedra.
#[must_use]
pub fn overlapping_pairs(tets: &[[DVec3; 4]]) -> Vec<(usize, usize, f64)> {
    use rayon::prelude::*;
    let boxes: Vec<(DVec3, DVec3)> = tets
        .iter()
        .map(|t| {
            let lo = t.iter().fold(DVec3::splat(f64::INFINITY), |a, &b| a.min(b));
            let hi = t
                .iter()
                .fold(DVec3::splat(f64::NEG_INFINITY), |a, &b| a.max(b));
            (lo, hi)
        })
        .collect();
    if tets.is_empty() {
        return Vec::new();
    }
    let longest: Vec<f64> = tets.iter().map(longest_edge).collect();
    let mean = boxes
        .iter()
        .map(|(lo, hi)| (*hi - *lo).max_element())
        .sum::<f64>()
        / boxes.len() as f64;
    let cell = if mean > 0.0 && mean.is_finite() {
        mean
    } else {
        1.0
    };
    let key = |p: DVec3| {
        let k = (p / cell).floor();
        (k.x as i64, k.y as i64, k.z as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (i, (lo, hi)) in boxes.iter().enumerate() {
        let (a, b) = (key(*lo), key(*hi));
        for x in a.0..=b.0 {
            for y in a.1..=b.1 {
                for z in a.2..=b.2 {
                    grid.entry((x, y, z)).or_default().push(i);
                }
            }
        }
    }
    let cells: Vec<((i64, i64, i64), Vec<usize>)> = grid.into_iter().collect();
    let mut out: Vec<(usize, usize, f64)> = cells
        .par_iter()
        .flat_map_iter(|(here, list)| {
            let mut found = Vec::new();
            for (k, &i) in list.iter().enumerate() {
                for &j in &list[k + 1..] {
                    let (a, b) = (boxes[i], boxes[j]);
                    if a.0.x > b.1.x
                        || b.0.x > a.1.x
                        || a.0.y > b.1.y
                        || b.0.y > a.1.y
                        || a.0.z > b.1.z
                        || b.0.z > a.1.z
                    {
                        continue;
                    }
                    if key(a.0.max(b.0)) != *here {
                        continue;
                    }
                    let scale = longest[i].min(longest[j]);
                    if let Some(depth) = sat_depth_above(&tets[i], &tets[j], OVERLAP_DEPTH * scale)
                    {
                        let depth = depth / scale;
                        if depth > OVERLAP_DEPTH {
                            found.push((i.min(j), i.max(j), depth));
                        }
                    }
                }
            }
            found
        })
        .collect();
    out.sort_by_key(|a| (a.0, a.1));
    out
}

/// [`sat_depth`] when it exceeds `limit`, else `None`; stops at the first axis whose overlap is
/// at most `limit` (the minimum over all axes then is too). Axes in the same order as
/// [`sat_depth`], so the depth returned is the same number.
#[must_use]
pub fn sat_depth_above(a: &[DVec3; 4], b: &[DVec3; 4], limit: f64) -> Option<f64> {
    let overlap = |axis: DVec3| -> Option<f64> {
        let ax = axis.try_normalize()?;
        let (mut a0, mut a1, mut b0, mut b1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in a {
            let x = ax.dot(*p);
            a0 = a0.min(x);
            a1 = a1.max(x);
        }
        for p in b {
            let x = ax.dot(*p);
            b0 = b0.min(x);
            b1 = b1.max(x);
        }
        Some(a1.min(b1) - a0.max(b0))
    };
    let mut depth = f64::INFINITY;
    for n in tet_face_normals(a).into_iter().chain(tet_face_normals(b)) {
        if let Some(d) = overlap(n) {
            depth = depth.min(d);
            if depth <= limit {
                return None;
            }
        }
    }
    let (ea, eb) = (tet_edges(a), tet_edges(b));
    for x in ea {
        for y in eb {
            let c = x.cross(y);
            if c.length_squared() > 1e-20 * x.length_squared() * y.length_squared() {
                if let Some(d) = overlap(c) {
                    depth = depth.min(d);
                    if depth <= limit {
                        return None;
                    }
                }
            }
        }
    }
    Some(depth)
}

/// The four face normals (unnormalised) of a tetrahedron, in [`sat_depth`]'s order.
fn tet_face_normals(t: &[DVec3; 4]) -> [DVec3; 4] {
    [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]].map(|[i, j, k]| (t[j] - t[i]).cross(t[k] - t[i]))
}

/// The six edge vectors of a tetrahedron, in [`sat_depth`]'s order.
fn tet_edges(t: &[DVec3; 4]) -> [DVec3; 6] {
    [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| t[j] - t[i])
}

/// The smallest overlap of the two tetrahedra's projections over all candidate separating axes
/// (face normals of both, cross products of their edges): ≤ 0 when a plane separates them.
#[must_use]
pub fn sat_depth(a: &[DVec3; 4], b: &[DVec3; 4]) -> f64 {
    // No limit: every axis is tested, so the minimum over all of them comes back.
    sat_depth_above(a, b, f64::NEG_INFINITY).unwrap_or(f64::NEG_INFINITY)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tet(o: DVec3) -> [DVec3; 4] {
        [o, o + DVec3::X, o + DVec3::Y, o + DVec3::Z]
    }

    /// Separated, face-sharing and overlapping tetrahedra against known answers.
    #[test]
    fn sat_depth_known_configurations() {
        let a = unit_tet(DVec3::ZERO);
        // Far apart: negative (gap of 1 along x at least).
        assert!(sat_depth(&a, &unit_tet(DVec3::new(2.0, 0.0, 0.0))) < -0.5);
        // Mirror image through the face x + y + z = 1 shares that face: depth 0.
        let m = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::splat(2.0 / 3.0)];
        assert!(sat_depth(&a, &m).abs() < 1e-15);
        // Shifted by a quarter along x overlaps (interior point (0.3, 0.1, 0.1) is in both).
        assert!(sat_depth(&a, &unit_tet(DVec3::new(0.25, 0.0, 0.0))) > 0.05);
    }

    /// The grid + early-exit search finds exactly the pairs (and depths) of the brute-force
    /// all-pairs full separating-axis test, on hulls with and without overlaps.
    #[test]
    fn overlapping_pairs_match_brute_force() {
        use crate::hull::inner::{build, InnerOptions};
        use crate::mesh::{self, NormalMethod};
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
        let mut with_overlaps = 0;
        for name in ["letter_P_poly.obj", "torus_quad.obj", "icosahedron.obj"] {
            let (m, _) = mesh::load(&root.join(name)).unwrap();
            let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
            let mut hull = build(&m, &normals, &InnerOptions::default()).unwrap();
            if name == "torus_quad.obj" {
                // Its hull verifies since `unfold` flips its folds; apexes raised to four times
                // their height over the base centroid make overlaps to compare on.
                for (t, tri) in hull.triangles.iter().enumerate() {
                    let g = tri.iter().map(|&i| hull.points[i as usize]).sum::<DVec3>() / 3.0;
                    for q in hull.apexes[t].iter_mut().flatten() {
                        *q = g + 4.0 * (*q - g);
                    }
                }
            }
            let mut tets = Vec::new();
            for t in 0..hull.triangles.len() {
                for s in Side::BOTH {
                    if let Some(x) = hull.face_tet(t, s) {
                        tets.push(x);
                    }
                }
            }
            tets.extend(hull.edge_tets().unwrap().iter().map(|e| e.tet));
            let mut brute = Vec::new();
            for i in 0..tets.len() {
                for j in i + 1..tets.len() {
                    let scale = longest_edge(&tets[i]).min(longest_edge(&tets[j]));
                    let depth = sat_depth(&tets[i], &tets[j]) / scale;
                    if depth > OVERLAP_DEPTH {
                        brute.push((i, j, depth));
                    }
                }
            }
            let fast = overlapping_pairs(&tets);
            assert_eq!(fast, brute, "{name}");
            with_overlaps += usize::from(!brute.is_empty());
        }
        // The comparison must cover overlapping pairs, not only empty lists.
        assert!(with_overlaps > 0);
    }
}

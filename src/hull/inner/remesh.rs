//! Appendix C of Bajaj, Chen, Xu (1994): re-meshing a corner round which no direction is "above
//! face", so that Algorithm 1 can cut it.
//!
//! [`super::above`] rotates a vertex normal until n · n_f > 0 for every face f round the
//! vertex. When the faces wrap round more than a hemisphere (a saddle whose face normals span
//! more than half the sphere) no normal qualifies, and the paper re-meshes the corner instead.
//! Its Appendix C (figures lost, text partly garbled) reads, reconstructed:
//!
//! * Intersect the faces round V with a small sphere S centred at V: a spherical polygon
//!   P = P_1 … P_n whose corners P_i are the directions of V's edges E_i and whose arcs lie in
//!   the faces. Replace every P_i by the midpoint of the arc P_i P_{i+1} and repeat, k times,
//!   until some great circle sees the polygon without overlap: then the normal of that circle
//!   is above every face of the new corner (the smoothing rounds the polygon off towards a
//!   convex loop or a great circle, like a curve-shortening flow).
//! * Map each smoothing round onto the mesh: on every edge E_i take a point D_i at one common
//!   distance from V, and a point M_i on the bisector of the face between E_i and E_{i+1}
//!   (the arc midpoint, equidistant from D_i and D_{i+1}, in that face's plane). Connect
//!   V M_i, M_i M_{i+1}, D_i M_i and D_{i+1} M_i and delete the edge pieces D_i V. V's faces are
//!   then the triangles V M_i M_{i+1}, whose directions are exactly the smoothed polygon; the
//!   next round works on them, with its D's on the edges V M_i.
//! * The new M_i have five faces (two triangles at V, two "chamfer" triangles M_i M_{i+1}
//!   D_{i+1} over the old edges, and the rest of their face), the D_i three: every new corner
//!   is smoothable, and every face keeps its plane (D_i, M_i, D_{i+1} lie in it).
//!
//! Distances: the paper puts D at 2k·s and M at (2k − 1)·s for a step s, which leaves M beyond
//! the chord D_i D_{i+1} whenever the face angle is below 120° and so makes the cut faces
//! non-convex at M. Here M_i lies inside the triangle V D_i D_{i+1} (at [`M_DEPTH`] of the way
//! to the chord's midpoint), so faces that were convex stay convex, and each round's D's sit at
//! [`NEXT_RADIUS`] of the shortest V M_i. The first round's radius is [`FIRST_RADIUS`] of the
//! nearest other feature of V's faces, so the cut stays inside them and away from neighbouring
//! vertices (also from a neighbour re-meshed itself).
//!
//! The number of rounds k is found on the sphere first ([`rounds_needed`]): the least k whose
//! polygon has a direction with clearance min n · n_f ≥ [`TARGET_CLEARANCE`] (or the best
//! round, when the polygon shrinks to a spike before reaching it). The re-meshed
//! mesh changes the polyhedron near V (the surface then interpolates the new vertices); the
//! new vertices get angle-weighted normals, and every original vertex keeps its own.

use super::above::{clearance, most_above, ABOVE_MARGIN};
use crate::error::{Error, Result};
use crate::mesh::geometry::area_vector;
use crate::mesh::{Mesh, Topology};
use glam::DVec3;

/// Clearance (min over V's faces of n · n_f for the best n) the smoothed corner must reach:
/// about 87° between the normal and the steepest face, so that the corner is well inside the
/// "above face" cone and [`super::above::make_above`] finds a normal with half of it.
pub const TARGET_CLEARANCE: f64 = 0.05;

/// Least clearance accepted when no round reaches [`TARGET_CLEARANCE`]: ten times
/// [`ABOVE_MARGIN`], so the normal [`super::above::make_above`] picks (half of the best
/// clearance) still clears the margin fivefold.
pub const MIN_CLEARANCE: f64 = 0.01;

/// Most smoothing rounds tried per corner; each round shrinks the cut by about half, so more
/// would leave features far below the model's scale.
pub const MAX_ROUNDS: usize = 24;

/// The first round's radius |V D_i| as a share of the nearest other feature of V's faces (its
/// shortest edge, or the distance to a face edge not at V).
pub const FIRST_RADIUS: f64 = 0.25;

/// |V M_i| as a share of the distance from V to the midpoint of the chord D_i D_{i+1}: below 1,
/// M_i lies inside the triangle V D_i D_{i+1} and the face keeps a convex corner at M_i.
pub const M_DEPTH: f64 = 0.8;

/// The next round's radius as a share of the shortest V M_i, so every next D_i lies strictly
/// inside its edge V M_i.
pub const NEXT_RADIUS: f64 = 0.75;

/// Passes over the mesh: new vertices M_i that still have no above-face direction are
/// re-meshed in the next pass.
pub const MAX_PASSES: usize = 3;

/// One corner re-meshed by [`remesh_corners`].
#[derive(Clone, Debug, PartialEq)]
pub struct RemeshedCorner {
    /// The vertex (index in the input mesh, or a vertex added by an earlier pass).
    pub vertex: u32,
    /// Smoothing rounds k applied.
    pub rounds: usize,
    /// Clearance of the input corner's best direction (< [`ABOVE_MARGIN`]).
    pub clearance_before: f64,
    /// Clearance of the re-meshed corner's best direction (≥ [`MIN_CLEARANCE`], usually
    /// ≥ [`TARGET_CLEARANCE`]).
    pub clearance_after: f64,
    /// The first round's radius |V D_i|.
    pub radius: f64,
    /// Vertices added for this corner (D's and M's of all rounds).
    pub new_vertices: std::ops::Range<u32>,
}

/// A mesh with its failing corners re-meshed, and normals for every vertex.
#[derive(Clone, Debug)]
pub struct Remeshed {
    /// The new mesh: the input's vertices first (unchanged), then the added ones; faces at
    /// re-meshed corners modified in place, new faces appended.
    pub mesh: Mesh,
    /// Unit normals: the given ones for input vertices, angle-weighted ones for new vertices.
    pub normals: Vec<DVec3>,
    /// The corners re-meshed, in order.
    pub corners: Vec<RemeshedCorner>,
}

/// The bisector of the corner angle θ at a vertex from unit edge direction `a` to unit edge
/// direction `b` (counter-clockwise about the face normal `n`, θ in (0, 2π)), and cos(θ/2).
/// On a non-planar face the corner's own plane (a × b, oriented by `n`) is used, so the
/// bisector lies exactly between its two edges.
#[must_use]
pub fn bisector(a: DVec3, b: DVec3, n: DVec3) -> (DVec3, f64) {
    let c = a.cross(b);
    let plane = if c.length() > 1e-9 {
        if c.dot(n) >= 0.0 {
            c.normalize()
        } else {
            -c.normalize()
        }
    } else {
        n
    };
    let p = plane.cross(a).normalize_or_zero();
    let theta = b.dot(p).atan2(b.dot(a)).rem_euclid(std::f64::consts::TAU);
    let half = 0.5 * theta;
    (
        (half.cos() * a + half.sin() * p).normalize_or_zero(),
        half.cos(),
    )
}

/// One smoothing round on the sphere: the arc midpoints of the spherical polygon with corners
/// `dirs` (unit) and arcs in planes with unit normals `normals` (arc i from corner i to i + 1),
/// and the normals of the new arcs (arc i from new corner i to i + 1, across old corner
/// i + 1). `None` when a new arc degenerates (two midpoints parallel or opposite).
#[must_use]
pub fn smooth_once(dirs: &[DVec3], normals: &[DVec3]) -> Option<(Vec<DVec3>, Vec<DVec3>)> {
    let n = dirs.len();
    let mids: Vec<DVec3> = (0..n)
        .map(|i| bisector(dirs[i], dirs[(i + 1) % n], normals[i]).0)
        .collect();
    let arcs = (0..n)
        .map(|i| {
            let (a, b) = (mids[i], mids[(i + 1) % n]);
            let c = a.cross(b);
            // The arc runs through old corner i + 1: the triangle must turn the same way.
            let via = dirs[(i + 1) % n];
            let turn = a.cross(via) + via.cross(b);
            (c.length() > 1e-12 && c.dot(turn) > 0.0).then(|| c.normalize())
        })
        .collect::<Option<Vec<_>>>()?;
    Some((mids, arcs))
}

/// The least number of smoothing rounds after which the spherical polygon (`dirs`, `normals`
/// as in [`smooth_once`]) has a direction with clearance ≥ [`TARGET_CLEARANCE`], with that
/// clearance. Corners whose polygon shrinks to a point (a folded spike) gain clearance only for
/// a few rounds and then lose it again (the corner sharpens into a thin cone): when no round
/// reaches the target, the round with the best clearance is taken if that is at least
/// [`MIN_CLEARANCE`]. `None` otherwise, or when an arc degenerates.
#[must_use]
pub fn rounds_needed(dirs: &[DVec3], normals: &[DVec3]) -> Option<(usize, f64)> {
    let (mut d, mut n) = (dirs.to_vec(), normals.to_vec());
    let mut best = (0, f64::NEG_INFINITY);
    for k in 1..=MAX_ROUNDS {
        (d, n) = smooth_once(&d, &n)?;
        let c = clearance(most_above(&n), &n);
        if c <= best.1 && best.1 >= TARGET_CLEARANCE {
            break; // past the best round after reaching the target
        }
        if c > best.1 {
            best = (k, c);
        }
    }
    (best.1 >= MIN_CLEARANCE).then_some(best)
}

/// Unit area normals of `faces` (zero for a zero-area face).
fn face_normals(mesh: &Mesh, faces: &[u32]) -> Vec<DVec3> {
    faces
        .iter()
        .map(|&f| area_vector(&mesh.positions, &mesh.faces[f as usize]).normalize_or_zero())
        .collect()
}

/// Closed manifold vertices with other than three faces round which no direction is above
/// every face (best clearance < [`ABOVE_MARGIN`]), with that best clearance. Trihedral
/// corners need no above-face normal (Algorithm 1 step (3)).
#[must_use]
pub fn corners_without_above(mesh: &Mesh) -> Vec<(u32, f64)> {
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    (0..mesh.positions.len() as u32)
        .filter_map(|v| {
            let fan = topo.vertex_fan(v)?;
            if !fan.closed || fan.faces.len() == 3 {
                return None;
            }
            let normals = face_normals(mesh, &fan.faces);
            let c = clearance(most_above(&normals), &normals);
            (c < ABOVE_MARGIN).then_some((v, c))
        })
        .collect()
}

/// Distance from `p` to the segment `a b`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * ab - p).length()
}

/// Adds a vertex at `p` (file line and normal slot of `like`), returning its index.
fn push_vertex(mesh: &mut Mesh, p: DVec3, like: u32) -> u32 {
    mesh.positions.push(p);
    let line = mesh.vertex_lines.get(like as usize).copied().unwrap_or(0);
    mesh.vertex_lines.push(line);
    if let Some(n) = &mut mesh.file_normals {
        let copy = n[like as usize];
        n.push(copy);
    }
    (mesh.positions.len() - 1) as u32
}

/// Appends face `face` with the file line and parent of face `like`.
fn push_face(mesh: &mut Mesh, face: Vec<u32>, like: u32) -> u32 {
    mesh.faces.push(face);
    mesh.face_lines.push(mesh.face_lines[like as usize]);
    mesh.face_parent.push(mesh.face_parent[like as usize]);
    (mesh.faces.len() - 1) as u32
}

/// Re-meshes the corner at `v` by `rounds` rounds of Appendix C (see the module
/// documentation), in place. Returns the first round's radius.
///
/// # Errors
/// `v` is not a closed manifold vertex, or a cut degenerates (coincident edge directions).
pub fn remesh_corner(mesh: &mut Mesh, v: u32, rounds: usize) -> Result<f64> {
    let line = mesh.vertex_lines.get(v as usize).copied().unwrap_or(0);
    let fail = |what: &str| {
        Error::Invalid(format!(
            "vertex {v} (line {line}): Appendix C re-meshing: {what}"
        ))
    };
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let fan = topo
        .vertex_fan(v)
        .filter(|f| f.closed)
        .ok_or_else(|| fail("the vertex is not a closed manifold corner"))?;
    let p = mesh.positions[v as usize];
    // The nearest other feature of V's faces: edges at V, and edges of its faces not at V.
    let mut reach = f64::INFINITY;
    for &f in &fan.faces {
        let face = &mesh.faces[f as usize];
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            reach = reach.min(if a == v {
                (pb - p).length()
            } else if b == v {
                (pa - p).length()
            } else {
                segment_distance(p, pa, pb)
            });
        }
    }
    if !(reach > 0.0 && reach.is_finite()) {
        return Err(fail("a face of the corner is degenerate"));
    }
    let first = FIRST_RADIUS * reach;
    let mut radius = first;
    let (mut ring, mut faces) = (fan.ring, fan.faces);
    for _ in 0..rounds {
        let n = ring.len();
        let dirs: Vec<DVec3> = ring
            .iter()
            .map(|&w| (mesh.positions[w as usize] - p).normalize_or_zero())
            .collect();
        let normals = face_normals(mesh, &faces);
        let d: Vec<u32> = (0..n)
            .map(|i| push_vertex(mesh, p + radius * dirs[i], v))
            .collect();
        let mut m = Vec::with_capacity(n);
        let mut shortest = f64::INFINITY;
        for i in 0..n {
            let (b, cos_half) = bisector(dirs[i], dirs[(i + 1) % n], normals[i]);
            if b == DVec3::ZERO {
                return Err(fail("two edges at the corner have one direction"));
            }
            // Inside the triangle V D_i D_{i+1} (cos θ/2 is the chord midpoint's distance over
            // the radius); straight and reflex corners: a fifth of the radius.
            let depth = M_DEPTH * radius * cos_half.max(0.25);
            shortest = shortest.min(depth);
            m.push(push_vertex(mesh, p + depth * b, v));
        }
        // Face i: ... ring[i+1], V, ring[i] ... becomes ... ring[i+1], D_{i+1}, M_i, D_i, ring[i] ...
        for i in 0..n {
            let face = &mut mesh.faces[faces[i] as usize];
            let at = face
                .iter()
                .position(|&x| x == v)
                .ok_or_else(|| fail("a face of the fan lost the vertex"))?;
            face.splice(at..=at, [d[(i + 1) % n], m[i], d[i]]);
        }
        let mut next = Vec::with_capacity(n);
        for i in 0..n {
            let j = (i + 1) % n;
            next.push(push_face(mesh, vec![v, m[i], m[j]], faces[i]));
            push_face(mesh, vec![m[j], m[i], d[j]], faces[i]);
        }
        ring = m;
        faces = next;
        radius = NEXT_RADIUS * shortest;
    }
    Ok(first)
}

/// Best clearance round a closed corner with other than three faces; `None` otherwise.
fn corner_clearance(mesh: &Mesh, topo: &Topology, v: u32) -> Option<f64> {
    let fan = topo.vertex_fan(v)?;
    if !fan.closed || fan.faces.len() == 3 {
        return None;
    }
    let normals = face_normals(mesh, &fan.faces);
    Some(clearance(most_above(&normals), &normals))
}

/// The number of rounds for the corner at `v` (closed fan `fan`) and the clearance it gives:
/// the least k for which the corner and every vertex it adds with other than three faces reach
/// [`TARGET_CLEARANCE`], else the k with the best such worst clearance if that is at least
/// [`MIN_CLEARANCE`]. The corner alone is judged on the sphere ([`smooth_once`]); the added
/// vertices (the M_i, whose faces depend on the cut's distances) by a trial re-meshing. A
/// corner smoothed into a thin wedge has M_i on its ridge whose faces through V M_i and the cut
/// face through M_i share the line V M_i and need not lie in a half-space: those rounds lose.
#[must_use]
pub fn best_rounds(mesh: &Mesh, v: u32, fan: &crate::mesh::Fan) -> Option<(usize, f64)> {
    let p = mesh.positions[v as usize];
    let (mut d, mut n): (Vec<DVec3>, Vec<DVec3>) = (
        fan.ring
            .iter()
            .map(|&w| (mesh.positions[w as usize] - p).normalize_or_zero())
            .collect(),
        face_normals(mesh, &fan.faces),
    );
    let mut best: Option<(usize, f64)> = None;
    for k in 1..=MAX_ROUNDS {
        let Some(next) = smooth_once(&d, &n) else {
            break;
        };
        (d, n) = next;
        let at_v = clearance(most_above(&n), &n);
        if at_v < MIN_CLEARANCE {
            continue;
        }
        let mut trial = mesh.clone();
        let start = trial.positions.len() as u32;
        if remesh_corner(&mut trial, v, k).is_err() {
            continue;
        }
        let topo = Topology::new(trial.positions.len(), &trial.faces);
        let worst = (start..trial.positions.len() as u32)
            .filter_map(|w| corner_clearance(&trial, &topo, w))
            .fold(at_v, f64::min);
        if best.is_none_or(|b| worst > b.1) {
            best = Some((k, worst));
        }
        if worst >= TARGET_CLEARANCE {
            break;
        }
    }
    best.filter(|b| b.1 >= MIN_CLEARANCE)
}

/// Re-meshes every corner of `mesh` that has no above-face direction ([`corners_without_above`])
/// by Appendix C; `normals` (#V, unit) are kept for the input's vertices. `Ok(None)` when no
/// corner needs it.
///
/// # Errors
/// A corner whose spherical polygon does not reach [`TARGET_CLEARANCE`] in [`MAX_ROUNDS`]
/// rounds, a degenerate cut, or corners still failing after [`MAX_PASSES`] passes, each naming
/// the vertex and its line.
pub fn remesh_corners(mesh: &Mesh, normals: &[DVec3]) -> Result<Option<Remeshed>> {
    let mut failing = corners_without_above(mesh);
    if failing.is_empty() {
        return Ok(None);
    }
    let mut out = mesh.clone();
    let mut corners = Vec::new();
    for _ in 0..MAX_PASSES {
        if failing.is_empty() {
            break;
        }
        for &(v, before) in &failing {
            let line = out.vertex_lines.get(v as usize).copied().unwrap_or(0);
            let topo = Topology::new(out.positions.len(), &out.faces);
            let Some(fan) = topo.vertex_fan(v).filter(|f| f.closed) else {
                continue;
            };
            let (rounds, after) = best_rounds(&out, v, &fan).ok_or_else(|| {
                Error::Invalid(format!(
                    "vertex {v} (line {line}): no normal direction is above all its faces and \
                     {MAX_ROUNDS} rounds of Appendix C's corner smoothing do not make one \
                     (for the corner and the vertices it adds)"
                ))
            })?;
            let start = out.positions.len() as u32;
            let radius = remesh_corner(&mut out, v, rounds)?;
            corners.push(RemeshedCorner {
                vertex: v,
                rounds,
                clearance_before: before,
                clearance_after: after,
                radius,
                new_vertices: start..out.positions.len() as u32,
            });
        }
        failing = corners_without_above(&out);
    }
    if let Some(&(v, c)) = failing.first() {
        let line = out.vertex_lines.get(v as usize).copied().unwrap_or(0);
        return Err(Error::Invalid(format!(
            "vertex {v} (line {line}): no normal direction is above all its faces (best \
             clearance {c:.3e}) after {MAX_PASSES} passes of Appendix C's re-meshing"
        )));
    }
    let angle = crate::mesh::vertex_normals(&out, crate::mesh::NormalMethod::Angle)?;
    let mut all = normals.to_vec();
    all.extend_from_slice(&angle[normals.len()..]);
    Ok(Some(Remeshed {
        mesh: out,
        normals: all,
        corners,
    }))
}

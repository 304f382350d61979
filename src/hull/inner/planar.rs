//! Planar faces for the 1994 schemes: non-planar polygons are split into triangles before the
//! inner hull, without moving a vertex.
//!
//! The inner hull (Algorithm 1) takes every face as planar: one centroid, one normal, and
//! corners whose faces lie in those planes. A subdivision control cage (spot_control_cage: 168
//! of its 180 quads deviate by up to 0.34 of their size) is no polyhedron in that sense, and its
//! hull overlaps itself. Splitting each polygon that deviates from its plane by more than a
//! tolerance (relative to the face size, [`crate::mesh::geometry::planarity_deviation`]) into
//! triangles makes it one; the vertices, and so the points the surface interpolates, stay.
//!
//! Steep corners first: where the hull's vertex normals are known
//! ([`split_nonplanar_steep`]), a diagonal should not end at a corner whose normal stands almost
//! in the polygon's plane (cosine below [`STEEP_CORNER`]). There the polygon's pieces meeting at
//! the corner would give it several points of T a few degrees apart seen along its normal, and
//! the fan triangle between them stands edge-on (spot_control_cage's vertex 104: 68 overlapping
//! tetrahedra named it, none once its quads 85/175 are cut the other way). Triangulations with
//! fewer diagonal ends at steep corners win before the fold sense below. And at a folded
//! corner (its input normal below one of its polygons: Appendix C turns it, often nearly into a
//! polygon's plane) two triangles of the split meeting there that are nearly coplanar
//! ([`JOIN_ANGLE`]) are joined back into one quad, so the corner gets one point of T from them
//! (spot_control_cage's vertex 52 and its pentagon 36).
//!
//! Which diagonals: a non-planar polygon folds along whichever diagonals it is cut by, and the
//! fold's sense matters. A new edge that is reflex where the polyhedron round it is convex makes
//! a saddle that needs L-U pairs in T, and its two triangles tilt so that a corner's faces can
//! wrap round more than a hemisphere (no "above face" normal, Appendix C). So every
//! triangulation of the polygon is scored ([`triangulations`], all of them up to
//! [`MAX_ENUMERATED`] corners, else ear clipping): its triangles must be positively oriented
//! about the polygon's area normal (a proper triangulation in projection), and its diagonals
//! should fold the way the polygon's own edges fold against their neighbours (the sign of the
//! sum of their signed dihedral sines: convex where the polyhedron is locally convex). For a
//! quad, one diagonal folds convex and the other reflex; in a convex region the convex one is
//! taken. Last, corners that still have no above-face direction ([`super::remesh`]) get their
//! faces' triangulations changed where that gives every corner of the face a direction (or
//! improves the worst one), a few passes over the failing corners ([`REPAIR_PASSES`]).
//!
//! A polygon none of whose triangulations is proper overlaps itself in its mean plane (a
//! twisted sliver whose projection is a bow tie: spot_control_cage's quads 60 and 150 at the
//! horn bases). Any split of it folds the surface back on itself (a triangle facing the other
//! way, whose corners then have no above-face direction and which Appendix C's re-meshing
//! cannot repair either), so it is kept whole and listed ([`PlanarSplit::kept`]).

use super::above::{clearance, most_above, ABOVE_MARGIN};
use crate::mesh::geometry::{area_vector, face_size, planarity_deviation};
use crate::mesh::{ear_clip, Mesh, Topology};
use glam::DVec3;

/// Default of the scene key `scheme.planar_tolerance`: polygons deviating from their plane by
/// more than this share of their size are split. Above the rounding of OBJ files printed with
/// 6–7 significant digits (the planar polygons of double_torus_poly and mpi_poly deviate by up
/// to 4.7e-6 and 5.0e-6), below the smallest deviation of spot_control_cage's bent quads
/// (5.5e-5).
pub const DEFAULT_TOLERANCE: f64 = 1e-5;

/// Polygons with at most this many corners are triangulated by trying every triangulation
/// (Catalan(7) = 429 for 9 corners); larger ones are ear-clipped in their mean plane.
pub const MAX_ENUMERATED: usize = 9;

/// A corner of a bent polygon is steep when its vertex normal's cosine with the polygon's
/// normal is below this: the polygon stands almost edge-on to the corner's fan, and pieces
/// of it meeting at the corner crowd their points of T together as seen along the normal.
pub const STEEP_CORNER: f64 = 0.2;

/// Two triangles of one split polygon whose diagonal ends at a folded corner (its input normal
/// not above all its polygons: Appendix C will turn it, [`super::above`]) are joined back into
/// one quad, one point of T, when their normals differ by less than this many degrees. Such
/// a corner's turned normal can stand almost in the polygon's plane, where two nearly coplanar
/// pieces give it two points of T a few degrees apart seen along the normal and a fan triangle
/// edge-on between them (spot_control_cage's vertex 52: face 36's pieces, 1.3° apart, 8° apart
/// seen along n_V). The quad deviates from its plane by at most this fold, which the hull
/// takes as planar (its centroid and area normal). Measured on spot_control_cage (hull
/// violations, holes): 2° 400 / 34, 3° and 5° 358 / 40, 10° 410 / 42 (10 `EdgeNonconvex`), none
/// 442 / 34; joining at any corner instead of folded ones: 1° 378 (14 `EdgeNonconvex`).
pub const JOIN_ANGLE: f64 = 3.0;

/// Passes of the above-face repair over the corners that still fail.
pub const REPAIR_PASSES: usize = 3;

/// One polygon split by [`split_nonplanar`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SplitFace {
    /// The face (index in the mesh handed in).
    pub face: u32,
    /// Its 1-based file line (0 when not from a file).
    pub line: u32,
    /// Its deviation from its plane, relative to its size.
    pub deviation: f64,
    /// Triangles it was split into.
    pub triangles: usize,
    /// New edges (diagonals) that fold against the sense of the polygon's own edges (reflex
    /// in a convex region, or convex in a concave one); 0 for polygons of more than
    /// [`MAX_ENUMERATED`] corners, which are ear-clipped unscored.
    pub against: usize,
    /// Pairs of its triangles joined back into one quad at a folded corner ([`JOIN_ANGLE`]);
    /// the polygon then has `triangles − joined` pieces.
    pub joined: usize,
}

/// A mesh with its non-planar polygons split, and what was split.
#[derive(Clone, Debug)]
pub struct PlanarSplit {
    /// The new mesh: same vertices, planar polygons kept (in order), each split polygon
    /// replaced in place by its triangles. `face_parent` and `face_lines` of the triangles are
    /// their polygon's.
    pub mesh: Mesh,
    /// The split polygons, by face index.
    pub faces: Vec<SplitFace>,
    /// Non-trihedral corners of the split mesh still without an above-face direction (left to
    /// Appendix C's re-meshing, [`super::remesh`]).
    pub corners_without_above: Vec<u32>,
    /// Non-planar polygons left whole because no triangulation of them is proper (they
    /// overlap themselves in their mean plane: twisted slivers, bow ties).
    pub kept: Vec<u32>,
    /// Split polygons whose triangulation the above-face repair changed from the best-scored
    /// one.
    pub repaired: usize,
    /// For every split polygon (as in `faces`), how many ranked triangulations it has: the
    /// range of [`Forced::triangulation`].
    pub candidates: Vec<usize>,
    /// For every split polygon (as in `faces`), the index of the triangulation taken (forced,
    /// or else the ranked choice after the above-face repair).
    pub chosen: Vec<usize>,
    /// For every split polygon (as in `faces`), whether its nearly coplanar pairs at folded
    /// corners were allowed to join ([`Forced::join`]; true unless forced off).
    pub join: Vec<bool>,
    /// For every split polygon (as in `faces`) and each of its ranked triangulations, whether
    /// joining ([`Forced::join`]) would join any pair (else both settings give one split).
    pub joinable: Vec<Vec<bool>>,
}

/// A split forced on one bent polygon instead of the ranked choice (see
/// [`super::retriangulate`], which picks these by the hull's own verification).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Forced {
    /// Index into the polygon's triangulations ranked as [`split_nonplanar_steep`] ranks them
    /// (best first).
    pub triangulation: usize,
    /// Whether nearly coplanar pairs meeting at a folded corner are joined back
    /// ([`JOIN_ANGLE`]).
    pub join: bool,
}

/// All triangulations of a convex-position polygon with corners `0..n` by diagonals, each as a
/// list of `n − 2` triangles (local corner indices, in the polygon's orientation). Catalan(n − 2)
/// of them; call only for small n.
#[must_use]
pub fn triangulations(n: usize) -> Vec<Vec<[usize; 3]>> {
    fn rec(idx: &[usize]) -> Vec<Vec<[usize; 3]>> {
        let m = idx.len();
        if m < 3 {
            return vec![Vec::new()];
        }
        let mut out = Vec::new();
        for k in 1..m - 1 {
            let left = rec(&idx[..=k]);
            let right = rec(&idx[k..]);
            for l in &left {
                for r in &right {
                    let mut t = Vec::with_capacity(m - 2);
                    t.push([idx[0], idx[k], idx[m - 1]]);
                    t.extend_from_slice(l);
                    t.extend_from_slice(r);
                    out.push(t);
                }
            }
        }
        out
    }
    let idx: Vec<usize> = (0..n).collect();
    rec(&idx)
}

/// Signed sine of the fold between two faces with unit outward normals `n1`, `n2` along the
/// unit edge direction `e` (oriented as in the first face): positive for a convex fold (as
/// seen from outside), negative for a reflex one.
fn fold(n1: DVec3, n2: DVec3, e: DVec3) -> f64 {
    n1.cross(n2).dot(e)
}

/// The sense the polygon `f`'s diagonals should fold: +1 (convex) or −1 (reflex), the sign of
/// the sum of the signed fold sines of its edges against their neighbouring faces (+1 when it
/// has none).
fn wanted_sense(mesh: &Mesh, topo: &Topology, f: usize) -> f64 {
    let face = &mesh.faces[f];
    let nf = area_vector(&mesh.positions, face).normalize_or_zero();
    let start = topo.face_start[f] as usize;
    let mut sum = 0.0;
    for k in 0..face.len() {
        let mate = topo.corner_mate[start + k];
        if mate == u32::MAX {
            continue;
        }
        let g = topo.corner_face[mate as usize] as usize;
        let ng = area_vector(&mesh.positions, &mesh.faces[g]).normalize_or_zero();
        let (a, b) = (face[k], face[(k + 1) % face.len()]);
        let e = (mesh.positions[b as usize] - mesh.positions[a as usize]).normalize_or_zero();
        sum += fold(nf, ng, e);
    }
    if sum >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// A candidate triangulation of one polygon, with its score (smaller is better).
#[derive(Clone, Debug)]
struct Candidate {
    /// Triangles as global vertex indices.
    triangles: Vec<[u32; 3]>,
    /// Diagonals folding against the wanted sense.
    against: usize,
    /// Sum of the fold sines against the wanted sense (≥ 0).
    against_sum: f64,
    /// Smallest positive projected area share (n_t · N / |n_t|) of its triangles: larger is
    /// better shaped.
    min_upright: f64,
    /// Diagonal ends at steep corners ([`STEEP_CORNER`]).
    steep: usize,
}

/// The valid triangulations of polygon `face` (global vertex indices), best first by the
/// score of the module documentation. Triangles must be oriented like the polygon about its
/// area normal (n_t · N > 1e-9 |n_t|, and area above 1e-12 of the size squared: no folded or
/// needle triangles). Empty when none is (then the caller ear-clips).
fn candidates(
    positions: &[DVec3],
    face: &[u32],
    sense: f64,
    normals: Option<&[DVec3]>,
) -> Vec<Candidate> {
    let n = face.len();
    let normal = area_vector(positions, face).normalize_or_zero();
    // Corners whose vertex normal stands almost in the polygon's plane.
    let steep: Vec<bool> = face
        .iter()
        .map(|&v| normals.is_some_and(|ns| ns[v as usize].dot(normal) < STEEP_CORNER))
        .collect();
    let size = face_size(positions, face);
    let p = |i: usize| positions[face[i] as usize];
    let mut out = Vec::new();
    'next: for tri in triangulations(n) {
        let mut normals = Vec::with_capacity(tri.len());
        let mut min_upright = f64::INFINITY;
        for t in &tri {
            let a = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            let len = a.length();
            if len.is_nan() || len <= 1e-12 * size * size {
                continue 'next;
            }
            let up = a.dot(normal) / len;
            if up <= 1e-9 {
                continue 'next;
            }
            min_upright = min_upright.min(up);
            normals.push(a / len);
        }
        // Diagonals: pairs of triangles sharing two corners.
        let (mut against, mut against_sum, mut steep_ends) = (0, 0.0, 0);
        for i in 0..tri.len() {
            for j in i + 1..tri.len() {
                for k in 0..3 {
                    let (a, b) = (tri[i][k], tri[i][(k + 1) % 3]);
                    let shared = (0..3).any(|l| tri[j][l] == b && tri[j][(l + 1) % 3] == a);
                    if shared {
                        steep_ends += usize::from(steep[a]) + usize::from(steep[b]);
                        let e = (p(b) - p(a)).normalize_or_zero();
                        let s = sense * fold(normals[i], normals[j], e);
                        if s < 0.0 {
                            against += 1;
                            against_sum -= s;
                        }
                    }
                }
            }
        }
        out.push(Candidate {
            triangles: tri.iter().map(|t| t.map(|i| face[i])).collect(),
            against,
            against_sum,
            min_upright,
            steep: steep_ends,
        });
    }
    out.sort_by(|x, y| {
        x.steep
            .cmp(&y.steep)
            .then(x.against.cmp(&y.against))
            .then(x.against_sum.total_cmp(&y.against_sum))
            .then(y.min_upright.total_cmp(&x.min_upright))
    });
    out
}

/// The faces round every vertex, for clearances under changing triangulations.
struct Around {
    /// For every vertex, the unit normals of the faces holding it that are not split.
    fixed: Vec<Vec<DVec3>>,
    /// For every vertex, the bent polygons (indices into `bent`) that hold it.
    bent: Vec<Vec<usize>>,
}

impl Around {
    fn new(mesh: &Mesh, bent: &[(usize, f64)]) -> Around {
        let n = mesh.positions.len();
        let (mut fixed, mut by) = (vec![Vec::new(); n], vec![Vec::new(); n]);
        let mut k = 0;
        for (f, face) in mesh.faces.iter().enumerate() {
            if k < bent.len() && bent[k].0 == f {
                for &v in face {
                    by[v as usize].push(k);
                }
                k += 1;
            } else {
                let nf = area_vector(&mesh.positions, face).normalize_or_zero();
                for &v in face {
                    fixed[v as usize].push(nf);
                }
            }
        }
        Around { fixed, bent: by }
    }

    /// Best clearance of vertex `v` (min over its faces of n · n_f for the most-above n) with
    /// the triangulations `choice` of the bent polygons: its other faces as they are, and from
    /// each bent polygon the chosen triangles that hold `v`. `None` for trihedral or unused
    /// vertices (Algorithm 1 step (3) needs no above-face normal).
    fn clearance(
        &self,
        mesh: &Mesh,
        options: &[Vec<Candidate>],
        choice: &[usize],
        v: usize,
    ) -> Option<f64> {
        let mut normals = self.fixed[v].clone();
        for &k in &self.bent[v] {
            for t in &options[k][choice[k]].triangles {
                if t.contains(&(v as u32)) {
                    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                    normals.push((b - a).cross(c - a).normalize_or_zero());
                }
            }
        }
        (!normals.is_empty() && normals.len() != 3)
            .then(|| clearance(most_above(&normals), &normals))
    }
}

/// The triangulation chosen for every bent polygon.
struct Choice {
    /// Index into each bent polygon's candidates.
    choice: Vec<usize>,
    /// Polygons whose choice the repair changed.
    repaired: usize,
}

/// The above-face repair of the module documentation: starting from every bent polygon's
/// best-scored triangulation, each corner without an above-face direction tries the other
/// triangulations of its bent polygons, keeping one when fewer of that polygon's corners fail
/// (or, as many failing, the worst clearance among them rises). [`REPAIR_PASSES`] passes.
fn repair_above_face(
    mesh: &Mesh,
    bent: &[(usize, f64)],
    options: &[Vec<Candidate>],
    around: &Around,
) -> Choice {
    let mut choice = vec![0usize; bent.len()];
    let original = choice.clone();
    // Only corners of bent polygons change; the others keep their clearance.
    let corners: Vec<usize> = (0..mesh.positions.len())
        .filter(|&v| !around.bent[v].is_empty())
        .collect();
    for _ in 0..REPAIR_PASSES {
        let failing: Vec<usize> = corners
            .iter()
            .copied()
            .filter(|&v| {
                around
                    .clearance(mesh, options, &choice, v)
                    .is_some_and(|c| c < ABOVE_MARGIN)
            })
            .collect();
        let mut changed = false;
        for v in failing {
            for &k in &around.bent[v] {
                if options[k].len() < 2 {
                    continue;
                }
                let verts = &mesh.faces[bent[k].0];
                let score = |choice: &[usize]| {
                    let mut bad = 0usize;
                    let mut worst = f64::INFINITY;
                    for &w in verts {
                        if let Some(c) = around.clearance(mesh, options, choice, w as usize) {
                            bad += usize::from(c < ABOVE_MARGIN);
                            worst = worst.min(c);
                        }
                    }
                    (bad, worst)
                };
                let mut best = (score(&choice), choice[k]);
                for alt in 0..options[k].len() {
                    if alt == choice[k] {
                        continue;
                    }
                    let mut trial = choice.clone();
                    trial[k] = alt;
                    let sc = score(&trial);
                    if sc.0 < best.0 .0 || (sc.0 == best.0 .0 && sc.1 > best.0 .1) {
                        best = (sc, alt);
                    }
                }
                if best.1 != choice[k] {
                    choice[k] = best.1;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let repaired = choice.iter().zip(&original).filter(|(a, b)| a != b).count();
    Choice { choice, repaired }
}

/// The pieces of one split polygon: its triangles `tris`, with edge-adjacent pairs whose
/// diagonal ends at a folded corner (`folded`) and whose normals differ by less than
/// [`JOIN_ANGLE`] made one quad again (greedy in triangle order, each triangle once).
fn join_flat_pairs(positions: &[DVec3], tris: &[[u32; 3]], folded: &[bool]) -> Vec<Vec<u32>> {
    let cos = JOIN_ANGLE.to_radians().cos();
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut used = vec![false; tris.len()];
    let mut out = Vec::new();
    for i in 0..tris.len() {
        if used[i] {
            continue;
        }
        let mut joined = None;
        {
            'search: for j in i + 1..tris.len() {
                if used[j] || normal(&tris[i]).dot(normal(&tris[j])) < cos {
                    continue;
                }
                for k in 0..3 {
                    let (a, b) = (tris[i][k], tris[i][(k + 1) % 3]);
                    for l in 0..3 {
                        if tris[j][l] == b
                            && tris[j][(l + 1) % 3] == a
                            && (folded[a as usize] || folded[b as usize])
                        {
                            let opp = tris[j][(l + 2) % 3];
                            joined = Some((j, vec![a, opp, b, tris[i][(k + 2) % 3]]));
                            break 'search;
                        }
                    }
                }
            }
        }
        match joined {
            Some((j, q)) => {
                used[j] = true;
                out.push(q);
            }
            None => out.push(tris[i].to_vec()),
        }
    }
    out
}

/// Splits every polygon of `mesh` that deviates from its plane by more than `tolerance`
/// (relative to its size) into triangles, as the module documentation describes. `None` when
/// no polygon deviates (the mesh is used as it is). Zero-area polygons are left alone (the
/// hull names them).
#[must_use]
pub fn split_nonplanar(mesh: &Mesh, tolerance: f64) -> Option<PlanarSplit> {
    split_nonplanar_steep(mesh, tolerance, None)
}

/// [`split_nonplanar`] with the vertex normals: diagonals avoid steep corners (vertex normal
/// within [`STEEP_CORNER`] of the polygon's plane) before anything else, so that such a
/// corner sees one piece of the polygon (one point of T) rather than several crowded ones.
#[must_use]
pub fn split_nonplanar_steep(
    mesh: &Mesh,
    tolerance: f64,
    normals: Option<&[DVec3]>,
) -> Option<PlanarSplit> {
    split_nonplanar_forced(mesh, tolerance, normals, &[])
}

/// [`split_nonplanar_steep`] with the splits of some polygons forced: `forced` lists (face of
/// `mesh`, split); a triangulation index beyond the polygon's candidates, or a face that is not
/// split, is ignored. The above-face repair runs before the forced choices replace its own.
#[must_use]
pub fn split_nonplanar_forced(
    mesh: &Mesh,
    tolerance: f64,
    normals: Option<&[DVec3]>,
    forced: &[(u32, Forced)],
) -> Option<PlanarSplit> {
    let bent: Vec<(usize, f64)> = mesh
        .faces
        .iter()
        .enumerate()
        .filter(|(_, f)| f.len() > 3)
        .filter_map(|(i, f)| {
            let d = planarity_deviation(&mesh.positions, f)?;
            (d > tolerance).then_some((i, d))
        })
        .collect();
    if bent.is_empty() {
        return None;
    }
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    // Per bent face: its candidates (best first) and the one chosen.
    let mut options: Vec<Vec<Candidate>> = Vec::with_capacity(bent.len());
    let mut kept = Vec::new();
    for &(f, _) in &bent {
        let face = &mesh.faces[f];
        let c = if face.len() <= MAX_ENUMERATED {
            candidates(&mesh.positions, face, wanted_sense(mesh, &topo, f), normals)
        } else {
            Vec::new()
        };
        let c = if !c.is_empty() {
            c
        } else if face.len() > MAX_ENUMERATED {
            let mut out = Vec::new();
            ear_clip(&mesh.positions, face, &mut Vec::new(), &mut out);
            vec![Candidate {
                triangles: out.iter().map(|t| [t[0], t[1], t[2]]).collect(),
                against: 0,
                against_sum: 0.0,
                min_upright: 0.0,
                steep: 0,
            }]
        } else {
            // No triangulation is proper: the polygon overlaps itself in its mean plane (a
            // twisted sliver, a bow tie). Splitting it would fold the surface back on itself;
            // it is kept whole and listed.
            kept.push(f as u32);
            Vec::new()
        };
        options.push(c);
    }
    let bent: Vec<(usize, f64)> = bent
        .into_iter()
        .zip(&options)
        .filter(|(_, c)| !c.is_empty())
        .map(|(b, _)| b)
        .collect();
    options.retain(|c| !c.is_empty());
    let around = Around::new(mesh, &bent);
    let chosen = repair_above_face(mesh, &bent, &options, &around);
    let repaired = chosen.repaired;
    let mut chosen = chosen.choice;
    let mut join = vec![true; bent.len()];
    for &(face, f) in forced {
        if let Some(k) = bent.iter().position(|&(b, _)| b == face as usize) {
            if f.triangulation < options[k].len() {
                chosen[k] = f.triangulation;
                join[k] = f.join;
            }
        }
    }
    let corners_without_above = (0..mesh.positions.len())
        .filter(|&v| {
            around
                .clearance(mesh, &options, &chosen, v)
                .is_some_and(|c| c < ABOVE_MARGIN)
        })
        .map(|v| v as u32)
        .collect();
    // Corners whose input normal is not above all their polygons (Appendix C will turn it).
    let folded: Vec<bool> = match normals {
        None => vec![false; mesh.positions.len()],
        Some(ns) => {
            let mut faces: Vec<Vec<DVec3>> = vec![Vec::new(); mesh.positions.len()];
            for face in &mesh.faces {
                let nf = area_vector(&mesh.positions, face).normalize_or_zero();
                for &v in face {
                    faces[v as usize].push(nf);
                }
            }
            ns.iter()
                .zip(&faces)
                .map(|(&n, fs)| fs.len() > 3 && clearance(n, fs) < ABOVE_MARGIN)
                .collect()
        }
    };
    let joinable: Vec<Vec<bool>> = options
        .iter()
        .map(|o| {
            o.iter()
                .map(|c| {
                    join_flat_pairs(&mesh.positions, &c.triangles, &folded).len()
                        < c.triangles.len()
                })
                .collect()
        })
        .collect();
    // Rebuild the mesh with lines and parents.
    let count = mesh.faces.len() + bent.len();
    let mut out = Mesh {
        positions: mesh.positions.clone(),
        faces: Vec::with_capacity(count),
        file_normals: mesh.file_normals.clone(),
        vertex_lines: mesh.vertex_lines.clone(),
        face_lines: Vec::with_capacity(count),
        face_parent: Vec::with_capacity(count),
    };
    let mut report = Vec::with_capacity(bent.len());
    let mut slot = 0;
    for (f, face) in mesh.faces.iter().enumerate() {
        let pieces: Vec<Vec<u32>> = if slot < bent.len() && bent[slot].0 == f {
            let c = &options[slot][chosen[slot]];
            let pieces = if join[slot] {
                join_flat_pairs(&mesh.positions, &c.triangles, &folded)
            } else {
                c.triangles.iter().map(|t| t.to_vec()).collect()
            };
            report.push(SplitFace {
                face: f as u32,
                line: mesh.face_lines.get(f).copied().unwrap_or(0),
                deviation: bent[slot].1,
                triangles: c.triangles.len(),
                against: c.against,
                joined: c.triangles.len() - pieces.len(),
            });
            slot += 1;
            pieces
        } else {
            vec![face.clone()]
        };
        for p in pieces {
            out.faces.push(p);
            out.face_lines
                .push(mesh.face_lines.get(f).copied().unwrap_or(0));
            out.face_parent
                .push(mesh.face_parent.get(f).copied().unwrap_or(f as u32));
        }
    }
    Some(PlanarSplit {
        mesh: out,
        faces: report,
        corners_without_above,
        kept,
        repaired,
        candidates: options.iter().map(Vec::len).collect(),
        chosen,
        join,
        joinable,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catalan numbers: 1, 2, 5, 14, 42 triangulations of 3…7 corners, each with n − 2
    /// triangles, all distinct.
    #[test]
    fn triangulation_counts_are_catalan() {
        for (n, c) in [(3, 1), (4, 2), (5, 5), (6, 14), (7, 42)] {
            let t = triangulations(n);
            assert_eq!(t.len(), c, "n = {n}");
            assert!(t.iter().all(|x| x.len() == n - 2));
            let mut sorted: Vec<Vec<[usize; 3]>> = t
                .iter()
                .map(|x| {
                    let mut y = x.clone();
                    y.sort_unstable();
                    y
                })
                .collect();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), c);
        }
    }

    /// Unit box whose top quad has its corners 0 and 2 raised (the fold along 0–2 is convex),
    /// the top polygon listed from corner `rot`.
    fn roof_box(rot: usize) -> Mesh {
        let mut positions = vec![
            DVec3::new(0.0, 0.0, 1.3),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 1.0, 1.3),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        positions.extend(positions.clone().iter().map(|p| DVec3::new(p.x, p.y, 0.0)));
        let top: Vec<u32> = (0..4).map(|k| ((k + rot) % 4) as u32).collect();
        let faces = vec![
            top,
            vec![4, 7, 6, 5],
            vec![0, 4, 5, 1],
            vec![1, 5, 6, 2],
            vec![2, 6, 7, 3],
            vec![3, 7, 4, 0],
        ];
        Mesh::new(positions, faces)
    }

    /// A quad bent along one diagonal: the convex diagonal is chosen when its neighbours are
    /// convex (a roof over a box), whichever vertex the quad starts at.
    #[test]
    fn bent_quad_takes_the_convex_diagonal() {
        for rot in 0..4 {
            let m = roof_box(rot);
            let s = split_nonplanar(&m, DEFAULT_TOLERANCE).unwrap();
            // Only the top is bent (the sides are trapezoids in vertical planes).
            assert_eq!(s.faces.len(), 1);
            let tris: Vec<&Vec<u32>> = s.mesh.faces.iter().filter(|f| f.len() == 3).collect();
            assert_eq!(tris.len(), 2);
            assert!(
                tris.iter().all(|t| t.contains(&0) && t.contains(&2)),
                "{tris:?}"
            );
            assert_eq!(s.faces[0].against, 0);
        }
    }

    /// The roof of `bent_quad_takes_the_convex_diagonal`, but corner 0's vertex normal lies
    /// almost in the roof's plane (cosine 0.1 < [`STEEP_CORNER`]): the diagonal 1–3, which
    /// does not end at that corner, is taken although it folds reflex; with normals that
    /// face the roof (cosine ≈ 1) the convex diagonal 0–2 stays.
    #[test]
    fn steep_corner_is_no_diagonal_end() {
        let m = roof_box(0);
        let roof = area_vector(&m.positions, &m.faces[0]).normalize();
        let diagonal = |normals: &[DVec3]| {
            let s = split_nonplanar_steep(&m, DEFAULT_TOLERANCE, Some(normals)).unwrap();
            let tris: Vec<Vec<u32>> = s.mesh.faces.into_iter().filter(|f| f.len() == 3).collect();
            assert_eq!(tris.len(), 2);
            // The two corners both triangles hold.
            let mut shared: Vec<u32> = tris[0]
                .iter()
                .copied()
                .filter(|v| tris[1].contains(v))
                .collect();
            shared.sort_unstable();
            shared
        };
        let mut normals = vec![roof; 8];
        assert_eq!(diagonal(&normals), vec![0, 2]);
        // A unit normal whose cosine with the roof's normal is 0.1.
        let side = roof.any_orthonormal_vector();
        normals[0] = 0.1 * roof + (1.0f64 - 0.01).sqrt() * side;
        assert!((normals[0].dot(roof) - 0.1).abs() < 1e-12);
        assert_eq!(diagonal(&normals), vec![1, 3]);
    }
}

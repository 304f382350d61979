//! Cleaning modelling slop into a polyhedron the 1994 inner hull can cut (opt-in repair, scene
//! key `model.clean`).
//!
//! Why: [`super::weld`] removes strips of faces whose two sides were meant to be one edge, which
//! is all the 2001 scheme needs (it triangulates and interpolates). The 1994 schemes cut the
//! polyhedron's corners face by face and need what welding alone leaves broken. mpi_poly.obj
//! has *needles*: a face running 3–4 units along a neighbouring face's plane at a width of
//! 0.002–0.02 (a corner of 0.1°), whose tip is a vertex between two faces lying in one plane.
//! The inner hull puts a corner guard inside every such needle, on the neighbour's plane, and
//! the tetrahedra there cannot satisfy Definition 3.6 (the pending scene's last violations).
//!
//! What, in order (`tolerance` = `relative` × the bounding-box diagonal):
//! 1. weld vertices closer than the tolerance ([`super::weld`]);
//! 2. split every face edge at the vertices lying within the tolerance of its interior
//!    (T-junctions: a needle's side runs along the neighbour's edge);
//! 3. remove repeated corners and antennas (a boundary running x → y → x), which the splits
//!    leave where a needle collapsed;
//! 4. at every vertex left with only two faces: merge the two faces when they are coplanar
//!    (normals within [`COPLANAR_COS`]; the needle's tip lay between two pieces of one plane),
//!    or drop the vertex from both when their shared chain runs straight through it (within
//!    the tolerance); anything else is an error naming the vertex;
//! 5. planarise: welding bent the faces by up to the tolerance, and the inner hull takes every
//!    face as planar. Alternate fitting each face's plane (Newell normal through the corners'
//!    mean) and moving each vertex to the least-squares point of its faces' planes, anchored to
//!    its welded position (a small weight, so that a direction the planes leave free does not
//!    drift), the anchor released for the last rounds (nearly coplanar neighbours that could
//!    not be merged share one plane); stop when every corner lies within
//!    [`PLANAR_GOAL`] × the diagonal of its face's plane.
//!
//! The result goes through [`super::from_polygons`] (orientation, validation); the inner hull
//! then checks that it is a closed manifold.

use super::geometry::bbox_diagonal;
use super::topology::{directed_edge_faces, UnionFind};
use super::{from_polygons, weld, Mesh, Report};
use crate::error::{Error, Result};
use glam::{DMat3, DVec3};
use std::collections::{BTreeMap, HashMap};

/// Two faces round a two-face vertex are merged when their unit normals' dot product exceeds
/// this (8°: a needle's tip lies between two pieces of one plane, up to the weld's slop).
pub const COPLANAR_COS: f64 = 0.99;

/// Largest `model.clean_coplanar` angle, degrees: above it a modelled crease could be taken
/// for slop.
pub const MAX_COPLANAR_ANGLE: f64 = 5.0;

/// What [`clean_with`] does beyond the tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CleanOptions {
    /// The tolerance, relative to the bounding-box diagonal (`model.clean`).
    pub relative: f64,
    /// Edge-adjacent faces meeting at less than this many degrees are merged into one polygon
    /// (or, where their union is not one loop, planarised onto one plane): modelling slop, not
    /// a modelled crease (`model.clean_coplanar`; 0 = off). mpi_poly.obj has 16 such pairs at
    /// 0.09°–0.16° (its next angle is above 5°); kept apart, each is a nearly flat crease of T
    /// between two flat nets, across which the quintic bends.
    pub coplanar_angle: f64,
}

/// The planarisation stops when every corner lies this close (× the bounding-box diagonal) to
/// its face's plane: well under `verify`'s edge-convexity tolerance (1e-9 relative), so nearly
/// flat edges of T do not read as folds.
pub const PLANAR_GOAL: f64 = 1e-13;

/// Rounds of the planarisation (half anchored, half nearly free).
pub const PLANAR_ROUNDS: usize = 600;

/// What [`clean`] changed.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct CleanReport {
    /// Vertices moved onto another by the weld.
    pub welded: usize,
    /// Corners inserted into face edges at T-junctions.
    pub t_junctions: usize,
    /// Pairs of coplanar faces merged at a two-face vertex.
    pub merged_faces: usize,
    /// Two-face vertices dropped from a straight chain.
    pub dropped_vertices: usize,
    /// Pairs of nearly coplanar faces merged (`model.clean_coplanar`).
    pub coplanar_merged: usize,
    /// Largest distance a vertex moved from the file's position (weld and planarisation).
    pub max_move: f64,
    /// Largest distance of a corner from its face's plane after the planarisation, relative
    /// to the bounding-box diagonal.
    pub planarity: f64,
}

/// Cleans `mesh` (module docs) at `relative` × its bounding-box diagonal. Returns the cleaned
/// mesh, its validation report and what changed.
///
/// # Errors
/// A tolerance out of range (as [`super::weld`]), a two-face vertex whose faces are neither
/// coplanar nor straight through it, or a result [`from_polygons`] rejects.
pub fn clean(mesh: &Mesh, relative: f64) -> Result<(Mesh, Report, CleanReport)> {
    clean_with(
        mesh,
        CleanOptions {
            relative,
            coplanar_angle: 0.0,
        },
    )
}

/// [`clean`] with nearly coplanar faces merged too ([`CleanOptions::coplanar_angle`]).
///
/// # Errors
/// As [`clean`].
pub fn clean_with(mesh: &Mesh, options: CleanOptions) -> Result<(Mesh, Report, CleanReport)> {
    let relative = options.relative;
    let (welded, _, moved) = weld(mesh, relative)?;
    let mut report = CleanReport {
        welded: moved,
        ..CleanReport::default()
    };
    let diag = bbox_diagonal(&welded.positions);
    let tol = relative * diag;
    let pos = welded.positions.clone();
    let mut faces: Vec<Vec<u32>> = welded.faces.clone();
    if tol > 0.0 {
        report.t_junctions = split_t_junctions(&pos, &mut faces, tol);
    }
    faces = faces
        .iter()
        .map(|f| collapse(f))
        .filter(|f| f.len() >= 3)
        .collect();
    two_face_vertices(&pos, &mut faces, tol, &mut report)?;
    let cos = (options.coplanar_angle > 0.0).then(|| options.coplanar_angle.to_radians().cos());
    if let Some(cos) = cos {
        report.coplanar_merged = merge_near_coplanar(&pos, &mut faces, cos);
        if report.coplanar_merged > 0 {
            two_face_vertices(&pos, &mut faces, tol, &mut report)?;
        }
    }
    let planar = planarise(&pos, &faces, diag, cos);
    report.planarity =
        max_deviation(&planar, &faces, &planes(&planar, &faces)) / diag.max(f64::MIN_POSITIVE);
    // The weld keeps each cluster's first position; measure the moves against the file.
    let (cleaned, validation) = from_polygons(planar, faces)?;
    let mut file = mesh.positions.clone();
    file.sort_by(|a, b| a.x.total_cmp(&b.x));
    report.max_move = cleaned
        .positions
        .iter()
        .map(|&p| nearest_distance(&file, p))
        .fold(0.0, f64::max);
    Ok((cleaned, validation, report))
}

/// The distance from `p` to the nearest of `sorted` (ordered by x; ∞ when empty): scans
/// outwards from p's x until the x gap alone exceeds the best distance found.
fn nearest_distance(sorted: &[DVec3], p: DVec3) -> f64 {
    let at = sorted.partition_point(|q| q.x < p.x);
    let mut best = f64::INFINITY;
    for q in &sorted[at..] {
        if q.x - p.x >= best {
            break;
        }
        best = best.min(q.distance(p));
    }
    for q in sorted[..at].iter().rev() {
        if p.x - q.x >= best {
            break;
        }
        best = best.min(q.distance(p));
    }
    best
}

/// `face` without cyclically repeated corners and antennas (x, y, x: the corners y and the
/// second x go).
#[must_use]
pub fn collapse(face: &[u32]) -> Vec<u32> {
    let mut f = face.to_vec();
    loop {
        let n = f.len();
        if n < 3 {
            return f;
        }
        if let Some(k) = (0..n).find(|&k| f[k] == f[(k + 1) % n]) {
            f.remove(k);
            continue;
        }
        if let Some(k) = (0..n).find(|&k| f[k] == f[(k + 2) % n]) {
            let (a, b) = ((k + 1) % n, (k + 2) % n);
            f.remove(a.max(b));
            f.remove(a.min(b));
            continue;
        }
        return f;
    }
}

/// Inserts into every face edge the used vertices within `tol` of its interior (ordered along
/// the edge). Returns how many corners were inserted.
fn split_t_junctions(pos: &[DVec3], faces: &mut [Vec<u32>], tol: f64) -> usize {
    let mut used: Vec<u32> = faces.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    // Vertices sorted by x, so an edge scans only its x-range.
    used.sort_by(|&a, &b| pos[a as usize].x.total_cmp(&pos[b as usize].x));
    let xs: Vec<f64> = used.iter().map(|&v| pos[v as usize].x).collect();
    let mut inserted = 0;
    for face in faces.iter_mut() {
        let n = face.len();
        let mut out = Vec::with_capacity(n);
        for k in 0..n {
            let (a, b) = (face[k], face[(k + 1) % n]);
            out.push(a);
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            let d = pb - pa;
            let len2 = d.length_squared();
            if len2 == 0.0 {
                continue;
            }
            let lo = xs.partition_point(|&x| x < pa.x.min(pb.x) - tol);
            let hi = xs.partition_point(|&x| x <= pa.x.max(pb.x) + tol);
            let mut on: Vec<(f64, u32)> = used[lo..hi]
                .iter()
                .filter(|&&v| v != a && v != b)
                .filter_map(|&v| {
                    let p = pos[v as usize];
                    let t = (p - pa).dot(d) / len2;
                    let inside = t > 0.0 && t < 1.0 && (pa + t * d).distance(p) < tol;
                    inside.then_some((t, v))
                })
                .collect();
            on.sort_by(|x, y| x.0.total_cmp(&y.0));
            inserted += on.len();
            out.extend(on.into_iter().map(|(_, v)| v));
        }
        *face = out;
    }
    inserted
}

/// Newell's area vector summed about the origin (twice the area vector). Not
/// [`super::geometry::area_vector`] (summed about the first corner): the two differ in
/// rounding only, but the planarised positions, and with them mpi_poly's hull, depend on it
/// (with that one mpi_poly's check fails on holes and j-sheets: measured).
fn area_vector(pos: &[DVec3], face: &[u32]) -> DVec3 {
    let n = face.len();
    (0..n)
        .map(|k| pos[face[k] as usize].cross(pos[face[(k + 1) % n] as usize]))
        .sum::<DVec3>()
}

/// Step 4 of the module docs: merges coplanar face pairs at two-face vertices and drops
/// two-face vertices on straight chains, until none is left.
fn two_face_vertices(
    pos: &[DVec3],
    faces: &mut Vec<Vec<u32>>,
    tol: f64,
    report: &mut CleanReport,
) -> Result<()> {
    loop {
        let mut of_vertex: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                of_vertex.entry(v).or_default().push(f);
            }
        }
        // Each list is ascending (faces in order), so repeats are adjacent.
        let distinct = |fs: &[usize]| 1 + fs.windows(2).filter(|w| w[0] != w[1]).count();
        let Some((&v, fs)) = of_vertex.iter().find(|(_, fs)| distinct(fs) <= 2) else {
            return Ok(());
        };
        let (f, g) = (fs[0], fs[fs.len() - 1]);
        let nf = area_vector(pos, &faces[f]).normalize_or_zero();
        let ng = area_vector(pos, &faces[g]).normalize_or_zero();
        if f != g && nf.dot(ng) > COPLANAR_COS {
            let merged = merge_faces(&faces[f], &faces[g]).ok_or_else(|| {
                Error::Invalid(format!(
                    "model.clean: vertex {v} lies between faces {f} and {g} only, and their \
                     union is not one polygon"
                ))
            })?;
            faces[f] = collapse(&merged);
            faces.remove(g);
            report.merged_faces += 1;
            continue;
        }
        // Straight through v: its neighbours in the first face, v within tol of their chord.
        let face = &faces[f];
        let k = face.iter().position(|&x| x == v).unwrap_or(0);
        let n = face.len();
        let (p, q) = (face[(k + n - 1) % n], face[(k + 1) % n]);
        let (pp, pq, pv) = (pos[p as usize], pos[q as usize], pos[v as usize]);
        let d = pq - pp;
        let t = ((pv - pp).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        if (pp + t * d).distance(pv) >= tol {
            return Err(Error::Invalid(format!(
                "model.clean: vertex {v} lies between faces {f} and {g} only (cosine {:.3} of \
                 their normals), which are not coplanar and do not run straight through it",
                nf.dot(ng)
            )));
        }
        for &h in &[f, g] {
            faces[h].retain(|&x| x != v);
        }
        report.dropped_vertices += 1;
    }
}

/// Merges edge-adjacent faces whose normals' dot product exceeds `cos` into one polygon, pair
/// by pair, where their union is one loop (pairs whose union is not stay apart and are
/// planarised onto one plane instead, [`plane_groups`]). Returns how many merged.
fn merge_near_coplanar(pos: &[DVec3], faces: &mut Vec<Vec<u32>>, cos: f64) -> usize {
    let mut merged = 0;
    let mut refused: std::collections::HashSet<(Vec<u32>, Vec<u32>)> = Default::default();
    'search: loop {
        let of_edge = directed_edge_faces(faces);
        for f in 0..faces.len() {
            let nf = area_vector(pos, &faces[f]).normalize_or_zero();
            for k in 0..faces[f].len() {
                let n = faces[f].len();
                let Some(&g) = of_edge.get(&(faces[f][(k + 1) % n], faces[f][k])) else {
                    continue;
                };
                if g <= f {
                    continue;
                }
                let ng = area_vector(pos, &faces[g]).normalize_or_zero();
                if nf.dot(ng) <= cos {
                    continue;
                }
                let key = (faces[f].clone(), faces[g].clone());
                if refused.contains(&key) {
                    continue;
                }
                match merge_faces(&faces[f], &faces[g]).map(|m| collapse(&m)) {
                    Some(m) if m.len() >= 3 => {
                        faces[f] = m;
                        faces.remove(g);
                        merged += 1;
                        continue 'search;
                    }
                    _ => {
                        refused.insert(key);
                    }
                }
            }
        }
        return merged;
    }
}

/// The union of two polygons sharing a chain of edges (the shared edges removed), when it is
/// one loop.
fn merge_faces(f: &[u32], g: &[u32]) -> Option<Vec<u32>> {
    let edges = |face: &[u32]| -> Vec<(u32, u32)> {
        (0..face.len())
            .map(|k| (face[k], face[(k + 1) % face.len()]))
            .collect()
    };
    let all: Vec<(u32, u32)> = edges(f).into_iter().chain(edges(g)).collect();
    let kept: Vec<(u32, u32)> = all
        .iter()
        .copied()
        .filter(|&(a, b)| !all.contains(&(b, a)))
        .collect();
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &kept {
        if next.insert(a, b).is_some() {
            return None;
        }
    }
    let start = kept.first()?.0;
    let mut out = vec![start];
    let mut x = next[&start];
    while x != start {
        out.push(x);
        x = *next.get(&x)?;
        if out.len() > kept.len() {
            return None;
        }
    }
    (out.len() == kept.len()).then_some(out)
}

/// Largest distance of a corner from its face's plane, `planes[f]` = (unit normal, offset).
fn max_deviation(pos: &[DVec3], faces: &[Vec<u32>], planes: &[(DVec3, f64)]) -> f64 {
    faces
        .iter()
        .zip(planes)
        .flat_map(|(f, &(n, d))| f.iter().map(move |&v| (n.dot(pos[v as usize]) - d).abs()))
        .fold(0.0, f64::max)
}

/// Every face's plane ([`plane`]).
fn planes(pos: &[DVec3], faces: &[Vec<u32>]) -> Vec<(DVec3, f64)> {
    faces.iter().map(|f| plane(pos, f)).collect()
}

/// The plane group of every face: edge-adjacent faces whose normals' dot product exceeds `cos`
/// are joined (transitively); ids are face indices (the group's representative).
fn plane_groups(pos: &[DVec3], faces: &[Vec<u32>], cos: f64) -> Vec<usize> {
    let normals: Vec<DVec3> = faces
        .iter()
        .map(|f| area_vector(pos, f).normalize_or_zero())
        .collect();
    let of_edge = directed_edge_faces(faces);
    let mut groups = UnionFind::new(faces.len());
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            let Some(&h) = of_edge.get(&(face[(k + 1) % face.len()], face[k])) else {
                continue;
            };
            if normals[f].dot(normals[h]) > cos {
                groups.union(f as u32, h as u32);
            }
        }
    }
    (0..faces.len())
        .map(|f| groups.find(f as u32) as usize)
        .collect()
}

/// Every face's plane, one per plane group ([`plane_groups`]): the group's summed area vector
/// through the mean of its faces' corners.
fn group_planes(pos: &[DVec3], faces: &[Vec<u32>], group: &[usize]) -> Vec<(DVec3, f64)> {
    let mut sums = vec![(DVec3::ZERO, DVec3::ZERO, 0usize); faces.len()];
    for (face, &g) in faces.iter().zip(group) {
        let e = &mut sums[g];
        e.0 += area_vector(pos, face);
        e.1 += face.iter().map(|&v| pos[v as usize]).sum::<DVec3>();
        e.2 += face.len();
    }
    group
        .iter()
        .map(|&g| {
            let (a, sum, count) = sums[g];
            let n = a.normalize_or_zero();
            (n, n.dot(sum / count as f64))
        })
        .collect()
}

fn plane(pos: &[DVec3], face: &[u32]) -> (DVec3, f64) {
    let n = area_vector(pos, face).normalize_or_zero();
    let mean = face.iter().map(|&v| pos[v as usize]).sum::<DVec3>() / face.len() as f64;
    (n, n.dot(mean))
}

/// Step 5 of the module docs: positions with every face planar (to [`PLANAR_GOAL`]).
/// With `coplanar` (a cosine), nearly coplanar neighbours share one plane ([`plane_groups`]).
fn planarise(pos: &[DVec3], faces: &[Vec<u32>], diag: f64, coplanar: Option<f64>) -> Vec<DVec3> {
    let mut x = pos.to_vec();
    let mut of_vertex: Vec<Vec<usize>> = vec![Vec::new(); pos.len()];
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            of_vertex[v as usize].push(f);
        }
    }
    let group = coplanar.map(|cos| plane_groups(pos, faces, cos));
    for round in 0..PLANAR_ROUNDS {
        let planes = match &group {
            Some(g) => group_planes(&x, faces, g),
            None => planes(&x, faces),
        };
        if max_deviation(&x, faces, &planes) <= PLANAR_GOAL * diag {
            break;
        }
        // Anchored first (no drift along directions the planes leave free), then nearly free.
        let anchor = if round < PLANAR_ROUNDS / 2 {
            1e-6
        } else {
            1e-12
        };
        for (v, fs) in of_vertex.iter().enumerate() {
            if fs.is_empty() {
                continue;
            }
            let mut m = DMat3::from_diagonal(DVec3::splat(anchor));
            let mut r = anchor * pos[v];
            for &f in fs {
                let (n, d) = planes[f];
                m += DMat3::from_cols(n * n.x, n * n.y, n * n.z);
                r += d * n;
            }
            x[v] = m.inverse() * r;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sorted scan finds the same nearest distance as trying every point (a scattered
    /// set from a fixed linear congruential sequence, queries inside and outside its range).
    #[test]
    fn nearest_distance_is_the_brute_force_minimum() {
        let mut rng = crate::fixtures::Lcg(12345);
        let mut next = || rng.uniform() * 4.0 - 2.0;
        let mut pts: Vec<DVec3> = (0..200)
            .map(|_| DVec3::new(next(), next(), next()))
            .collect();
        let queries: Vec<DVec3> = (0..50)
            .map(|_| 1.5 * DVec3::new(next(), next(), next()))
            .collect();
        pts.sort_by(|a, b| a.x.total_cmp(&b.x));
        for q in queries {
            let brute = pts
                .iter()
                .map(|p| p.distance(q))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(nearest_distance(&pts, q), brute);
        }
        assert_eq!(nearest_distance(&[], DVec3::ZERO), f64::INFINITY);
    }

    #[test]
    fn collapse_removes_repeats_and_antennas() {
        assert_eq!(collapse(&[0, 1, 1, 2]), vec![0, 1, 2]);
        assert_eq!(collapse(&[0, 1, 2, 1, 3]), vec![0, 1, 3]);
        assert_eq!(collapse(&[0, 1, 0]), vec![0, 1]);
    }

    fn cube_corners() -> Vec<DVec3> {
        (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect()
    }

    /// The unit cube with its top z = 1 split into two quads along y = 0.5, at the midline's
    /// ends `a` (vertex 8, over x = 0) and `b` (9, over x = 1); `walls`: the side walls x = 0
    /// and x = 1 have them as corners too (else they are T-junctions).
    fn split_top(a: DVec3, b: DVec3, walls: bool) -> Mesh {
        let mut p = cube_corners();
        p.push(a);
        p.push(b);
        let (w0, w1) = if walls {
            (vec![0, 4, 8, 6, 2], vec![1, 3, 7, 9, 5])
        } else {
            (vec![0, 4, 6, 2], vec![1, 3, 7, 5])
        };
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 9, 8],
            vec![8, 9, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            w0,
            w1,
        ];
        Mesh::new(p, faces)
    }

    /// Largest distance of a corner from its face's plane, fitted here by three corners
    /// (independent of [`plane`]'s Newell fit).
    fn bend(c: &Mesh) -> f64 {
        c.faces
            .iter()
            .flat_map(|f| {
                let p = |k: usize| c.positions[f[k] as usize];
                let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize();
                f.iter()
                    .map(move |&v| (c.positions[v as usize] - p(0)).dot(n).abs())
            })
            .fold(0.0, f64::max)
    }

    /// A unit cube whose top is two rectangles meeting at y = 0.5 (vertices 8 at x = 0 and 9 at
    /// x = 1, 9 bent 1e-4 out of the plane x = 1), while the side faces x = 0 and x = 1 do not
    /// name 8 and 9: two T-junctions. Not a closed manifold as it stands.
    #[test]
    fn t_junctions_are_split_and_a_bent_corner_is_planarised() {
        let m = split_top(
            DVec3::new(0.0, 0.5, 1.0),
            DVec3::new(1.0 + 1e-4, 0.5, 1.0),
            false,
        );
        // 1e-3 of the diagonal √3 reaches both junctions (distance 0 and 1e-4).
        let (c, validation, report) = clean(&m, 1e-3).unwrap();
        validation.require(true).unwrap();
        assert_eq!(report.t_junctions, 2, "{report:?}");
        assert_eq!((c.positions.len(), c.faces.len()), (10, 7));
        assert_eq!(c.faces.iter().map(Vec::len).sum::<usize>(), 4 * 7 + 2);
        // Planar within rounding of the solve (1e-12 ≫ PLANAR_GOAL × √3 plus the check's own
        // three-point fit on faces of size 1).
        // Once 9 is a corner of the wall x = 1 that wall is bent by 1e-4.
        assert!(bend(&c) < 1e-12, "{}", bend(&c));
        // Vertex 9 moves about its bend (the planes move too, so up to twice it), no more.
        assert!(
            report.max_move > 1e-5 && report.max_move < 2e-4,
            "{report:?}"
        );
    }

    /// The cube's wall x = 1 as two faces sharing the bent chain 1 → m → 7 (m = (1, 0.3, 0.7)
    /// has only these two faces, as a needle's tip has after the weld): the two merge into the
    /// wall and m is gone. With m moved off the wall's plane by 0.2 (not coplanar, not
    /// straight) the clean is an error naming m.
    #[test]
    fn a_vertex_between_two_coplanar_faces_merges_them() {
        let mut p = cube_corners();
        p.push(DVec3::new(1.0, 0.3, 0.7));
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 8],
            vec![1, 8, 7, 5],
        ];
        let (c, validation, report) = clean(&Mesh::new(p.clone(), faces.clone()), 1e-3).unwrap();
        validation.require(true).unwrap();
        assert_eq!(report.merged_faces, 1, "{report:?}");
        assert_eq!((c.positions.len(), c.faces.len()), (8, 6));
        assert!(c.faces.iter().all(|f| f.len() == 4), "{:?}", c.faces);
        p[8].x = 1.2;
        let e = clean(&Mesh::new(p, faces), 1e-3).unwrap_err().to_string();
        assert!(e.contains("vertex 8") && e.contains("not coplanar"), "{e}");
    }

    /// The cube's top z = 1 as two faces meeting at 0.1° along y = 0.5 (the midline's ends
    /// 8, 9 lifted by 1e-3, each a corner of its side wall too): with `clean_coplanar` 0.5°
    /// they merge into one face, the midline's ends, now between two faces on a straight edge,
    /// are dropped, and the top is planar again (the cube back, 8 corners, 6 quads); with the
    /// merge off the two faces stay apart. A 0.05° angle is below a 0.5° threshold, 0.1°
    /// above a 0.05° one: only the angle decides.
    #[test]
    fn nearly_coplanar_faces_merge_on_request() {
        let m = split_top(
            DVec3::new(0.0, 0.5, 1.0 + 1e-3),
            DVec3::new(1.0, 0.5, 1.0 + 1e-3),
            true,
        );
        // The two halves' normals: 1e-3 over 0.5, 0.115°.
        // 1e-3 of the diagonal √3 covers the ends' 1e-3 off the straight edges they are
        // dropped from.
        let options = |angle: f64| CleanOptions {
            relative: 1e-3,
            coplanar_angle: angle,
        };
        let (c, validation, report) = clean_with(&m, options(0.5)).unwrap();
        validation.require(true).unwrap();
        assert_eq!(report.coplanar_merged, 1, "{report:?}");
        assert_eq!(report.dropped_vertices, 2, "{report:?}");
        assert_eq!(c.faces.len(), 6, "{:?}", c.faces);
        assert!(c.faces.iter().all(|f| f.len() == 4), "{:?}", c.faces);
        // Planar within rounding of the solve (as above).
        assert!(bend(&c) < 1e-12, "{}", bend(&c));
        for (angle, merged) in [(0.0, 0), (0.05, 0)] {
            let (c, _, report) = clean_with(&m, options(angle)).unwrap();
            assert_eq!(report.coplanar_merged, merged, "{angle}");
            assert_eq!(c.faces.len(), 7, "{angle}");
            assert_eq!(clean(&m, 1e-3).unwrap().0.faces, c.faces);
        }
    }
}

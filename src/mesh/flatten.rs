//! Nearly flat regions snapped onto exact planes (opt-in, scene key `model.flatten`).
//!
//! Why: a file whose coordinates are rounded (fandisk.obj keeps 4–5 decimals on edges of
//! ~0.02) tilts the triangles of one flat face against each other by up to ~0.3°, far above the
//! inner hull's coplanar merge ([`crate::hull::inner::coplanar`], 1e-9), so the flat face stays
//! a fine triangulation of *nearly* coplanar triangles. Round a point of T in such a region the
//! quintic's star systems are then nearly singular (the C2 conditions of a planar
//! triangulation are dependent), and they amplify any inconsistency of the data by the inverse
//! of that near-singularity; on an exactly flat face the paper's own treatment applies (one
//! face per plane, Appendix B). A box of 6 × 6 triangles per side, rotated and rounded to 4
//! decimals, reproduces fandisk's failure in a minute; flattened, it is the cube again.
//!
//! What: faces are grown into regions of edge-adjacent faces whose every corner lies within
//! `relative` × the bounding-box diagonal of the region's plane (area-weighted normal through
//! the mean of its corners, refitted as the region grows), largest faces first; a face joins
//! only along one chain of its edges, so every region stays a disk. Each region of two or more
//! faces gets its final plane (neighbouring regions that fit one plane share it), and every
//! vertex is moved to the point nearest its file position on all the planes of its regions. A
//! vertex whose planes meet at a small angle would move far along their intersection; such a
//! vertex (a move beyond [`MAX_MOVE`] × the tolerance) leaves the smaller region, with the
//! faces it has there, and the planes are fitted again. The moves stay within [`MAX_MOVE`] ×
//! the tolerance, so this undoes rounding and does not change the shape; the coplanar merge
//! then makes each region one polygon. Set the tolerance to the file's rounding: a gently
//! curved tessellation whose neighbouring faces deviate less than it would be flattened in
//! strips (fandisk's cylinders at 1e-4, docs/quintic.md "Rounded flat faces").

use super::geometry::{area_vector, bbox_diagonal};
use super::topology::{boundary_loop, directed_edge_faces, UnionFind};
use super::Mesh;
use glam::{DMat3, DVec3};
use std::collections::{HashMap, HashSet, VecDeque};

/// Largest `model.flatten` tolerance (relative to the bounding-box diagonal): beyond it
/// modelled shallow features, not rounding, would be flattened.
pub const MAX_RELATIVE: f64 = 1e-3;

/// Largest move of a vertex, as a multiple of the tolerance, before it leaves its smaller
/// region: a vertex lies within the tolerance of each of its planes, so only planes meeting at
/// a small angle move it further.
pub const MAX_MOVE: f64 = 2.0;

/// Fewest faces of a region that is flattened unless the scene says otherwise
/// (`model.flatten_min_faces`).
pub const MIN_FACES: usize = 2;

/// What [`flatten_with`] flattens: `model.flatten` and `model.flatten_min_faces`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlattenOptions {
    /// Tolerance, relative to the bounding-box diagonal.
    pub relative: f64,
    /// Fewest faces of a region that is flattened (at least 2). Regions of a few faces also
    /// form where a gently curved tessellation happens to be flat within the tolerance; made
    /// polygons, they put the inner hull's corner guards among the curved part's centroids,
    /// where the quintic's star systems become nearly singular (fandisk: `docs/quintic.md`,
    /// session 39). A larger count keeps only the model's flat faces.
    pub min_faces: usize,
}

/// Faces whose unit normals differ by more than this (cosine of 25°) never share a region:
/// a tiny face can lie within the tolerance of any plane.
const NORMAL_COS: f64 = 0.9;

/// What [`flatten`] changed.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FlattenReport {
    /// Planes that regions of two or more faces were snapped onto (neighbouring regions of
    /// one plane count once).
    pub regions: usize,
    /// Faces in those regions.
    pub faces: usize,
    /// Vertices moved.
    pub moved: usize,
    /// Largest move, in the file's units.
    pub max_move: f64,
}

/// A plane fitted to a set of faces: unit normal and a point on it.
fn fit(positions: &[DVec3], faces: &[Vec<u32>], members: &[usize]) -> Option<(DVec3, DVec3)> {
    let mut area = DVec3::ZERO;
    let mut sum = DVec3::ZERO;
    let mut count = 0usize;
    for &f in members {
        area += area_vector(positions, &faces[f]);
        for &v in &faces[f] {
            sum += positions[v as usize];
            count += 1;
        }
    }
    let n = area.try_normalize()?;
    Some((n, sum / count.max(1) as f64))
}

/// The regions of nearly coplanar faces (every face in exactly one, most of them alone).
/// Deterministic: seeds by decreasing area, then index.
fn grow(mesh: &Mesh, tol: f64) -> Vec<Vec<usize>> {
    let pos = &mesh.positions;
    let nf = mesh.faces.len();
    let areas: Vec<DVec3> = mesh.faces.iter().map(|f| area_vector(pos, f)).collect();
    let of_edge = directed_edge_faces(&mesh.faces);
    let mut order: Vec<usize> = (0..nf).collect();
    order.sort_by(|&a, &b| {
        areas[b]
            .length()
            .total_cmp(&areas[a].length())
            .then(a.cmp(&b))
    });
    let mut region = vec![usize::MAX; nf];
    let mut regions: Vec<Vec<usize>> = Vec::new();
    for &seed in &order {
        if region[seed] != usize::MAX || areas[seed].try_normalize().is_none() {
            continue;
        }
        let id = regions.len();
        region[seed] = id;
        let mut members = vec![seed];
        let mut area = areas[seed];
        let mut sum: DVec3 = mesh.faces[seed].iter().map(|&v| pos[v as usize]).sum();
        let mut count = mesh.faces[seed].len();
        let mut queue = VecDeque::from([seed]);
        // Faces of the region at each of its vertices.
        let mut uses: HashMap<u32, usize> = mesh.faces[seed].iter().map(|&v| (v, 1)).collect();
        while let Some(f) = queue.pop_front() {
            let face = &mesh.faces[f];
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                let Some(&g) = of_edge.get(&(b, a)) else {
                    continue;
                };
                if region[g] != usize::MAX {
                    continue;
                }
                let (Some(n), Some(ng)) = (area.try_normalize(), areas[g].try_normalize()) else {
                    continue;
                };
                let c = sum / count as f64;
                let near = mesh.faces[g]
                    .iter()
                    .all(|&v| n.dot(pos[v as usize] - c).abs() <= tol);
                if near
                    && n.dot(ng) >= NORMAL_COS
                    && keeps_disk(&mesh.faces[g], id, &region, &of_edge, &uses)
                {
                    for &v in &mesh.faces[g] {
                        *uses.entry(v).or_insert(0) += 1;
                    }
                    region[g] = id;
                    members.push(g);
                    area += areas[g];
                    sum += mesh.faces[g]
                        .iter()
                        .map(|&v| pos[v as usize])
                        .sum::<DVec3>();
                    count += mesh.faces[g].len();
                    queue.push_back(g);
                }
            }
        }
        regions.push(members);
    }
    regions
}

/// True when adding `face` to region `id` keeps the region a disk: the face meets the region
/// along one chain of its edges and nowhere else (no hole closed, no two pieces touching at a
/// corner), so that the coplanar merge can make the region one polygon.
fn keeps_disk(
    face: &[u32],
    id: usize,
    region: &[usize],
    of_edge: &HashMap<(u32, u32), usize>,
    uses: &HashMap<u32, usize>,
) -> bool {
    let n = face.len();
    let shared: Vec<bool> = (0..n)
        .map(|k| {
            of_edge
                .get(&(face[(k + 1) % n], face[k]))
                .is_some_and(|&g| region[g] == id)
        })
        .collect();
    let runs = (0..n)
        .filter(|&k| shared[k] && !shared[(k + n - 1) % n])
        .count();
    if runs != 1 {
        return false;
    }
    // Vertices of the face off the shared chain must be new to the region.
    (0..n).all(|k| {
        let on_chain = shared[k] || shared[(k + n - 1) % n];
        on_chain || !uses.contains_key(&face[k])
    })
}

/// True when the union of `members` is a disk: one simple boundary loop
/// ([`boundary_loop`]) and Euler characteristic 1.
fn is_disk(faces: &[Vec<u32>], members: &[usize]) -> bool {
    let Some(boundary) = boundary_loop(faces, members) else {
        return false;
    };
    let half: HashSet<(u32, u32)> = members
        .iter()
        .flat_map(|&f| {
            let face = &faces[f];
            (0..face.len()).map(move |k| (face[k], face[(k + 1) % face.len()]))
        })
        .collect();
    let mut vertices: Vec<u32> = members
        .iter()
        .flat_map(|&f| faces[f].iter().copied())
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    let edges = (half.len() + boundary.len()) / 2;
    vertices.len() + members.len() == edges + 1
}

/// The point nearest `p` on every plane of `planes` (least-norm move; planes through one line
/// or point are met exactly, nearly parallel ones only approximately).
fn nearest_on(p: DVec3, planes: &[(DVec3, DVec3)]) -> DVec3 {
    // Minimise |x − p|² subject to n_i·x = n_i·c_i: x = p + Σ λ_i n_i with the Gram system
    // G λ = r, G_ij = n_i·n_j, r_i = n_i·(c_i − p). At most three independent planes in 3-D.
    let k = planes.len().min(3);
    let mut g = DMat3::IDENTITY;
    let mut r = DVec3::ZERO;
    for i in 0..k {
        for j in 0..k {
            g.col_mut(j)[i] = planes[i].0.dot(planes[j].0);
        }
        r[i] = planes[i].0.dot(planes[i].1 - p);
    }
    let lambda = g.inverse() * r;
    let mut x = p;
    for i in 0..k {
        x += lambda[i] * planes[i].0;
    }
    x
}

/// `mesh` with its nearly flat regions made exactly flat (module docs), and what changed.
/// Vertex and face indices, lines and normals are kept; only positions move. `relative` ≤ 0
/// returns the mesh unchanged.
#[must_use]
pub fn flatten(mesh: &Mesh, relative: f64) -> (Mesh, FlattenReport) {
    flatten_with(
        mesh,
        FlattenOptions {
            relative,
            min_faces: MIN_FACES,
        },
    )
}

/// [`flatten`] of the regions of at least `options.min_faces` faces.
#[must_use]
pub fn flatten_with(mesh: &Mesh, options: FlattenOptions) -> (Mesh, FlattenReport) {
    let FlattenOptions {
        relative,
        min_faces,
    } = options;
    let min_faces = min_faces.max(MIN_FACES);
    let mut out = mesh.clone();
    let mut report = FlattenReport::default();
    let tol = relative * bbox_diagonal(&mesh.positions);
    if tol <= 0.0 || !tol.is_finite() {
        return (out, report);
    }
    let pos = &mesh.positions;
    let mut regions: Vec<Vec<usize>> = grow(mesh, tol)
        .into_iter()
        .filter(|r| r.len() >= min_faces)
        .collect();
    let nv = pos.len();
    // Vertices leave their smaller regions until every vertex's planes are well apart.
    let (targets, planes) = loop {
        // Evictions can leave a region pinched or holed: it is then not flattened at all.
        regions.retain(|r| r.len() >= min_faces && is_disk(&mesh.faces, r));
        let mut of_vertex: Vec<Vec<usize>> = vec![Vec::new(); nv];
        for (id, r) in regions.iter().enumerate() {
            for &f in r {
                for &v in &mesh.faces[f] {
                    if !of_vertex[v as usize].contains(&id) {
                        of_vertex[v as usize].push(id);
                    }
                }
            }
        }
        // Regions of one plane (a ring the disk rule cut in two, a face grown around) share
        // one fitted plane: neighbours whose union lies within the tolerance of its plane.
        // Each set of regions is named by its smallest region (`low`, kept at the set's
        // representative), so the order below does not depend on how the sets were joined.
        let mut class = UnionFind::new(regions.len());
        let mut low: Vec<usize> = (0..regions.len()).collect();
        let name =
            |class: &mut UnionFind, low: &[usize], r: usize| low[class.find(r as u32) as usize];
        let mut tried: HashSet<(usize, usize)> = HashSet::new();
        for list in &of_vertex {
            for (i, &a) in list.iter().enumerate() {
                for &b in &list[i + 1..] {
                    let (ra, rb) = (name(&mut class, &low, a), name(&mut class, &low, b));
                    if ra == rb || !tried.insert((ra.min(rb), ra.max(rb))) {
                        continue;
                    }
                    let union: Vec<usize> = (0..regions.len())
                        .filter(|&r| {
                            let rr = name(&mut class, &low, r);
                            rr == ra || rr == rb
                        })
                        .flat_map(|r| regions[r].iter().copied())
                        .collect();
                    let one = fit(pos, &mesh.faces, &union).is_some_and(|(n, c)| {
                        union.iter().all(|&f| {
                            mesh.faces[f]
                                .iter()
                                .all(|&v| n.dot(pos[v as usize] - c).abs() <= tol)
                        })
                    });
                    if one {
                        class.union(a as u32, b as u32);
                        low[class.find(a as u32) as usize] = ra.min(rb);
                    }
                }
            }
        }
        let roots: Vec<usize> = (0..regions.len())
            .map(|r| name(&mut class, &low, r))
            .collect();
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); regions.len()];
        for (r, &c) in roots.iter().enumerate() {
            members[c].extend(regions[r].iter().copied());
        }
        let planes: Vec<Option<(DVec3, DVec3)>> = members
            .iter()
            .map(|faces| {
                (!faces.is_empty())
                    .then(|| fit(pos, &mesh.faces, faces))
                    .flatten()
            })
            .collect();
        let mut targets: Vec<Option<DVec3>> = vec![None; nv];
        let mut evict: Vec<(usize, u32)> = Vec::new();
        for (v, list) in of_vertex.iter().enumerate() {
            if list.is_empty() {
                continue;
            }
            // The vertex's planes, larger classes first; the smallest region gives way.
            let mut classes: Vec<usize> = list.iter().map(|&r| roots[r]).collect();
            classes.sort_unstable();
            classes.dedup();
            classes.sort_by(|&a, &b| members[b].len().cmp(&members[a].len()).then(a.cmp(&b)));
            let Some(ps) = classes
                .iter()
                .map(|&c| planes[c])
                .collect::<Option<Vec<_>>>()
            else {
                evict.push((
                    *list.iter().min_by_key(|&&r| regions[r].len()).unwrap(),
                    v as u32,
                ));
                continue;
            };
            let p = pos[v];
            let x = nearest_on(p, &ps);
            let exact = ps
                .iter()
                .all(|&(n, c)| n.dot(x - c).abs() <= 1e-12 * tol.max(1.0));
            if (x - p).length() > MAX_MOVE * tol || !exact || ps.len() > 3 {
                let last = *classes.last().unwrap();
                let r = *list
                    .iter()
                    .filter(|&&r| roots[r] == last)
                    .min_by_key(|&&r| (regions[r].len(), r))
                    .unwrap();
                evict.push((r, v as u32));
            } else {
                targets[v] = Some(x);
            }
        }
        if evict.is_empty() {
            break (targets, roots);
        }
        for (id, v) in evict {
            regions[id].retain(|&f| !mesh.faces[f].contains(&v));
        }
    };
    for (v, t) in targets.iter().enumerate() {
        if let Some(x) = *t {
            let d = (x - pos[v]).length();
            if d > 0.0 {
                report.moved += 1;
                report.max_move = report.max_move.max(d);
            }
            out.positions[v] = x;
        }
    }
    let mut classes = planes;
    classes.sort_unstable();
    classes.dedup();
    report.regions = classes.len();
    report.faces = regions.iter().map(Vec::len).sum();
    (out, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::inner::coplanar::merge_coplanar;

    fn rounded_box() -> Mesh {
        crate::mesh::load(std::path::Path::new("scenes/models/box_rounded.obj"))
            .unwrap()
            .0
    }

    /// The rounded box's six sides (6 × 6 × 2 triangles each, flat only to the file's 4
    /// decimals) become six exact planes, each one polygon after the hull's coplanar merge.
    #[test]
    fn rounded_box_sides_become_planes() {
        let m = rounded_box();
        // Unflattened, the merge (1e-9) finds the rounded sides far from coplanar.
        assert!(merge_coplanar(&m).faces.len() > 100);
        let diag = bbox_diagonal(&m.positions);
        let (flat, report) = flatten(&m, 1e-4);
        assert_eq!((report.regions, report.faces), (6, 432));
        // Rounding to 4 decimals moves a point by at most √3 × 5e-5 ≈ 8.7e-5; the fitted plane
        // adds less than that again, and no vertex may move beyond the tolerance's MAX_MOVE.
        assert!(report.max_move > 1e-6 && report.max_move <= MAX_MOVE * 1e-4 * diag);
        let merged = merge_coplanar(&flat);
        assert_eq!(merged.faces.len(), 6);
        for face in &merged.faces {
            let n = area_vector(&merged.positions, face).normalize();
            let o = merged.positions[face[0] as usize];
            for &v in face {
                // Unit-size coordinates snapped onto the plane: exact to a few ulps.
                assert!(n.dot(merged.positions[v as usize] - o).abs() < 1e-14);
            }
        }
    }

    /// `min_faces`: the box's sides have 72 triangles each, so at 72 all six are flattened as
    /// by default and at 73 none is (the mesh comes back bit for bit).
    #[test]
    fn min_faces_keeps_only_large_regions() {
        let m = rounded_box();
        let at = |min_faces| {
            flatten_with(
                &m,
                FlattenOptions {
                    relative: 1e-4,
                    min_faces,
                },
            )
        };
        let (all, report) = at(72);
        assert_eq!((report.regions, report.faces), (6, 432));
        assert_eq!(all, flatten(&m, 1e-4).0);
        let (none, report) = at(73);
        assert_eq!((report.regions, report.faces, report.moved), (0, 0, 0));
        assert_eq!(none, m);
    }

    /// A real bump (a side's vertex raised 50× the tolerance) is no rounding: its faces stay
    /// out of the side's region and it does not move.
    #[test]
    fn bump_is_kept() {
        let mut m = rounded_box();
        // An interior vertex of a side: all its faces (4 or 8) with one normal.
        let v = (0..m.positions.len() as u32)
            .find(|&v| {
                let fs: Vec<&Vec<u32>> = m.faces.iter().filter(|f| f.contains(&v)).collect();
                fs.len() >= 4
                    && fs.iter().all(|f| {
                        area_vector(&m.positions, f)
                            .normalize()
                            .dot(area_vector(&m.positions, fs[0]).normalize())
                            > 0.999
                    })
            })
            .expect("an interior vertex");
        let n = m
            .faces
            .iter()
            .find(|f| f.contains(&v))
            .map(|f| area_vector(&m.positions, f).normalize())
            .unwrap();
        let tol = 1e-4 * bbox_diagonal(&m.positions);
        m.positions[v as usize] += 50.0 * tol * n;
        let (flat, report) = flatten(&m, 1e-4);
        // The bump stays: its height over the side's plane (through a corner of the side far
        // from it) is what it was, within the moves the flattening allows (MAX_MOVE × tol
        // for the bump and for that corner).
        let far = m
            .faces
            .iter()
            .filter(|f| {
                !f.iter()
                    .any(|&w| m.faces.iter().any(|g| g.contains(&v) && g.contains(&w)))
            })
            .find(|f| area_vector(&m.positions, f).normalize().dot(n) > 0.999)
            .expect("a face of the side away from the bump");
        let side = area_vector(&flat.positions, far).normalize();
        let height = side.dot(flat.positions[v as usize] - flat.positions[far[0] as usize]);
        assert!(
            (height - 50.0 * tol).abs() <= 2.0 * MAX_MOVE * tol,
            "{height}"
        );
        // Every other face of the box is in a region (the bump's faces only in the pairs its
        // grid lines make: two triangles along one line are one plane whatever the bump).
        let around = m.faces.iter().filter(|f| f.contains(&v)).count();
        assert!(report.faces >= 432 - around, "{report:?}");
    }

    /// A finely tessellated sphere folds by ~9° between neighbours: nothing is flat.
    #[test]
    fn sphere_is_left_alone() {
        let m = crate::mesh::load(std::path::Path::new("scenes/models/icosahedron.obj"))
            .unwrap()
            .0;
        let sub = crate::mesh::subdivide(
            &m,
            crate::mesh::Subdivision {
                rule: crate::mesh::SubdivisionRule::Loop,
                levels: 2,
            },
        )
        .unwrap();
        let (flat, report) = flatten(&sub, 1e-4);
        assert_eq!(report, FlattenReport::default());
        assert_eq!(flat.positions, sub.positions);
    }

    /// A flat ring (a square frame) cannot be one disk: every region grown on it is a disk,
    /// and its faces still end up on one plane.
    #[test]
    fn ring_regions_are_disks() {
        // Outer square 3 × 3, hole 1 × 1, eight quads split into triangles, heights ±1e-6.
        let mut positions = Vec::new();
        for (k, &(x, y)) in [(0., 0.), (3., 0.), (3., 3.), (0., 3.)].iter().enumerate() {
            positions.push(DVec3::new(x, y, if k % 2 == 0 { 1e-6 } else { -1e-6 }));
        }
        for &(x, y) in &[(1., 1.), (2., 1.), (2., 2.), (1., 2.)] {
            positions.push(DVec3::new(x, y, 0.0));
        }
        let mut faces = Vec::new();
        for k in 0..4u32 {
            let (a, b, c, d) = (k, (k + 1) % 4, 4 + (k + 1) % 4, 4 + k);
            faces.push(vec![a, b, c]);
            faces.push(vec![a, c, d]);
        }
        let m = Mesh::new(positions, faces);
        let regions = grow(&m, 1e-4 * bbox_diagonal(&m.positions));
        assert!(regions.iter().all(|r| is_disk(&m.faces, r)));
        assert!(regions.len() >= 2, "one region would close the ring");
        let (flat, _) = flatten(&m, 1e-4);
        for p in &flat.positions {
            assert!(p.z.abs() < 1e-15, "{p}");
        }
    }
}

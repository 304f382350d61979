//! Coplanar faces merged into polygons before the hull is built (Appendix B's coplanarity,
//! treated at its source).
//!
//! A triangulated flat region (the triangulated hallway corner, the flat sides of the nut or
//! fandisk) gives Algorithm 1 corners whose faces share one plane: a "non-trihedral" vertex
//! whose centroids are coplanar with it has no pseudo-centroid off that plane, and the face
//! tetrahedra built there are flat. The paper's own polyhedra have one face per plane; we
//! restore that: edge-adjacent faces with the same plane are merged into one polygon (when the
//! merged region is a disk bounded by one simple loop), and vertices then left on a straight
//! edge between only two polygons are dropped from both (their edges are collinear). Vertex
//! indices and positions are unchanged; every merged polygon remembers one of its input faces.

use crate::mesh::geometry::area_vector;
use crate::mesh::Mesh;
use glam::DVec3;
use std::collections::HashMap;

/// Two faces are coplanar when their unit normals differ by less than this (about 1e-6 rad)
/// and each one's vertices lie within [`PLANE_DISTANCE`] of the other's plane.
pub const NORMAL_TOL: f64 = 1e-6;

/// Largest distance of a face's vertices from a coplanar neighbour's plane, relative to the
/// pair's size: rounding of unit-size coordinates, far below any modelled feature.
pub const PLANE_DISTANCE: f64 = 1e-9;

/// Merges coplanar edge-adjacent faces of `mesh` (see the module documentation). The result
/// has the same positions and vertex lines; `face_parent` names, for each polygon, the input
/// face it contains first, and `face_lines` that face's line. Returns the mesh unchanged (a
/// clone) when nothing is coplanar.
#[must_use]
pub fn merge_coplanar(mesh: &Mesh) -> Mesh {
    merge_coplanar_counted(mesh).0
}

/// [`merge_coplanar`], also returning how many input faces each polygon of the result holds
/// (1 for a face kept as it was; [`super::flatnet`] treats only merged regions).
#[must_use]
pub fn merge_coplanar_counted(mesh: &Mesh) -> (Mesh, Vec<usize>) {
    merge_coplanar_keeping(mesh, |_, _| false)
}

/// [`merge_coplanar_counted`], keeping the vertices on a straight edge between two polygons
/// whose representative input faces (`face_parent`) `keep` accepts: corners of both polygons
/// with a straight angle, which the hull gives no corner triangles, only guards and step (5')
/// cells ([`super::flatnet`], `InnerOptions::straight_corners`): between two flat nets a
/// straight edge otherwise becomes one edge as long as the whole crease (flattened fandisk:
/// 0.81, its neighbours 0.019), and each net's triangles on it are needles.
#[must_use]
pub fn merge_coplanar_keeping(mesh: &Mesh, keep: impl Fn(u32, u32) -> bool) -> (Mesh, Vec<usize>) {
    let nf = mesh.faces.len();
    let normals: Vec<Option<DVec3>> = mesh
        .faces
        .iter()
        .map(|f| area_vector(&mesh.positions, f).try_normalize())
        .collect();
    let directed = crate::mesh::topology::directed_edge_faces(&mesh.faces);
    let mut parent: Vec<usize> = (0..nf).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let coplanar = |f: usize, g: usize| -> bool {
        let (Some(nf_), Some(ng)) = (normals[f], normals[g]) else {
            return false;
        };
        same_plane(&mesh.positions, &mesh.faces[f], nf_, &mesh.faces[g], ng)
    };
    let mut any = false;
    for (&(a, b), &f) in &directed {
        if let Some(&g) = directed.get(&(b, a)) {
            if f < g && coplanar(f, g) {
                let (rf, rg) = (root(&mut parent, f), root(&mut parent, g));
                if rf != rg {
                    parent[rf.max(rg)] = rf.min(rg);
                    any = true;
                }
            }
        }
    }
    if !any {
        return (mesh.clone(), vec![1; nf]);
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    for f in 0..nf {
        let r = root(&mut parent, f);
        groups.entry(r).or_default().push(f);
    }
    let mut roots: Vec<usize> = groups.keys().copied().collect();
    roots.sort_unstable();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut reps: Vec<u32> = Vec::new();
    let mut counts: Vec<usize> = Vec::new();
    for r in roots {
        let group = &groups[&r];
        let keep_all = |faces: &mut Vec<Vec<u32>>, reps: &mut Vec<u32>, counts: &mut Vec<usize>| {
            for &f in group {
                faces.push(mesh.faces[f].clone());
                reps.push(f as u32);
                counts.push(1);
            }
        };
        if group.len() == 1 {
            keep_all(&mut faces, &mut reps, &mut counts);
            continue;
        }
        match crate::mesh::topology::boundary_loop(&mesh.faces, group) {
            Some(poly) => {
                faces.push(poly);
                reps.push(group[0] as u32);
                counts.push(group.len());
            }
            None => keep_all(&mut faces, &mut reps, &mut counts),
        }
    }
    // Vertices on a straight edge between only two polygons.
    let mut count: HashMap<u32, Vec<usize>> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            let e = count.entry(v).or_default();
            if !e.contains(&f) {
                e.push(f);
            }
        }
    }
    let kept_straight = |v: &u32| {
        let fs = &count[v];
        fs.len() == 2 && keep(reps[fs[0]], reps[fs[1]])
    };
    for face in &mut faces {
        let kept: Vec<u32> = face
            .iter()
            .copied()
            .filter(|v| count[v].len() > 2 || kept_straight(v))
            .collect();
        if kept.len() >= 3 {
            *face = kept;
        }
    }
    let merged = Mesh {
        positions: mesh.positions.clone(),
        file_normals: mesh.file_normals.clone(),
        vertex_lines: mesh.vertex_lines.clone(),
        face_lines: reps
            .iter()
            .map(|&f| mesh.face_lines.get(f as usize).copied().unwrap_or(0))
            .collect(),
        face_parent: reps,
        faces,
    };
    (merged, counts)
}

/// True when faces `f` and `g` (unit normals `nf`, `ng`) lie in one plane: normals within
/// [`NORMAL_TOL`] and `g`'s vertices within [`PLANE_DISTANCE`] (relative) of `f`'s plane.
#[must_use]
pub fn same_plane(positions: &[DVec3], f: &[u32], nf: DVec3, g: &[u32], ng: DVec3) -> bool {
    if (nf - ng).length() > NORMAL_TOL {
        return false;
    }
    let pts = |h: &[u32]| h.iter().map(|&v| positions[v as usize]).collect::<Vec<_>>();
    let o = positions[f[0] as usize];
    let (pf, pg) = (pts(f), pts(g));
    let size = pf
        .iter()
        .chain(&pg)
        .map(|&p| (p - o).length())
        .fold(0.0, f64::max);
    pg.iter()
        .all(|&p| nf.dot(p - o).abs() <= PLANE_DISTANCE * size)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 1 × 1 box whose four long sides are each two unit squares: merged, each side is
    /// one polygon and the four vertices of the middle ring (each between only two sides) are
    /// dropped, leaving quadrilaterals; kept for the sides `keep` names, those sides keep them
    /// as straight corners (hexagons), the others still drop them.
    #[test]
    fn straight_vertices_are_kept_between_the_polygons_asked_for() {
        let mut positions = Vec::new();
        for x in [0.0, 1.0, 2.0] {
            for (y, z) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                positions.push(DVec3::new(x, y, z));
            }
        }
        // Ring r, corner c: index 4r + c; outward orientation.
        let v = |r: u32, c: u32| 4 * r + c % 4;
        let mut faces = vec![
            vec![v(0, 0), v(0, 3), v(0, 2), v(0, 1)],
            vec![v(2, 0), v(2, 1), v(2, 2), v(2, 3)],
        ];
        for r in 0..2 {
            for c in 0..4 {
                faces.push(vec![v(r, c), v(r, c + 1), v(r + 1, c + 1), v(r + 1, c)]);
            }
        }
        let m = Mesh::new(positions, faces);
        let (dropped, counts) = merge_coplanar_counted(&m);
        let mut sizes: Vec<usize> = dropped.faces.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, vec![4; 6]);
        assert_eq!(counts.iter().filter(|&&c| c == 2).count(), 4);
        let (kept, _) = merge_coplanar_keeping(&m, |_, _| true);
        let mut sizes: Vec<usize> = kept.faces.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, vec![4, 4, 6, 6, 6, 6]);
        // Only the vertex between the sides whose first squares are faces 2 and 3 (y = 1,
        // z = 0 at x = 1: vertex 5) is kept when only that pair is asked for.
        let (one, _) = merge_coplanar_keeping(&m, |a, b| a.min(b) == 2 && a.max(b) == 3);
        let holding: Vec<usize> = (0..one.faces.len())
            .filter(|&f| one.faces[f].contains(&5))
            .collect();
        assert_eq!(holding.len(), 2);
        assert!(holding.iter().all(|&f| one.faces[f].len() == 5));
        assert!(!one
            .faces
            .iter()
            .any(|f| f.contains(&4) || f.contains(&6) || f.contains(&7)));
    }

    /// The triangulated hallway corner (an L-shaped block) becomes the L prism: two hexagons
    /// and six quadrilaterals, same vertices.
    #[test]
    fn triangulated_l_block_merges_to_prism() {
        let (m, _) =
            crate::mesh::load(std::path::Path::new("scenes/models/hallway_corner.obj")).unwrap();
        let merged = merge_coplanar(&m);
        let mut sizes: Vec<usize> = merged.faces.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, vec![4, 4, 4, 4, 4, 4, 6, 6]);
        // Every merged polygon is planar with its representative input face's normal.
        for (f, face) in merged.faces.iter().enumerate() {
            let n = area_vector(&merged.positions, face).normalize();
            let rep = &m.faces[merged.face_parent[f] as usize];
            let nr = area_vector(&m.positions, rep).normalize();
            // Axis-aligned unit-size geometry: exact up to rounding.
            assert!((n - nr).length() < 1e-12);
        }
    }
}

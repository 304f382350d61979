//! Repair of non-manifold vertices: a vertex whose faces form several edge-connected fans
//! (two surfaces touching at one point, e.g. the teapot's spout meeting its body) becomes one
//! vertex per fan.
//!
//! Two faces at a vertex v belong to the same fan when they share an edge at v. Faces are
//! linked across every edge at v that has two or more faces, whatever the faces' orientation
//! (this runs before [`super::orient`]), so non-manifold *edges* are never split here: they stay
//! for validation to report. Each extra fan gets a new vertex, appended after the others, with
//! the original's file line and file normal; the fan containing the vertex's first corner (in
//! face order) keeps the original index. The new vertex is moved [`SPLIT_OFFSET`] of the way
//! towards the centroid of its fan's other corners: far below any visible size, but the two
//! sheets no longer share a point, so consumers that identify vertices by their position (the
//! check's interpolation measure, watertight tessellation) keep them apart.

use super::report::{Element, FindingKind, Report};
use super::topology::{Topology, UnionFind};
use super::Mesh;

/// How far (relative to the distance to its fan's centroid) a split-off vertex moves into its fan.
pub const SPLIT_OFFSET: f64 = 1e-6;

/// Splits every vertex whose incident faces form more than one edge-connected fan into one
/// vertex per fan; records the split vertices (original index and line) in `report` as
/// [`FindingKind::SplitVertex`]. Returns the number of vertices added.
pub fn split_vertex_fans(mesh: &mut Mesh, report: &mut Report) -> usize {
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let mut split = Vec::new();
    let mut added = 0;
    for v in 0..mesh.positions.len() as u32 {
        let corners = topo.vertex_corners(v);
        if corners.len() < 2 {
            continue;
        }
        // Local union-find over the corners at v; corners whose faces share an edge at v
        // (the edge leaving v at the corner, or the one arriving at it) are joined.
        let mut uf = UnionFind::new(corners.len());
        let local = |c: u32| corners.iter().position(|&x| x == c);
        for (i, &c) in corners.iter().enumerate() {
            for h in [c, topo.prev(c)] {
                let on_edge = topo.edge_corners(topo.corner_edge[h as usize]);
                if on_edge.len() < 2 {
                    continue;
                }
                for &o in on_edge {
                    // The corner of the other face at v: o itself when it starts at v,
                    // otherwise the corner after it (the edge's other end is v).
                    let at_v = if topo.corner_vertex[o as usize] == v {
                        o
                    } else {
                        topo.next(o)
                    };
                    if let Some(j) = local(at_v) {
                        uf.union(i as u32, j as u32);
                    }
                }
            }
        }
        let roots: Vec<u32> = (0..corners.len() as u32).map(|i| uf.find(i)).collect();
        let first_root = roots[0];
        // New vertex per further fan, in the order of first appearance.
        let mut new_of_root: Vec<(u32, u32)> = Vec::new();
        for (i, &r) in roots.iter().enumerate() {
            if r == first_root {
                continue;
            }
            let nv = match new_of_root.iter().find(|(root, _)| *root == r) {
                Some(&(_, nv)) => nv,
                None => {
                    let nv = mesh.positions.len() as u32;
                    let p = mesh.positions[v as usize];
                    let (sum, count) = corners
                        .iter()
                        .zip(&roots)
                        .filter(|&(_, &root)| root == r)
                        .fold((glam::DVec3::ZERO, 0.0), |(s, k), (&c, _)| {
                            let a = mesh.positions[topo.head(c) as usize];
                            let b =
                                mesh.positions[topo.corner_vertex[topo.prev(c) as usize] as usize];
                            (s + a + b, k + 2.0)
                        });
                    mesh.positions.push(p + SPLIT_OFFSET * (sum / count - p));
                    mesh.vertex_lines.push(mesh.vertex_lines[v as usize]);
                    if let Some(n) = &mut mesh.file_normals {
                        n.push(n[v as usize]);
                    }
                    new_of_root.push((r, nv));
                    nv
                }
            };
            let c = corners[i];
            let f = topo.corner_face[c as usize] as usize;
            let k = (c - topo.face_start[f]) as usize;
            mesh.faces[f][k] = nv;
        }
        if !new_of_root.is_empty() {
            added += new_of_root.len();
            split.push(Element::Vertex {
                index: v,
                line: mesh.vertex_lines[v as usize],
            });
        }
    }
    if !split.is_empty() {
        report.add(
            FindingKind::SplitVertex,
            format!(
                "{} vertices had faces in several edge-connected fans (surfaces touching at a \
                 point); split into one vertex per fan ({added} vertices added at the end)",
                split.len()
            ),
            split,
        );
    }
    added
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn bow_tie_is_split_and_a_fan_is_not() {
        // Two triangles touching at vertex 0 only.
        let p = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(-1.0, -1.0, 0.0),
        ];
        let mut m = Mesh::new(p, vec![vec![0, 1, 2], vec![0, 3, 4]]);
        let mut r = Report::default();
        assert_eq!(split_vertex_fans(&mut m, &mut r), 1);
        assert_eq!(m.faces, vec![vec![0, 1, 2], vec![5, 3, 4]]);
        // Moved 1e-6 of the way to the centroid (−1, −0.5, 0) of its fan's other corners.
        assert_ne!(m.positions[5], DVec3::ZERO);
        assert!((m.positions[5] - DVec3::new(-1e-6, -0.5e-6, 0.0)).length() < 1e-15);
        assert_eq!(m.vertex_lines.len(), 6);
        let f = r.get(FindingKind::SplitVertex).expect("finding");
        assert_eq!(f.elements, vec![Element::Vertex { index: 0, line: 0 }]);
        // Two triangles sharing an edge: one fan at every vertex, nothing changes.
        let mut fan = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ONE],
            vec![vec![0, 1, 2], vec![2, 1, 3]],
        );
        let before = fan.clone();
        let mut r = Report::default();
        assert_eq!(split_vertex_fans(&mut fan, &mut r), 0);
        assert_eq!(fan, before);
        assert!(r.findings.is_empty());
    }
}

//! What the 1994 schemes need from the mesh, said in one error: a closed 2-manifold.
//!
//! The inner hull cuts every corner of a polyhedron (Algorithm 1); an open mesh has corners
//! with an open fan, and a vertex where two surfaces touch at a point (a non-manifold vertex,
//! split into one vertex per fan on loading, `mesh::split`) has two. The generic validation
//! error names only the first problem found; this one names every boundary loop (its length,
//! its first edge and that edge's line), every vertex that was non-manifold in the file (index
//! and line), and what to do about them.

use crate::error::{Error, Result};
use crate::mesh::{Element, FindingKind, Mesh, Report, Topology};

/// Loops of boundary edges of `mesh`: each as its vertices in order (an open fan's boundary
/// walk; every vertex with one outgoing boundary edge).
#[must_use]
pub fn boundary_loops(mesh: &Mesh) -> Vec<Vec<u32>> {
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    // Boundary half-edges a → b (the face's own direction), keyed by a.
    let mut next: std::collections::BTreeMap<u32, Vec<u32>> = std::collections::BTreeMap::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let start = topo.face_start[f] as usize;
        for k in 0..face.len() {
            let e = topo.corner_edge[start + k];
            if topo.is_boundary_edge(e) {
                next.entry(face[k])
                    .or_default()
                    .push(face[(k + 1) % face.len()]);
            }
        }
    }
    let mut loops = Vec::new();
    while let Some((&a, _)) = next.iter().find(|(_, v)| !v.is_empty()) {
        let mut walk = vec![a];
        let mut at = a;
        while let Some(b) = next.get_mut(&at).and_then(Vec::pop) {
            if b == a {
                break;
            }
            walk.push(b);
            at = b;
        }
        loops.push(walk);
    }
    loops
}

/// Accepts `mesh` (loaded with `report`) for the 1994 schemes, or explains in one error why
/// not: the boundary loops and the non-manifold vertices (those split on loading as well as
/// those kept), each with its file line, and what to do. Other problems (non-manifold edges,
/// non-orientable parts) are [`Report::require`]'s errors.
///
/// # Errors
/// The mesh is open, non-manifold or non-orientable, naming the file.
pub fn require_closed(mesh: &Mesh, report: &Report) -> Result<()> {
    let loops = boundary_loops(mesh);
    let vertices: Vec<Element> = [FindingKind::SplitVertex, FindingKind::NonManifoldVertex]
        .iter()
        .filter_map(|&k| report.get(k))
        .flat_map(|f| f.elements.iter().copied())
        .collect();
    if loops.is_empty() && vertices.is_empty() {
        return report.require(true);
    }
    let line_of = |v: u32| mesh.vertex_lines.get(v as usize).copied().unwrap_or(0);
    let mut parts = Vec::new();
    if !loops.is_empty() {
        let edges: usize = loops.iter().map(Vec::len).sum();
        let listed: Vec<String> = loops
            .iter()
            .map(|l| {
                format!(
                    "{} edges from vertex {} (line {})",
                    l.len(),
                    l[0],
                    line_of(l[0])
                )
            })
            .collect();
        parts.push(format!(
            "it is open: {edges} boundary edges in {} loop{} ({})",
            loops.len(),
            if loops.len() == 1 { "" } else { "s" },
            listed.join("; ")
        ));
    }
    if !vertices.is_empty() {
        let listed: Vec<String> = vertices.iter().map(ToString::to_string).collect();
        parts.push(format!(
            "{} non-manifold (surfaces touching at a point; split into one vertex per fan on \
             loading, which leaves each fan's corner open or pinched): {}",
            if vertices.len() == 1 {
                "a vertex is".to_string()
            } else {
                format!("{} vertices are", vertices.len())
            },
            listed.join(", ")
        ));
    }
    Err(Error::Input {
        path: report.path.clone().into(),
        message: format!(
            "the 1994 schemes (cubic-c1, quintic-c2) need a closed 2-manifold polyhedron, and \
             {}. To use them, close every boundary loop with faces and separate the surfaces \
             at the non-manifold vertices in the model; or use `type = \"rational-c1\"`, which \
             accepts boundary edges and non-manifold vertices",
            parts.join("; and ")
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// An open cube (top missing): one loop of 4 edges, named with its length; a closed cube
    /// passes.
    #[test]
    fn open_box_names_its_loop() {
        let positions: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2)))
            .collect();
        let all = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        let closed = Mesh::new(positions.clone(), all.clone());
        assert!(boundary_loops(&closed).is_empty());
        assert!(require_closed(&closed, &Report::default()).is_ok());
        let open = Mesh::new(
            positions,
            all[..1].iter().chain(&all[2..]).cloned().collect(),
        );
        let loops = boundary_loops(&open);
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 4);
        let e = require_closed(&open, &Report::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("4 boundary edges in 1 loop (4 edges from vertex")
                && e.contains("rational-c1"),
            "{e}"
        );
    }
}

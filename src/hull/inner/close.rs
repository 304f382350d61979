//! Near-duplicate corners merged into one corner of T (opt-in, `scheme.merge_close`).
//!
//! Why: subdivision control cages make creases with rings of near-duplicate vertices joined by
//! sliver faces (spot_control_cage's horn bases: pairs 85/86, 87/88, 89/90 and the cluster
//! 91/92/94, 0.003–0.012 apart, against quads 0.1–0.4 long; a Catmull–Clark crease trick).
//! Algorithm 1 cuts each of those corners on its own. They are unseparable (C_0 = V), so the
//! two fans of a close pair share the sliver faces' centroids and fold back onto each other:
//! at edge 87–88 the hull triangles [C_0(87), G_60, C_62] and [C_0(88), C_62, G_60] nearly
//! coincide with opposite orientations, and their face and edge tetrahedra overlap (1641 of
//! the cage's 2261 overlaps). No flip of T's edges helps there (`unfold` refuses the flip to
//! C_0(87)C_0(88): it adds a fold), because the two corners are closer than anything the
//! hull can resolve between them.
//!
//! What: vertices of one polygon closer than `t` × the bounding-box diagonal are merged, on the
//! mesh the hull is built from, into the cluster's lowest-numbered vertex; the polyhedron's
//! vertices are not moved (the representative keeps its place, the others drop out of the
//! hull's mesh and are no corners of T). Faces lose their repeated corners (and back-and-forth
//! spikes x, y, x); faces with fewer than three corners left (the slivers) are dropped. The
//! representative's normal is the normalised sum of the cluster's normals. The result must be
//! a closed, oriented 2-manifold again, else the merge is an error naming the cluster.
//! The surface then interpolates T of the merged polyhedron: it passes through the
//! representative (when unseparable) within `t` × the diagonal of every merged vertex.

use crate::error::{Error, Result};
use crate::mesh::topology::UnionFind;
use crate::mesh::{Mesh, Topology};
use glam::DVec3;
use std::collections::HashMap;

/// The hull's mesh after [`merge_close_vertices`].
#[derive(Clone, Debug)]
pub struct CloseMerge {
    /// Same positions, vertex lines and vertex numbering as the input; faces without the
    /// merged vertices (`face_parent`: the input face each one comes from).
    pub mesh: Mesh,
    /// Normals: the input's, with each cluster's sum (normalised) at its representative.
    pub normals: Vec<DVec3>,
    /// Every cluster of more than one vertex, representative first, ascending.
    pub clusters: Vec<Vec<u32>>,
    /// Input faces dropped (fewer than three distinct corners left).
    pub dropped_faces: Vec<u32>,
}

/// `face` with merged corners: representatives substituted, cyclic repeats and spikes
/// (x, y, x) removed ([`crate::mesh::clean::collapse`]).
fn collapse(face: &[u32], rep: &[u32]) -> Vec<u32> {
    let f: Vec<u32> = face.iter().map(|&v| rep[v as usize]).collect();
    crate::mesh::clean::collapse(&f)
}

/// Merges the vertices of `mesh` that share a polygon and lie closer than `t` × the bounding
/// box diagonal (module docs). `None` when `t` ≤ 0 or nothing is that close. `normals` may be
/// empty (then so are the returned ones) when only the mesh is wanted.
///
/// # Errors
/// A merge that leaves a face with a repeated corner, or a mesh that is no closed, oriented
/// 2-manifold, naming the cluster (vertices and lines) and the threshold.
pub fn merge_close_vertices(mesh: &Mesh, normals: &[DVec3], t: f64) -> Result<Option<CloseMerge>> {
    if t.is_nan() || t <= 0.0 {
        return Ok(None);
    }
    let nv = mesh.positions.len();
    let reach = t * crate::mesh::geometry::bbox_diagonal(&mesh.positions);
    let mut uf = UnionFind::new(nv);
    let mut any = false;
    for face in &mesh.faces {
        for (i, &a) in face.iter().enumerate() {
            for &b in &face[i + 1..] {
                let d = mesh.positions[a as usize].distance(mesh.positions[b as usize]);
                if a != b && d < reach {
                    uf.union(a, b);
                    any = true;
                }
            }
        }
    }
    if !any {
        return Ok(None);
    }
    // Representative: the lowest vertex of each cluster.
    let mut members: HashMap<u32, Vec<u32>> = HashMap::new();
    for v in 0..nv as u32 {
        members.entry(uf.find(v)).or_default().push(v);
    }
    let mut rep: Vec<u32> = (0..nv as u32).collect();
    let mut clusters: Vec<Vec<u32>> = members.into_values().filter(|c| c.len() > 1).collect();
    for c in &mut clusters {
        c.sort_unstable();
        for &v in &c[1..] {
            rep[v as usize] = c[0];
        }
    }
    clusters.sort_unstable();
    let lines = |c: &[u32]| -> String {
        c.iter()
            .map(|&v| {
                format!(
                    "{v} (line {})",
                    mesh.vertex_lines.get(v as usize).copied().unwrap_or(0)
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let cluster_of = |v: u32| -> Vec<u32> {
        clusters
            .iter()
            .find(|c| c.contains(&v))
            .cloned()
            .unwrap_or_else(|| vec![v])
    };
    let why = |v: u32, what: &str| {
        Error::Invalid(format!(
            "merge_close = {t}: merging vertices {} (closer than {reach:.3e}) {what}; \
             use a smaller `scheme.merge_close`",
            lines(&cluster_of(v))
        ))
    };
    let mut out = Mesh {
        positions: mesh.positions.clone(),
        faces: Vec::with_capacity(mesh.faces.len()),
        file_normals: None,
        vertex_lines: mesh.vertex_lines.clone(),
        face_lines: Vec::with_capacity(mesh.faces.len()),
        face_parent: Vec::with_capacity(mesh.faces.len()),
    };
    let mut dropped_faces = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let g = collapse(face, &rep);
        if g.len() < 3 {
            dropped_faces.push(f as u32);
            continue;
        }
        let mut sorted = g.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(why(w[0], &format!("leaves face {f} touching itself")));
        }
        out.faces.push(g);
        out.face_lines
            .push(mesh.face_lines.get(f).copied().unwrap_or(0));
        out.face_parent
            .push(mesh.face_parent.get(f).copied().unwrap_or(f as u32));
    }
    // Closed, oriented 2-manifold: every directed edge once, its reverse once; one closed fan
    // round every corner.
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for g in &out.faces {
        for k in 0..g.len() {
            *directed.entry((g[k], g[(k + 1) % g.len()])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        if n != 1 || !directed.contains_key(&(b, a)) {
            return Err(why(a, &format!("leaves edge {a}–{b} non-manifold")));
        }
    }
    let topo = Topology::new(nv, &out.faces);
    for c in &clusters {
        if !topo.vertex_fan(c[0]).is_some_and(|fan| fan.closed) {
            return Err(why(c[0], "leaves a corner that is not one closed fan"));
        }
    }
    let mut merged_normals = normals.to_vec();
    for c in &clusters {
        let sum: DVec3 = c.iter().filter_map(|&v| normals.get(v as usize)).sum();
        if let (Some(n), Some(slot)) = (sum.try_normalize(), merged_normals.get_mut(c[0] as usize))
        {
            *slot = n;
        }
    }
    Ok(Some(CloseMerge {
        mesh: out,
        normals: merged_normals,
        clusters,
        dropped_faces,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Repeats and spikes go; a sliver quad collapses to two corners.
    #[test]
    fn collapse_removes_repeats_and_spikes() {
        let rep = [0, 1, 1, 3, 4, 3];
        assert_eq!(collapse(&[0, 1, 2, 3], &rep), vec![0, 1, 3]);
        // [3, 4, 5(→3), 1] is a spike 3, 4, 3 on the edge 3–1.
        assert_eq!(collapse(&[3, 4, 5, 1], &rep), vec![3, 1]);
        assert_eq!(collapse(&[1, 2, 3, 5], &rep), vec![1, 3]);
    }
}

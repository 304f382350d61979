//! Consistent and outward orientation of the faces.
//!
//! Faces are linked across edges with exactly two faces. Within each linked component the
//! orientation of the majority of faces is kept and the others are flipped so that every shared
//! edge is traversed once in each direction; a conflict means the component is not orientable.
//! Afterwards every closed, orientable component with negative signed volume is flipped so its
//! faces are counter-clockwise seen from outside.

use super::geometry::area_vector;
use super::report::{Element, FindingKind, Report};
use super::topology::Topology;
use super::Mesh;
use glam::DVec3;

/// Makes the orientation consistent, then outward; records what it changed in `report`.
/// Returns the mesh's topology when no face changed (so it need not be rebuilt).
pub fn orient(mesh: &mut Mesh, report: &mut Report) -> Option<Topology> {
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let n_faces = mesh.faces.len();
    const UNSEEN: u32 = u32::MAX;
    let mut component = vec![UNSEEN; n_faces];
    let mut flip = vec![false; n_faces];
    let mut stack = Vec::new();
    let mut flipped = Vec::new();
    let mut non_orientable = Vec::new();
    let mut inward = Vec::new();
    let mut n_components = 0u32;
    for seed in 0..n_faces {
        if component[seed] != UNSEEN {
            continue;
        }
        let id = n_components;
        n_components += 1;
        component[seed] = id;
        stack.push(seed as u32);
        let mut members = Vec::new();
        let mut conflict = false;
        let mut closed = true;
        while let Some(f) = stack.pop() {
            members.push(f);
            let (s, e) = (topo.face_start[f as usize], topo.face_start[f as usize + 1]);
            for c in s..e {
                let o = topo.corner_mate[c as usize];
                if o == u32::MAX {
                    closed = false;
                    continue;
                }
                let g = topo.corner_face[o as usize];
                // Same direction in both faces means one of them must be flipped.
                let same = topo.corner_vertex[o as usize] == topo.corner_vertex[c as usize];
                let want = flip[f as usize] ^ same;
                if component[g as usize] == UNSEEN {
                    component[g as usize] = id;
                    flip[g as usize] = want;
                    stack.push(g);
                } else if flip[g as usize] != want {
                    conflict = true;
                }
            }
        }
        // Keep the majority's orientation.
        let n_flip = members.iter().filter(|&&f| flip[f as usize]).count();
        if 2 * n_flip > members.len() {
            for &f in &members {
                flip[f as usize] = !flip[f as usize];
            }
        }
        if conflict {
            non_orientable.extend(members.iter().copied());
            continue;
        }
        for &f in &members {
            if flip[f as usize] {
                mesh.faces[f as usize].reverse();
                flipped.push(f);
            }
        }
        if closed && signed_volume(mesh, &members) < 0.0 {
            for &f in &members {
                mesh.faces[f as usize].reverse();
            }
            inward.extend(members.iter().copied());
        }
    }
    let face_elements = |mesh: &Mesh, mut faces: Vec<u32>| -> Vec<Element> {
        faces.sort_unstable();
        faces
            .into_iter()
            .map(|f| Element::Face {
                index: f,
                line: mesh.face_lines[f as usize],
            })
            .collect()
    };
    let unchanged = flipped.is_empty() && inward.is_empty();
    if !flipped.is_empty() {
        let n = flipped.len();
        report.add(
            FindingKind::InconsistentOrientation,
            format!("{n} faces were oriented against their neighbours; flipped"),
            face_elements(mesh, flipped),
        );
    }
    if !non_orientable.is_empty() {
        let n = non_orientable.len();
        report.add(
            FindingKind::NonOrientable,
            format!("{n} faces form a non-orientable surface; left as in the file"),
            face_elements(mesh, non_orientable),
        );
    }
    if !inward.is_empty() {
        let n = inward.len();
        report.add(
            FindingKind::InwardOrientation,
            format!("closed surface oriented inwards; all {n} of its faces flipped"),
            face_elements(mesh, inward),
        );
    }
    unchanged.then_some(topo)
}

/// Signed volume enclosed by `faces` (positive when they face outwards), computed about their
/// centroid to limit cancellation.
#[must_use]
pub fn signed_volume(mesh: &Mesh, faces: &[u32]) -> f64 {
    let mut c = DVec3::ZERO;
    let mut n = 0.0;
    for &f in faces {
        for &v in &mesh.faces[f as usize] {
            c += mesh.positions[v as usize];
            n += 1.0;
        }
    }
    let c = c / n;
    let mut vol = 0.0;
    for &f in faces {
        let face = &mesh.faces[f as usize];
        let p0 = mesh.positions[face[0] as usize] - c;
        // Volume of the cone from c over the face = (p0 − c) · area vector / 3.
        vol += p0.dot(area_vector(&mesh.positions, face)) / 3.0;
    }
    vol
}

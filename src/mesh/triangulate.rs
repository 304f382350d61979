//! Triangulation of polygon faces by ear clipping in the face plane (non-convex polygons
//! respected; never a naive fan).

use super::geometry::area_vector;
use super::Mesh;
use glam::{DVec2, DVec3};

/// Splits every polygon face into triangles. Triangles keep their face's orientation; vertices,
/// file normals and vertex lines are unchanged; `face_lines` and `face_parent` of each triangle
/// are those of its polygon (so `face_parent` maps triangle → original face).
#[must_use]
pub fn triangulate(mesh: &Mesh) -> Mesh {
    let mut faces = Vec::with_capacity(mesh.faces.len() * 2);
    let mut face_lines = Vec::with_capacity(mesh.faces.len() * 2);
    let mut face_parent = Vec::with_capacity(mesh.faces.len() * 2);
    let mut scratch = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let before = faces.len();
        if face.len() == 3 {
            faces.push(face.clone());
        } else {
            ear_clip(&mesh.positions, face, &mut scratch, &mut faces);
        }
        for _ in before..faces.len() {
            face_lines.push(mesh.face_lines[f]);
            face_parent.push(mesh.face_parent[f]);
        }
    }
    Mesh {
        positions: mesh.positions.clone(),
        faces,
        file_normals: mesh.file_normals.clone(),
        vertex_lines: mesh.vertex_lines.clone(),
        face_lines,
        face_parent,
    }
}

/// Ear clipping of one polygon (vertex indices `face`) projected onto the plane normal to its
/// area vector. Pushes `face.len() − 2` triangles onto `out`. An ear is a convex corner whose
/// triangle contains no other polygon vertex, not even on its sides up to a rounding tolerance
/// (1e-12 of the polygon's size squared, so a vertex exactly on a diagonal in 3D, like the
/// collinear notch of mpi_poly.obj's face 15, still blocks the ear after projection to 2D and
/// cannot end in a zero-area triangle); when rounding leaves no strict ear (nearly degenerate
/// input), the most convex corner is clipped so the count is always right.
pub fn ear_clip(
    positions: &[DVec3],
    face: &[u32],
    scratch: &mut Vec<DVec2>,
    out: &mut Vec<Vec<u32>>,
) {
    let n = face.len();
    // Project onto an orthonormal basis (u, v) of the face plane, so CCW about the normal is
    // CCW in 2D.
    let normal = area_vector(positions, face)
        .try_normalize()
        .unwrap_or(DVec3::Z);
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let o = positions[face[0] as usize];
    scratch.clear();
    scratch.extend(face.iter().map(|&i| {
        let d = positions[i as usize] - o;
        DVec2::new(d.dot(u), d.dot(v))
    }));
    let p = &*scratch;
    // Doubly linked list of the remaining corners.
    let mut next: Vec<usize> = (0..n).map(|i| (i + 1) % n).collect();
    let mut prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let (lo, hi) = p
        .iter()
        .fold((p[0], p[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    let on = -1e-12 * (hi - lo).length_squared();
    let mut remaining = n;
    let mut i = 0usize;
    let mut since_clip = 0usize;
    while remaining > 3 {
        let (a, b, c) = (prev[i], i, next[i]);
        let is_ear = since_clip <= remaining && {
            cross(p[a], p[b], p[c]) > 0.0 && {
                // No other remaining vertex inside or on the triangle (a, b, c).
                let mut j = next[c];
                let mut clear = true;
                while j != a {
                    let q = p[j];
                    if cross(p[a], p[b], q) >= on
                        && cross(p[b], p[c], q) >= on
                        && cross(p[c], p[a], q) >= on
                        && q != p[a]
                        && q != p[c]
                    {
                        clear = false;
                        break;
                    }
                    j = next[j];
                }
                clear
            }
        };
        let clip = if is_ear {
            Some(b)
        } else if since_clip > remaining {
            // No strict ear found in a whole pass: clip the most convex corner.
            let mut best = i;
            let mut best_val = f64::NEG_INFINITY;
            let mut j = i;
            for _ in 0..remaining {
                let val = cross(p[prev[j]], p[j], p[next[j]]);
                if val > best_val {
                    best_val = val;
                    best = j;
                }
                j = next[j];
            }
            Some(best)
        } else {
            None
        };
        match clip {
            Some(b) => {
                let (a, c) = (prev[b], next[b]);
                out.push(vec![face[a], face[b], face[c]]);
                next[a] = c;
                prev[c] = a;
                remaining -= 1;
                since_clip = 0;
                i = a;
            }
            None => {
                i = next[i];
                since_clip += 1;
            }
        }
    }
    let b = i;
    out.push(vec![face[prev[b]], face[b], face[next[b]]]);
}

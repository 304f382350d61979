//! Corner guards of non-convex faces (§5, Definition 2.5) by convex decomposition.
//!
//! The paper notes (§4, after Theorem 4.1) that "the convex face restriction can be enforced by
//! subdividing nonconvex faces into convex ones". We do that: every non-convex polygon is
//! ear-clipped in its plane and the triangles are merged back greedily while the union stays
//! convex (Hertel–Mehlhorn, at most 4× the minimum number of pieces). The centroid of every piece
//! sees all of that piece's corners, so the piece centroids form a corner guard set; the dual tree
//! of the pieces (two pieces adjacent over a diagonal) is the corner guard net that the surface
//! interpolates (§7.2). Each piece keeps the normal of its polygon, so the edges of T inside the
//! polygon are zero convex (§5: "the edges in corner guard nets are zero convex by construction").
//!
//! Reflex corners (the hallway corner of step (3')) are split by a diagonal into corners of at
//! most π, so after the decomposition every vertex is handled by Algorithm 1's steps (3)–(5).

use crate::error::{Error, Result};
use crate::mesh::convexity::polygon_is_convex;
use crate::mesh::geometry::area_vector;
use crate::mesh::{ear_clip, Mesh};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// The faces Algorithm 1 runs on: convex polygons, each with its input polygon and that
/// polygon's unit normal.
#[derive(Clone, Debug, Default)]
pub struct Pieces {
    /// Convex polygons (vertex indices of the input mesh, counter-clockwise from outside).
    pub faces: Vec<Vec<u32>>,
    /// Input polygon of each piece.
    pub parent: Vec<u32>,
    /// Unit normal of each piece: its input polygon's area vector, normalised.
    pub normal: Vec<DVec3>,
    /// True for the pieces of a non-convex input polygon (their centroids are corner guards).
    pub guard: Vec<bool>,
    /// Input polygons that were split, with their number of pieces.
    pub split: Vec<(u32, usize)>,
}

/// Splits the non-convex polygons of `mesh` into convex pieces; convex polygons pass unchanged.
///
/// # Errors
/// A polygon with zero area (no normal), naming the face and its line.
pub fn convex_pieces(mesh: &Mesh) -> Result<Pieces> {
    let mut out = Pieces::default();
    let mut scratch = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let Some(normal) = area_vector(&mesh.positions, face).try_normalize() else {
            return Err(Error::Invalid(format!(
                "face {f} (line {}) has zero area: it has no normal for the inner hull",
                mesh.face_lines.get(f).copied().unwrap_or(0)
            )));
        };
        if face.len() == 3 || polygon_is_convex(&mesh.positions, face) {
            out.faces.push(face.clone());
            out.parent.push(f as u32);
            out.normal.push(normal);
            out.guard.push(false);
            continue;
        }
        let mut tris = Vec::new();
        ear_clip(&mesh.positions, face, &mut scratch, &mut tris);
        let pieces = merge_convex(&mesh.positions, normal, tris);
        out.split.push((f as u32, pieces.len()));
        for p in pieces {
            out.faces.push(p);
            out.parent.push(f as u32);
            out.normal.push(normal);
            out.guard.push(true);
        }
    }
    Ok(out)
}

/// Hertel–Mehlhorn: removes diagonals between triangles of one polygon while the union of the
/// two pieces on either side stays convex (in the plane normal to `normal`).
fn merge_convex(positions: &[DVec3], normal: DVec3, tris: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let flat = |i: u32| {
        let p = positions[i as usize];
        DVec2::new(p.dot(u), p.dot(v))
    };
    let mut pieces: Vec<Option<Vec<u32>>> = tris.into_iter().map(Some).collect();
    // Directed edge → piece holding it.
    let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
    for (k, p) in pieces.iter().enumerate() {
        let p = p.as_ref().expect("all pieces alive at start");
        for i in 0..p.len() {
            owner.insert((p[i], p[(i + 1) % p.len()]), k);
        }
    }
    let mut diagonals: Vec<(u32, u32)> = owner
        .keys()
        .filter(|&&(a, b)| a < b && owner.contains_key(&(b, a)))
        .copied()
        .collect();
    diagonals.sort_unstable();
    for (a, b) in diagonals {
        let (Some(&pa), Some(&pb)) = (owner.get(&(a, b)), owner.get(&(b, a))) else {
            continue;
        };
        if pa == pb {
            continue;
        }
        let (Some(p), Some(q)) = (pieces[pa].as_ref(), pieces[pb].as_ref()) else {
            continue;
        };
        // p holds a→b: walk p from b round to a; q holds b→a: add q's vertices strictly after a
        // up to (not including) b.
        let start = p.iter().position(|&x| x == b).expect("b in p");
        let mut merged: Vec<u32> = (0..p.len()).map(|i| p[(start + i) % p.len()]).collect();
        let qa = q.iter().position(|&x| x == a).expect("a in q");
        let mut i = (qa + 1) % q.len();
        while q[i] != b {
            merged.push(q[i]);
            i = (i + 1) % q.len();
        }
        if !is_convex_2d(&merged.iter().map(|&x| flat(x)).collect::<Vec<_>>()) {
            continue;
        }
        for i in 0..merged.len() {
            owner.insert((merged[i], merged[(i + 1) % merged.len()]), pa);
        }
        owner.remove(&(a, b));
        owner.remove(&(b, a));
        pieces[pa] = Some(merged);
        pieces[pb] = None;
    }
    pieces.into_iter().flatten().collect()
}

/// Every corner of the counter-clockwise polygon turns left or goes straight. Straightness is
/// judged relative to the corner's edge lengths (1e-12: rounding of the projection, not geometry).
fn is_convex_2d(p: &[DVec2]) -> bool {
    let n = p.len();
    (0..n).all(|i| {
        let a = p[(i + n - 1) % n];
        let b = p[i];
        let c = p[(i + 1) % n];
        let cross = (b - a).perp_dot(c - b);
        cross >= -1e-12 * (b - a).length() * (c - b).length()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L-shaped hexagon splits into two convex quadrilaterals that tile it (areas add up).
    #[test]
    fn l_shape_splits_into_two_convex_pieces() {
        let positions: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let mesh = Mesh::new(positions.clone(), vec![(0..6).collect()]);
        let pieces = convex_pieces(&mesh).unwrap();
        assert_eq!(pieces.faces.len(), 2);
        assert_eq!(pieces.split, vec![(0, 2)]);
        let area: f64 = pieces
            .faces
            .iter()
            .map(|f| {
                assert!(polygon_is_convex(&positions, f));
                area_vector(&positions, f).z
            })
            .sum();
        // Exact area 3; the pieces are made of the input vertices, so only rounding differs.
        assert!((area - 3.0).abs() < 1e-12);
    }
}

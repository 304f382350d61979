//! Corner guards of non-convex faces (§5, Definition 2.5).
//!
//! A star-shaped polygon (non-empty kernel: the points that see all of it) keeps a single corner
//! guard, the centroid of its kernel ([`kernel_guard`]) — "for a convex polygon or a star-shaped
//! polygon, a minimum corner guard set consists of just a single point" (§2). Its reflex
//! corners then stay trihedral and become Algorithm 2's hallway corners (step (3'), in
//! [`super::corner`]). Unless that guard is far from a corner ([`guard_is_near`]: more than
//! [`GUARD_REACH`] times the corner's longer edge; mpi_poly's face 7, kernel 14 % of an L
//! whose arm ends 18 away): long thin triangles of T from such a corner to the guard overlap
//! their neighbours, so the polygon is split like the others below and gets a corner guard net
//! with guards near their corners ([`super::guardnet`]; Appendix B's corner guard circles).
//!
//! Other non-convex polygons are split, as the paper allows (§4, after Theorem 4.1: "the convex
//! face restriction can be enforced by subdividing nonconvex faces into convex ones"): every
//! such polygon is ear-clipped in its plane and the triangles are merged back greedily while the
//! union stays convex (Hertel–Mehlhorn, at most 4× the minimum number of pieces). The centroid of
//! every piece sees all of that piece's corners, so the piece centroids form a corner guard set;
//! the dual tree of the pieces (two pieces adjacent over a diagonal) is the corner guard net
//! that the surface interpolates (§7.2). Each piece keeps the normal of its polygon, so the
//! edges of T inside the polygon are zero convex (§5: "the edges in corner guard nets are zero
//! convex by construction"). Reflex corners are split there by a diagonal into corners of at
//! most π, handled by Algorithm 1's steps (3)–(5); the hulls of such polygons still overlap
//! (letter_P_poly: see `scenes/pending/paper1994/README.md`).

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
    /// The point of T standing for each piece: the vertex mean of a convex piece, or the
    /// corner guard (in the polygon's plane) of a non-convex one.
    pub center: Vec<DVec3>,
    /// Non-convex input polygons kept whole because they are star shaped, with their single
    /// corner guard (a point in the interior of the kernel, which sees every corner).
    pub star: Vec<(u32, DVec3)>,
    /// Star-shaped polygons split anyway because their kernel guard is far from a corner
    /// ([`guard_is_near`]), with that guard (kept if no corner guard net is found).
    pub far_star: Vec<(u32, DVec3)>,
}

impl Pieces {
    /// The pieces with every polygon of `faces` (indices of `mesh`'s faces, listed in
    /// [`Pieces::far_star`]) whole again, with its kernel guard, as [`convex_pieces`] keeps a
    /// star-shaped polygon.
    #[must_use]
    pub fn restore_stars(&self, mesh: &Mesh, faces: &[u32]) -> Pieces {
        let mut out = Pieces {
            split: self
                .split
                .iter()
                .filter(|(f, _)| !faces.contains(f))
                .copied()
                .collect(),
            star: self.star.clone(),
            far_star: self
                .far_star
                .iter()
                .filter(|(f, _)| !faces.contains(f))
                .copied()
                .collect(),
            ..Pieces::default()
        };
        for p in 0..self.faces.len() {
            if faces.contains(&self.parent[p]) {
                continue;
            }
            out.faces.push(self.faces[p].clone());
            out.parent.push(self.parent[p]);
            out.normal.push(self.normal[p]);
            out.guard.push(self.guard[p]);
            out.center.push(self.center[p]);
        }
        for &(f, g) in &self.far_star {
            if !faces.contains(&f) {
                continue;
            }
            let Some(p) = self.parent.iter().position(|&x| x == f) else {
                continue;
            };
            out.faces.push(mesh.faces[f as usize].clone());
            out.parent.push(f);
            out.normal.push(self.normal[p]);
            out.guard.push(true);
            out.center.push(g);
            out.star.push((f, g));
        }
        out
    }
}

/// Smallest kernel area, relative to the polygon's area, for which a star-shaped polygon keeps
/// a single corner guard: below it the guard would sit within rounding of a reflex corner's
/// edge lines and the tetrahedra there would be thin, so the polygon is split instead.
pub const MIN_KERNEL_AREA: f64 = 1e-3;

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
        let mean = face
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .sum::<DVec3>()
            / face.len() as f64;
        if face.len() == 3 || polygon_is_convex(&mesh.positions, face) {
            out.faces.push(face.clone());
            out.parent.push(f as u32);
            out.normal.push(normal);
            out.guard.push(false);
            out.center.push(mean);
            continue;
        }
        let kernel = kernel_guard(&mesh.positions, face, normal)
            // Corner guards lie exactly in the polygon's plane (through its vertex mean).
            .map(|g| g - normal.dot(g - mean) * normal);
        if let Some(g) = kernel.filter(|&g| !guard_is_near(&mesh.positions, face, g)) {
            out.far_star.push((f as u32, g));
        }
        if let Some(g) = kernel.filter(|&g| guard_is_near(&mesh.positions, face, g)) {
            out.faces.push(face.clone());
            out.parent.push(f as u32);
            out.normal.push(normal);
            out.guard.push(true);
            out.center.push(g);
            out.star.push((f as u32, g));
            continue;
        }
        let mut tris = Vec::new();
        ear_clip(&mesh.positions, face, &mut scratch, &mut tris);
        let pieces = merge_convex(&mesh.positions, normal, tris);
        out.split.push((f as u32, pieces.len()));
        for p in pieces {
            let c = p.iter().map(|&v| mesh.positions[v as usize]).sum::<DVec3>() / p.len() as f64;
            out.center.push(c - normal.dot(c - mean) * normal);
            out.faces.push(p);
            out.parent.push(f as u32);
            out.normal.push(normal);
            out.guard.push(true);
        }
    }
    Ok(out)
}

/// How far a single corner guard may lie from a corner it serves, in units of the longer of
/// the corner's two edges.
pub const GUARD_REACH: f64 = 5.0;

/// True when every corner of `face` lies within [`GUARD_REACH`] of its longer edge's length of
/// the guard `g`.
#[must_use]
pub fn guard_is_near(positions: &[DVec3], face: &[u32], g: DVec3) -> bool {
    let n = face.len();
    (0..n).all(|k| {
        let p = |i: usize| positions[face[i % n] as usize];
        let v = p(k);
        let e = (p(k + 1) - v).length().max((p(k + n - 1) - v).length());
        (v - g).length() <= GUARD_REACH * e
    })
}

/// The centroid of the kernel of a star-shaped polygon (the points that see all of it: the
/// intersection of the inner half-planes of its edges), when the kernel has at least
/// [`MIN_KERNEL_AREA`] of the polygon's area; `None` otherwise. The centroid of a convex region
/// of positive area lies in its interior, so every corner is visible from it (Definition 2.5).
#[must_use]
pub fn kernel_guard(positions: &[DVec3], face: &[u32], normal: DVec3) -> Option<DVec3> {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let o = positions[face[0] as usize];
    let flat: Vec<DVec2> = face
        .iter()
        .map(|&i| {
            let p = positions[i as usize] - o;
            DVec2::new(p.dot(u), p.dot(v))
        })
        .collect();
    let area = polygon_area(&flat);
    if area <= 0.0 {
        return None;
    }
    let kernel = kernel_region(&flat)?;
    let ka = polygon_area(&kernel);
    if ka < MIN_KERNEL_AREA * area {
        return None;
    }
    // Area centroid of the kernel.
    let mut c = DVec2::ZERO;
    for k in 0..kernel.len() {
        let (p, q) = (kernel[k], kernel[(k + 1) % kernel.len()]);
        c += (p + q) * p.perp_dot(q);
    }
    c /= 6.0 * ka;
    Some(o + c.x * u + c.y * v)
}

/// The kernel of a counter-clockwise 2D polygon (the intersection of the inner half-planes of
/// its edges) as a convex polygon, or `None` when it has fewer than three corners (empty).
#[must_use]
pub fn kernel_region(flat: &[DVec2]) -> Option<Vec<DVec2>> {
    let n = flat.len();
    let (lo, hi) = flat.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    let mut kernel = vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    for i in 0..n {
        let (a, b) = (flat[i], flat[(i + 1) % n]);
        let inside = |p: DVec2| (b - a).perp_dot(p - a);
        let mut next = Vec::with_capacity(kernel.len() + 1);
        for k in 0..kernel.len() {
            let (p, q) = (kernel[k], kernel[(k + 1) % kernel.len()]);
            let (sp, sq) = (inside(p), inside(q));
            if sp >= 0.0 {
                next.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                next.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        kernel = next;
        if kernel.len() < 3 {
            return None;
        }
    }
    Some(kernel)
}

/// Signed area of a 2D polygon (positive counter-clockwise).
#[must_use]
pub fn polygon_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    0.5 * (0..n).map(|k| p[k].perp_dot(p[(k + 1) % n])).sum::<f64>()
}

/// Hertel–Mehlhorn: removes diagonals between convex polygons (triangles of one polygon, or
/// coplanar faces) while the union of the
/// two pieces on either side stays convex (in the plane normal to `normal`).
pub fn merge_convex(positions: &[DVec3], normal: DVec3, tris: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
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

    fn flat_mesh(pts: &[(f64, f64)]) -> Mesh {
        let positions: Vec<DVec3> = pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
        let n = positions.len() as u32;
        Mesh::new(positions, vec![(0..n).collect()])
    }

    /// An L-shaped hexagon is star shaped: it stays whole, with one corner guard at the centroid
    /// of its kernel, the unit square [0, 1]².
    #[test]
    fn l_shape_keeps_one_guard_in_its_kernel() {
        let mesh = flat_mesh(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]);
        let pieces = convex_pieces(&mesh).unwrap();
        assert_eq!(pieces.faces.len(), 1);
        assert!(pieces.split.is_empty());
        assert_eq!(pieces.star.len(), 1);
        assert!(pieces.guard[0]);
        // The kernel's centroid is (0.5, 0.5); clipping rounds at the 1e-16 level.
        assert!((pieces.center[0] - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-12);
    }

    /// A U-shaped octagon has an empty kernel (no point sees both prongs): it is split into
    /// convex pieces that tile it (areas add up).
    #[test]
    fn u_shape_splits_into_convex_pieces() {
        let pts = [
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 2.0),
            (2.0, 2.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let mesh = flat_mesh(&pts);
        let n = DVec3::Z;
        assert!(kernel_guard(&mesh.positions, &mesh.faces[0], n).is_none());
        let pieces = convex_pieces(&mesh).unwrap();
        assert!(pieces.faces.len() >= 3);
        assert_eq!(pieces.split, vec![(0, pieces.faces.len())]);
        let area: f64 = pieces
            .faces
            .iter()
            .map(|f| {
                assert!(polygon_is_convex(&mesh.positions, f));
                area_vector(&mesh.positions, f).z
            })
            .sum();
        // Exact area 5; the pieces are made of the input vertices, so only rounding differs.
        assert!((area - 5.0).abs() < 1e-12);
    }
}

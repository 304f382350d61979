//! Tessellation of a shooting-rule patch complex (2001 scheme, §5): every mesh triangle's
//! face patches are sampled on the triangular grid of their base, every mesh edge's edge patches
//! on a quad grid (x along the edge, y between the two face tetrahedra's tops).
//!
//! A surface point is the smallest root t ∈ [0, 1] of F along the shooting line from a base grid
//! point q to its top point. Watertightness comes from identity, not from tolerance:
//! - base grid points are computed canonically (a point on a segment from its lexicographically
//!   smaller end), so every patch sharing a segment gets bit-identical q's;
//! - surface points are cached by their shooting line (q, top), points with t = 0 (mesh vertices,
//!   planar faces) by q alone, and each (q, face) records the point its face used;
//! - the side (u or v tetrahedron) of a base point is decided once per q from the sign of F(q)
//!   (F(q) ≤ 0: positive side) and reused by every patch touching q;
//! - edge strips take their y = 0 / y = 1 rows from the two faces' recorded points; where no
//!   edge tetrahedron exists, the two rows are stitched directly.
//!
//! Each face's and edge's triangles are oriented together so that their geometric normals agree
//! with ∇F (outward: F > 0 outside). Vertex normals are ∇F/|∇F| (the complex's normals at mesh
//! vertices). Only [`SheetRule::Shooting`] complexes with the 2001 layouts (face: base [0,1,2]
//! top [3]; edge: base [0,1] top [2,3]) and planar patches are supported; anything else is an
//! error ("tessellation needs shooting-rule patches"). Mesh edges with one face (open meshes)
//! get no strip, so open inputs give open tessellations.

use crate::bb::uni::first_root;
use crate::bb::{index_of, Tet};
use crate::complex::{Patch, PatchComplex, Role, SheetRule};
use glam::DVec3;
use std::collections::HashMap;

/// A plain triangle mesh: positions, unit vertex normals and counter-clockwise (seen from
/// outside) triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Unit vertex normals (same length as `positions`).
    pub normals: Vec<[f64; 3]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Largest accepted resolution (grid intervals per edge); keeps the output within u32 indices.
pub const MAX_RESOLUTION: usize = 1024;

/// Exact identity of a point.
type Key = [u64; 3];

fn key(p: DVec3) -> Key {
    // +0.0 and −0.0 are the same point.
    [p.x, p.y, p.z].map(|v| (v + 0.0).to_bits())
}

/// The point k/n of the way along segment [a, b], computed from the lexicographically smaller
/// end so that both orientations give the same bits.
fn seg_point(a: DVec3, b: DVec3, k: usize, n: usize) -> DVec3 {
    if k == 0 {
        return a;
    }
    if k == n {
        return b;
    }
    let (lo, hi, k) = if key(a) <= key(b) {
        (a, b, k)
    } else {
        (b, a, n - k)
    };
    lo + (hi - lo) * (k as f64 / n as f64)
}

/// Base grid point (i, j, k), i + j + k = n, of triangle [p0 p1 p2] (weights i/n, j/n, k/n).
fn tri_point(p: [DVec3; 3], i: usize, j: usize, k: usize, n: usize) -> DVec3 {
    match (i, j, k) {
        (_, 0, 0) => p[0],
        (0, _, 0) => p[1],
        (0, 0, _) => p[2],
        (0, _, _) => seg_point(p[1], p[2], k, n),
        (_, 0, _) => seg_point(p[0], p[2], k, n),
        (_, _, 0) => seg_point(p[0], p[1], j, n),
        _ => (p[0] * i as f64 + p[1] * j as f64 + p[2] * k as f64) / n as f64,
    }
}

/// Side of a face or edge tetrahedron: 0 = positive (u, top weight > 0), 1 = negative (v).
fn side_of(p: &Patch) -> usize {
    let n = p.degree;
    // The weight at the (first) top vertex: (0,0,0,n) for faces, (0,0,n,0) for edges.
    let top = if p.role == Role::Edge {
        [0, 0, n, 0]
    } else {
        [0, 0, 0, n]
    };
    usize::from(p.weights[index_of(top)] < 0.0)
}

struct Builder<'a> {
    complex: &'a PatchComplex,
    tets: Vec<Option<Tet>>,
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    mesh_vertex: HashMap<Key, usize>,
    by_q: HashMap<Key, u32>,
    by_line: HashMap<(Key, Key), u32>,
    side: HashMap<Key, usize>,
    /// (q, face element) → the point that face used at q.
    face_point: HashMap<(Key, u32), u32>,
}

impl Builder<'_> {
    fn push(&mut self, p: DVec3, n: DVec3) -> u32 {
        let n = if n.length_squared() > 0.0 && n.is_finite() {
            n.normalize()
        } else {
            DVec3::Z
        };
        self.positions.push(p);
        self.normals.push(n);
        (self.positions.len() - 1) as u32
    }

    fn gradient(&self, patch: usize, x: DVec3) -> DVec3 {
        match &self.tets[patch] {
            Some(t) => t.world_gradient(self.complex.patches[patch].gradient_bary(t.bary(x))),
            None => DVec3::ZERO,
        }
    }

    /// The point q itself (on the surface there: a mesh vertex, a planar face, or t = 0).
    fn at_q(&mut self, q: DVec3, patch: usize) -> u32 {
        let k = key(q);
        if let Some(&i) = self.by_q.get(&k) {
            return i;
        }
        let n = match self.mesh_vertex.get(&k) {
            Some(&v) if v < self.complex.normals.len() => {
                DVec3::from_array(self.complex.normals[v])
            }
            _ => self.gradient(patch, q),
        };
        let i = self.push(q, n);
        self.by_q.insert(k, i);
        i
    }

    /// The surface point on the shooting line q → top of `patch` (top's barycentrics `a1`).
    fn on_line(&mut self, patch: usize, q: DVec3, top: DVec3, a1: [f64; 4]) -> Option<u32> {
        if self.mesh_vertex.contains_key(&key(q)) {
            return Some(self.at_q(q, patch));
        }
        let lk = (key(q), key(top));
        if let Some(&i) = self.by_line.get(&lk) {
            return Some(i);
        }
        let tet = self.tets[patch].as_ref()?;
        let p = &self.complex.patches[patch];
        let a0 = tet.bary(q);
        let mut c = [0.0; 16];
        let mut len = p.segment_poly_bary(a0, a1, &mut c);
        let wmax = p.weights.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        // |F| ≤ max|w| in the tetrahedron; this much of it is rounding: q is on the surface.
        let t = if p.value_bary(a0).abs() <= 1e-13 * wmax {
            0.0
        } else {
            // F(q) ≠ 0 but the cleared polynomial vanishes at t = 0: a rational denominator
            // vanishes on the base (edge tetrahedra). Divide the factor t out.
            let cmax = c[..len].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            while len > 1 && c[0].abs() <= 1e-13 * cmax {
                len = crate::bb::uni::deflate_at_zero(&mut c, len);
            }
            first_root(&c[..len])?
        };
        let i = if t <= 1e-12 {
            self.at_q(q, patch)
        } else {
            let x = q + (top - q) * t;
            let g = self.gradient(patch, x);
            self.push(x, g)
        };
        self.by_line.insert(lk, i);
        Some(i)
    }

    fn value(&self, patch: usize, q: DVec3) -> f64 {
        match &self.tets[patch] {
            Some(t) => self.complex.patches[patch].value_bary(t.bary(q)),
            None => 0.0,
        }
    }

    /// Adds triangles of one face or strip, oriented together so their normals agree with ∇F.
    fn emit(&mut self, tris: &[[u32; 3]]) {
        let mut vote = 0.0;
        let kept: Vec<[u32; 3]> = tris
            .iter()
            .copied()
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        for t in &kept {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n: DVec3 = t.iter().map(|&i| self.normals[i as usize]).sum();
            vote += (b - a).cross(c - a).dot(n);
        }
        for t in kept {
            self.triangles
                .push(if vote < 0.0 { [t[0], t[2], t[1]] } else { t });
        }
    }
}

/// Tessellates `complex` with `resolution` grid intervals per patch edge.
///
/// # Errors
/// A resolution outside 1..=[`MAX_RESOLUTION`] or one that could give more than `i32::MAX`
/// vertices, or a complex that is not made of shooting-rule
/// face/edge patches and planar patches ("tessellation needs shooting-rule patches").
pub fn tessellate(complex: &PatchComplex, resolution: usize) -> anyhow::Result<TriMesh> {
    let n = resolution;
    if n == 0 || n > MAX_RESOLUTION {
        anyhow::bail!("resolution must be in 1..={MAX_RESOLUTION}, got {n}");
    }
    // Every patch contributes at most (n+1)(n+2)/2 new points (edge strips (n+1)², fewer).
    let bound = complex.patches.len().saturating_mul((n + 1) * (n + 1));
    if bound > i32::MAX as usize {
        anyhow::bail!(
            "resolution {n} on {} patches could exceed {} vertices; use a smaller resolution",
            complex.patches.len(),
            i32::MAX
        );
    }
    let face_rule = SheetRule::Shooting {
        base: [0, 1, 2].into(),
        top: [3].into(),
    };
    let edge_rule = SheetRule::Shooting {
        base: [0, 1].into(),
        top: [2, 3].into(),
    };
    let mut faces: Vec<usize> = Vec::new();
    let mut edges: Vec<usize> = Vec::new();
    let mut planars: Vec<usize> = Vec::new();
    for (i, p) in complex.patches.iter().enumerate() {
        match (p.role, &p.sheet) {
            (Role::Planar, _) => planars.push(i),
            (Role::Face, r) if *r == face_rule => faces.push(i),
            (Role::Edge, r) if *r == edge_rule => edges.push(i),
            _ => anyhow::bail!(
                "tessellation needs shooting-rule patches (rational-c1 scheme); patch {i} \
                 (role {}) has another sheet rule or layout",
                p.role.name()
            ),
        }
    }
    let tets: Vec<Option<Tet>> = complex.patches.iter().map(Patch::tet).collect();
    let mut b = Builder {
        complex,
        tets,
        positions: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::new(),
        mesh_vertex: complex
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| (key(DVec3::from_array(*v)), i))
            .collect(),
        by_q: HashMap::new(),
        by_line: HashMap::new(),
        side: HashMap::new(),
        face_point: HashMap::new(),
    };
    let pts = |p: usize| complex.patches[p].tet_points();

    // Face patches grouped by their base triangle: [positive, negative] side.
    let mut groups: Vec<([Key; 3], [Option<usize>; 2])> = Vec::new();
    let mut group_of: HashMap<[Key; 3], usize> = HashMap::new();
    for &f in &faces {
        let t = pts(f);
        let k = [key(t[0]), key(t[1]), key(t[2])];
        let g = *group_of.entry(k).or_insert_with(|| {
            groups.push((k, [None, None]));
            groups.len() - 1
        });
        groups[g].1[side_of(&complex.patches[f])] = Some(f);
    }
    // Mesh edges (both ends mesh vertices) → the face elements around them.
    let mut edge_faces: HashMap<(Key, Key), (DVec3, DVec3, Vec<u32>)> = HashMap::new();
    let mut note_edge = |a: DVec3, c: DVec3, element: u32, mv: &HashMap<Key, usize>| {
        if !(mv.contains_key(&key(a)) && mv.contains_key(&key(c))) {
            return;
        }
        let (lo, hi) = if key(a) <= key(c) { (a, c) } else { (c, a) };
        let e = edge_faces
            .entry((key(lo), key(hi)))
            .or_insert((lo, hi, Vec::new()));
        if !e.2.contains(&element) {
            e.2.push(element);
        }
    };
    let mut top_face: HashMap<Key, u32> = HashMap::new();

    for (_, sides) in &groups {
        let first = sides[0].or(sides[1]).expect("group has a patch");
        let element = complex.patches[first].element;
        let base = pts(first);
        let p3 = [base[0], base[1], base[2]];
        for s in sides.iter().flatten() {
            top_face.insert(key(pts(*s)[3]), element);
        }
        for (a, c) in [(0, 1), (1, 2), (2, 0)] {
            note_edge(p3[a], p3[c], element, &b.mesh_vertex);
        }
        let index = tri_grid(p3, n, |q| {
            let qk = key(q);
            let s = match b.side.get(&qk) {
                Some(&s) if sides[s].is_some() => s,
                _ => {
                    let s = if b.value(first, q) <= 0.0 { 0 } else { 1 };
                    let s = if sides[s].is_some() { s } else { 1 - s };
                    b.side.entry(qk).or_insert(s);
                    s
                }
            };
            let pa = sides[s].expect("side exists");
            let top = pts(pa)[3];
            let v = match b.on_line(pa, q, top, [0.0, 0.0, 0.0, 1.0]) {
                Some(v) => Some(v),
                None => sides[1 - s].and_then(|o| b.on_line(o, q, pts(o)[3], [0.0, 0.0, 0.0, 1.0])),
            }
            .unwrap_or_else(|| b.at_q(q, pa));
            b.face_point.entry((qk, element)).or_insert(v);
            v
        });
        b.emit(&grid_triangles(&index, n));
    }

    for &pl in &planars {
        let t = pts(pl);
        let p3 = [t[0], t[1], t[2]];
        let element = complex.patches[pl].element;
        for (a, c) in [(0, 1), (1, 2), (2, 0)] {
            note_edge(p3[a], p3[c], element, &b.mesh_vertex);
        }
        let index = tri_grid(p3, n, |q| {
            let v = b.at_q(q, pl);
            b.face_point.entry((key(q), element)).or_insert(v);
            v
        });
        b.emit(&grid_triangles(&index, n));
    }

    // Edge patches by mesh edge: [positive, negative] side.
    let mut edge_patches: HashMap<(Key, Key), [Option<usize>; 2]> = HashMap::new();
    for &e in &edges {
        let t = pts(e);
        let (a, c) = (key(t[0]), key(t[1]));
        let k = if a <= c { (a, c) } else { (c, a) };
        edge_patches.entry(k).or_default()[side_of(&complex.patches[e])] = Some(e);
    }
    let mut edge_list: Vec<_> = edge_faces.into_iter().collect();
    edge_list.sort_by_key(|x| x.0);
    for (ek, (lo, hi, elems)) in edge_list {
        if elems.len() != 2 {
            continue; // boundary (or non-manifold) edge: nothing to stitch
        }
        let ep = edge_patches.get(&ek).copied().unwrap_or_default();
        // Faces A and B in the edge tetrahedra's order when there are any.
        let (fa, fb) = match ep[0].or(ep[1]) {
            Some(e) => {
                let t = pts(e);
                match (top_face.get(&key(t[2])), top_face.get(&key(t[3]))) {
                    (Some(&x), Some(&y)) => (x, y),
                    _ => (elems[0], elems[1]),
                }
            }
            None => (elems[0], elems[1]),
        };
        let mut cols: Vec<Vec<u32>> = Vec::with_capacity(n + 1);
        for k in 0..=n {
            let q = seg_point(lo, hi, k, n);
            let qk = key(q);
            let (Some(&va), Some(&vb)) = (b.face_point.get(&(qk, fa)), b.face_point.get(&(qk, fb)))
            else {
                anyhow::bail!("internal: face points missing on a mesh edge");
            };
            let mut col = vec![vb];
            if va != vb {
                let s = b.side.get(&qk).copied().unwrap_or(0);
                if let Some(e) = ep[s].or(ep[1 - s]) {
                    let t = pts(e);
                    // The edge tetrahedron's own A/B order decides which top is y = 1.
                    let a_first = top_face.get(&key(t[2])) == Some(&fa);
                    for l in 1..n {
                        let y = l as f64 / n as f64;
                        let (wa, wb) = if a_first { (y, 1.0 - y) } else { (1.0 - y, y) };
                        let top = t[2] * wa + t[3] * wb;
                        if let Some(v) = b.on_line(e, q, top, [0.0, 0.0, wa, wb]) {
                            col.push(v);
                        }
                    }
                }
            }
            col.push(va);
            col.dedup();
            cols.push(col);
        }
        let mut tris = Vec::new();
        for k in 0..n {
            strip_triangles(&cols[k], &cols[k + 1], &b.positions, &mut tris);
        }
        b.emit(&tris);
    }
    Ok(TriMesh {
        positions: b.positions.iter().map(|p| p.to_array()).collect(),
        normals: b.normals.iter().map(|p| p.to_array()).collect(),
        triangles: b.triangles,
    })
}

/// The vertex indices of the degree-`n` grid on triangle `p`: row i, entry j is `vertex` of
/// the grid point (i, j, n − i − j) ([`tri_point`]), visited row by row.
fn tri_grid(p: [DVec3; 3], n: usize, mut vertex: impl FnMut(DVec3) -> u32) -> Vec<Vec<u32>> {
    (0..=n)
        .map(|i| {
            (0..=n - i)
                .map(|j| vertex(tri_point(p, i, j, n - i - j, n)))
                .collect()
        })
        .collect()
}

/// Triangles of a triangular grid `index[i][j]` (i + j ≤ n), in base order.
fn grid_triangles(index: &[Vec<u32>], n: usize) -> Vec<[u32; 3]> {
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n - i {
            // Up triangle (i,j) (i-1... written in (i, j, k) with k implicit).
            tris.push([index[i + 1][j], index[i][j + 1], index[i][j]]);
            if i + j + 2 <= n {
                tris.push([index[i + 1][j], index[i + 1][j + 1], index[i][j + 1]]);
            }
        }
    }
    tris
}

/// Triangulates the band between two columns of points (possibly of different lengths) by
/// advancing along the shorter diagonal.
fn strip_triangles(a: &[u32], c: &[u32], pos: &[DVec3], out: &mut Vec<[u32; 3]>) {
    let (mut i, mut j) = (0, 0);
    while i + 1 < a.len() || j + 1 < c.len() {
        let advance_a = if i + 1 >= a.len() {
            false
        } else if j + 1 >= c.len() {
            true
        } else {
            let da = pos[a[i + 1] as usize].distance_squared(pos[c[j] as usize]);
            let dc = pos[a[i] as usize].distance_squared(pos[c[j + 1] as usize]);
            da <= dc
        };
        if advance_a {
            out.push([a[i], c[j], a[i + 1]]);
            i += 1;
        } else {
            out.push([a[i], c[j], c[j + 1]]);
            j += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{quadric_complex, Quadric};

    /// Both orientations of a segment give bit-identical grid points (the watertightness key).
    #[test]
    fn segment_points_do_not_depend_on_orientation() {
        let a = DVec3::new(0.1, -0.3, 0.7);
        let b = DVec3::new(-1.3, 0.37, 0.2);
        for n in 1..9 {
            for k in 0..=n {
                assert_eq!(key(seg_point(a, b, k, n)), key(seg_point(b, a, n - k, n)));
            }
        }
        let p = [a, b, DVec3::new(0.3, 0.3, 0.3)];
        let q = [b, p[2], a];
        // (i, j, k) of p is (j, k, i) of q.
        assert_eq!(key(tri_point(p, 2, 3, 0, 5)), key(tri_point(q, 3, 0, 2, 5)));
    }

    /// Single-sheet (`SheetRule::Any`) complexes are refused with the documented message.
    #[test]
    fn any_rule_complexes_are_refused() {
        let q = Quadric::sphere(DVec3::ZERO, 0.7);
        let c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 2, 2);
        let e = tessellate(&c, 2).unwrap_err().to_string();
        assert!(
            e.contains("tessellation needs shooting-rule patches"),
            "{e}"
        );
        let e = tessellate(&c, 0).unwrap_err().to_string();
        assert!(e.contains("resolution"), "{e}");
    }
}

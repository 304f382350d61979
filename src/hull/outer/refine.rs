//! Local refinement of §3.1: when two adjacent face tetrahedra intersect, the common edge is
//! split at its butterfly point (Dyn, Levin and Gregory 1990, tension w = 1/16) and both
//! triangles are split in two; the new vertex's normal is the same butterfly stencil applied to
//! the normals, normalised (n_a + n_b normalised when the stencil is incomplete or degenerate).
//! When the butterfly point would leave a corner normal on the wrong side of a new triangle,
//! the edge is split at its midpoint instead (the new triangles stay in the old planes and
//! n_a + n_b is above both).
//!
//! [`SplitRule::Midpoint`] always splits at the midpoint. It is the fallback of the rational
//! scheme's build when butterfly refinement does not converge: on coarse meshes with tight
//! curvature (the Utah teapot's rim lip and spout tip) the butterfly point of an edge along a
//! fold leaves the old triangles' planes and folds the new triangles against their other
//! neighbours, so each round makes more intersecting face tetrahedra than it removes
//! (teapot_newell.obj: 40 → 39 → 42 → 65 → 53 → 105 → 149), while midpoint splits make no new
//! fold and only shorten the triangles along it, which lowers their tetrahedra (40 → 2 → 0).

use super::{edge_map, NO_FACE};
use crate::error::Result;
use glam::DVec3;

/// A triangle mesh being refined, with each triangle's input triangle (`origin`).
#[derive(Clone, Debug, PartialEq)]
pub struct RefineMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Unit vertex normals.
    pub normals: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the index of the input triangle it came from.
    pub origin: Vec<u32>,
}

/// Where [`split_edges_with`] puts the new vertex of an edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitRule {
    /// The butterfly point (midpoint where it would put a normal below a new triangle).
    Butterfly,
    /// Always the midpoint, with normal n_a + n_b normalised.
    Midpoint,
}

/// Splits the given edges (edge indices in the numbering of [`edge_map`]) at their butterfly
/// points; edges whose triangle was already split in this call are skipped. Returns how many
/// edges were split.
pub fn split_edges(mesh: &mut RefineMesh, edges: &[u32]) -> Result<usize> {
    split_edges_with(mesh, edges, SplitRule::Butterfly)
}

/// [`split_edges`] with the given rule for the new points.
pub fn split_edges_with(mesh: &mut RefineMesh, edges: &[u32], rule: SplitRule) -> Result<usize> {
    let (emap, _) = edge_map(mesh.positions.len(), &mesh.triangles)?;
    let mut touched = vec![false; mesh.triangles.len()];
    let mut split = 0;
    let third = |tri: &[u32; 3], a: u32, b: u32| -> u32 {
        *tri.iter().find(|&&v| v != a && v != b).unwrap_or(&a)
    };
    // The wing vertex across edge (x, y) from triangle `f`.
    let wing = |f: u32, x: u32, y: u32, tris: &[[u32; 3]]| -> Option<u32> {
        let (_, faces) = emap
            .iter()
            .find(|(v, _)| (v[0] == x && v[1] == y) || (v[0] == y && v[1] == x))?;
        let g = if faces[0] == f { faces[1] } else { faces[0] };
        (g != NO_FACE).then(|| third(&tris[g as usize], x, y))
    };
    for &e in edges {
        let ([a, b], [f0, f1]) = emap[e as usize];
        if f1 == NO_FACE || touched[f0 as usize] || touched[f1 as usize] {
            continue;
        }
        let tris = mesh.triangles.clone();
        let k = third(&tris[f0 as usize], a, b);
        let l = third(&tris[f1 as usize], a, b);
        let wings = [
            wing(f0, a, k, &tris),
            wing(f0, b, k, &tris),
            wing(f1, a, l, &tris),
            wing(f1, b, l, &tris),
        ];
        let p = |i: u32| mesh.positions[i as usize];
        let n = |i: u32| mesh.normals[i as usize];
        let (pm, nm) = if rule == SplitRule::Butterfly && wings.iter().all(Option::is_some) {
            let w: Vec<u32> = wings.iter().map(|x| x.unwrap_or(a)).collect();
            let pm = 0.5 * (p(a) + p(b)) + 0.125 * (p(k) + p(l))
                - (p(w[0]) + p(w[1]) + p(w[2]) + p(w[3])) / 16.0;
            let nm = 0.5 * (n(a) + n(b)) + 0.125 * (n(k) + n(l))
                - (n(w[0]) + n(w[1]) + n(w[2]) + n(w[3])) / 16.0;
            (pm, nm)
        } else {
            (0.5 * (p(a) + p(b)), n(a) + n(b))
        };
        let nm = nm
            .try_normalize()
            .or_else(|| (n(a) + n(b)).try_normalize())
            .unwrap_or(n(a));
        // Every corner normal must stay strictly above the four new triangles; otherwise
        // split at the plain midpoint (new triangles in the old planes, normal n_a + n_b).
        let above = |pm: DVec3, nm: DVec3| -> bool {
            [(a, k), (b, k), (a, l), (b, l)].iter().all(|&(x, z)| {
                let f = (p(x) - pm).cross(p(z) - pm);
                let s = n(x) + n(z) + nm;
                let f = if f.dot(s) < 0.0 { -f } else { f };
                let Some(f) = f.try_normalize() else {
                    return false;
                };
                [n(x), n(z), nm].iter().all(|v| f.dot(*v) > 1e-9)
            })
        };
        let (pm, nm) = if above(pm, nm) {
            (pm, nm)
        } else {
            let mid = 0.5 * (p(a) + p(b));
            (mid, (n(a) + n(b)).try_normalize().unwrap_or(n(a)))
        };
        let m = mesh.positions.len() as u32;
        mesh.positions.push(pm);
        mesh.normals.push(nm);
        for f in [f0, f1] {
            let tri = mesh.triangles[f as usize];
            let c = (0..3)
                .find(|&c| {
                    let (x, y) = (tri[c], tri[(c + 1) % 3]);
                    (x == a && y == b) || (x == b && y == a)
                })
                .unwrap_or(0);
            let (x, y, z) = (tri[c], tri[(c + 1) % 3], tri[(c + 2) % 3]);
            mesh.triangles[f as usize] = [x, m, z];
            mesh.triangles.push([m, y, z]);
            mesh.origin.push(mesh.origin[f as usize]);
            touched[f as usize] = true;
            touched.push(true);
        }
        split += 1;
    }
    Ok(split)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn midpoint_split_keeps_planes_and_origins() {
        // Two triangles folded along the edge 0-1 (the x axis).
        let positions = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, -0.5, -0.8),
        ];
        let normals = vec![DVec3::Z; 4];
        let mut mesh = RefineMesh {
            positions,
            normals,
            triangles: vec![[0, 1, 2], [1, 0, 3]],
            origin: vec![0, 1],
        };
        let (emap, _) = edge_map(4, &mesh.triangles).unwrap();
        let e = emap
            .iter()
            .position(|(v, _)| v.contains(&0) && v.contains(&1));
        let n = split_edges_with(&mut mesh, &[e.unwrap() as u32], SplitRule::Midpoint).unwrap();
        assert_eq!(n, 1);
        assert_eq!(mesh.positions[4], DVec3::new(0.5, 0.0, 0.0));
        assert_eq!(mesh.normals[4], DVec3::Z);
        assert_eq!(mesh.triangles.len(), 4);
        assert_eq!(mesh.origin, vec![0, 1, 0, 1]);
        // Every new triangle lies in the plane of the triangle it came from (exact: the
        // midpoint of an axis edge and the old corners are representable).
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let q = tri.map(|i| mesh.positions[i as usize]);
            let nt = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
            let o = [[0, 1, 2], [1, 0, 3]][mesh.origin[t] as usize].map(|i| mesh.positions[i]);
            let no = (o[1] - o[0]).cross(o[2] - o[0]).normalize();
            assert!((nt.dot(no) - 1.0).abs() < 1e-12, "triangle {t}");
        }
    }
}

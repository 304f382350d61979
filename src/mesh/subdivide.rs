//! Approximating pre-subdivision of a triangle mesh (Loop 1987), the documented opt-in remedy
//! for coarse, folded meshes under the 2001 scheme.
//!
//! Why: §3.1 of Xu, Huang and Bajaj (2001) refines the common edge of two intersecting face
//! tetrahedra, but when the two triangles meet at a fold (90° and sharper between coarse
//! polygons, creases, non-planar control-cage quads) no split of that edge removes the fold:
//! the new triangles keep the old planes (midpoint) or fold against their other neighbours
//! (butterfly point). An *approximating* scheme moves the old vertices too and so spreads each
//! fold over the new rows of triangles: on a regular mesh every level roughly halves the
//! dihedral angle between adjacent triangles. After enough levels the hull's face tetrahedra
//! stop intersecting and the usual local refinement finishes the job.
//!
//! The price: the surface then interpolates the **subdivided** mesh (its vertices and normals),
//! not the input polyhedron, whose vertices move (Loop's vertex rule) and whose edges and
//! creases are rounded. Scenes opt in with `[model] subdivide = { rule = "loop", levels = N }`
//! and `apatch check` says so.
//!
//! Rules (Loop 1987; boundary rules as in Hoppe et al. 1994): each triangle becomes four.
//! - interior vertex of valence n: (1 − nβ) v + β Σ ring, β = (5/8 − (3/8 + cos(2π/n)/4)²)/n;
//! - interior edge [a b] with opposite vertices c, d: 3/8 (a + b) + 1/8 (c + d);
//! - boundary edge: (a + b)/2;
//! - boundary vertex with exactly two boundary edges (neighbours l, r): 3/4 v + 1/8 (l + r),
//!   the cubic B-spline rule, so the boundary curve is subdivided on its own;
//! - any other vertex on an edge that does not have two triangles (a corner of several
//!   boundary loops, a non-manifold edge): kept where it is.

use super::topology::Topology;
use super::Mesh;
use crate::error::{Error, Result};
use glam::DVec3;
use std::f64::consts::TAU;
use std::fmt;

/// The subdivision rules [`subdivide`] knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SubdivisionRule {
    /// Loop's approximating scheme for triangle meshes, with the boundary curve rules.
    Loop,
}

impl fmt::Display for SubdivisionRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SubdivisionRule::Loop => "loop",
        })
    }
}

/// A pre-subdivision request: the rule and how many levels (each multiplies the triangles by 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Subdivision {
    /// The rule.
    pub rule: SubdivisionRule,
    /// Levels, 0 (nothing) to [`Subdivision::MAX_LEVELS`].
    pub levels: u32,
}

impl Subdivision {
    /// The largest accepted number of levels (4^6 = 4096 triangles per input triangle).
    pub const MAX_LEVELS: u32 = 6;
}

/// β of Loop's vertex rule for an interior vertex of valence `n` (1/16 for n = 6).
#[must_use]
pub fn loop_beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 3.0 / 8.0 + 0.25 * (TAU / n).cos();
    (5.0 / 8.0 - c * c) / n
}

/// Applies `s.levels` levels of `s.rule` to a triangle mesh. Triangles keep their orientation;
/// `face_lines` and `face_parent` of each new triangle are those of the triangle it came from,
/// old vertices keep their `vertex_lines`, new (edge) vertices get line 0; file normals are
/// dropped (they belonged to the old vertices' positions).
///
/// # Errors
/// A face that is not a triangle (triangulate first), or more than [`Subdivision::MAX_LEVELS`].
pub fn subdivide(mesh: &Mesh, s: Subdivision) -> Result<Mesh> {
    if s.levels > Subdivision::MAX_LEVELS {
        return Err(Error::Invalid(format!(
            "subdivision: {} levels is more than the limit of {}",
            s.levels,
            Subdivision::MAX_LEVELS
        )));
    }
    if let Some((f, face)) = mesh.faces.iter().enumerate().find(|(_, f)| f.len() != 3) {
        return Err(Error::Invalid(format!(
            "subdivision `{}` needs triangles, but face {f} (line {}) has {} vertices; \
             triangulate first",
            s.rule,
            mesh.face_lines.get(f).copied().unwrap_or(0),
            face.len()
        )));
    }
    let mut m = mesh.clone();
    if s.levels > 0 {
        m.file_normals = None;
    }
    for _ in 0..s.levels {
        m = match s.rule {
            SubdivisionRule::Loop => loop_level(&m),
        };
    }
    Ok(m)
}

/// One level of Loop subdivision of a triangle mesh.
fn loop_level(mesh: &Mesh) -> Mesh {
    let nv = mesh.positions.len();
    let topo = Topology::new(nv, &mesh.faces);
    let p = &mesh.positions;
    let ne = topo.edges.len();
    // Edge points.
    let mut positions: Vec<DVec3> = Vec::with_capacity(nv + ne);
    positions.resize(nv, DVec3::ZERO);
    for e in 0..ne {
        let [a, b] = topo.edges[e];
        let (pa, pb) = (p[a as usize], p[b as usize]);
        let corners = topo.edge_corners(e as u32);
        let q = if corners.len() == 2 {
            // The vertex of each triangle opposite the edge: the head of the next corner.
            let c = topo.corner_vertex[topo.next(topo.next(corners[0])) as usize];
            let d = topo.corner_vertex[topo.next(topo.next(corners[1])) as usize];
            0.375 * (pa + pb) + 0.125 * (p[c as usize] + p[d as usize])
        } else {
            0.5 * (pa + pb)
        };
        positions.push(q);
    }
    // Vertex points. Neighbours and "crease" (not two-triangle) edges per vertex, from the edges.
    let mut ring_sum = vec![DVec3::ZERO; nv];
    let mut valence = vec![0usize; nv];
    let mut crease_sum = vec![DVec3::ZERO; nv];
    let mut creases = vec![0usize; nv];
    for e in 0..ne {
        let [a, b] = topo.edges[e];
        let (a, b) = (a as usize, b as usize);
        ring_sum[a] += p[b];
        ring_sum[b] += p[a];
        valence[a] += 1;
        valence[b] += 1;
        if topo.edge_corners(e as u32).len() != 2 {
            crease_sum[a] += p[b];
            crease_sum[b] += p[a];
            creases[a] += 1;
            creases[b] += 1;
        }
    }
    for v in 0..nv {
        positions[v] = match creases[v] {
            0 if valence[v] > 0 => {
                let beta = loop_beta(valence[v]);
                (1.0 - valence[v] as f64 * beta) * p[v] + beta * ring_sum[v]
            }
            2 => 0.75 * p[v] + 0.125 * crease_sum[v],
            _ => p[v],
        };
    }
    // Four triangles per triangle, same orientation: three corners and the middle one.
    let mut faces = Vec::with_capacity(4 * mesh.faces.len());
    let mut face_lines = Vec::with_capacity(4 * mesh.faces.len());
    let mut face_parent = Vec::with_capacity(4 * mesh.faces.len());
    for (f, face) in mesh.faces.iter().enumerate() {
        let s = topo.face_start[f] as usize;
        // m[k]: the edge point of the half-edge face[k] → face[k+1].
        let m: [u32; 3] = std::array::from_fn(|k| nv as u32 + topo.corner_edge[s + k]);
        let v = [face[0], face[1], face[2]];
        faces.push(vec![v[0], m[0], m[2]]);
        faces.push(vec![m[0], v[1], m[1]]);
        faces.push(vec![m[2], m[1], v[2]]);
        faces.push(vec![m[0], m[1], m[2]]);
        for _ in 0..4 {
            face_lines.push(mesh.face_lines[f]);
            face_parent.push(mesh.face_parent[f]);
        }
    }
    let mut vertex_lines = mesh.vertex_lines.clone();
    vertex_lines.resize(nv + ne, 0);
    Mesh {
        positions,
        faces,
        file_normals: None,
        vertex_lines,
        face_lines,
        face_parent,
    }
}

/// The fold angle (degrees, 0 = flat, 180 = a knife edge) across every edge with exactly two
/// faces: the angle between the two faces' area vectors (consistently oriented faces). The
/// measure the pre-subdivision lowers; edges of degenerate faces are skipped.
#[must_use]
pub fn fold_angles(mesh: &Mesh) -> Vec<f64> {
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let normals: Vec<Option<DVec3>> = mesh
        .faces
        .iter()
        .map(|f| super::geometry::area_vector(&mesh.positions, f).try_normalize())
        .collect();
    (0..topo.edges.len() as u32)
        .filter_map(|e| {
            let c = topo.edge_corners(e);
            if c.len() != 2 {
                return None;
            }
            let a = normals[topo.corner_face[c[0] as usize] as usize]?;
            let b = normals[topo.corner_face[c[1] as usize] as usize]?;
            Some(a.dot(b).clamp(-1.0, 1.0).acos().to_degrees())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOOP1: Subdivision = Subdivision {
        rule: SubdivisionRule::Loop,
        levels: 1,
    };
    const LOOP2: Subdivision = Subdivision {
        rule: SubdivisionRule::Loop,
        levels: 2,
    };

    /// A regular triangular grid (every interior vertex of valence 6) of `n` × `n` cells with
    /// unit spacing along the three lattice directions, in the plane z = 0.
    fn grid(n: usize) -> Mesh {
        let h = 3f64.sqrt() / 2.0;
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64 + 0.5 * j as f64, h * j as f64, 0.0));
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                faces.push(vec![id(i, j), id(i + 1, j), id(i, j + 1)]);
                faces.push(vec![id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh::new(positions, faces)
    }

    fn euler(m: &Mesh) -> i64 {
        let t = Topology::new(m.positions.len(), &m.faces);
        m.positions.len() as i64 - t.edges.len() as i64 + m.faces.len() as i64
    }

    #[test]
    fn beta_is_loops() {
        // Valence 6: β = 1/16 (the regular box-spline mask); valence 3: 3/16 (Warren's value
        // coincides with Loop's there).
        assert!((loop_beta(6) - 1.0 / 16.0).abs() < 1e-15);
        assert!((loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
    }

    #[test]
    fn reproduces_affine_functions_and_keeps_planes() {
        // Every mask is an affine combination, so an affine height z = a·(x, y) + c over any
        // planar mesh (interior, boundary, any valence) stays exactly on that plane.
        let mut m = grid(5);
        // Irregular valences: collapse nothing, but move vertices inside the plane.
        for (k, p) in m.positions.iter_mut().enumerate() {
            p.x += 0.1 * ((k * 7 % 5) as f64 - 2.0) / 2.0;
            p.z = 0.3 * p.x - 0.7 * p.y + 2.0;
        }
        let s = subdivide(&m, LOOP2).unwrap();
        for p in &s.positions {
            // Rounding of a few affine combinations of O(10) coordinates.
            assert!((p.z - (0.3 * p.x - 0.7 * p.y + 2.0)).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn quadratic_heights_are_reproduced_up_to_a_constant_on_a_regular_grid() {
        // Loop's regular masks are those of the quartic box spline, which maps samples of a
        // quadratic q to samples of q + const on the refined grid: for q = x² on a unit grid
        // the shift is 3/16 at every new vertex, even or odd (worked out by hand from the
        // masks 3/8, 3/8, 1/8, 1/8 and 10/16, 1/16 × 6). Interior vertices only (far from
        // the boundary rules).
        let mut m = grid(8);
        for p in &mut m.positions {
            p.z = p.x * p.x - 0.5 * p.x * p.y + 2.0 * p.y * p.y;
        }
        let s = subdivide(&m, LOOP1).unwrap();
        // The shift for q = x² − xy/2 + 2y²: the masks are linear in q, so the shift is the sum
        // of the shifts of the monomials: x² → 3/16, y² → 3/16 (the lattice is symmetric
        // under rotation by 60°, so the second moments are isotropic), xy → 0 (odd under
        // y → −y).
        let shift = 3.0 / 16.0 + 2.0 * 3.0 / 16.0;
        let mut inside = 0;
        for p in &s.positions {
            // Lattice coordinates (i, j) of the point; two rows away from the parallelogram's
            // sides, so that no mask reaches a boundary vertex.
            let j = p.y / (3f64.sqrt() / 2.0);
            let i = p.x - 0.5 * j;
            if i > 2.0 && i < 6.0 && j > 2.0 && j < 6.0 {
                let q = p.x * p.x - 0.5 * p.x * p.y + 2.0 * p.y * p.y;
                // Rounding of sums of O(100) values.
                assert!((p.z - q - shift).abs() < 1e-12, "{p}: {}", p.z - q);
                inside += 1;
            }
        }
        assert!(inside > 20, "{inside}");
    }

    #[test]
    fn boundary_curve_follows_the_cubic_b_spline_rules() {
        // Along the bottom row of the grid (a boundary polyline), new vertices must be the
        // cubic B-spline's: edge points (a + b)/2, vertex points (l + 6v + r)/8, whatever
        // the heights inside.
        let mut m = grid(4);
        for (k, p) in m.positions.iter_mut().enumerate() {
            p.z = ((k * 13 % 7) as f64) * 0.1;
        }
        let s = subdivide(&m, LOOP1).unwrap();
        // The old bottom row: vertices 0..=4 (interior ones 1..=3 have two boundary edges).
        let old: Vec<DVec3> = (0..=4).map(|i| m.positions[i]).collect();
        for i in 1..4 {
            let want = (old[i - 1] + 6.0 * old[i] + old[i + 1]) / 8.0;
            assert!((s.positions[i] - want).length() < 1e-14, "vertex {i}");
        }
        for i in 0..4 {
            let want = 0.5 * (old[i] + old[i + 1]);
            let found = s.positions.iter().any(|p| (*p - want).length() < 1e-14);
            assert!(found, "edge point {i}");
        }
        // The grid's corners have two boundary edges too and follow the same rule; none is
        // left fixed except where more than two boundary edges meet (none here).
    }

    /// The regular octahedron on the unit axes, faces wound outward.
    fn octahedron() -> Mesh {
        Mesh::new(
            vec![
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                -DVec3::X,
                -DVec3::Y,
                -DVec3::Z,
            ],
            vec![
                vec![0, 1, 2],
                vec![1, 3, 2],
                vec![3, 4, 2],
                vec![4, 0, 2],
                vec![1, 0, 5],
                vec![3, 1, 5],
                vec![4, 3, 5],
                vec![0, 4, 5],
            ],
        )
    }

    #[test]
    fn euler_characteristic_and_orientation_are_kept() {
        // A closed octahedron (χ = 2) and an open grid (χ = 1), two levels each; every
        // undirected edge of the closed result has two opposite half-edges (consistently
        // oriented, manifold), and the counts follow V' = V + E, F' = 4F.
        let oct = octahedron();
        for (m, chi) in [(oct, 2), (grid(3), 1)] {
            let s = subdivide(&m, LOOP2).unwrap();
            assert_eq!(euler(&s), chi);
            assert_eq!(s.faces.len(), 16 * m.faces.len());
            let t = Topology::new(s.positions.len(), &s.faces);
            for e in 0..t.edges.len() as u32 {
                let c = t.edge_corners(e);
                if c.len() == 2 {
                    // Opposite directions: the tail of one is the head of the other.
                    assert_eq!(t.corner_vertex[c[0] as usize], t.head(c[1]));
                }
            }
            // Every triangle maps back to its input triangle.
            assert!(s.face_parent.iter().all(|&f| (f as usize) < m.faces.len()));
        }
    }

    #[test]
    fn octahedron_shrinks_towards_a_sphere_like_limit() {
        // Symmetry check: the octahedron's vertices stay on the axes, all at one distance
        // (valence 4 everywhere), strictly inside the unit sphere (the vertex rule averages).
        let oct = octahedron();
        let s = subdivide(&oct, LOOP1).unwrap();
        // (1 − 4β) with β = loop_beta(4) (the four neighbours sum to zero).
        let r = 1.0 - 4.0 * loop_beta(4);
        for v in 0..6 {
            assert!((s.positions[v].length() - r).abs() < 1e-15);
        }
    }

    #[test]
    fn non_manifold_and_inconsistent_input_does_not_panic() {
        // Three triangles on one edge (0-1), one of them oriented against the others, an
        // unused vertex and a lone triangle: the rules fall back (edge midpoints, fixed
        // vertices where more than two non-manifold or boundary edges meet) without a panic,
        // and every new position is finite.
        let m = Mesh::new(
            vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                DVec3::new(0.5, -1.0, 0.0),
                DVec3::splat(7.0),
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(4.0, 0.0, 0.0),
                DVec3::new(3.0, 1.0, 0.0),
            ],
            vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4], vec![6, 7, 8]],
        );
        let s = subdivide(&m, LOOP2).unwrap();
        assert_eq!(s.faces.len(), 64);
        assert!(s.positions.iter().all(|p| p.is_finite()));
        // The unused vertex stays where it was.
        assert_eq!(s.positions[5], DVec3::splat(7.0));
    }

    #[test]
    fn polygons_and_too_many_levels_are_errors() {
        let quad = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::ONE, DVec3::Y],
            vec![vec![0, 1, 2, 3]],
        );
        let e = subdivide(&quad, LOOP1).unwrap_err().to_string();
        assert!(e.contains("face 0") && e.contains("triangulate"), "{e}");
        let e = subdivide(
            &grid(1),
            Subdivision {
                rule: SubdivisionRule::Loop,
                levels: 7,
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("7 levels"), "{e}");
    }
}

//! Checks of a welded, oriented mesh: degenerate and non-planar faces, non-manifold edges and
//! vertices, boundary edges.

use super::geometry::{area_vector, face_size, planarity_deviation};
use super::report::{Element, FindingKind, Report};
use super::topology::Topology;
use super::Mesh;

/// A face is zero-area when its area is at most this times the square of its size (float
/// rounding of exactly collinear input stays many orders below it).
pub const ZERO_AREA_TOL: f64 = 1e-12;

/// A polygon is non-planar when a vertex is farther than this times the face size from its
/// best-fit plane (OBJ/OFF files usually print 6–7 significant digits, whose rounding stays
/// well below it).
pub const PLANARITY_TOL: f64 = 1e-4;

/// Adds the geometric and topological findings of `mesh` to `report`; returns its topology
/// (`topology`, when given, must be that of `mesh`).
pub fn validate(mesh: &Mesh, topology: Option<Topology>, report: &mut Report) -> Topology {
    let mut zero = Vec::new();
    let mut non_planar = Vec::new();
    let mut worst = 0.0f64;
    for (f, face) in mesh.faces.iter().enumerate() {
        let el = Element::Face {
            index: f as u32,
            line: mesh.face_lines[f],
        };
        let size = face_size(&mesh.positions, face);
        let area = area_vector(&mesh.positions, face).length();
        if area <= ZERO_AREA_TOL * size * size || area.is_nan() {
            zero.push(el);
            continue;
        }
        if let Some(d) = planarity_deviation(&mesh.positions, face) {
            if d > PLANARITY_TOL {
                worst = worst.max(d);
                non_planar.push(el);
            }
        }
    }
    if !zero.is_empty() {
        report.add(
            FindingKind::ZeroAreaFace,
            format!("{} faces have zero area", zero.len()),
            zero,
        );
    }
    if !non_planar.is_empty() {
        report.add(
            FindingKind::NonPlanarFace,
            format!(
                "{} polygon faces are non-planar (worst deviation {worst:.3e} of the face size, tolerance {PLANARITY_TOL:e})",
                non_planar.len()
            ),
            non_planar,
        );
    }

    let topo = topology.unwrap_or_else(|| Topology::new(mesh.positions.len(), &mesh.faces));
    let edge_line = |e: u32| {
        let c = topo.edge_corners(e)[0];
        mesh.face_lines[topo.corner_face[c as usize] as usize]
    };
    let mut non_manifold = Vec::new();
    let mut boundary = Vec::new();
    for (e, ends) in topo.edges.iter().enumerate() {
        let n = topo.edge_corners(e as u32).len();
        let el = Element::Edge {
            vertices: *ends,
            line: edge_line(e as u32),
        };
        if n > 2 {
            non_manifold.push(el);
        } else if n == 1 {
            boundary.push(el);
        }
    }
    if !non_manifold.is_empty() {
        report.add(
            FindingKind::NonManifoldEdge,
            format!("{} edges have more than two faces", non_manifold.len()),
            non_manifold,
        );
    }
    if !boundary.is_empty() {
        report.add(
            FindingKind::BoundaryEdge,
            format!(
                "{} boundary edges in {} loops (the 2001 rational scheme accepts them; the 1994 schemes need a closed mesh)",
                boundary.len(),
                topo.boundary_loops()
            ),
            boundary,
        );
    }
    let mut bad_vertices = Vec::new();
    for v in 0..mesh.positions.len() as u32 {
        if topo.vertex_fan(v).is_none() {
            bad_vertices.push(Element::Vertex {
                index: v,
                line: mesh.vertex_lines[v as usize],
            });
        }
    }
    if !bad_vertices.is_empty() {
        report.add(
            FindingKind::NonManifoldVertex,
            format!(
                "{} vertices are non-manifold (their faces do not form one consistently oriented fan)",
                bad_vertices.len()
            ),
            bad_vertices,
        );
    }
    topo
}

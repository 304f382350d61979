//! The facts `apatch info` prints: counts, topology, bounding box, convexity classes of both
//! papers, and the findings.

use super::convexity::{
    edge_convexity, edge_convexity_1994, polygon_is_convex, triangle_convexity,
    triangle_convexity_1994, Convexity,
};
use super::normals::{above_face_failures, vertex_normals, NormalMethod};
use super::topology::Topology;
use super::{triangulate, Mesh, Report};
use glam::DVec3;
use serde::Serialize;
use std::collections::BTreeMap;

/// Counts of the four convexity classes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ClassCounts {
    /// Positive convex.
    pub positive: usize,
    /// Zero convex.
    pub zero: usize,
    /// Negative convex.
    pub negative: usize,
    /// Nonconvex.
    pub nonconvex: usize,
}

impl ClassCounts {
    fn add(&mut self, c: Convexity) {
        match c {
            Convexity::Positive => self.positive += 1,
            Convexity::Zero => self.zero += 1,
            Convexity::Negative => self.negative += 1,
            Convexity::Nonconvex => self.nonconvex += 1,
        }
    }
}

/// Everything `apatch info` reports about a mesh.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Number of vertices (after welding).
    pub vertices: usize,
    /// Number of faces.
    pub faces: usize,
    /// Faces by number of vertices.
    pub faces_by_valence: BTreeMap<usize, usize>,
    /// Number of undirected edges.
    pub edges: usize,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Closed loops of boundary edges.
    pub boundary_loops: usize,
    /// Connected components (faces sharing a vertex are connected).
    pub components: usize,
    /// V − E + F.
    pub euler_characteristic: i64,
    /// Total genus (sum over components), when the mesh is a manifold, orientable surface.
    pub genus: Option<i64>,
    /// Smallest corner of the axis-aligned bounding box.
    pub bbox_min: [f64; 3],
    /// Largest corner of the axis-aligned bounding box.
    pub bbox_max: [f64; 3],
    /// Interior vertices where exactly three faces meet (1994 paper).
    pub trihedral_vertices: usize,
    /// Interior manifold vertices with more than three faces.
    pub non_trihedral_vertices: usize,
    /// Manifold vertices on the boundary.
    pub boundary_vertices: usize,
    /// Vertices whose faces do not form one fan.
    pub non_manifold_vertices: usize,
    /// The normals the classes below use.
    pub normals: NormalMethod,
    /// Why the normals could not be computed (then the normal-dependent fields are `None`).
    pub normals_error: Option<String>,
    /// 2001 classes of the edges of the (ear-clipped, if needed) triangle mesh.
    pub edges_2001: Option<ClassCounts>,
    /// 2001 classes of the triangles of the (ear-clipped, if needed) triangle mesh.
    pub triangles_2001: Option<ClassCounts>,
    /// True when the 2001 classes were computed on an ear-clipped triangulation.
    pub triangulated_for_2001: bool,
    /// 1994 classes (Definition 3.1) of the mesh's edges.
    pub edges_1994: Option<ClassCounts>,
    /// 1994 classes (Definition 3.2) of the triangles of the (ear-clipped, if needed) mesh.
    pub triangles_1994: Option<ClassCounts>,
    /// 1994: polygon faces that are convex in their plane.
    pub convex_faces_1994: usize,
    /// 1994: polygon faces that are not convex.
    pub nonconvex_faces_1994: usize,
    /// 1994: vertices failing the above-face condition (n · n_f ≤ 0 for an incident face).
    pub above_face_failures: Option<Vec<u32>>,
    /// The validation report.
    pub report: Report,
}

/// Summarises `mesh` (as returned by `load` with `report`) for the chosen `normals`. When the
/// normals cannot be computed the summary says why and omits what depends on them.
#[must_use]
pub fn summary(mesh: &Mesh, report: &Report, normals: NormalMethod) -> Summary {
    let n = vertex_normals(mesh, normals);
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let mut faces_by_valence = BTreeMap::new();
    for f in &mesh.faces {
        *faces_by_valence.entry(f.len()).or_insert(0) += 1;
    }
    let boundary_edges = (0..topo.edges.len() as u32)
        .filter(|&e| topo.is_boundary_edge(e))
        .count();
    let non_manifold_edges = (0..topo.edges.len() as u32)
        .filter(|&e| topo.edge_corners(e).len() > 2)
        .count();
    let (components, _) = topo.components();
    let boundary_loops = topo.boundary_loops();
    let (mut tri, mut non_tri, mut bnd, mut nm) = (0, 0, 0, 0);
    for v in 0..mesh.positions.len() as u32 {
        match topo.vertex_fan(v) {
            None => nm += 1,
            Some(fan) if !fan.closed => bnd += 1,
            Some(fan) if fan.faces.len() == 3 => tri += 1,
            Some(_) => non_tri += 1,
        }
    }
    let euler = mesh.positions.len() as i64 - topo.edges.len() as i64 + mesh.faces.len() as i64;
    let genus = report
        .is_manifold()
        .then_some(())
        .filter(|_| report.get(super::FindingKind::NonOrientable).is_none())
        .map(|_| (2 * components as i64 - boundary_loops as i64 - euler) / 2);
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in &mesh.positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }

    // 2001 classes on triangles.
    let triangulated = !mesh.is_triangle_mesh();
    let tri_mesh;
    let tm = if triangulated {
        tri_mesh = triangulate(mesh);
        &tri_mesh
    } else {
        mesh
    };
    let classes = n.as_ref().ok().map(|n| {
        let rebuilt;
        let tt = if triangulated {
            rebuilt = Topology::new(tm.positions.len(), &tm.faces);
            &rebuilt
        } else {
            &topo
        };
        let p = &tm.positions;
        let mut edges = ClassCounts::default();
        for [i, j] in &tt.edges {
            let (i, j) = (*i as usize, *j as usize);
            edges.add(edge_convexity(p[i], n[i], p[j], n[j]));
        }
        let mut triangles = ClassCounts::default();
        let mut triangles_1994 = ClassCounts::default();
        for f in &tm.faces {
            let [a, b, c] = [f[0] as usize, f[1] as usize, f[2] as usize];
            let (tp, tn) = ([p[a], p[b], p[c]], [n[a], n[b], n[c]]);
            triangles.add(triangle_convexity(tp, tn));
            triangles_1994.add(triangle_convexity_1994(tp, tn));
        }
        let mut edges_1994 = ClassCounts::default();
        for [i, j] in &topo.edges {
            let (i, j) = (*i as usize, *j as usize);
            edges_1994.add(edge_convexity_1994(p[i], n[i], p[j], n[j]));
        }
        (edges, triangles, edges_1994, triangles_1994)
    });
    let convex = mesh
        .faces
        .iter()
        .filter(|f| polygon_is_convex(&mesh.positions, f))
        .count();
    Summary {
        vertices: mesh.positions.len(),
        faces: mesh.faces.len(),
        faces_by_valence,
        edges: topo.edges.len(),
        boundary_edges,
        non_manifold_edges,
        boundary_loops,
        components,
        euler_characteristic: euler,
        genus,
        bbox_min: lo.to_array(),
        bbox_max: hi.to_array(),
        trihedral_vertices: tri,
        non_trihedral_vertices: non_tri,
        boundary_vertices: bnd,
        non_manifold_vertices: nm,
        normals,
        normals_error: n.as_ref().err().map(ToString::to_string),
        edges_2001: classes.map(|c| c.0),
        triangles_2001: classes.map(|c| c.1),
        edges_1994: classes.map(|c| c.2),
        triangles_1994: classes.map(|c| c.3),
        triangulated_for_2001: triangulated,
        convex_faces_1994: convex,
        nonconvex_faces_1994: mesh.faces.len() - convex,
        above_face_failures: n.as_ref().ok().map(|n| above_face_failures(mesh, n)),
        report: report.clone(),
    }
}

//! Every validation finding is triggered by a small crafted file in `tests/corpus/` and points at
//! the right element and line; repairs (orientation, welding, dropping) leave a valid mesh.

use apatch::mesh::{self, Element, FindingKind, Format, Mesh, Report, Topology};
use std::path::Path;

fn corpus(name: &str) -> (Mesh, Report) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(name);
    mesh::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn elements(report: &Report, kind: FindingKind) -> Vec<Element> {
    report
        .get(kind)
        .unwrap_or_else(|| panic!("no {kind:?} in {:#?}", report.findings))
        .elements
        .clone()
}

fn face(index: u32, line: u32) -> Element {
    Element::Face { index, line }
}

fn vertex(index: u32, line: u32) -> Element {
    Element::Vertex { index, line }
}

/// Every manifold edge is traversed once in each direction.
fn assert_consistent(m: &Mesh) {
    let t = Topology::new(m.positions.len(), &m.faces);
    for e in 0..t.edges.len() as u32 {
        let cs = t.edge_corners(e);
        if cs.len() == 2 {
            assert!(
                t.twin(cs[0]).is_some(),
                "edge {:?} not consistent",
                t.edges[e as usize]
            );
        }
    }
}

#[test]
fn non_manifold_edge() {
    let (_, r) = corpus("nonmanifold_edge.obj");
    assert_eq!(
        elements(&r, FindingKind::NonManifoldEdge),
        vec![Element::Edge {
            vertices: [0, 1],
            line: 6
        }]
    );
    assert!(!r.is_manifold());
    assert!(r.require(false).is_err());
}

/// Two closed tetrahedra touching at one vertex (a bow-tie of solids): the vertex is split into
/// one vertex per fan, and the result is two closed genus-0 components.
#[test]
fn non_manifold_vertex_is_split() {
    let (m, r) = corpus("nonmanifold_vertex.obj");
    assert_eq!(elements(&r, FindingKind::SplitVertex), vec![vertex(0, 1)]);
    assert!(r.get(FindingKind::NonManifoldVertex).is_none());
    assert!(r.get(FindingKind::NonManifoldEdge).is_none());
    assert!(r.require(true).is_ok(), "{:#?}", r.findings);
    // 7 file vertices + 1 copy of vertex 0, appended with its line, moved a relative 1e-6 into
    // its own fan (so the two sheets do not share a point).
    assert_eq!(m.positions.len(), 8);
    let d = (m.positions[7] - m.positions[0]).length();
    assert!(d > 0.0 && d < 1e-5, "{d}");
    assert_eq!(m.vertex_lines[7], 1);
    let t = Topology::new(m.positions.len(), &m.faces);
    assert_eq!(t.components().0, 2);
    assert_eq!(t.edges.len(), 12);
    assert_eq!(t.boundary_loops(), 0);
    for v in 0..m.positions.len() as u32 {
        let fan = t
            .vertex_fan(v)
            .expect("every vertex is manifold after the split");
        assert!(fan.closed);
        assert_eq!(fan.faces.len(), 3, "vertex {v}");
    }
    let s = mesh::summary(&m, &r, mesh::NormalMethod::Angle);
    // V − E + F = 8 − 12 + 8 = 4 − 6 + 4 twice: two spheres.
    assert_eq!(s.euler_characteristic, 4);
    assert_eq!(s.genus, Some(0));
    assert_eq!(s.non_manifold_vertices, 0);
    assert_consistent(&m);
}

/// A bow-tie of two triangles sharing only a vertex (open surfaces): split, and each triangle
/// keeps its three boundary edges.
#[test]
fn bow_tie_triangles_are_split() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n";
    let (m, r) = mesh::load_bytes(text.as_bytes(), Format::Obj, Path::new("bowtie.obj")).unwrap();
    assert_eq!(elements(&r, FindingKind::SplitVertex), vec![vertex(0, 1)]);
    assert!(r.is_manifold());
    assert_eq!(m.positions.len(), 6);
    let t = Topology::new(m.positions.len(), &m.faces);
    assert_eq!(t.components().0, 2);
    assert_eq!(t.boundary_loops(), 2);
    assert!((0..6).all(|v| t.vertex_fan(v).is_some_and(|f| !f.closed)));
}

#[test]
fn inconsistent_orientation_is_fixed() {
    let (m, r) = corpus("inconsistent_orientation.obj");
    assert_eq!(
        elements(&r, FindingKind::InconsistentOrientation),
        vec![face(2, 7)]
    );
    assert!(r.get(FindingKind::InwardOrientation).is_none());
    assert_consistent(&m);
    let all: Vec<u32> = (0..m.faces.len() as u32).collect();
    assert!(mesh::signed_volume(&m, &all) > 0.0);
}

#[test]
fn inward_orientation_is_flipped() {
    let (m, r) = corpus("inward_orientation.obj");
    assert_eq!(
        elements(&r, FindingKind::InwardOrientation),
        vec![face(0, 5), face(1, 6), face(2, 7), face(3, 8)]
    );
    assert!(r.get(FindingKind::InconsistentOrientation).is_none());
    let all: Vec<u32> = (0..4).collect();
    // Unit tetrahedron corner: volume 1/6 (exact up to rounding of a few products).
    assert!((mesh::signed_volume(&m, &all) - 1.0 / 6.0).abs() < 1e-12);
    assert!(r.require(true).is_ok());
}

#[test]
fn zero_area_face() {
    let (m, r) = corpus("zero_area_face.obj");
    assert_eq!(elements(&r, FindingKind::ZeroAreaFace), vec![face(0, 5)]);
    assert_eq!(m.faces.len(), 2, "zero-area faces are kept");
    assert!(r.get(FindingKind::InconsistentOrientation).is_none());
}

#[test]
fn repeated_vertex_is_removed() {
    let (m, r) = corpus("repeated_vertex.obj");
    assert_eq!(elements(&r, FindingKind::RepeatedVertex), vec![face(0, 5)]);
    assert_eq!(m.faces, vec![vec![0, 1, 3, 2]]);
}

#[test]
fn face_with_a_vertex_twice_is_dropped() {
    let (m, r) = corpus("dropped_face.obj");
    // Element index is the file's face number.
    assert_eq!(elements(&r, FindingKind::DroppedFace), vec![face(1, 6)]);
    assert_eq!(m.faces.len(), 1);
    assert_eq!(m.face_lines, vec![5]);
    // Vertex 4 was used only by the dropped face.
    assert_eq!(
        elements(&r, FindingKind::UnreferencedVertices),
        vec![vertex(3, 4)]
    );
}

#[test]
fn face_collapsed_by_welding_is_dropped() {
    let (m, r) = corpus("welded_collapse.obj");
    assert_eq!(elements(&r, FindingKind::DroppedFace), vec![face(1, 6)]);
    assert_eq!(m.positions.len(), 3);
}

#[test]
fn non_planar_face() {
    let (m, r) = corpus("non_planar_face.obj");
    assert_eq!(elements(&r, FindingKind::NonPlanarFace), vec![face(0, 5)]);
    // The deviation measure itself: vertex heights 0,0,0.2,0 → best-fit plane through the
    // centroid; a planar quad measures 0.
    let flat = Mesh::new(
        m.positions.iter().map(|p| p.with_z(0.0)).collect(),
        m.faces.clone(),
    );
    assert!(mesh::geometry::planarity_deviation(&flat.positions, &flat.faces[0]).unwrap() < 1e-15);
}

#[test]
fn unreferenced_vertex_is_dropped() {
    let (m, r) = corpus("unreferenced_vertex.obj");
    assert_eq!(
        elements(&r, FindingKind::UnreferencedVertices),
        vec![vertex(3, 4)]
    );
    assert_eq!(m.positions.len(), 3);
}

#[test]
fn mobius_strip_is_non_orientable() {
    let (m, r) = corpus("mobius.obj");
    assert_eq!(elements(&r, FindingKind::NonOrientable).len(), 12);
    assert!(r.get(FindingKind::InconsistentOrientation).is_none());
    assert_eq!(m.faces.len(), 12);
    assert!(r.require(false).is_err());
}

#[test]
fn incomplete_file_normals() {
    let (m, r) = corpus("incomplete_normals.obj");
    assert_eq!(
        elements(&r, FindingKind::FileNormalsIncomplete),
        vec![vertex(3, 4)]
    );
    assert!(m.file_normals.is_none());
}

#[test]
fn notes() {
    let (_, r) = corpus("boundary_note.obj");
    assert_eq!(elements(&r, FindingKind::BoundaryEdge).len(), 3);
    assert!(!r.has_warnings());
    assert!(
        r.require(false).is_ok(),
        "the 2001 scheme accepts boundaries"
    );
    assert!(
        r.require(true).is_err(),
        "the 1994 schemes need closed meshes"
    );

    let (m, r) = corpus("welded_note.obj");
    assert_eq!(m.positions.len(), 4);
    // The vertex kept, with the duplicate's line.
    assert_eq!(
        elements(&r, FindingKind::WeldedVertices),
        vec![vertex(1, 4), vertex(2, 5)]
    );
    assert_eq!(
        elements(&r, FindingKind::BoundaryEdge).len(),
        4,
        "welded: one shared edge"
    );

    let (_, r) = corpus("ignored_note.obj");
    assert!(r
        .get(FindingKind::IgnoredStatements)
        .unwrap()
        .message
        .contains("line 4"));

    let (m, _) = corpus("negative_indices_valid.obj");
    assert_eq!(m.faces, vec![vec![0, 1, 2]]);
}

#[test]
fn clean_models_have_no_findings() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    for name in [
        "tetrahedron.obj",
        "cube.obj",
        "octahedron.obj",
        "icosahedron.obj",
        "dodecahedron.obj",
        "torus_quad12x8.obj",
        "l_prism.obj",
        "star_prism.obj",
        "hallway_corner.obj",
        "spot.obj",
        "torus_quad.obj",
    ] {
        let (m, r) = mesh::load(&dir.join(name)).unwrap();
        assert!(r.findings.is_empty(), "{name}: {:#?}", r.findings);
        assert!(r.require(true).is_ok());
        assert_consistent(&m);
        let all: Vec<u32> = (0..m.faces.len() as u32).collect();
        assert!(mesh::signed_volume(&m, &all) > 0.0, "{name}");
    }
}

#[test]
fn genus_components_and_loops_of_models() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    // Truth from /work/shared/meshes/README.md and the generator.
    for (name, genus, faces) in [
        ("torus_quad.obj", 1, 25),
        ("double_torus_poly.obj", 2, 220),
        ("mpi_poly.obj", 1, 52),
        ("dodecahedron.obj", 0, 12),
        ("torus_quad12x8.obj", 1, 96),
    ] {
        let (m, r) = mesh::load(&dir.join(name)).unwrap();
        let s = mesh::summary(&m, &r, mesh::NormalMethod::Angle);
        assert_eq!(s.genus, Some(genus), "{name}");
        assert_eq!(s.faces, faces, "{name}");
        assert_eq!(s.components, 1, "{name}");
        assert_eq!(s.boundary_loops, 0, "{name}");
    }
    let (m, r) = mesh::load(&dir.join("teapot_npm.obj")).unwrap();
    let s = mesh::summary(&m, &r, mesh::NormalMethod::Angle);
    assert!(s.boundary_edges > 0 && s.boundary_loops > 0);
}

#[test]
fn obj_and_off_read_the_same_cube() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
               f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    let off = "OFF # comment\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
               4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6 255 0 0\n4 3 0 4 7\n";
    let (a, ra) = mesh::load_bytes(obj.as_bytes(), Format::Obj, Path::new("c.obj")).unwrap();
    let (b, rb) = mesh::load_bytes(off.as_bytes(), Format::Off, Path::new("c.off")).unwrap();
    assert_eq!(a.positions, b.positions);
    assert_eq!(a.faces, b.faces);
    assert!(ra.findings.is_empty() && rb.findings.is_empty());
    assert_eq!(a.face_lines[0], 9);
    assert_eq!(b.face_lines[0], 11);
}

#[test]
fn file_normals_obj_corners_and_noff() {
    // Two corners of vertex 1 disagree: averaged (note).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0.6 0.8\n\
               f 1//1 2//1 3//1\nf 2//2 4//1 3//1\n";
    let (m, r) = mesh::load_bytes(obj.as_bytes(), Format::Obj, Path::new("n.obj")).unwrap();
    let n = m.file_normals.as_ref().unwrap();
    assert!((n[0] - glam::DVec3::Z).length() < 1e-15);
    let want = (glam::DVec3::Z + glam::DVec3::new(0.0, 0.6, 0.8)).normalize();
    assert!((n[1] - want).length() < 1e-12, "{}", n[1]);
    assert_eq!(
        elements(&r, FindingKind::FileNormalsAveraged),
        vec![vertex(1, 2)]
    );
    let off = "NOFF\n3 1 0\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
    let (m, _) = mesh::load_bytes(off.as_bytes(), Format::Off, Path::new("n.off")).unwrap();
    assert_eq!(m.file_normals.unwrap()[0], glam::DVec3::Z);
    // One unreferenced `vn` per `v`: per-vertex normals.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 3\nvn 0 0 1\nvn 1 0 0\nf 1 2 3\n";
    let (m, _) = mesh::load_bytes(obj.as_bytes(), Format::Obj, Path::new("n.obj")).unwrap();
    assert_eq!(
        m.file_normals.unwrap(),
        vec![glam::DVec3::Z, glam::DVec3::Z, glam::DVec3::X]
    );
}

#[test]
fn fans_are_counter_clockwise_from_outside() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    for name in ["octahedron.obj", "dodecahedron.obj", "l_prism.obj"] {
        let (m, _) = mesh::load(&dir.join(name)).unwrap();
        let t = Topology::new(m.positions.len(), &m.faces);
        let centre = m.positions.iter().sum::<glam::DVec3>() / m.positions.len() as f64;
        for v in 0..m.positions.len() as u32 {
            let fan = t.vertex_fan(v).unwrap();
            assert!(fan.closed);
            assert_eq!(fan.ring.len(), fan.faces.len());
            let p = m.positions[v as usize];
            let k = fan.ring.len();
            for i in 0..k {
                let a = m.positions[fan.ring[i] as usize] - p;
                let b = m.positions[fan.ring[(i + 1) % k] as usize] - p;
                // Convex solids: the turn from ring[i] to ring[i+1] is CCW about the outward
                // direction (for the L prism the outward direction at a vertex is not the
                // radial one, so only the convex solids are checked this way).
                if name != "l_prism.obj" {
                    assert!(a.cross(b).dot(p - centre) > 0.0, "{name} vertex {v}");
                }
                // Face i lies between ring[i] and ring[i+1].
                let f = &m.faces[fan.faces[i] as usize];
                assert!(f.contains(&fan.ring[i]) && f.contains(&fan.ring[(i + 1) % k]));
            }
        }
    }
}

#[test]
fn from_polygons_runs_the_same_pipeline() {
    let (m, _) = corpus("inward_orientation.obj");
    // Reverse every face again: the pipeline must flip them back.
    let faces: Vec<Vec<u32>> = m
        .faces
        .iter()
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    let (fixed, r) = mesh::from_polygons(m.positions.clone(), faces).unwrap();
    assert_eq!(fixed.faces, m.faces);
    assert_eq!(elements(&r, FindingKind::InwardOrientation).len(), 4);
    let e = mesh::from_polygons(m.positions.clone(), vec![vec![0, 1, 7]]).unwrap_err();
    assert!(e.to_string().contains("face 0 refers to vertex 7"), "{e}");
    let e = mesh::from_polygons(vec![glam::DVec3::NAN; 3], vec![vec![0, 1, 2]]).unwrap_err();
    assert!(e.to_string().contains("vertex 0: non-finite"), "{e}");
}

#[test]
fn duplicate_faces_are_dropped() {
    // A closed tetrahedron plus the same face twice more (once reversed, once rotated).
    let (m, r) = corpus("duplicate_face.obj");
    assert_eq!(
        elements(&r, FindingKind::DuplicateFace),
        vec![face(2, 7), face(5, 10)]
    );
    assert_eq!(m.faces.len(), 4);
    assert!(r.get(FindingKind::InconsistentOrientation).is_none());
    assert!(r.require(true).is_ok());
}

/// `vn` lines may follow the faces that use them (positive indices are resolved at the end),
/// and the corner normals then still reach their vertices.
#[test]
fn normals_defined_after_faces() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                f 1//1 3//3 2//2\nf 1//1 2//2 4//4\nf 1//1 4//4 3//3\nf 2//2 3//3 4//4\n\
                vn -1 -1 -1\nvn 1 0 0\nvn 0 1 0\nvn 1 1 1\n";
    let (m, _) = mesh::load_bytes(text.as_bytes(), Format::Obj, Path::new("after.obj"))
        .unwrap_or_else(|e| panic!("{e}"));
    let n = m.file_normals.expect("file normals");
    // Vertex 3 (line 5) has corner normal 4 = (1,1,1)/√3 at every corner; exact up to the
    // rounding of one normalisation.
    let expect = glam::DVec3::ONE.normalize();
    assert!((n[3] - expect).length() < 1e-15, "{:?}", n[3]);
}

//! Ear clipping: n − 2 triangles covering exactly the polygon (area sums match, every triangle
//! keeps the polygon's orientation, every triangle's centroid lies inside the polygon), for
//! non-convex model faces and seeded random star-shaped polygons in tilted planes.

use apatch::fixtures::Lcg;
use apatch::mesh::{self, geometry::area_vector, Mesh};
use glam::{DVec2, DVec3};
use std::path::Path;

/// Even–odd point-in-polygon test in 2D.
fn inside(poly: &[DVec2], q: DVec2) -> bool {
    let mut c = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            c = !c;
        }
    }
    c
}

/// Checks the triangulation of every face of `m`.
fn check(m: &Mesh) {
    let t = mesh::triangulate(m);
    assert_eq!(t.positions, m.positions);
    for (f, face) in m.faces.iter().enumerate() {
        let tris: Vec<&Vec<u32>> = t
            .faces
            .iter()
            .zip(&t.face_parent)
            .filter(|(_, &p)| p as usize == f)
            .map(|(t, _)| t)
            .collect();
        assert_eq!(tris.len(), face.len() - 2, "face {f}");
        let a = area_vector(&m.positions, face);
        let n = a.normalize();
        let u = n.any_orthonormal_vector();
        let w = n.cross(u);
        let o = m.positions[face[0] as usize];
        let flat = |p: DVec3| DVec2::new((p - o).dot(u), (p - o).dot(w));
        let poly: Vec<DVec2> = face
            .iter()
            .map(|&v| flat(m.positions[v as usize]))
            .collect();
        let mut total = 0.0;
        for tri in &tris {
            assert!(tri.iter().all(|v| face.contains(v)));
            let ta = area_vector(&m.positions, tri);
            // Same orientation as the polygon (a naive fan of a non-convex polygon fails this).
            assert!(ta.dot(n) > 0.0, "face {f}: triangle {tri:?} flipped");
            total += ta.dot(n);
            let c = tri
                .iter()
                .map(|&v| flat(m.positions[v as usize]))
                .sum::<DVec2>()
                / 3.0;
            assert!(
                inside(&poly, c),
                "face {f}: triangle {tri:?} outside the polygon"
            );
        }
        // Planar polygon: triangle areas add up to its area (rounding of n terms).
        assert!(
            (total - a.length()).abs() <= 1e-12 * a.length(),
            "face {f}: {total} vs {}",
            a.length()
        );
    }
}

#[test]
fn non_convex_model_faces() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    for name in [
        "l_prism.obj",
        "star_prism.obj",
        "corner_poly.obj",
        "dodecahedron.obj",
        "cube.obj",
    ] {
        let (m, _) = mesh::load(&dir.join(name)).unwrap();
        check(&m);
    }
}

/// Polygons with collinear vertices (mpi_poly.obj: face 15, line 113, has a notch whose side is
/// collinear with a vertex across the polygon) give no zero-area triangle, in every model.
#[test]
fn no_zero_area_triangles_in_any_model() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    names.sort();
    for path in names {
        let (m, _) = mesh::load(&path).unwrap();
        let t = mesh::triangulate(&m);
        for (i, tri) in t.faces.iter().enumerate() {
            let p: Vec<DVec3> = tri.iter().map(|&v| t.positions[v as usize]).collect();
            let longest = (p[1] - p[0])
                .length()
                .max((p[2] - p[1]).length())
                .max((p[0] - p[2]).length());
            let area = area_vector(&t.positions, tri).length();
            // The zero-area face tolerance of validation (far above rounding of real triangles).
            assert!(
                area > mesh::ZERO_AREA_TOL * longest * longest,
                "{}: triangle {i} {tri:?} of face {} has zero area",
                path.display(),
                t.face_parent[i]
            );
        }
    }
}

#[test]
fn random_star_shaped_polygons_in_tilted_planes() {
    let mut rng = Lcg(99);
    for trial in 0..300 {
        let n = 3 + (trial % 40);
        let normal = DVec3::new(
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
        )
        .normalize();
        let u = normal.any_orthonormal_vector();
        let w = normal.cross(u);
        let centre = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
        let positions: Vec<DVec3> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + 0.4 * (rng.uniform() - 0.5)) / n as f64;
                let r = 0.1 + rng.uniform();
                centre + r * (a.cos() * u + a.sin() * w)
            })
            .collect();
        let m = Mesh::new(positions, vec![(0..n as u32).collect()]);
        check(&m);
    }
}

#[test]
fn triangle_mesh_is_unchanged() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    let (m, _) = mesh::load(&dir.join("icosahedron.obj")).unwrap();
    let t = mesh::triangulate(&m);
    assert_eq!(t.faces, m.faces);
    assert_eq!(t.face_lines, m.face_lines);
}

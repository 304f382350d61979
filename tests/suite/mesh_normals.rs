//! Vertex normals against analytic truth: radial directions on solids inscribed in a sphere,
//! exact graph normals of quadratics sampled on a regular (valence-6) lattice, and Loop limit
//! normals of extraordinary vertices against the local subdivision iterated to convergence.

use apatch::fixtures::Lcg;
use apatch::mesh::{self, Fan, Format, Mesh, NormalMethod};
use glam::DVec3;
use std::path::Path;

fn model(name: &str) -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/models")
        .join(name);
    mesh::load(&path).unwrap().0
}

#[test]
fn inscribed_solids_give_radial_normals() {
    // By symmetry every method gives the radial direction; the positions are exact to f64
    // rounding (~1e-16), so 1e-12 leaves room for the sums of a few angle/area terms.
    const TOL: f64 = 1e-12;
    for (name, methods) in [
        (
            "icosahedron.obj",
            &[NormalMethod::Angle, NormalMethod::Area, NormalMethod::Loop][..],
        ),
        (
            "octahedron.obj",
            &[NormalMethod::Angle, NormalMethod::Area, NormalMethod::Loop][..],
        ),
        (
            "tetrahedron.obj",
            &[NormalMethod::Angle, NormalMethod::Area, NormalMethod::Loop][..],
        ),
        ("cube.obj", &[NormalMethod::Angle, NormalMethod::Area][..]),
        (
            "dodecahedron.obj",
            &[NormalMethod::Angle, NormalMethod::Area][..],
        ),
    ] {
        let m = model(name);
        for &method in methods {
            let n = mesh::vertex_normals(&m, method).unwrap();
            for (v, (p, n)) in m.positions.iter().zip(&n).enumerate() {
                let err = (*n - p.normalize()).length();
                assert!(
                    err < TOL,
                    "{name} {method} vertex {v}: {n} vs {p} (err {err:e})"
                );
            }
            assert!(mesh::above_face_failures(&m, &n).is_empty());
        }
    }
}

#[test]
fn file_normals_are_used_and_required() {
    let ico = model("icosahedron.obj");
    let mut obj = String::new();
    for p in &ico.positions {
        obj += &format!(
            "v {} {} {}\nvn {} {} {}\n",
            p.x,
            p.y,
            p.z,
            2.0 * p.x,
            2.0 * p.y,
            2.0 * p.z
        );
    }
    for f in &ico.faces {
        obj += &format!(
            "f {0}//{0} {1}//{1} {2}//{2}\n",
            f[0] + 1,
            f[1] + 1,
            f[2] + 1
        );
    }
    let (m, _) = mesh::load_bytes(obj.as_bytes(), Format::Obj, Path::new("i.obj")).unwrap();
    let n = mesh::vertex_normals(&m, NormalMethod::File).unwrap();
    for (p, n) in m.positions.iter().zip(&n) {
        // Normalisation of (2p) only: rounding level.
        assert!((*n - p.normalize()).length() < 1e-15);
    }
    let e = mesh::vertex_normals(&ico, NormalMethod::File).unwrap_err();
    assert!(e.to_string().contains("no vertex normals"), "{e}");
    let e = mesh::vertex_normals(&model("cube.obj"), NormalMethod::Loop).unwrap_err();
    assert!(e.to_string().contains("triangle mesh"), "{e}");
    assert_eq!("AREA".parse::<NormalMethod>(), Ok(NormalMethod::Area));
    assert!("nope"
        .parse::<NormalMethod>()
        .unwrap_err()
        .contains("angle, area, loop or file"));
}

/// Triangles of the three-direction lattice i·a + j·b (|i|,|j| ≤ r), heights z = f(x, y).
fn lattice(a: [f64; 2], b: [f64; 2], r: i32, f: impl Fn(f64, f64) -> f64) -> (Mesh, u32) {
    let side = (2 * r + 1) as u32;
    let id = |i: i32, j: i32| ((i + r) as u32) * side + (j + r) as u32;
    let mut positions = Vec::new();
    for i in -r..=r {
        for j in -r..=r {
            let x = i as f64 * a[0] + j as f64 * b[0];
            let y = i as f64 * a[1] + j as f64 * b[1];
            positions.push(DVec3::new(x, y, f(x, y)));
        }
    }
    let mut faces = Vec::new();
    for i in -r..r {
        for j in -r..r {
            faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (Mesh::new(positions, faces), id(0, 0))
}

#[test]
fn loop_normal_of_regular_patch_on_a_quadric_is_the_graph_normal() {
    // Loop surfaces reproduce linear functions exactly and quadratics up to a constant, so the
    // limit surface of a sampled quadratic graph z = f(x, y) has the graph's exact normal
    // (−f_x, −f_y, 1) above each lattice vertex — for any affine image of the lattice.
    let (cx, cy) = (0.7, -0.3);
    let f = |x: f64, y: f64| {
        let (u, v) = (x + cx, y + cy);
        0.3 * u * u - 0.45 * u * v + 0.5 * v * v + 0.1 * u - 0.4 * v + 2.0
    };
    let truth =
        DVec3::new(-(0.6 * cx - 0.45 * cy + 0.1), -(-0.45 * cx + cy - 0.4), 1.0).normalize();
    for (a, b) in [
        ([1.0, 0.0], [0.5, 0.75f64.sqrt()]),
        ([0.9, 0.2], [0.3, 1.1]),
    ] {
        let (m, centre) = lattice(a, b, 2, f);
        let n = mesh::vertex_normals(&m, NormalMethod::Loop).unwrap();
        let err = (n[centre as usize] - truth).length();
        // Exact in exact arithmetic; a few dozen rounded products.
        assert!(
            err < 1e-12,
            "lattice {a:?} {b:?}: {} vs {truth} ({err:e})",
            n[centre as usize]
        );
        // The angle-weighted normal is not exact on a curved, skewed patch: the test can fail.
        let angle = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        assert!((angle[centre as usize] - truth).length() > 1e-6);
    }
}

/// The limit normal by iterating Loop's rules on the one-ring (v, p_0..p_{n−1}), which map the
/// one-ring onto the next level's one-ring, until the ring lies in the tangent plane.
fn limit_normal_by_subdivision(mut v: DVec3, mut ring: Vec<DVec3>) -> DVec3 {
    let n = ring.len();
    let nf = n as f64;
    let c = 3.0 / 8.0 + 0.25 * (std::f64::consts::TAU / nf).cos();
    let beta = (5.0 / 8.0 - c * c) / nf;
    for _ in 0..200 {
        let sum: DVec3 = ring.iter().sum();
        let nv = (1.0 - nf * beta) * v + beta * sum;
        let nr: Vec<DVec3> = (0..n)
            .map(|i| 0.375 * (v + ring[i]) + 0.125 * (ring[(i + n - 1) % n] + ring[(i + 1) % n]))
            .collect();
        // Rescale about the centre by 1/c (the subdominant eigenvalue) to stay far from underflow.
        v = nv;
        ring = nr.iter().map(|p| v + (*p - v) / c).collect();
    }
    let mut s = DVec3::ZERO;
    for i in 0..n {
        s += (ring[i] - v).cross(ring[(i + 1) % n] - v);
    }
    s.normalize()
}

#[test]
fn loop_limit_normal_matches_subdivision_for_all_valences() {
    let mut rng = Lcg(12345);
    for n in 3..=12usize {
        for _trial in 0..5 {
            let v = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
            let ring: Vec<DVec3> = (0..n)
                .map(|k| {
                    let a =
                        std::f64::consts::TAU * (k as f64 + 0.3 * (rng.uniform() - 0.5)) / n as f64;
                    let r = 0.5 + rng.uniform();
                    v + DVec3::new(r * a.cos(), r * a.sin(), 0.6 * (rng.uniform() - 0.5))
                })
                .collect();
            let positions: Vec<DVec3> = ring.clone();
            let fan = Fan {
                ring: (0..n as u32).collect(),
                faces: (0..n as u32).collect(),
                closed: true,
            };
            let got = mesh::loop_limit_normal(&positions, v, &fan).normalize();
            let want = limit_normal_by_subdivision(v, ring);
            // The iteration converges like (second/first eigenvalue)^200 (< 1e-30); the rest is
            // rounding of O(n) terms.
            assert!(
                (got - want).length() < 1e-10,
                "valence {n}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn loop_boundary_normals_of_a_plane_are_the_plane_normal() {
    // A tilted planar lattice: every vertex, boundary ones included (k = 1, 2, 3 faces),
    // must get the plane's normal.
    let (m, _) = lattice([1.0, 0.1], [0.2, 0.9], 3, |x, y| 0.2 * x - 0.3 * y);
    let want = DVec3::new(-0.2, 0.3, 1.0).normalize();
    let n = mesh::vertex_normals(&m, NormalMethod::Loop).unwrap();
    for (v, n) in n.iter().enumerate() {
        // Exact for a plane up to rounding.
        assert!((*n - want).length() < 1e-12, "vertex {v}: {n}");
    }
}

#[test]
fn above_face_check_flags_bad_normals() {
    let m = model("octahedron.obj");
    let mut n = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    // Tilt vertex 2's normal until it is perpendicular to one of its faces' normals … and beyond.
    n[2] = (n[2] + 3.0 * DVec3::X).normalize();
    let fails = mesh::above_face_failures(&m, &n);
    assert_eq!(fails, vec![2]);
}

#[test]
fn loop_normals_converge_on_a_sampled_quadric_boundary_included() {
    // z = 0.5x² − 0.3xy + 0.4y² sampled on hexagonal lattices of spacing h: interior Loop
    // normals are exact (see above); boundary normals (k = 1, 2, 3 faces) approximate the graph
    // normal to first order, so halving h must roughly halve the worst error.
    let f = |x: f64, y: f64| 0.5 * x * x - 0.3 * x * y + 0.4 * y * y;
    let truth =
        |p: DVec3| DVec3::new(-(p.x - 0.3 * p.y), -(-0.3 * p.x + 0.8 * p.y), 1.0).normalize();
    let worst = |h: f64| -> (f64, f64) {
        let r = (0.6 / h) as i32;
        let (m, _) = lattice([h, 0.0], [0.5 * h, 0.75f64.sqrt() * h], r, f);
        let t = mesh::Topology::new(m.positions.len(), &m.faces);
        let n = mesh::vertex_normals(&m, NormalMethod::Loop).unwrap();
        let (mut interior, mut boundary) = (0.0f64, 0.0f64);
        for (v, n) in n.iter().enumerate() {
            let e = (*n - truth(m.positions[v])).length();
            if t.vertex_fan(v as u32).unwrap().closed {
                interior = interior.max(e);
            } else {
                boundary = boundary.max(e);
            }
        }
        (interior, boundary)
    };
    let (i1, b1) = worst(0.1);
    let (i2, b2) = worst(0.05);
    // Interior: exact up to rounding of a few dozen terms.
    assert!(i1 < 1e-13 && i2 < 1e-13, "{i1:e} {i2:e}");
    // Boundary: measured 5.65e-2 → 2.63e-2 (ratio 0.47); first order allows at most ~0.6.
    assert!(b1 < 0.07 && b2 < 0.6 * b1, "{b1:e} {b2:e}");
}

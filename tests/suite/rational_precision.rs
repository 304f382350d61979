//! Quadratic precision (Theorem 4.2), plane recovery, the free-parameter choices, bad input and
//! the local refinement of the rational C¹ scheme.

use crate::rational_support as support;

use apatch::complex::{Role, SheetRule};
use apatch::scheme::rational_c1::bound::minimal_root_slope;
use apatch::scheme::rational_c1::eval::value_gradient;
use apatch::scheme::rational_c1::{build, Free, RationalOptions};
use glam::DVec3;
use support::*;

/// Largest | |p| − 1 | over the minimal roots of shooting cubics on a grid of every face and
/// edge patch.
fn sphere_radius_error(m: &Model) -> (usize, f64) {
    let opts = RationalOptions {
        free: Free::Quadric,
        ..RationalOptions::default()
    };
    let b = build(&m.positions, &m.triangles, &m.normals, &opts).expect("sphere builds");
    assert_eq!(
        b.raised_faces, 0,
        "the quadric's own values must pass the bounds"
    );
    let mut worst = 0.0f64;
    let mut count = 0;
    let n = 5;
    for p in &b.complex.patches {
        let SheetRule::Shooting { base, top } = &p.sheet else {
            continue;
        };
        let t = p.tet_points();
        for i in 0..=n {
            for j in 0..=n - i.min(n) {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                let (q, u) = if base.len() == 3 {
                    if x + y > 1.0 {
                        continue;
                    }
                    (
                        t[base[0] as usize] * x
                            + t[base[1] as usize] * y
                            + t[base[2] as usize] * (1.0 - x - y),
                        t[top[0] as usize],
                    )
                } else {
                    (
                        t[base[0] as usize] * x + t[base[1] as usize] * (1.0 - x),
                        t[top[0] as usize] * y + t[top[1] as usize] * (1.0 - y),
                    )
                };
                let c = shooting_cubic(p, q, u);
                if let Some((r, _)) = minimal_root_slope(c) {
                    let pt = q + (u - q) * r;
                    worst = worst.max((pt.length() - 1.0).abs());
                    count += 1;
                }
            }
        }
    }
    (count, worst)
}

#[test]
fn icosahedron_gives_the_unit_sphere() {
    let (count, err) = sphere_radius_error(&sphere_model("icosahedron", 0));
    eprintln!("icosahedron: {count} surface points, max | |p| - 1 | = {err:.2e}");
    assert!(count > 300);
    // Exact reproduction; the root bisection runs to ~1e-16 in t, rounding remains.
    assert!(err < 1e-9, "radius error {err}");
}

#[test]
fn subdivided_icosahedron_gives_the_unit_sphere() {
    let (count, err) = sphere_radius_error(&sphere_model("icosahedron/1", 1));
    eprintln!("icosahedron/1: {count} surface points, max | |p| - 1 | = {err:.2e}");
    assert!(count > 1000);
    // As above.
    assert!(err < 1e-9, "radius error {err}");
}

#[test]
fn quadric_choice_on_an_ellipsoid_matches_the_quadric() {
    // Data from Q = x²/4 + y² + z²/2.25 − 1 scaled so that ∇Q is the unit normal at the vertices
    // is not a quadric with unit-gradient data; instead check the weaker property that the
    // quadric choice stays above the bound and keeps the surface C¹ (by the model checks).
    let (v, f) = icosahedron();
    let (v, f) = subdivide_sphere(&v, &f, 1);
    let r = DVec3::new(2.0, 1.0, 1.5);
    let pos: Vec<DVec3> = v.iter().map(|p| *p * r).collect();
    let nrm: Vec<DVec3> = v.iter().map(|p| (*p / r).normalize()).collect();
    let opts = RationalOptions {
        free: Free::Quadric,
        ..RationalOptions::default()
    };
    let b = build(&pos, &f, &nrm, &opts).expect("ellipsoid builds");
    for (lb, fv) in b.lower_bounds.iter().zip(&b.free_values) {
        // σ f ≥ B for the positive side (σ = +1).
        assert!(fv[0] >= lb[0], "f {} below bound {}", fv[0], lb[0]);
    }
    let cont = continuity(&b.complex, 5);
    // C¹ by construction; rounding only.
    assert!(cont.max_grad_jump < 1e-9 && cont.max_value_jump < 1e-9);
}

#[test]
fn plane_recovery() {
    // Fig. 10: a zero-convex face next to a nonconvex one.
    let m = paper_example(10);
    let b = build(
        &m.positions,
        &m.triangles,
        &m.normals,
        &RationalOptions::default(),
    )
    .unwrap();
    assert_eq!(b.faces_by_class[1], 1);
    let planar: Vec<_> = b
        .complex
        .patches
        .iter()
        .filter(|p| p.role == Role::Planar)
        .collect();
    assert_eq!(planar.len(), 1);
    // The planar patch vanishes exactly on its face.
    let tri = m.triangles[1].map(|i| m.positions[i as usize]);
    for (a, c) in [(0.2, 0.3), (0.6, 0.1), (1.0 / 3.0, 1.0 / 3.0)] {
        let x = tri[0] * (1.0 - a - c) + tri[1] * a + tri[2] * c;
        let (f, g) = value_gradient(planar[0], x);
        assert!(f.abs() < 1e-14, "planar F = {f}");
        // Unit gradient along the face normal (0, 0, 1), up to rounding.
        assert!((g - DVec3::Z).length() < 1e-12);
    }
    // The curved neighbour contains the shared (zero-convex) edge with normal (0,0,1) along it.
    let (p1, p2) = (m.positions[0], m.positions[1]);
    for p in b.complex.patches.iter().filter(|p| p.role == Role::Face) {
        let tet = p.tet_points();
        if !(tet.contains(&p1) && tet.contains(&p2)) {
            continue;
        }
        for s in [0.1, 0.37, 0.5, 0.8] {
            let x = p1 * (1.0 - s) + p2 * s;
            let (f, g) = value_gradient(p, x);
            // F ≡ 0 and ∇F ∥ n on a zero-convex edge (the Hermite data vanish); rounding only.
            assert!(f.abs() < 1e-13, "F on the edge = {f}");
            assert!((g.normalize() - DVec3::Z).length() < 1e-12, "normal {g}");
        }
    }
    // A flat mesh with face normals is nothing but planar patches.
    let pos = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
    let tris = vec![[0, 1, 3], [0, 3, 2]];
    let nrm = vec![DVec3::Z; 4];
    let b = build(&pos, &tris, &nrm, &RationalOptions::default()).unwrap();
    assert!(b.complex.patches.iter().all(|p| p.role == Role::Planar));
}

#[test]
fn offset_respects_bounds_and_orders_the_family() {
    // Fig. 2: f_0003 = B + b; a larger b pushes the surface down towards the base triangle.
    let m = paper_example(6);
    let mut last_height = f64::INFINITY;
    for off in [0.01, 0.5, 5.0, 50.0] {
        let opts = RationalOptions {
            free: Free::Offset(off),
            ..RationalOptions::default()
        };
        let b = build(&m.positions, &m.triangles, &m.normals, &opts).unwrap();
        for (lb, fv) in b.lower_bounds.iter().zip(&b.free_values) {
            // The offset is exact unless an edge check raised the face.
            assert!((fv[0] - (lb[0] + off)).abs() < 1e-12 * (1.0 + off) || b.raised_faces > 0);
        }
        // Height of the surface above the centroid of face 0.
        let p = &b.complex.patches[0];
        let t = p.tet_points();
        let q = (t[0] + t[1] + t[2]) / 3.0;
        let c = shooting_cubic(p, q, t[3]);
        let (r, _) = minimal_root_slope(c).expect("root");
        assert!(
            r < last_height,
            "offset {off}: t = {r} not below {last_height}"
        );
        last_height = r;
    }
}

#[test]
fn per_face_override() {
    let m = paper_example(6);
    let opts = RationalOptions {
        free: Free::Offset(0.1),
        face_free: vec![(1, Free::Offset(3.0))],
        ..RationalOptions::default()
    };
    let b = build(&m.positions, &m.triangles, &m.normals, &opts).unwrap();
    let d0 = b.free_values[0][0] - b.lower_bounds[0][0];
    let d1 = b.free_values[1][0] - b.lower_bounds[1][0];
    // Exact offsets (rounding only) unless raised.
    assert!(
        (d0 - 0.1).abs() < 1e-12 && (d1 - 3.0).abs() < 1e-12,
        "{d0} {d1}"
    );
}

#[test]
fn bad_input_is_an_error() {
    let m = paper_example(6);
    let opts = RationalOptions::default();
    // A normal on the wrong side of its triangle: the documented fallback replaces it by the
    // angle-weighted normal, and the result is still C¹.
    let mut n = m.normals.clone();
    n[2] = -n[2];
    let b = build(&m.positions, &m.triangles, &n, &opts).unwrap();
    assert_eq!(b.replaced_normals, 1);
    let cont = continuity(&b.complex, 5);
    // Rounding only.
    assert!(cont.max_grad_jump < 1e-9);
    let mut n = m.normals.clone();
    n[1] = DVec3::ZERO;
    let e = build(&m.positions, &m.triangles, &n, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertex 1"), "{e}");
    let mut p = m.positions.clone();
    p[2] = p[0];
    let e = build(&p, &m.triangles, &m.normals, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("degenerate"), "{e}");
    let tris = vec![[0, 1, 2], [1, 0, 3], [0, 1, 3]];
    let e = build(&m.positions, &tris, &m.normals, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("more than two"), "{e}");
    let e = build(&m.positions, &[[0, 1, 9]], &m.normals, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("out of range"), "{e}");
    // A normal in the plane of its face.
    let mut n = m.normals.clone();
    n[0] = DVec3::new(0.0, 1.0, 0.25).normalize();
    let r = build(&m.positions, &m.triangles, &n, &opts);
    if let Err(e) = r {
        assert!(e.to_string().contains("triangle"), "{e}");
    }
}

#[test]
fn options_from_toml() {
    let file = std::path::Path::new("scene.toml");
    let t: toml::Table = toml::from_str(
        r#"type = "rational-c1"
free = { offset = 0.5 }
epsilon = 0.1
faces = { "3" = "quadric", "4" = { offset = 2 } }"#,
    )
    .unwrap();
    let o = RationalOptions::from_toml(&t, file).unwrap();
    assert_eq!(o.free, Free::Offset(0.5));
    assert_eq!(o.epsilon, 0.1);
    assert_eq!(
        o.face_free,
        vec![(3, Free::Quadric), (4, Free::Offset(2.0))]
    );
    for (bad, key) in [
        ("free = \"cubic\"", "free"),
        ("free = { offset = -1 }", "free"),
        ("colour = 3", "colour"),
        ("epsilon = \"x\"", "epsilon"),
        ("faces = { \"x\" = \"default\" }", "faces"),
    ] {
        let t: toml::Table = toml::from_str(bad).unwrap();
        let e = RationalOptions::from_toml(&t, file)
            .unwrap_err()
            .to_string();
        assert!(e.contains("scene.toml") && e.contains(key), "{bad}: {e}");
    }
}

#[test]
fn valley_is_refined_or_rejected_cleanly() {
    // A narrow concave V: the positive face tetrahedra of its two flanks point into the valley.
    let pos = vec![
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.6, 2.0),
        DVec3::new(0.0, -0.6, 2.0),
    ];
    let tris = vec![[0, 1, 2], [1, 0, 3]];
    let nrm = vec![
        DVec3::Z,
        DVec3::Z,
        DVec3::new(0.0, -0.3, 1.0).normalize(),
        DVec3::new(0.0, 0.3, 1.0).normalize(),
    ];
    match build(&pos, &tris, &nrm, &RationalOptions::default()) {
        Ok(b) => {
            eprintln!(
                "valley: refined {} edges into {} triangles",
                b.refined_edges,
                b.triangles.len()
            );
            let cont = continuity(&b.complex, 5);
            assert!(cont.max_grad_jump < 1e-9 && cont.max_sharing <= 2);
        }
        Err(e) => {
            eprintln!("valley: {e}");
            assert!(e.to_string().contains("refine"), "{e}");
        }
    }
}

//! Fair free weights of the 1994 cubic scheme (issue 7): the fairness figure
//! ([`apatch::scheme::cubic_c1::fairness`], the angle between the surface normal and the blend
//! of the normals at T's points) of the fair target ([`FreeWeights::Fair`], the default) against
//! the level rule ([`FreeWeights::Level`], the old default) on the same hull, and `check` on the
//! fair surfaces. `cargo test --release --test suite cubic_fair:: -- --ignored --nocapture` prints the
//! figure for every cubic scene (the README's survey).

use apatch::check::{check, CheckOptions};
use apatch::scene;
use apatch::scheme::cubic_c1::fairness::{fairness, Fairness};
use apatch::scheme::cubic_c1::{build_full, options_from_toml, CubicOptions, FreeWeights};
use std::path::{Path, PathBuf};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/paper1994")
        .join(format!("{name}.toml"))
}

/// The scene's hull (before the scheme's own apex changes, which `build_full` makes) and its
/// cubic options.
fn hull_and_options(name: &str) -> (apatch::hull::simplicial::SimplicialHull, CubicOptions) {
    let path = scene_path(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let scheme = table["scheme"].as_table().unwrap().clone();
    let model = table["model"].as_table().unwrap();
    let file = path.parent().unwrap().join(model["file"].as_str().unwrap());
    let method = model["normals"].as_str().unwrap().parse().unwrap();
    let (m, _) = apatch::mesh::load(&file).unwrap();
    let vn = apatch::mesh::vertex_normals(&m, method).unwrap();
    let (cubic, inner) = options_from_toml(&scheme, &path).unwrap();
    let hull = apatch::hull::inner::build(&m, &vn, &inner).unwrap();
    (hull, cubic)
}

fn row(name: &str, f: &Fairness) -> String {
    format!(
        "| {name} | {:.1} / {:.1} / {:.1} | {:.1} / {:.1} / {:.1} |",
        f.face.max, f.face.p95, f.face.rms, f.edge.max, f.edge.p95, f.edge.rms
    )
}

/// On the models the issue names (coarse quad tori, the genus-2 waist, the nut) the fair target
/// lowers the 95th percentile of the normal deviation, on face and on edge tetrahedra, by at
/// least the factor asked below, and the fair surfaces pass `check` (C¹ to 1e-9, interpolation,
/// single sheets, no holes) and keep every sign condition (no edge tetrahedron unsigned).
#[test]
fn fair_target_lowers_normal_deviation_and_passes_check() {
    // (model, largest fair/level ratios of the p95 deviations on face and on edge tetrahedra).
    // Measured: torus_quad 18.1/47.1 (face) 17.6/33.0 (edge), torus_quad12x8 9.8/19.4,
    // 9.4/16.4, double_torus_poly 11.4/18.6, 10.6/21.3, nut 20.3/25.0, 19.7/27.4 (its scene's
    // ring_normals hull; 26.9/35.8, 21.9/31.7 on the paper's normals); the bounds
    // leave ~10–20% room for rounding across platforms (the figure samples a fixed lattice, so
    // it is deterministic on one machine) while failing if the improvement goes.
    for (name, face_ratio, edge_ratio) in [
        ("torus_quad", 0.45, 0.6),
        ("torus_quad12x8", 0.6, 0.65),
        ("double_torus_poly", 0.7, 0.6),
        ("nut", 0.85, 0.8),
    ] {
        let (hull, options) = hull_and_options(name);
        assert_eq!(options.free, FreeWeights::Fair, "{name}: the default");
        let fair = build_full(&hull, &options).unwrap();
        let level = build_full(
            &hull,
            &CubicOptions {
                free: FreeWeights::Level,
                ..options.clone()
            },
        )
        .unwrap();
        assert!(fair.fair_faces > 0 && level.fair_faces == 0, "{name}");
        let (ff, fl) = (fairness(&fair.complex), fairness(&level.complex));
        eprintln!("{} (fair)\n{} (level)", row(name, &ff), row(name, &fl));
        assert!(ff.face.samples > 100 && ff.edge.samples > 100, "{name}");
        assert!(
            ff.face.p95 <= face_ratio * fl.face.p95,
            "{name}: face {ff:?} vs {fl:?}"
        );
        assert!(
            ff.edge.p95 <= edge_ratio * fl.edge.p95,
            "{name}: edge {ff:?} vs {fl:?}"
        );
        assert_eq!(fair.unsigned, 0, "{name}");
        let r = check(&fair.complex, &CheckOptions::default());
        assert!(r.passed(), "{name}: {:?}", r.failures());
        // 1e-9: the bound on relative C¹ jumps; the fair target only changes free
        // weights, so the constrained ones stay exact to round-off.
        assert!(r.gradient_jump.worst <= 1e-9, "{name}");
    }
}

/// The nut's scene turns its pseudo-centroid normals towards the large flat faces
/// (`ring_normals = 1`, `hull::inner::normals`): the hull still verifies, the turned normals are
/// only pseudo-centroids', and the fairness figure on face and edge tetrahedra drops against the
/// same scene with the paper's normals (ring_normals = 0); `scenes_all` checks the surface.
#[test]
fn nut_ring_normals_flatten_the_sides() {
    let path = scene_path("nut");
    let text = std::fs::read_to_string(&path).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let mut scheme = table["scheme"].as_table().unwrap().clone();
    assert_eq!(scheme["ring_normals"].as_float(), Some(1.0));
    let (flat_hull, options) = hull_and_options("nut");
    scheme.insert("ring_normals".into(), 0.0.into());
    let (_, inner0) = options_from_toml(&scheme, &path).unwrap();
    assert_eq!(inner0.ring_normals, 0.0);
    let file = path.parent().unwrap().join("../models/nut_pyvista.obj");
    let (m, _) = apatch::mesh::load(&file).unwrap();
    let vn = apatch::mesh::vertex_normals(&m, apatch::mesh::NormalMethod::Angle).unwrap();
    let paper_hull = apatch::hull::inner::build(&m, &vn, &inner0).unwrap();
    assert!(apatch::hull::inner::verify(&flat_hull).is_empty());
    assert_eq!(flat_hull.points, paper_hull.points);
    let turned: Vec<usize> = (0..flat_hull.normals.len())
        .filter(|&i| flat_hull.normals[i] != paper_hull.normals[i])
        .collect();
    assert!(!turned.is_empty());
    for &i in &turned {
        assert!(matches!(
            flat_hull.origins[i],
            apatch::hull::simplicial::PointOrigin::PseudoCentroid { .. }
        ));
    }
    let flat = fairness(&build_full(&flat_hull, &options).unwrap().complex);
    let paper = fairness(&build_full(&paper_hull, &options).unwrap().complex);
    eprintln!(
        "{} (ring_normals 1)\n{} (ring_normals 0)",
        row("nut", &flat),
        row("nut", &paper)
    );
    // Measured p95: face 20.3° vs 26.9°, edge 19.7° vs 21.9°; the bounds keep some room for
    // rounding across platforms while failing if the flattening goes.
    assert!(
        flat.face.p95 <= 0.85 * paper.face.p95,
        "{flat:?} vs {paper:?}"
    );
    assert!(
        flat.edge.p95 <= 0.97 * paper.edge.p95,
        "{flat:?} vs {paper:?}"
    );
}

/// Where no triangle stands on a pseudo-centroid (the cube: every corner trihedral, the apex is
/// the polyhedron's vertex and `level` its shape control) the fair option changes nothing, bit
/// for bit; a scene that sets `level` gets the level rule.
#[test]
fn trihedral_corners_keep_the_level_rule() {
    let (hull, options) = hull_and_options("cube");
    let fair = build_full(&hull, &options).unwrap();
    let level = build_full(
        &hull,
        &CubicOptions {
            free: FreeWeights::Level,
            ..options
        },
    )
    .unwrap();
    assert_eq!(fair.fair_faces, 0);
    assert_eq!(fair.complex, level.complex);

    let mut t = toml::Table::new();
    t.insert("type".into(), "cubic-c1".into());
    t.insert("level".into(), 0.4.into());
    let (o, _) = options_from_toml(&t, Path::new("x.toml")).unwrap();
    assert_eq!(o.free, FreeWeights::Level);
    t.insert("free".into(), "fair".into());
    assert_eq!(
        options_from_toml(&t, Path::new("x.toml")).unwrap().0.free,
        FreeWeights::Fair
    );
    t.insert("free".into(), "smooth".into());
    let e = options_from_toml(&t, Path::new("x.toml")).unwrap_err();
    assert!(format!("{e}").contains("scheme.free"), "{e}");
}

/// Prints the figure for every cubic scene as shipped (no assertion: the survey behind the
/// README table).
#[test]
#[ignore = "survey: prints the fairness table for all cubic scenes (about a minute in release)"]
fn survey() {
    eprintln!("| scene | face max / p95 / rms (°) | edge max / p95 / rms (°) |");
    for name in [
        "bunny",
        "corner_poly",
        "cube",
        "cube_poly",
        "dodecahedron",
        "double_torus_poly",
        "hallway_corner",
        "icosahedron",
        "knot",
        "l_prism",
        "letter_P_poly",
        "nut",
        "octahedron",
        "spot",
        "star_prism",
        "tetrahedron",
        "torus_quad",
        "torus_quad12x8",
    ] {
        let s = scene::load(&scene_path(name)).unwrap();
        let c = scene::build_complex(&s).unwrap();
        eprintln!("{}", row(name, &fairness(&c)));
    }
}

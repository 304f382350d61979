//! The quintic's holes on boundary faces of the hull (issue 8): explorations on a cached complex.

use apatch::complex::{PatchComplex, Role};
use std::path::PathBuf;

/// The complex of `SCENE`, read from `CACHE` (a patches JSON) when it exists, else built and
/// written there (building the knot takes minutes).
fn complex() -> PatchComplex {
    let cache = std::env::var_os("CACHE").map(PathBuf::from);
    if let Some(c) = &cache {
        if c.exists() {
            return apatch::complex_io::read_json_file(c).unwrap();
        }
    }
    let path = PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    if let Some(f) = &cache {
        apatch::complex_io::write_json_file(&c, f).unwrap();
    }
    c
}

/// Exploration: every crossed boundary face of an edge tetrahedron, with its 21 weights as a
/// triangle (rows by the opposite point's multiplicity), where F is most negative on it, and
/// how far the apex-side sign goes.
/// `SCENE=… CACHE=/tmp/x.json cargo test --release --test suite quintic_holes::edge_hole_faces --
/// --ignored --nocapture`.
#[test]
#[ignore = "exploration: SCENE=path [CACHE=json]"]
fn edge_hole_faces() {
    let c = complex();
    let (crossed, wmax) = apatch::fixtures::crossed_boundary_faces(
        &c,
        24,
        1e-12,
        apatch::fixtures::SignScale::Complex,
    );
    eprintln!("{} crossed boundary faces, wmax {wmax:.3e}", crossed.len());
    let mut by: std::collections::BTreeMap<String, usize> = Default::default();
    for (k, opp) in crossed {
        let p = &c.patches[k];
        *by.entry(format!("{:?} opp {opp}", p.role)).or_default() += 1;
        if p.role != Role::Edge {
            continue;
        }
        let s = p.weights[apatch::bb::index_of([0, 0, 0, 5])].signum();
        let others: Vec<usize> = (0..4).filter(|&x| x != opp).collect();
        // Most negative (apex-side sign) point of F on the face.
        let steps = 40;
        let (mut worst, mut at) = (f64::INFINITY, [0.0; 4]);
        for i in 0..=steps {
            for j in 0..=steps - i {
                let mut b = [0.0; 4];
                b[others[0]] = i as f64 / steps as f64;
                b[others[1]] = j as f64 / steps as f64;
                b[others[2]] = (steps - i - j) as f64 / steps as f64;
                let f = s * p.value_bary(b);
                if f < worst {
                    worst = f;
                    at = b;
                }
            }
        }
        eprintln!(
            "patch {k} el {} opp {opp}: min sF {worst:.3e} at {at:.2?}; weights (index: [l0 l1 l2 l3])",
            p.element
        );
        // Rows: the first of the other corners (a point of T for opp = 0 or 1).
        for a in (0..=5u8).rev() {
            let mut line = format!("  {}^{a}:", others[0]);
            for b in (0..=5 - a).rev() {
                let mut l = [0u8; 4];
                l[others[0]] = a;
                l[others[1]] = b;
                l[others[2]] = 5 - a - b;
                let w = s * p.weights[apatch::bb::index_of(l)];
                line += &format!(" {l:?}={w:+.2e}");
            }
            eprintln!("{line}");
        }
    }
    eprintln!("{by:?}");
}

/// The hole repair on a small model with the knot's hole pattern: the 12×8 quad torus without
/// `relax_stars` crosses hundreds of outer faces [p q s] of edge tetrahedra (its star weights,
/// determined by the square star systems, miss their signs there). With `repair_holes` the
/// late weights around each such face are re-solved with the face's weights pinned: no
/// crossed face left, by the checker and by an independent sampling (not the scheme's own
/// test; session 12's repair left 93 of 384, session 10's 196), the checker's C1/C2 measures
/// within issue 8's bounds (the re-solve keeps every C1/C2 equation), and no more patches
/// crossed twice along a j-line than before.
#[test]
#[ignore = "slow (64 s release): repair_holes is opt-in; the knot's scene sets it"]
fn repair_holes_reduces_the_torus_holes_and_keeps_c2() {
    use apatch::check::{check, CheckOptions};
    use apatch::mesh::{self, NormalMethod};
    use apatch::scheme::quintic_c2::{build_with_stats, QuinticOptions};
    let (m, _) = mesh::load(std::path::Path::new("scenes/models/torus_quad12x8.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::default_for(&m)).unwrap();
    let hull =
        apatch::hull::inner::build(&m, &normals, &apatch::hull::inner::InnerOptions::default())
            .unwrap();
    let mut crossed = Vec::new();
    for repair in [false, true] {
        let o = QuinticOptions {
            relax_stars: false,
            repair_holes: repair,
            ..QuinticOptions::default()
        };
        let (c, stats) = build_with_stats(&hull, &o).unwrap();
        let r = check(&c, &CheckOptions::default());
        // Issue 8's C2 acceptance on the checker's relative measures.
        assert!(r.gradient_jump.worst <= 1e-9, "{:?}", r.gradient_jump);
        assert!(r.hessian_jump.worst <= 1e-7, "{:?}", r.hessian_jump);
        // A lattice of 15 steps; "zero" is 1e-12 of the largest weight (rounding of the
        // degree-5 evaluation; F = 0 at the points of T on the faces).
        let sampled = apatch::fixtures::crossed_boundary_faces(
            &c,
            15,
            1e-12,
            apatch::fixtures::SignScale::Complex,
        )
        .0
        .len();
        eprintln!(
            "repair {repair}: {:?}, checker holes {:?}, sampled {sampled}, j-sheets {}",
            stats.hole_repair, r.holes.crossing_by_role, r.sheets.j_multi_patches
        );
        crossed.push((
            r.holes.crossing,
            sampled,
            stats.hole_repair,
            r.sheets.j_multi_patches,
        ));
    }
    assert!(crossed[0].0 > 100 && crossed[0].1 > 100, "{crossed:?}");
    assert!(crossed[1].2.repaired > 0, "{crossed:?}");
    assert!(crossed[1].0 == 0 && crossed[1].1 == 0, "{crossed:?}");
    // The repair also judges j-sheets: it may not add any (the checker's count).
    assert!(crossed[1].3 <= crossed[0].3, "{crossed:?}");
}

/// The repair's j-sheet half and its parallel waves, on a small model: letter_P_poly's quintic
/// without `hessian_signs` has patches crossed twice along j-lines and crossed base faces
/// whose weights are jets and stars. With `repair_holes` the checker finds no j-sheet, no more
/// crossed faces, and everything else within issue 8's bounds; and
/// the repaired weights are the same, bit for bit, on one thread and on four (the waves run
/// only repairs that touch nothing of each other's together).
#[test]
fn repair_mends_letter_p_j_sheets_on_any_thread_count() {
    use apatch::check::{check, CheckOptions};
    let path = std::path::Path::new("scenes/paper1994/letter_P_poly_quintic.toml");
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("hessian_signs = true"), "the scene changed");
    let plain = text.replace("hessian_signs = true", "hessian_signs = false");
    // The Hessian passes are left to the next test (they take ~50 s here).
    let repaired = plain.replace(
        "hessian_signs = false",
        "hessian_signs = false\nrepair_holes = true\nrepair_hessians = false",
    );
    let build = |text: &str, threads: usize| {
        let scene = apatch::scene::parse(text, path).unwrap();
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| apatch::scene::build_complex(&scene).unwrap())
    };
    let before = check(&build(&plain, 2), &CheckOptions::default());
    let one = build(&repaired, 1);
    let four = build(&repaired, 4);
    assert_eq!(one.patches.len(), four.patches.len());
    for (a, b) in one.patches.iter().zip(&four.patches) {
        let bits =
            |p: &apatch::complex::Patch| p.weights.iter().map(|w| w.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(a), bits(b));
    }
    let after = check(&one, &CheckOptions::default());
    assert!(before.sheets.j_multi_patches > 0, "{:?}", before.sheets);
    assert_eq!(after.sheets.j_multi_patches, 0, "{:?}", after.sheets);
    // The base faces' weights are jets and stars, which these passes do not free (the Hessian
    // passes do: next test): no more crossed faces than before.
    assert!(
        after.holes.crossing <= before.holes.crossing,
        "{:?}",
        after.holes
    );
    // Everything else passes: C1/C2 within issue 8's bounds, vertex values and normals still
    // interpolated.
    assert_eq!(after.failures(), ["holes"], "{after:?}");
}

/// The repair's Hessian passes (`repair_hessians`, on by default): letter_P_poly's quintic
/// without `hessian_signs` keeps crossed base faces of face tetrahedra after the other passes,
/// because all their weights are jets and stars; freeing the jets' Hessians within reach (one
/// symmetric change per point, values and normals held) mends some of them. Checked against
/// the same repair without the Hessian passes: fewer crossed faces, still no j-sheet, C1/C2
/// and interpolation within issue 8's bounds.
#[test]
fn repair_hessian_passes_mend_letter_p_base_faces() {
    use apatch::check::{check, CheckOptions};
    let path = std::path::Path::new("scenes/paper1994/letter_P_poly_quintic.toml");
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("hessian_signs = true"), "the scene changed");
    let repaired = text.replace(
        "hessian_signs = true",
        "hessian_signs = false\nrepair_holes = true",
    );
    let without = repaired.replace(
        "repair_holes = true",
        "repair_holes = true\nrepair_hessians = false",
    );
    let build = |text: &str| {
        let scene = apatch::scene::parse(text, path).unwrap();
        apatch::scene::build_complex(&scene).unwrap()
    };
    let base = check(&build(&without), &CheckOptions::default());
    // Fewer crossed faces than without the Hessians, and no j-sheet.
    let mends = |text: &str| {
        let report = check(&build(text), &CheckOptions::default());
        assert!(
            report.holes.crossing < base.holes.crossing,
            "{:?} vs {:?}",
            report.holes,
            base.holes
        );
        assert_eq!(report.sheets.j_multi_patches, 0, "{:?}", report.sheets);
        report
    };
    let after = mends(&repaired);
    assert_eq!(after.failures(), ["holes"], "{after:?}");
    // `repair_hessians = "all"`: the Hessians free in every pass, as the environment
    // override `APATCH_HOLE_HESSIANS=1` asked before the key existed.
    mends(&repaired.replace(
        "repair_holes = true",
        "repair_holes = true\nrepair_hessians = \"all\"",
    ));
}

/// Exploration `APATCH_HOLE_ELEVATE`: letter_P_poly without `hessian_signs`, repaired with the
/// Hessians free in every pass, keeps crossed base faces whose pins are Theorem 2.1's signs on
/// the weights (at its crease points the sides ask opposite signs of the curvature along one
/// line: no margin is feasible); with the signs asked of the faces' coefficients elevated by
/// 2 degrees instead, those faces are mended and C1/C2 stay within `check`'s bounds, with the
/// margins tried in turn: the whole `check` passes; the scene keys `repair_elevate` and
/// `repair_margins` ask the same.
#[test]
fn elevated_face_pins_mend_what_weight_pins_cannot() {
    use std::process::Command;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("scenes/paper1994/letter_P_poly_quintic.toml"))
        .unwrap()
        .replace(
            "\"../models/",
            &format!("\"{}/", root.join("scenes/models").display()),
        )
        .replace(
            "hessian_signs = true",
            "hessian_signs = false\nrepair_holes = true\nrepair_hessians = \"all\"",
        );
    assert!(text.contains("repair_holes = true"), "the scene changed");
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let scene = dir.join("letter_p_elevate.toml");
    // The same cascade asked by the scene keys instead of the environment.
    let keyed = dir.join("letter_p_elevate_keys.toml");
    std::fs::write(
        &keyed,
        text.replace(
            "repair_holes = true",
            "repair_holes = true\nrepair_elevate = 2\nrepair_margins = [\"weights\", 1, 1e-2, 0]",
        ),
    )
    .unwrap();
    std::fs::write(&scene, text).unwrap();
    let export = |scene: &std::path::Path, out: &str, elevate: Option<(&str, &str)>| {
        let out = dir.join(out);
        let mut c = Command::new(env!("CARGO_BIN_EXE_apatch"));
        c.args(["export", "patches"]).arg(scene).arg("-o").arg(&out);
        for v in [
            "APATCH_HOLE_ELEVATE",
            "APATCH_HOLE_ELEVATE_MARGIN",
            "APATCH_HOLE_ELEVATE_SCOPE",
            "APATCH_HOLE_RINGS",
        ] {
            c.env_remove(v);
        }
        if let Some((r, margins)) = elevate {
            c.env("APATCH_HOLE_ELEVATE", r)
                .env("APATCH_HOLE_ELEVATE_MARGIN", margins);
        }
        let o = c.output().expect("run apatch");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let run = |out: &str, elevate: Option<(&str, &str)>| {
        let out = export(&scene, out, elevate);
        let complex = apatch::complex_io::read_json_file(&out).unwrap();
        apatch::check::check(&complex, &apatch::check::CheckOptions::default())
    };
    let plain = run("letter_p_plain.json", None);
    // The cascade fandisk's repair runs: 6 of the 12 face repairs refuse the weights' pins and
    // are kept with the elevated ones at margin 1 (none here needs a smaller margin, so the
    // elevated tries' shared factor is built once per defect and not reused).
    let elevated = run("letter_p_elevated.json", Some(("2", "w,1,1e-2,0")));
    assert!(plain.holes.crossing > 0, "{:?}", plain.holes);
    // Only the crossed face is elevated (the default scope), its neighbours watched by whether
    // they turn: every defect is mended, j-sheets too, and `check` passes.
    assert_eq!(elevated.holes.crossing, 0, "{:?}", elevated.holes);
    assert!(elevated.failures().is_empty(), "{elevated}");
    // The scheme's C1 and C2 bounds as `check` applies them (1e-9 and 1e-7).
    assert!(
        elevated.gradient_jump.worst <= 1e-9,
        "{}",
        elevated.gradient_jump.worst
    );
    assert!(
        elevated.hessian_jump.worst <= 1e-7,
        "{}",
        elevated.hessian_jump.worst
    );
    // `repair_elevate = 2`, `repair_margins = ["weights", 1, 1e-2, 0]`: the same repair, bit
    // for bit.
    let by_keys = export(&keyed, "letter_p_elevated_keys.json", None);
    assert!(
        std::fs::read(by_keys).unwrap()
            == std::fs::read(dir.join("letter_p_elevated.json")).unwrap(),
        "the scene keys' cascade differs from the environment's"
    );
}

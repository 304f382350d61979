//! The rational C¹ scheme on generated models: interpolation, C¹ continuity across every shared
//! tetrahedron face, at most two patches per face, simple selected roots.

use crate::rational_support as support;

use apatch::scheme::rational_c1::{build, Free, RationalOptions};
use support::*;

/// Interpolation is exact by construction (Steps 1–2); only rounding remains.
const INTERP_TOL: f64 = 1e-12;
/// C¹ joins are exact by construction ((2.2)/(2.3)); rounding in the weights and in the
/// reference evaluation (barycentrics by a 3×3 inverse) remains.
const JUMP_TOL: f64 = 1e-9;

fn check_model(m: &Model, opts: &RationalOptions) {
    let b = build(&m.positions, &m.triangles, &m.normals, opts)
        .unwrap_or_else(|e| panic!("{}: {e}", m.name));
    let c = &b.complex;
    let (fv, gv) = interpolation(c);
    let cont = continuity(c, 6);
    let (lines, slope) = min_root_slope(c, 6);
    eprintln!(
        "{}",
        build_summary(m.name, &b, (fv, gv), &cont, (lines, slope))
    );
    assert!(
        fv < INTERP_TOL && gv < INTERP_TOL,
        "{}: interpolation {fv} {gv}",
        m.name
    );
    assert!(
        cont.max_value_jump < JUMP_TOL,
        "{}: value jump {}",
        m.name,
        cont.max_value_jump
    );
    assert!(
        cont.max_grad_jump < JUMP_TOL,
        "{}: gradient jump {}",
        m.name,
        cont.max_grad_jump
    );
    assert!(
        cont.max_sharing <= 2,
        "{}: a face shared by {} patches",
        m.name,
        cont.max_sharing
    );
    // A simple root has a nonzero slope; 1e-9 of the coefficient scale is far from rounding.
    assert!(
        slope > 1e-9,
        "{}: a selected root is (nearly) double: {slope}",
        m.name
    );
}

#[test]
fn octahedron() {
    check_model(&support::octahedron(), &RationalOptions::default());
}

#[test]
fn icosahedron() {
    check_model(&sphere_model("icosahedron", 0), &RationalOptions::default());
}

#[test]
fn subdivided_icosahedron() {
    check_model(
        &sphere_model("icosahedron/1", 1),
        &RationalOptions::default(),
    );
}

#[test]
fn noisy_sphere() {
    check_model(
        &support::noisy_sphere(1, 0.08, 7),
        &RationalOptions::default(),
    );
}

#[test]
fn torus() {
    check_model(
        &support::torus(1.0, 0.4, 12, 8),
        &RationalOptions::default(),
    );
}

#[test]
fn paper_examples() {
    for fig in [6, 7, 9, 10] {
        let mut m = paper_example(fig);
        m.name = ["fig6", "fig7", "fig9", "fig10"]
            [[6, 7, 9, 10].iter().position(|&f| f == fig).unwrap()];
        check_model(&m, &RationalOptions::default());
    }
}

#[test]
fn offset_family() {
    for b in [0.05, 1.0, 10.0] {
        let opts = RationalOptions {
            free: Free::Offset(b),
            ..RationalOptions::default()
        };
        check_model(&paper_example(6), &opts);
        check_model(&paper_example(9), &opts);
    }
}

/// The 1994 polyhedra of `scenes/models` under the 2001 scheme, through the scene pipeline
/// (load, ear clipping, angle-weighted normals, default options), held to `apatch check`'s
/// default tolerances. l_prism, star_prism, hallway_corner, corner_poly and letter_P_poly do not
/// build as they are (intersecting face tetrahedra after the refinement bound, see
/// `scenes/pending/README.md`); they pass with Loop pre-subdivision (next test).
#[test]
fn paper1994_polyhedra_pass_check() {
    use apatch::check::{check, CheckOptions};
    use apatch::mesh::{self, NormalMethod};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    for name in [
        "tetrahedron",
        "cube",
        "cube_poly",
        "octahedron",
        "icosahedron",
        "dodecahedron",
        "torus_quad12x8",
    ] {
        let (m, report) = mesh::load(&dir.join(format!("{name}.obj"))).unwrap();
        report.require(false).unwrap();
        let t = mesh::triangulate(&m);
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let tris: Vec<[u32; 3]> = t.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
        let b = apatch::scheme::rational_c1::build(
            &t.positions,
            &tris,
            &normals,
            &RationalOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = check(&b.complex, &CheckOptions::default());
        assert!(r.passed(), "{name}:\n{r}");
    }
}

/// The 1994 polyhedra that do not build as they are (their 90° and sharper folds survive any
/// split of the common edge, see `scenes/pending/README.md`) build and pass `apatch check`'s
/// default tolerances after one level of Loop pre-subdivision (`model.subdivide`), with
/// angle-weighted normals of the subdivided mesh. Also asserts that the subdivision is what
/// the surface interpolates: the complex's first vertices are the subdivided mesh's.
#[test]
fn paper1994_folded_polyhedra_pass_check_with_loop_pre_subdivision() {
    use apatch::check::{check, CheckOptions};
    use apatch::mesh::{self, subdivide::fold_angles, NormalMethod, Subdivision, SubdivisionRule};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    for name in [
        "l_prism",
        "star_prism",
        "hallway_corner",
        "corner_poly",
        "letter_P_poly",
    ] {
        let (m, report) = mesh::load(&dir.join(format!("{name}.obj"))).unwrap();
        report.require(false).unwrap();
        let t = mesh::triangulate(&m);
        let one = Subdivision {
            rule: SubdivisionRule::Loop,
            levels: 1,
        };
        let s = mesh::subdivide(&t, one).unwrap();
        // The reason it works: the largest fold shrinks (measured 90 → 58, 135 → 91, 90 → 72,
        // 90 → 65, 90 → 67 degrees in this order; the bound 0.85 is above every measured ratio
        // and well below 1, where a rule that only splits triangles would stay).
        let max_fold = |m: &mesh::Mesh| fold_angles(m).into_iter().fold(0.0, f64::max);
        let (before, after) = (max_fold(&t), max_fold(&s));
        assert!(
            before >= 90.0 - 1e-6 && after < 0.85 * before,
            "{name}: folds {before} → {after}"
        );
        let normals = mesh::vertex_normals(&s, NormalMethod::Angle).unwrap();
        let tris: Vec<[u32; 3]> = s.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
        let b = apatch::scheme::rational_c1::build(
            &s.positions,
            &tris,
            &normals,
            &RationalOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        for (v, p) in s.positions.iter().enumerate() {
            assert_eq!(b.complex.vertices[v], p.to_array(), "{name}: vertex {v}");
        }
        let r = check(&b.complex, &CheckOptions::default());
        eprintln!(
            "{name}: folds {before:.1}° → {after:.1}°, {} → {} triangles, refined {}",
            t.faces.len(),
            s.faces.len(),
            b.refined_edges
        );
        assert!(r.passed(), "{name}:\n{r}");
    }
}

/// Survey (not a proof, prints a table): every model of `scenes/models` under the 2001 scheme
/// with 0..=`APATCH_SURVEY_LEVELS` (default 3) levels of Loop pre-subdivision and the normals
/// in `APATCH_SURVEY_NORMALS` (default angle): triangles, fold angles (max / median / count
/// ≥ 90°), whether it builds and passes `check`, refined edges, seconds.
/// `APATCH_SURVEY_MODELS` (comma-separated stems) restricts the models; `APATCH_SURVEY_WELD`
/// welds first (`mesh::weld`, relative tolerance); `APATCH_SURVEY_ROUNDS`, `APATCH_SURVEY_EPSILON`
/// set `refine_rounds` and `epsilon`; `APATCH_SURVEY_WORST` lists the folds of 90° or more.
/// Run: `cargo test --release --test suite rational_models::survey -- --ignored --nocapture`.
#[test]
#[ignore = "survey of every model and level (minutes); prints a table"]
fn survey_pre_subdivision() {
    use apatch::check::{check, CheckOptions};
    use apatch::mesh::{self, subdivide::fold_angles, NormalMethod, Subdivision, SubdivisionRule};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    let max_levels: u32 = std::env::var("APATCH_SURVEY_LEVELS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let method: NormalMethod = std::env::var("APATCH_SURVEY_NORMALS")
        .unwrap_or_else(|_| "angle".into())
        .parse()
        .unwrap();
    let only: Option<Vec<String>> = std::env::var("APATCH_SURVEY_MODELS")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "obj").then(|| p.file_stem()?.to_str().map(str::to_string))?
        })
        .collect();
    names.sort();
    for name in names {
        if only.as_ref().is_some_and(|o| !o.contains(&name)) {
            continue;
        }
        let (mut m, report) = mesh::load(&dir.join(format!("{name}.obj"))).unwrap();
        if report.require(false).is_err() {
            eprintln!("{name}: rejected by load");
            continue;
        }
        if let Some(w) = std::env::var("APATCH_SURVEY_WELD")
            .ok()
            .and_then(|s| s.parse().ok())
        {
            let (welded, _, moved) = mesh::weld(&m, w).unwrap();
            eprintln!("{name}: weld {w}: {moved} vertices moved");
            m = welded;
        }
        let tri = mesh::triangulate(&m);
        for levels in 0..=max_levels {
            let t0 = std::time::Instant::now();
            let s = mesh::subdivide(
                &tri,
                Subdivision {
                    rule: SubdivisionRule::Loop,
                    levels,
                },
            )
            .unwrap();
            let mut folds = fold_angles(&s);
            folds.sort_by(f64::total_cmp);
            let (max, med) = (
                folds.last().copied().unwrap_or(0.0),
                folds.get(folds.len() / 2).copied().unwrap_or(0.0),
            );
            let over90 = folds.iter().filter(|&&a| a >= 90.0).count();
            if std::env::var_os("APATCH_SURVEY_WORST").is_some() {
                let topo = apatch::mesh::Topology::new(s.positions.len(), &s.faces);
                let all = fold_angles(&s);
                let mut k = 0;
                for e in 0..topo.edges.len() as u32 {
                    if topo.edge_corners(e).len() == 2 {
                        if all[k] >= 90.0 {
                            let [a, b] = topo.edges[e as usize];
                            eprintln!(
                                "  fold {:.1} at edge {a}-{b} {} {}",
                                all[k], s.positions[a as usize], s.positions[b as usize]
                            );
                        }
                        k += 1;
                    }
                }
            }
            let normals = if levels == 0 && method != NormalMethod::Loop {
                mesh::vertex_normals(&m, method)
            } else {
                mesh::vertex_normals(&s, method)
            };
            let tris: Vec<[u32; 3]> = s.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
            let result = normals.map_err(|e| e.to_string()).and_then(|n| {
                apatch::scheme::rational_c1::build(
                    &s.positions,
                    &tris,
                    &n,
                    &RationalOptions {
                        refine_rounds: std::env::var("APATCH_SURVEY_ROUNDS")
                            .ok()
                            .and_then(|s| s.parse().ok())
                            .unwrap_or(4),
                        epsilon: std::env::var("APATCH_SURVEY_EPSILON")
                            .ok()
                            .and_then(|s| s.parse().ok())
                            .unwrap_or(0.05),
                        ..RationalOptions::default()
                    },
                )
                .map_err(|e| e.to_string())
            });
            let build_s = t0.elapsed().as_secs_f64();
            let verdict = match &result {
                Err(e) => format!("FAIL build: {}", &e[..e.len().min(160)]),
                Ok(b) => {
                    let r = check(&b.complex, &CheckOptions::default());
                    eprintln!(
                        "  build {build_s:.1} s, check {:.1} s",
                        t0.elapsed().as_secs_f64() - build_s
                    );
                    if r.passed() {
                        format!("ok, refined {}", b.refined_edges)
                    } else {
                        format!("FAIL check: {:?}", r.failures())
                    }
                }
            };
            eprintln!(
                "{name} L{levels} {method}: {} tris, folds max {max:.1} med {med:.1} ≥90: {over90}; {verdict}; {:.1} s",
                s.faces.len(),
                t0.elapsed().as_secs_f64()
            );
            if result.is_ok() && levels > 0 {
                break;
            }
        }
    }
}

/// `apatch check` on a pre-subdivided scene says that the surface interpolates the subdivided
/// mesh, not the input (text and JSON), and passes.
#[test]
fn check_cli_reports_the_pre_subdivision() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_apatch"))
            .args(args)
            .current_dir(root)
            .output()
            .unwrap()
    };
    let out = run(&["check", "scenes/corner.toml"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("2 levels of `loop`") && text.contains("not the input mesh"),
        "{text}"
    );
    assert!(
        text.contains("20 triangles, 320 after subdivision") && text.contains("edges refined"),
        "{text}"
    );
    // The same scene with a weld (it moves no vertex of this model), as JSON.
    let dir = std::env::temp_dir().join(format!("apatch-folds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = std::fs::read_to_string(root.join("scenes/corner.toml"))
        .unwrap()
        .replace(
            "file = \"models/",
            &format!("weld = 1e-4\nfile = \"{}/scenes/models/", root.display()),
        );
    let path = dir.join("corner_weld.toml");
    std::fs::write(&path, scene).unwrap();
    let out = run(&["check", path.to_str().unwrap(), "--json"]);
    std::fs::remove_dir_all(&dir).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(json["passed"], true);
    assert_eq!(json["subdivision"]["levels"], 2);
    assert_eq!(json["subdivision"]["rule"], "loop");
    assert_eq!(json["weld"], 1e-4);
    // The mesh pipeline's counts: corner_poly's 20 triangles, 16 × 20 after two levels, and
    // the refined edges (none or a few: the count the build reports, at most all edges).
    let mb = &json["mesh_build"];
    assert_eq!(mb["input_triangles"], 20);
    assert_eq!(mb["subdivided_triangles"], 320);
    assert_eq!(mb["welded_vertices"], 0);
    assert!(
        mb["refined_edges"].as_u64().is_some_and(|r| r <= 480),
        "{mb}"
    );
}

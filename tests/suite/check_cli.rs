//! `apatch check` and `apatch export patches` from the command line: exit 0 on a good complex,
//! 1 on a broken one (with the jump reported), 2 with one clear line on bad input.

use apatch::complex_io::write_json_file;
use apatch::fixtures::{quadric_complex, Quadric};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("check_cli_{name}"))
}

fn apatch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(args)
        .output()
        .expect("run apatch")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `apatch check` of the complex at `path`, which must fail (exit 1): the text report and its
/// line starting with `measure`.
fn failed_check(path: &Path, measure: &str) -> (String, String) {
    let o = apatch(&["check", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    let line = out
        .lines()
        .find(|l| l.starts_with(measure))
        .unwrap_or_else(|| panic!("{out}"))
        .to_string();
    (out, line)
}

fn sphere_file(name: &str, degree: usize) -> PathBuf {
    let q = Quadric::sphere(DVec3::new(0.05, 0.1, -0.1), 0.7);
    let c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 3, degree);
    let path = tmp(name);
    write_json_file(&c, &path).unwrap();
    path
}

#[test]
fn good_complex_passes() {
    let path = sphere_file("good.json", 3);
    let o = apatch(&["check", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("PASSED"), "{out}");
    assert!(out.contains("value jump"), "{out}");
    assert!(out.contains("270 shared"), "{out}");
}

#[test]
fn good_complex_json_report() {
    let path = sphere_file("good_json.json", 2);
    let o = apatch(&[
        "check",
        path.to_str().unwrap(),
        "--json",
        "--continuity",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON report");
    assert_eq!(v["passed"], true);
    assert_eq!(v["continuity"], 2);
    assert_eq!(v["faces"]["shared"], 270);
    let jump = v["value_jump"]["worst"].as_f64().unwrap();
    // One global quadric: rounding only.
    assert!(jump < 1e-13, "{jump}");
}

#[test]
fn broken_complex_fails_with_the_jump_named() {
    let q = Quadric::sphere(DVec3::ZERO, 0.6);
    let mut c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 2, 3);
    // Weight (0,1,1,1) lies on the face opposite vertex 1 of patch 9.
    let k = apatch::bb::index_of([0, 1, 1, 1]);
    c.patches[9].weights[k] += 1e-4;
    let path = tmp("broken.json");
    write_json_file(&c, &path).unwrap();
    let (out, line) = failed_check(&path, "value jump");
    assert!(line.contains("FAIL"), "{line}");
    assert!(line.contains("patches") && line.contains('9'), "{line}");
    assert!(out.contains("FAILED: value jump, gradient jump"), "{out}");

    // Loosened tolerances accept it.
    let o = apatch(&["check", path.to_str().unwrap(), "--jump-tolerance", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));

    let o = apatch(&["check", path.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["passed"], false);
    let patches = v["value_jump"]["at"]["patches"].as_array().unwrap();
    assert!(patches.iter().any(|p| p == 9), "{v}");
}

/// A sphere complex with one patch on the sphere removed has a hole: exit 1, the text names the
/// failure "holes" with the patch and point, the JSON report carries the same.
#[test]
fn holed_complex_fails_with_the_hole_located() {
    let q = Quadric::sphere(DVec3::ZERO, 0.7);
    let mut c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 3, 3);
    let k = c
        .patches
        .iter()
        .position(|p| {
            let a = p.tet().unwrap().bary(DVec3::new(0.7, 0.01, 0.02));
            a.iter().all(|&x| x > 0.0)
        })
        .unwrap();
    c.patches.remove(k);
    let path = tmp("holed.json");
    write_json_file(&c, &path).unwrap();
    let (out, line) = failed_check(&path, "holes");
    assert!(
        line.contains("FAIL") && line.contains("worst: patch "),
        "{line}"
    );
    assert!(out.contains("FAILED: holes"), "{out}");

    let o = apatch(&["check", path.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["passed"], false);
    assert!(
        v["failures"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f == "holes"),
        "{v}"
    );
    assert!(v["holes"]["crossing"].as_u64().unwrap() > 0, "{v}");
    let at = &v["holes"]["crossing_at"];
    assert_eq!(at["patches"].as_array().unwrap().len(), 1, "{v}");
    assert_eq!(at["point"].as_array().unwrap().len(), 3, "{v}");
    // Every other measure still passes: the hole is the only failure.
    assert_eq!(v["failures"].as_array().unwrap().len(), 1, "{v}");
}

/// Runs `apatch check` on `text` written to `name` and returns stderr (exit 2 required).
fn bad_input(name: &str, text: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    let o = apatch(&["check", path.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert_eq!(err.lines().count(), 1, "{name}: one line: {err}");
    assert!(err.starts_with("apatch: error: "), "{err}");
    assert!(
        err.contains(path.to_str().unwrap()),
        "names the file: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    err
}

const HEAD: &str =
    r#"{"format":"apatch-patches","version":1,"scheme":"test","vertices":[],"patches":["#;
const TET: &str = r#""tet":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]],"role":"other","element":0"#;

fn one_patch(degree: &str, weights: &str) -> String {
    format!("{HEAD}{{{TET},\"degree\":{degree},\"weights\":{weights}}}]}}")
}

#[test]
fn bad_inputs_exit_2_with_one_line() {
    let e = bad_input("trailing.json", &(one_patch("1", "[1,2,3,4]") + "x"));
    assert!(e.contains("trailing characters"), "{e}");
    let e = bad_input("syntax.json", &one_patch("1", "[1,2,3,4]x"));
    assert!(e.contains("patch 0: expected `,` or `}` at line 1"), "{e}");
    let e = bad_input("truncated.json", &one_patch("1", "[1,2,3,4]")[..80]);
    assert!(e.contains("EOF"), "{e}");
    let e = bad_input("count.json", &one_patch("2", "[1,2,3,4]"));
    assert!(e.contains("patch 0: 4 weights for degree 2"), "{e}");
    let e = bad_input("nan_string.json", &one_patch("1", r#"[1,"NaN",3,4]"#));
    assert!(e.contains("patch 0"), "{e}");
    let e = bad_input("null.json", &one_patch("1", "[1,null,3,4]"));
    assert!(e.contains("patch 0"), "{e}");
    let e = bad_input("overflow.json", &one_patch("1", "[1,2e308,3,4]"));
    assert!(e.contains("patch 0"), "{e}");
    let e = bad_input(
        "degree.json",
        &one_patch("9", &format!("[{}]", vec!["1"; 220].join(","))),
    );
    assert!(e.contains("patch 0: degree 9"), "{e}");
    let e = bad_input("scene.toml", "[camera]\n");
    assert!(e.contains("missing field"), "{e}");
    let e = bad_input("model.obj", "v 0 0 0\n");
    assert!(
        e.contains("model input needs a scheme; not available yet"),
        "{e}"
    );
    let e = bad_input("what.xyz", "");
    assert!(e.contains("unknown input type"), "{e}");
}

const SCENE: &str = r#"
[model]
patches = "PATCHES"
[camera]
origin = [0, 0, 5]
target = [0, 0, 0]
fov = 40
width = 8
height = 8
[[lights]]
type = "directional"
direction = [0, 0, -1]
irradiance = 2.0
"#;

#[test]
fn scene_input_is_checked() {
    let patches = sphere_file("scene_patches.json", 2);
    let scene = tmp("scene_ok.toml");
    let name = patches.file_name().unwrap().to_str().unwrap();
    std::fs::write(&scene, SCENE.replace("PATCHES", name)).unwrap();
    let o = apatch(&["check", scene.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("PASSED"));

    // A scene naming an invalid complex is bad input (exit 2), with the patch named.
    let bad = tmp("scene_bad_patches.json");
    std::fs::write(&bad, one_patch("2", "[1,2,3,4]")).unwrap();
    let bad_name = bad.file_name().unwrap().to_str().unwrap();
    let scene = tmp("scene_bad.toml");
    std::fs::write(&scene, SCENE.replace("PATCHES", bad_name)).unwrap();
    let o = apatch(&["check", scene.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains(bad.to_str().unwrap()), "{e}");
    assert!(e.contains("patch 0: 4 weights for degree 2"), "{e}");
}

#[test]
fn missing_file_exits_2() {
    for name in ["missing.json", "missing.toml"] {
        let path = tmp(name);
        let o = apatch(&["check", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(path.to_str().unwrap()), "{err}");
        // The cause appears once.
        assert_eq!(err.matches("os error").count().max(1), 1, "{err}");
        assert!(
            err.contains("no such file") || err.contains("No such file"),
            "{err}"
        );
    }
}

#[test]
fn export_patches_rewrites_json() {
    let src = sphere_file("export_src.json", 2);
    let dst = tmp("export_dst.json");
    let o = apatch(&[
        "export",
        "patches",
        src.to_str().unwrap(),
        "-o",
        dst.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read(&src).unwrap(), std::fs::read(&dst).unwrap());

    let o = apatch(&[
        "export",
        "patches",
        "scene.toml",
        "-o",
        dst.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = apatch(&[
        "export",
        "patches",
        src.to_str().unwrap(),
        "-o",
        "/nonexistent/dir/out.json",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("/nonexistent/dir/out.json"),
        "{}",
        stderr(&o)
    );
}

/// A fixture that is C1 but not C2 across the plane x = x0 (the quadric c·(x − x0)² added on
/// its right), under the given scheme name and continuity field.
fn c1_not_c2_file(name: &str, scheme: &str, continuity: Option<u8>) -> PathBuf {
    let q = Quadric::sphere(DVec3::ZERO, 0.7);
    let mut c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 3, 4);
    c.scheme = scheme.to_string();
    c.continuity = continuity;
    // The grid plane exactly as the fixture computes it.
    let x0 = -1.0 + 2.0 / 3.0 * 2.0;
    let bump = Quadric {
        a: glam::DMat3::from_diagonal(DVec3::new(0.05, 0.0, 0.0)),
        b: DVec3::new(-0.1 * x0, 0.0, 0.0),
        c: 0.05 * x0 * x0,
    };
    for p in &mut c.patches {
        let tet = p.tet_points();
        if tet.iter().all(|v| v.x >= x0) {
            let extra = apatch::fixtures::quadric_weights(&bump, &tet, 4);
            for (w, e) in p.weights.iter_mut().zip(extra) {
                *w += e;
            }
        }
    }
    let path = tmp(name);
    write_json_file(&c, &path).unwrap();
    path
}

#[test]
fn promised_continuity_follows_scheme_and_field() {
    for (name, scheme, field, code) in [
        ("c1_scheme.json", "cubic-c1", None, 0),
        ("c2_scheme.json", "quintic-c2", None, 1),
        ("c2_field.json", "cubic-c1", Some(2), 1),
        ("c1_field.json", "quintic-c2", Some(1), 0),
    ] {
        let path = c1_not_c2_file(name, scheme, field);
        let o = apatch(&["check", path.to_str().unwrap()]);
        let out = stdout(&o);
        assert_eq!(o.status.code(), Some(code), "{name}: {out}");
        if code == 1 {
            assert!(out.contains("FAILED: hessian jump"), "{name}: {out}");
        }
    }
    // The flag overrides both.
    let path = c1_not_c2_file("c2_flag.json", "quintic-c2", Some(2));
    let o = apatch(&["check", path.to_str().unwrap(), "--continuity", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
}

#[test]
fn scene_with_scheme_is_built_and_checked() {
    // End to end: mesh → rational C1 scheme → check (the cube scene of the repository).
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["scheme"], "rational-c1");
    assert!(v["faces"]["shared"].as_u64().unwrap() > 0);
    assert!(v["interpolation"]["value"]["samples"].as_u64().unwrap() > 0);
}

/// A 1994-scheme scene: `check --json` reports the inner hull's validity (Def. 3.6 and
/// Lemmas 4.1–4.3 via `hull::inner::verify`) and the surface's distance to the polyhedron, which
/// for a corner-cutting surface is positive and below the size of the model.
#[test]
fn inner_hull_scene_reports_hull_and_distance() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper1994/octahedron.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["hull"]["valid"], true, "{v}");
    assert_eq!(v["passed"], true);
    let max = v["distance"]["max"].as_f64().unwrap();
    assert!(max > 0.0 && max < 0.5, "{max}");
    let o = apatch(&["check", scene.to_str().unwrap()]);
    assert!(
        stdout(&o).contains("hull             valid"),
        "{}",
        stdout(&o)
    );
}

/// A scene with `model.flatten`: `check` says what the flattening did (`--json`: `flatten`), the
/// same figures as `mesh::flatten` on the file, and the hull it reports is the flattened box's:
/// one face per side, so the cube's 32 patches (a second path: the box's 432 triangles would
/// give thousands).
#[test]
fn flatten_scene_reports_its_flattening() {
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper1994/box_rounded_quintic.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let (m, _) = apatch::mesh::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/box_rounded.obj"),
    )
    .unwrap();
    let (_, r) = apatch::mesh::flatten::flatten(&m, 1e-4);
    assert_eq!(v["flatten"]["regions"].as_u64().unwrap(), r.regions as u64);
    assert_eq!(v["flatten"]["moved"].as_u64().unwrap(), r.moved as u64);
    assert_eq!(v["flatten"]["max_move"].as_f64().unwrap(), r.max_move);
    assert_eq!(v["patches"].as_u64(), Some(32), "{v}");
    assert_eq!(v["passed"], true);
    let o = apatch(&["check", scene.to_str().unwrap()]);
    assert!(
        stdout(&o).contains("flatten          6 nearly flat regions (432 faces)"),
        "{}",
        stdout(&o)
    );
}

/// A quintic scene: `check` reports what the scheme's solve did, the same figures as the
/// library's `quintic_c2::build_with_stats` on the scene's hull and options (a second path to
/// the numbers); a cubic scene has no solve to report.
#[test]
fn quintic_scene_reports_its_solve() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper1994/l_prism_quintic.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let s = &v["solve"];
    let loaded = apatch::scene::load(&scene).unwrap();
    let hull = apatch::scene::inner_hull(&loaded).unwrap().unwrap();
    let table: toml::Table = toml::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap();
    let scheme = table["scheme"].as_table().unwrap();
    let options = apatch::scheme::quintic_c2::QuinticOptions::from_toml(scheme, &scene).unwrap();
    let (_, stats) = apatch::scheme::quintic_c2::build_with_stats(&hull, &options).unwrap();
    assert_eq!(s["unknowns"].as_u64(), Some(stats.unknowns as u64), "{s}");
    assert_eq!(s["equations"].as_u64(), Some(stats.equations as u64), "{s}");
    assert_eq!(
        s["relaxed_points"].as_u64(),
        Some(stats.relaxed_points as u64),
        "{s}"
    );
    assert_eq!(s["global"], false, "{s}");
    assert!(stats.unknowns > 0 && stats.equations > 0);
    let text = stdout(&apatch(&["check", scene.to_str().unwrap()]));
    let line = text
        .lines()
        .find(|l| l.starts_with("solve "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains(&format!(
            "{} unknowns, {} equations",
            stats.unknowns, stats.equations
        )),
        "{line}"
    );
    let cubic = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper1994/octahedron.toml");
    let o = apatch(&["check", cubic.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(v.get("solve").is_none(), "{v}");
}

/// A 1994 scene: `check` reports what the inner hull's builder changed (`hull_steps`), the
/// same counts as the library's `hull::inner::build_with_report` on the scene's mesh, normals
/// and options; the text line names the nonzero ones, and a hull built without repairs (the
/// octahedron) prints none.
#[test]
fn inner_hull_scene_reports_its_hull_steps() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("scenes/paper1994/torus_quad.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let steps = &v["hull_steps"];
    let (m, vn, scheme) = scene_mesh(&scene);
    let scheme = &scheme;
    let options = apatch::hull::inner::InnerOptions::from_toml(scheme, &scene).unwrap();
    let (_, r) = apatch::hull::inner::build_with_report(&m, &vn, &options).unwrap();
    assert!(
        r.flipped_folds > 0 && r.lifted_apexes > 0,
        "the torus needs both"
    );
    assert_eq!(
        steps["folds_flipped"].as_u64(),
        Some(r.flipped_folds as u64),
        "{steps}"
    );
    assert_eq!(
        steps["apexes_lifted"].as_u64(),
        Some(r.lifted_apexes as u64),
        "{steps}"
    );
    assert_eq!(
        steps["normals_above_face"].as_u64(),
        Some(r.adjusted_normals.len() as u64)
    );
    // Every step has its key, including those that did nothing here (the torus has no slit).
    assert_eq!(
        steps["slits_flipped"].as_u64(),
        Some(r.flipped_slits as u64),
        "{steps}"
    );
    let text = stdout(&apatch(&["check", scene.to_str().unwrap()]));
    let line = text
        .lines()
        .find(|l| l.starts_with("hull steps"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains(&format!("folds flipped {}", r.flipped_folds)),
        "{line}"
    );
    let plain = root.join("scenes/paper1994/octahedron.toml");
    let text = stdout(&apatch(&["check", plain.to_str().unwrap()]));
    assert!(!text.contains("hull steps"), "{text}");
}

/// `check` reports what the cubic scheme changed on the hull before filling it
/// (`cubic_c1::prepare_hull`: apexes moved over tangent planes, its own apex search), which the
/// `hull steps` line (the builder's report) leaves out: the CLI's figures are the library's
/// `prepare_hull` on the builder's hull (mpi_poly: 38 apexes moved over tangent planes, then
/// the scheme's apex search clears 24 overlapping pairs in 7 moves; ~1 s, where
/// spot_control_cage, used before, took ~27 CPU-s a check and left the apex search idle); a
/// scene whose hull the scheme leaves alone prints no such line.
#[test]
fn cubic_scene_reports_the_schemes_apex_changes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("scenes/paper1994/mpi_poly.toml");
    let o = apatch(&["check", scene.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let steps = &v["cubic_steps"];
    let (m, vn, scheme) = scene_mesh(&scene);
    let scheme = &scheme;
    let (options, inner) = apatch::scheme::cubic_c1::options_from_toml(scheme, &scene).unwrap();
    let hull = apatch::hull::inner::build(&m, &vn, &inner).unwrap();
    let s = apatch::scheme::cubic_c1::prepare_hull(&hull, &options).steps();
    // Both of the scheme's steps have something to do on mpi_poly: the text line below must
    // name the apex search as well as the tangent moves.
    assert!(s.tangent_moved + s.tangent_stuck > 0, "{s:?}");
    assert!(
        s.reapex.before > 0 && !s.reapex.moved.is_empty(),
        "apex search: {} overlapping pairs before, {} moves",
        s.reapex.before,
        s.reapex.moved.len()
    );
    let count = |k: &str| steps[k].as_u64().map(|n| n as usize);
    assert_eq!(count("tangent_moved"), Some(s.tangent_moved), "{steps}");
    assert_eq!(count("tangent_stuck"), Some(s.tangent_stuck), "{steps}");
    assert_eq!(count("lu_completed"), Some(s.lu_completed), "{steps}");
    assert_eq!(count("apex_search_moves"), Some(s.reapex.moved.len()));
    assert_eq!(count("apex_search_overlaps_after"), Some(s.reapex.after));
    let text = stdout(&apatch(&["check", scene.to_str().unwrap()]));
    let line = text
        .lines()
        .find(|l| l.starts_with("cubic steps"))
        .unwrap_or_else(|| panic!("{text}"));
    let searched = format!(
        "apex search {} moves (overlapping pairs {} -> {})",
        s.reapex.moved.len(),
        s.reapex.before,
        s.reapex.after
    );
    assert!(line.contains(&searched), "{line}");
    assert!(
        line.contains(&format!(
            "apexes moved over tangent planes {}",
            s.tangent_moved
        )),
        "{line}"
    );
    let plain = root.join("scenes/paper1994/octahedron.toml");
    let text = stdout(&apatch(&["check", plain.to_str().unwrap()]));
    assert!(!text.contains("cubic steps"), "{text}");
}

/// A mesh scene's mesh, vertex normals (its `model.normals`) and `[scheme]` table.
fn scene_mesh(scene: &Path) -> (apatch::mesh::Mesh, Vec<DVec3>, toml::Table) {
    let loaded = apatch::scene::load(scene).unwrap();
    let apatch::scene::Model::Mesh {
        file,
        normals,
        scheme,
        clean,
        ..
    } = &loaded.model
    else {
        panic!("a mesh scene");
    };
    let (m, _, _) = apatch::scene::polyhedron_1994(file, *clean).unwrap();
    let vn = apatch::mesh::vertex_normals(&m, normals.parse().unwrap()).unwrap();
    (m, vn, scheme.clone())
}

/// `--holes FILE` lists every crossed boundary face. The rounded cylinder's quintic without
/// `joint_stars` and `signs` crosses the outer faces of the edge tetrahedra at its caps' rims
/// (128, docs/quintic.md, "Small reproducers"). Independent truth, from the exported patches:
/// each listed face is a face of its patch that no other patch has, F has a strict sign at the
/// listed point and the opposite one somewhere on a lattice of the face, the list is as
/// long as the report's count, and each face's coefficient most against its sign (the
/// anatomy, `check::anatomy`) is recomputed from its patch's weights. A path in a missing directory is a clear error (exit 2) and
/// leaves no file.
#[test]
fn holes_file_lists_every_crossed_face() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = tmp("holes_cylinder.toml");
    let model = root.join("scenes/models/cylinder_rounded.obj");
    let text = std::fs::read_to_string(root.join("scenes/paper1994/cylinder_rounded_quintic.toml"))
        .unwrap()
        .replace(
            "\"../models/cylinder_rounded.obj\"",
            &format!("{:?}", model.display().to_string()),
        )
        .replace("joint_stars = true", "")
        .replace("signs = true", "");
    std::fs::write(&scene, text).unwrap();
    let patches = tmp("holes_cylinder.json");
    let o = apatch(&[
        "export",
        "patches",
        scene.to_str().unwrap(),
        "-o",
        patches.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let holes = tmp("holes_cylinder_holes.json");
    let _ = std::fs::remove_file(&holes);
    let o = apatch(&[
        "check",
        patches.to_str().unwrap(),
        "--json",
        "--holes",
        holes.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}{}", stdout(&o), stderr(&o));
    let report: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let count = report["holes"]["crossing"].as_u64().unwrap() as usize;
    assert!(count > 0, "{report}");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&holes).unwrap()).unwrap();
    assert_eq!(doc["format"], "apatch-holes");
    assert_eq!(doc["crossing"].as_u64().unwrap() as usize, count);
    let faces = doc["faces"].as_array().unwrap();
    assert_eq!(faces.len(), count);
    // The j-sheets beside them: as many as the report counts (none on this cylinder; the
    // list's content is tested in `check::tests::j_sheets_are_listed_with_their_first_root`).
    let sheets = report["sheets"]["j_multi_patches"].as_u64().unwrap();
    assert_eq!(doc["j_sheet_patches"].as_u64(), Some(sheets));
    assert_eq!(doc["j_sheets"].as_array().unwrap().len() as u64, sheets);

    let complex = apatch::complex_io::read_json_file(&patches).unwrap();
    let key = |p: [f64; 3]| p.map(f64::to_bits);
    let mut corner_sets = std::collections::HashMap::new();
    for p in &complex.patches {
        for skip in 0..4 {
            let mut f: Vec<[u64; 3]> = (0..4)
                .filter(|&k| k != skip)
                .map(|k| key(p.tet[k]))
                .collect();
            f.sort_unstable();
            *corner_sets.entry(f).or_insert(0) += 1;
        }
    }
    let xyz = |v: &serde_json::Value| -> [f64; 3] {
        let a = v.as_array().unwrap();
        [0, 1, 2].map(|i| a[i].as_f64().unwrap())
    };
    let mut by_cause = std::collections::BTreeMap::new();
    for face in faces {
        let patch = &complex.patches[face["patch"].as_u64().unwrap() as usize];
        let corners: Vec<[f64; 3]> = face["corners"]
            .as_array()
            .unwrap()
            .iter()
            .map(xyz)
            .collect();
        assert!(corners.iter().all(|c| patch.tet.contains(c)), "{face}");
        let mut f: Vec<[u64; 3]> = corners.iter().map(|&c| key(c)).collect();
        f.sort_unstable();
        assert_eq!(corner_sets[&f], 1, "not a boundary face: {face}");
        // 1e-12 of the largest weight: `check`'s own zero (far above the weights' rounding).
        let zero = 1e-12 * patch.weights.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
        let at = patch.value(DVec3::from_array(xyz(&face["point"])));
        assert!(at.abs() > zero, "{face}: F = {at:e}");
        let c = corners
            .iter()
            .map(|&c| DVec3::from_array(c))
            .collect::<Vec<_>>();
        let steps = 24;
        let opposite = (0..=steps).any(|i| {
            (0..=steps - i).any(|j| {
                let (u, v) = (i as f64 / steps as f64, j as f64 / steps as f64);
                let p = c[0] * (1.0 - u - v) + c[1] * u + c[2] * v;
                patch.value(p) * at.signum() < -zero
            })
        });
        assert!(opposite, "F keeps one sign on {face}");

        // The anatomy: a face crossed has a coefficient against the sign its number 1 weights
        // give (the Bernstein basis is positive), and the one named is the face's least
        // coefficient times that sign, at its distance from the corners on the surface.
        let opp = (0..4).find(|&k| !corners.contains(&patch.tet[k])).unwrap();
        let on_surface = |k: usize| k != opp && complex.vertices.contains(&patch.tet[k]);
        let n = patch.degree;
        let face_w: Vec<([u8; 4], f64)> = apatch::bb::multi_indices(n.into())
            .into_iter()
            .zip(patch.weights.iter().copied())
            .filter(|(l, _)| l[opp] == 0)
            .collect();
        let order = |l: &[u8; 4]| {
            n - (0..4)
                .filter(|&k| on_surface(k))
                .map(|k| l[k])
                .max()
                .unwrap()
        };
        let sign = face["sign"].as_i64().unwrap() as f64;
        assert!(sign == 1.0 || sign == -1.0, "{face}");
        let first: f64 = face_w
            .iter()
            .filter(|(l, _)| order(l) == 1)
            .map(|c| c.1)
            .sum();
        assert_eq!(first.signum(), sign, "{face}");
        let largest = face_w.iter().fold(0.0_f64, |m, c| m.max(c.1.abs()));
        let least = face_w
            .iter()
            .map(|c| sign * c.1)
            .fold(f64::INFINITY, f64::min);
        let index: Vec<u8> = face["against"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap() as u8)
            .collect();
        let index: [u8; 4] = index.try_into().unwrap();
        let w = patch.weights[apatch::bb::index_of(index)];
        assert_eq!(index[opp], 0, "{face}");
        assert_eq!(sign * w, least, "{face}");
        let share = face["against_share"].as_f64().unwrap();
        assert!(share < 0.0, "{face}");
        // 1e-15: the same division, rounded once.
        assert!((share - least / largest).abs() <= 1e-15, "{face}");
        let o = order(&index);
        assert_eq!(face["against_order"].as_u64(), Some(u64::from(o)), "{face}");
        let held = match o {
            1 => "normal",
            2 => "hessian",
            _ => "weights",
        };
        assert_eq!(face["held_by"], held, "{face}");
        *by_cause.entry(held.to_string()).or_insert(0_u64) += 1;
    }
    let counted: std::collections::BTreeMap<String, u64> =
        serde_json::from_value(report["holes"]["crossing_by_cause"].clone()).unwrap();
    assert_eq!(counted, by_cause);

    let bad = tmp("no_such_dir").join("holes.json");
    let o = apatch(&[
        "check",
        patches.to_str().unwrap(),
        "--holes",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no_such_dir"), "{}", stderr(&o));
    assert!(!bad.exists());
}

//! `apatch info` end to end: text and JSON output on real models, exit codes, option errors.

use std::path::Path;
use std::process::Command;

fn info(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .arg("info")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn json_of_models_matches_known_topology() {
    // Counts from /work/shared/meshes/README.md and the generator.
    for (file, v, f, genus) in [
        ("scenes/models/spot_control_cage.obj", 188, 180, 0),
        ("scenes/models/double_torus_poly.obj", 231, 220, 2),
        ("scenes/models/knot1.obj", 3200, 6400, 1),
        ("scenes/models/octahedron.obj", 6, 8, 0),
    ] {
        let (code, out, err) = info(&["--json", file]);
        assert!(code == 0 || code == 1, "{file}: {err}");
        let j: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(j["vertices"], v, "{file}");
        assert_eq!(j["faces"], f, "{file}");
        assert_eq!(j["genus"], genus, "{file}");
    }
    // Radial normals of a convex solid: every edge and triangle is positive convex.
    let (_, out, _) = info(&[
        "--json",
        "--normals",
        "area",
        "scenes/models/icosahedron.obj",
    ]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["normals"], "area");
    assert_eq!(j["edges_2001"]["positive"], 30);
    assert_eq!(j["triangles_2001"]["positive"], 20);
    // 1994 pairs the normals the other way round: the same edges are negatively convex.
    assert_eq!(j["edges_1994"]["negative"], 30);
    assert_eq!(j["triangles_1994"]["negative"], 20);
    assert_eq!(j["trihedral_vertices"], 0);
    assert_eq!(j["above_face_failures"].as_array().unwrap().len(), 0);
}

#[test]
fn text_output_and_exit_codes() {
    let (code, out, _) = info(&["scenes/models/l_prism.obj"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("faces             8 (6×4-gon, 2×6-gon)"),
        "{out}"
    );
    assert!(out.contains("12 trihedral"), "{out}");
    assert!(out.contains("6 convex, 2 non-convex polygons"), "{out}");
    assert!(out.contains("normals           angle"), "{out}");
    // Warnings: exit 1 and listed.
    let (code, out, _) = info(&["scenes/models/teapot_npm.obj"]);
    assert_eq!(code, 1);
    assert!(out.contains("boundary edges"), "{out}");
    // The spout touches the body at one vertex: split, reported as a repaired warning.
    assert!(out.contains("split into one vertex per fan"), "{out}");
    assert!(out.contains("vertex 115 (line 123)"), "{out}");
    assert!(!out.contains("non-manifold (their faces"), "{out}");
    // `file` normals on a model without them: still describes the mesh, exit 1.
    let (code, out, _) = info(&["--normals", "file", "scenes/models/cube.obj"]);
    assert_eq!(code, 1);
    assert!(out.contains("no vertex normals"), "{out}");
    // Errors: exit 2, one line.
    let (code, _, err) = info(&["no/such/file.obj"]);
    assert_eq!(code, 2);
    assert!(err.contains("no/such/file.obj"), "{err}");
    let (code, _, err) = info(&["--normals", "bogus", "scenes/models/cube.obj"]);
    assert_eq!(code, 2);
    assert!(err.contains("expected angle, area, loop or file"), "{err}");
    assert!(Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/models/LICENSES.md")
        .exists());
}

#[test]
fn byte_order_mark_and_trailing_comments_are_accepted() {
    let bytes = b"\xEF\xBB\xBFv 0 0 0 # caf\xe9\nv 1 0 0\nv 0 1 0\nf 1 2 3 # t\xe9\n";
    let (m, _) =
        apatch::mesh::load_bytes(bytes, apatch::mesh::Format::Obj, Path::new("b.obj")).unwrap();
    assert_eq!(m.faces.len(), 1);
}

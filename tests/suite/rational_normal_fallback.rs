//! The above-face normal fallback on the real models that needed it (issue 4): mpi (triangle 76)
//! and spot_cage (triangle 70) have angle-weighted vertex normals below a triangle around them,
//! which the angle-weighted repair cannot fix. With the above-face normal the build gets past
//! the normals and stops only at the refinement limit (`scenes/pending/README.md` says why).
//! Their scenes now build through the opt-in pre-subdivision (`model.subdivide`, `model.weld`);
//! this test drops those keys to keep measuring the input meshes.

use apatch::scene;
use std::path::Path;

/// The build error of a scene's input mesh (its `subdivide` and `weld` lines dropped) with no
/// refinement rounds (fast: the hull is built once).
fn build_error(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml"));
    let text: String = std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with("subdivide") && !l.starts_with("weld"))
        .map(|l| format!("{l}\n"))
        .collect();
    let text = text.replacen(
        "type = \"rational-c1\"",
        "type = \"rational-c1\"\nrefine_rounds = 0",
        1,
    );
    assert!(
        text.contains("refine_rounds = 0"),
        "{name}: no rational-c1 scheme line"
    );
    let scene = scene::parse(&text, &path).unwrap();
    match scene::build_complex(&scene) {
        Ok(_) => String::new(),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
fn mpi_and_spot_cage_get_past_their_bad_normals() {
    for name in ["mpi", "spot_cage"] {
        let e = build_error(name);
        // Before the fallback: "triangle 76 (70): the normal of its corner 1 points to the
        // other side of the triangle".
        assert!(!e.contains("points to the other side"), "{name}: {e}");
        // Now the build reaches the hull and its intersection test (the known limit), or builds.
        assert!(
            e.is_empty() || e.contains("face tetrahedra still intersect"),
            "{name}: {e}"
        );
    }
}

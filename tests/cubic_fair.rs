//! Fairness of the 1994 cubic surfaces (issue 7): the normal of the surface against the blend
//! of the normals at T's points ([`apatch::scheme::cubic_c1::fairness`]), per shipped scene.
//! `cargo test --release --test cubic_fair -- --nocapture` prints the table.

use apatch::scene;
use apatch::scheme::cubic_c1::fairness::fairness;
use std::path::Path;

fn measure(name: &str) -> apatch::scheme::cubic_c1::fairness::Fairness {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/paper1994")
        .join(format!("{name}.toml"));
    let s = scene::load(&path).unwrap();
    let c = scene::build_complex(&s).unwrap();
    let f = fairness(&c);
    eprintln!(
        "| {name} | {:.2} / {:.2} / {:.2} | {:.2} / {:.2} / {:.2} |",
        f.face.max, f.face.p95, f.face.rms, f.edge.max, f.edge.p95, f.edge.rms
    );
    f
}

/// Prints the figure for every cubic scene (no assertion: the survey behind the README table).
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
        measure(name);
    }
}

//! The rational C¹ scheme on generated models: interpolation, C¹ continuity across every shared
//! tetrahedron face, at most two patches per face, simple selected roots.

#[path = "rational_support.rs"]
mod support;

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
        "{}: {} tris, {} patches, classes {:?}, edges {:?}, refined {}, promoted {}, raised {}, \
         interp {fv:.1e}/{gv:.1e}, shared {} jumps {:.1e}/{:.1e}, sharing {}, roots {lines} min slope {slope:.2e}",
        m.name,
        b.triangles.len(),
        c.patches.len(),
        b.faces_by_class,
        b.edges_by_class,
        b.refined_edges,
        b.promoted_faces,
        b.raised_faces,
        cont.shared_faces,
        cont.max_value_jump,
        cont.max_grad_jump,
        cont.max_sharing
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
/// build yet (intersecting face tetrahedra after the refinement bound, see
/// `scenes/pending/README.md`).
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

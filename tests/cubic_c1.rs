//! The C¹ cubic scheme (1994) on test hulls: continuity, interpolation and sheets by `check`.

use apatch::check::{check, CheckOptions};
use apatch::fixtures::trihedral_hull;
use apatch::scheme::cubic_c1::{build_full, CubicOptions};
use std::path::Path;

fn trihedral(model: &str, options: &CubicOptions) -> apatch::check::CheckReport {
    let (m, _) = apatch::mesh::load(Path::new(model)).unwrap();
    let hull = trihedral_hull(&m);
    let b = build_full(&hull, options).unwrap();
    assert_eq!(b.unsigned, 0, "{model}");
    check(&b.complex, &CheckOptions::default())
}

/// Cube and dodecahedron on the trihedral hull: C¹ jumps ≤ 1e-9 relative, every point of T
/// interpolated with its normal, no face shared by more than two patches.
#[test]
fn trihedral_solids_are_c1() {
    for model in [
        "scenes/models/cube.obj",
        "scenes/models/dodecahedron.obj",
        "scenes/models/tetrahedron.obj",
    ] {
        for level in [0.2, 0.5, 0.8] {
            let r = trihedral(
                model,
                &CubicOptions {
                    level,
                    ..CubicOptions::default()
                },
            );
            eprintln!(
                "{model} level {level}: value {:e} gradient {:e} failures {:?}",
                r.value_jump.worst,
                r.gradient_jump.worst,
                r.failures()
            );
            // 1e-9: the bound on relative C¹ jumps (f64 round-off is ~1e-15).
            assert!(
                r.gradient_jump.worst <= 1e-9 && r.value_jump.worst <= 1e-9,
                "{model}"
            );
            assert!(r.passed(), "{model} {:?}", r.failures());
        }
    }
}

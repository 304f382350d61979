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

/// Lines from vertex `j` of every patch to a lattice on the opposite face: the largest number of
/// sign changes of F along any of them (sampled at 400 points; values within 1e-12 of the
/// patch's largest weight count as zero, so the interpolated vertices and edges on T do not
/// count). An independent sampling, not the checker's.
fn max_crossings(p: &apatch::complex::Patch, j: usize) -> usize {
    let wmax = p.weights.iter().fold(0.0_f64, |a, w| a.max(w.abs()));
    let res = 10;
    let mut worst = 0;
    for a in 0..=res {
        for b in 0..=res - a {
            let c = res - a - b;
            let mut face = [0.0; 4];
            let others: Vec<usize> = (0..4).filter(|&k| k != j).collect();
            face[others[0]] = a as f64 / res as f64;
            face[others[1]] = b as f64 / res as f64;
            face[others[2]] = c as f64 / res as f64;
            let mut last = 0.0_f64;
            let mut changes = 0;
            for s in 1..400 {
                let t = s as f64 / 400.0;
                let mut x = [0.0; 4];
                for k in 0..4 {
                    x[k] = t * face[k];
                }
                x[j] += 1.0 - t;
                let f = p.value_bary(x);
                if f.abs() <= 1e-12 * wmax {
                    continue;
                }
                if last != 0.0 && f.signum() != last.signum() {
                    changes += 1;
                }
                last = f;
            }
            worst = worst.max(changes);
        }
    }
    worst
}

/// Every patch is a triangular j-patch for some vertex j (Definition 2.1): lines through vertex
/// j cross the zero set at most once; face tetrahedra with j at their apex. Sampled independently
/// of the checker, whose own single-sheet judgement must agree.
#[test]
fn trihedral_patches_are_single_sheeted() {
    for name in ["cube", "tetrahedron", "dodecahedron"] {
        let hull = hull_of(name);
        let (c, _) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
        for (i, p) in c.patches.iter().enumerate() {
            let best = (0..4).map(|j| max_crossings(p, j)).min().unwrap();
            assert!(
                best <= 1,
                "{name}: patch {i} ({:?}) crossed {best} times",
                p.role
            );
            if p.role == apatch::complex::Role::Face {
                assert!(
                    max_crossings(p, 3) <= 1,
                    "{name}: face patch {i} from its apex"
                );
            }
        }
        let opts = CheckOptions {
            single_sheet: true,
            ..CheckOptions::default()
        };
        let r = check(&c, &opts);
        assert_eq!(r.sheets.multi_sheet_patches, 0, "{name}");
    }
}

/// Points of T moved off their symmetric positions (general position, as the paper assumes):
/// still C2 to rounding, interpolating, and the solve's own residual is at rounding level.
#[test]
fn perturbed_hull_is_c2() {
    let mut hull = hull_of("dodecahedron");
    // Deterministic small displacements along each point's tangent plane keep the hull valid.
    for (i, p) in hull.points.iter_mut().enumerate() {
        let n = hull.normals[i];
        let (t1, t2) = n.any_orthonormal_pair();
        let a = (i as f64 * 1.7).sin() * 0.02;
        let b = (i as f64 * 2.3).cos() * 0.02;
        *p += t1 * a + t2 * b;
    }
    let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    // Relative residual of the solved equations: rounding of O(1) sums.
    assert!(stats.max_residual < 1e-12, "{stats:?}");
    let r = check(&c, &CheckOptions::default());
    // The bounds: C1 jumps ≤ 1e-9, Hessian jumps ≤ 1e-7 (relative, the checker's).
    assert!(r.gradient_jump.worst <= 1e-9, "{:?}", r.gradient_jump);
    assert!(r.hessian_jump.worst <= 1e-7, "{:?}", r.hessian_jump);
    // Interpolation: rounding of the blossom sums.
    assert!(r.interpolation.value.worst <= 1e-12);
    assert!(r.interpolation.normal_angle.worst <= 1e-9);
    assert!(r.passed(), "{:?}", r.failures());
}

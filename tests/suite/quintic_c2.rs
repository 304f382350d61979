//! C2 quintic scheme (1994 §6) on the trihedral hulls of convex polyhedra: continuity,
//! interpolation and single-sheetedness measured by the independent checker.

use crate::common;

use apatch::check::{check, CheckOptions};
use apatch::fixtures::trihedral_hull;
use apatch::hull::simplicial::EdgePoint;
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

/// A fan of `k` triangles of T around the point 0 (ring points at angles `angles`, heights
/// `z`), one outer face tetrahedron per triangle with apex over its centroid moved by
/// `offsets`: the star of point 0 is closed (edge tetrahedra on every edge at 0).
fn fan_hull(
    angles: &[f64],
    z: &[f64],
    offsets: &[glam::DVec3],
) -> apatch::hull::simplicial::SimplicialHull {
    use apatch::hull::simplicial::{PointOrigin, SimplicialHull};
    use glam::DVec3;
    let k = angles.len();
    let mut points = vec![DVec3::ZERO];
    for m in 0..k {
        points.push(DVec3::new(angles[m].cos(), angles[m].sin(), z[m]));
    }
    let triangles: Vec<[u32; 3]> = (0..k)
        .map(|m| [0, 1 + m as u32, 1 + ((m + 1) % k) as u32])
        .collect();
    let apexes = triangles
        .iter()
        .zip(offsets)
        .map(|(t, o)| {
            let c = t.iter().map(|&v| points[v as usize]).sum::<DVec3>() / 3.0;
            [Some(c + *o), None]
        })
        .collect();
    SimplicialHull {
        normals: vec![DVec3::Z; k + 1],
        origins: vec![PointOrigin::Other; k + 1],
        element: (0..k as u32).collect(),
        points,
        triangles,
        apexes,
    }
}

/// (rows, cols, rank drop, smallest σ/σmax above the drop) of the star system of point 0.
fn star_of_centre(
    hull: &apatch::hull::simplicial::SimplicialHull,
    rule: apatch::hull::simplicial::EdgePoint,
) -> (usize, usize, usize, f64) {
    use apatch::scheme::quintic_c2::{dense, system};
    let (tets, _) = system::tetrahedra_with(hull, rule).unwrap();
    let sys = system::assemble(&tets, hull.points.len() as u32).unwrap();
    let st = sys
        .star_systems()
        .into_iter()
        .find(|s| s.point == 0)
        .unwrap();
    let s = dense::singular_values(&st.matrix, st.rows, st.cols);
    // Structural zeros come out at 1e-16 of σmax and below (rounding of the equations'
    // coefficients); the other singular values of these O(1) stars are above 1e-4.
    let rank = s.iter().filter(|&&x| x > 1e-10 * s[0]).count();
    (
        st.rows,
        st.cols,
        st.rows.min(st.cols) - rank,
        s[rank - 1] / s[0],
    )
}

/// Issue 8: the vertex-star system of appendices D and E (numbers 5, 6 and 9 around a point
/// with k triangles: 12k equations in 12k weights) is singular for *every* hull, not only for
/// points in special position. Appendix D's chain has determinant Πφ − (−1)^k Πψ, and the
/// ratios φ_i/ψ_i telescope to ±1 around the point whatever the apexes and the edge
/// tetrahedra's shared point s are (docs/quintic.md: each ratio is a quotient of
/// det(d_{i−1}, d_i, d_{i+1})-terms of the edges d_i at the point), so the rank drops by
/// exactly one on a generic star, for s at the apexes' midpoint, elsewhere on their line, or
/// off it. Appendix E's chain is nonsingular on a generic star but singular too where every
/// edge's two triangles are mirror images (a regular fan): there the drop is two at the
/// midpoint and one with s off the middle.
#[test]
fn star_systems_are_singular_for_every_edge_point() {
    use apatch::hull::simplicial::EdgePoint;
    use glam::DVec3;
    // Seeded jitter (LCG) for a generic fan of 5 triangles.
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let k = 5;
    let rules = [
        EdgePoint::Midpoint,
        EdgePoint::Ratio(0.3),
        EdgePoint::Lift(0.5),
        EdgePoint::Lift(-0.4),
    ];
    for _fan in 0..3 {
        let angles: Vec<f64> = (0..k)
            .map(|m| std::f64::consts::TAU * (m as f64 + 0.3 * rnd()) / k as f64)
            .collect();
        let z: Vec<f64> = (0..k).map(|_| -0.2 + 0.3 * rnd()).collect();
        let offsets: Vec<DVec3> = (0..k)
            .map(|_| DVec3::new(0.2 * rnd(), 0.2 * rnd(), 0.5 + 0.3 * rnd()))
            .collect();
        let hull = fan_hull(&angles, &z, &offsets);
        for rule in rules {
            let (m, n, drop, next) = star_of_centre(&hull, rule);
            assert_eq!((m, n), (12 * k, 12 * k), "{rule:?}");
            assert_eq!(
                drop, 1,
                "{rule:?}: appendix D's chain, singular for any geometry"
            );
            // The rest is well conditioned on a generic fan (1e-4 and above here).
            assert!(next > 1e-7, "{rule:?}: {next:e}");
        }
    }
    // A regular fan: every edge's two triangles (and apexes) are mirror images.
    let angles: Vec<f64> = (0..k)
        .map(|m| std::f64::consts::TAU * m as f64 / k as f64)
        .collect();
    let hull = fan_hull(&angles, &[-0.2; 5], &[DVec3::new(0.0, 0.0, 0.5); 5]);
    assert_eq!(star_of_centre(&hull, EdgePoint::Midpoint).2, 2);
    assert_eq!(
        star_of_centre(&hull, EdgePoint::Lift(0.5)).2,
        2,
        "s on the mirror"
    );
    assert_eq!(
        star_of_centre(&hull, EdgePoint::Ratio(0.3)).2,
        1,
        "mirror broken"
    );
}

/// Every 1994 quintic scene, shipped and pending, sorted.
fn quintic_scenes() -> Vec<std::path::PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut paths: Vec<_> = ["paper1994", "pending/paper1994"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with("_quintic.toml"))
        .collect();
    paths.sort();
    paths
}

/// The inner hull builder's hull of a quintic scene, before the quintic's changes
/// (`scene::builder_hull`), with the scene's quintic options.
fn built_hull(p: &Path) -> Option<(apatch::hull::simplicial::SimplicialHull, QuinticOptions)> {
    let scene = apatch::scene::load(p).unwrap();
    let hull = apatch::scene::builder_hull(&scene).unwrap()?;
    let apatch::scene::Model::Mesh { scheme, .. } = &scene.model else {
        return None;
    };
    Some((hull, QuinticOptions::from_toml(scheme, p).unwrap()))
}

/// The thinnest edge tetrahedra of every quintic scene's hull as the quintic fills it (the
/// builder's hull with the L-U partners added, `prepare_hull` without `thicken_edges`), for
/// choosing `slivers::EDGE_MIN_VOLUME`: prints, per scene, the smallest pair volumes, how many
/// lie below the bound and remain after the scene's own preparation, and the hull violations
/// of the built, the L-U completed and the prepared hull.
#[test]
#[ignore = "survey for humans: builds every 1994 quintic scene's hull (~1 min)"]
fn edge_sliver_survey() {
    use apatch::scheme::quintic_c2::{prepare_hull, slivers};
    for p in quintic_scenes() {
        let Some((hull, options)) = built_hull(&p) else {
            continue;
        };
        let lu_only = QuinticOptions {
            thicken_edges: false,
            contain_tangents: false,
            zero_groups: false,
            ..options.clone()
        };
        let completed = prepare_hull(&hull, &lu_only).unwrap().hull;
        let mut thin = slivers::thin_edges(&completed, 1e-2);
        thin.sort_by(|a, b| a.2.total_cmp(&b.2));
        let below = thin
            .iter()
            .filter(|t| t.2 < slivers::EDGE_MIN_VOLUME)
            .count();
        let smallest: Vec<String> = thin
            .iter()
            .take(4)
            .map(|t| format!("{:.1e}", t.2))
            .collect();
        let prepared = prepare_hull(&hull, &options).unwrap().hull;
        let left = slivers::thin_edges(&prepared, slivers::EDGE_MIN_VOLUME).len();
        let violations = (
            apatch::hull::inner::verify(&hull).len(),
            apatch::hull::inner::verify(&completed).len(),
            apatch::hull::inner::verify(&prepared).len(),
        );
        println!(
            "{}: {below} below the bound ({left} after preparing); smallest {}; hull violations built / L-U completed / prepared {violations:?}",
            p.file_name().unwrap().to_string_lossy(),
            smallest.join(", ")
        );
    }
}

/// spot_control_cage's quintic (the shipped scene without its hole repair, ~50 CPU-s): C2 to the
/// check's own bounds once its one sliver pair of edge tetrahedra (relative volume 4.8e-5) is
/// opened. Left as it is (`thicken_edges = false`) the f64 weights' rounding in that sliver is a
/// relative Hessian jump of 2.3e-7 against the bound 1e-7 (`apatch check` with
/// `thicken_edges = false`, session 29), so this test fails without the thickening.
#[test]
fn spot_control_cage_quintic_is_c2_with_its_sliver_opened() {
    let path = Path::new("scenes/paper1994/spot_control_cage_quintic.toml");
    let mut scene = apatch::scene::load(path).unwrap();
    common::set_scheme(&mut scene, "repair_holes", false);
    let built = apatch::scene::build_scene(&scene).unwrap();
    let stats = built.solve.as_ref().unwrap();
    assert_eq!(
        (stats.slivers_found, stats.slivers_thickened),
        (1, 1),
        "{stats:?}"
    );
    let report = check(&built.complex, &CheckOptions::default());
    let failures = report.failures();
    // The check's own tolerances (gradient 1e-9, Hessian 1e-7 relative: issue 8's bounds).
    for continuity in [
        "value jump",
        "gradient jump",
        "hessian jump",
        "vertex value",
        "vertex normal",
    ] {
        assert!(
            !failures.contains(&continuity),
            "{continuity}: {failures:?}"
        );
    }
    assert!(apatch::hull::inner::verify(built.hull.as_ref().unwrap()).is_empty());
}

/// How far C1 extrapolates across each face tetrahedron's side face [p_i p_j q] into its edge
/// tetrahedron, with s placed by `rule`: the sum of |barycentric coordinates| of s in
/// `[p_i p_j p_k q]` ([`apatch::hull::simplicial::extrapolation`]), with the triangle and edge.
fn extrapolation(
    hull: &apatch::hull::simplicial::SimplicialHull,
    rule: apatch::hull::simplicial::EdgePoint,
) -> Vec<(f64, u32, u32)> {
    hull.edge_tets_with(rule)
        .unwrap()
        .iter()
        .map(|et| {
            let face = hull.face_tet(et.face as usize, et.side).unwrap();
            let factor = apatch::bb::Tet::new(face).map_or(f64::INFINITY, |t| {
                apatch::hull::simplicial::extrapolation(&t, et.tet[3])
            });
            (factor, et.face, et.edge)
        })
        .collect()
}

/// Survey (ignored; prints only): per quintic scene, T's triangles with a small angle and the
/// C1 extrapolation factor from face into edge tetrahedra ([`extrapolation`]).
#[test]
#[ignore]
fn needle_survey() {
    use apatch::scheme::quintic_c2::prepare_hull;
    for p in quintic_scenes() {
        let Some((hull, options)) = built_hull(&p) else {
            continue;
        };
        let hull = prepare_hull(&hull, &options).unwrap().hull;
        let mut angles: Vec<f64> = hull
            .triangles
            .iter()
            .map(|t| {
                let v = t.map(|i| hull.points[i as usize]);
                (0..3)
                    .map(|k| {
                        let a = v[(k + 1) % 3] - v[k];
                        let b = v[(k + 2) % 3] - v[k];
                        a.angle_between(b).to_degrees()
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        angles.sort_by(f64::total_cmp);
        let mut ex = extrapolation(&hull, EdgePoint::Midpoint);
        ex.sort_by(|a, b| b.0.total_cmp(&a.0));
        let over = |t: f64| ex.iter().filter(|e| e.0 > t).count();
        let balanced = extrapolation(&hull, EdgePoint::Balanced)
            .iter()
            .fold(0.0_f64, |m, e| m.max(e.0));
        println!(
            "{}: {} triangles, min angles {:.2}° {:.2}° {:.2}°, < 5°: {}; extrapolation max {:.1} (face {}; balanced {balanced:.1}), > 5: {}, > 10: {}, > 20: {}",
            p.file_name().unwrap().to_string_lossy(),
            angles.len(),
            angles[0],
            angles[1.min(angles.len() - 1)],
            angles[2.min(angles.len() - 1)],
            angles.iter().filter(|&&a| a < 5.0).count(),
            ex[0].0,
            ex[0].1,
            over(5.0),
            over(10.0),
            over(20.0)
        );
    }
}

/// Details (ignored; prints only) for `APATCH_NEEDLES=scene.toml`: the triangles of T with the
/// largest extrapolation factors, their angles, their neighbours across each edge and the fold
/// to each. With `APATCH_NEEDLE_NETS=1` instead: per flat net (triangles whose points are all
/// guards of one face), its triangles, smallest angle, needles below 5° and largest factor; with
/// `APATCH_NEEDLE_POINTS=i,j,…`: every triangle of T at those points (the points an unmet row
/// of `APATCH_SOLVE_TRACE` names), with angles, edge lengths, factor and origins.
#[test]
#[ignore]
fn needle_details() {
    use apatch::scheme::quintic_c2::prepare_hull;
    let Ok(name) = std::env::var("APATCH_NEEDLES") else {
        return;
    };
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(&name);
    let Some((hull, options)) = built_hull(&p) else {
        return;
    };
    let hull = prepare_hull(&hull, &options).unwrap().hull;
    let edges = hull.edges().unwrap();
    let mut ex = extrapolation(&hull, EdgePoint::Midpoint);
    ex.sort_by(|a, b| b.0.total_cmp(&a.0));
    let normal = |t: usize| {
        let v = hull.triangles[t].map(|i| hull.points[i as usize]);
        (v[1] - v[0]).cross(v[2] - v[0]).normalize()
    };
    if std::env::var("APATCH_NEEDLE_NETS").is_ok() {
        let mut worst: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        for &(f, face, _) in &ex {
            let w = worst.entry(face).or_insert(0.0);
            *w = w.max(f);
        }
        let mut per: std::collections::BTreeMap<u32, (usize, f64, usize, f64)> = Default::default();
        for (t, tri) in hull.triangles.iter().enumerate() {
            let faces: Vec<Option<u32>> = tri
                .iter()
                .map(|&i| match hull.origins[i as usize] {
                    apatch::hull::simplicial::PointOrigin::CornerGuard { face } => Some(face),
                    _ => None,
                })
                .collect();
            let Some(f) = faces[0] else { continue };
            if faces.iter().any(|g| *g != Some(f)) {
                continue;
            }
            let v = tri.map(|i| hull.points[i as usize]);
            let a = common::corner_angles(v)
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            let e = per.entry(f).or_insert((0, f64::INFINITY, 0, 0.0));
            e.0 += 1;
            e.1 = e.1.min(a);
            e.2 += usize::from(a < 5.0);
            e.3 = e.3.max(worst.get(&(t as u32)).copied().unwrap_or(0.0));
        }
        for (f, (n, a, few, w)) in per {
            if n >= 10 {
                println!("net face {f}: {n} triangles, min angle {a:.2}°, < 5°: {few}, max factor {w:.1}");
            }
        }
        return;
    }
    if let Ok(list) = std::env::var("APATCH_NEEDLE_POINTS") {
        let pts: Vec<u32> = list.split(',').map(|x| x.trim().parse().unwrap()).collect();
        let mut worst: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        for &(f, face, _) in &ex {
            let w = worst.entry(face).or_insert(0.0);
            *w = w.max(f);
        }
        for &p in &pts {
            println!(
                "point {p} {:?} origin {:?}",
                hull.points[p as usize], hull.origins[p as usize]
            );
            for (t, tri) in hull.triangles.iter().enumerate() {
                if !tri.contains(&p) {
                    continue;
                }
                let v = tri.map(|i| hull.points[i as usize]);
                let ang = common::corner_angles(v).map(|a| format!("{a:.2}"));
                let lens: Vec<String> = (0..3)
                    .map(|k| format!("{:.4}", (v[(k + 1) % 3] - v[k]).length()))
                    .collect();
                println!(
                    "   tri {t} {tri:?} elem {} angles {ang:?} lens {lens:?} factor {:.1} origins {:?}",
                    hull.element[t],
                    worst.get(&(t as u32)).copied().unwrap_or(0.0),
                    tri.map(|i| hull.origins[i as usize])
                );
            }
        }
        return;
    }
    let mut seen = std::collections::HashSet::new();
    for &(f, face, edge) in ex.iter().take(40) {
        if !seen.insert(face) {
            continue;
        }
        let t = hull.triangles[face as usize];
        let v = t.map(|i| hull.points[i as usize]);
        let ang = common::corner_angles(v).map(|a| format!("{a:.2}"));
        println!(
            "face {face} {t:?} elem {} origins {:?} angles {ang:?} factor {f:.1} (edge {:?})",
            hull.element[face as usize],
            t.map(|i| hull.origins[i as usize]),
            edges[edge as usize].v
        );
        for e in edges.iter().filter(|e| e.faces.contains(&face)) {
            let other = if e.faces[0] == face {
                e.faces[1]
            } else {
                e.faces[0]
            };
            if other == u32::MAX {
                continue;
            }
            let fold = normal(face as usize)
                .angle_between(normal(other as usize))
                .to_degrees();
            let len = (hull.points[e.v[0] as usize] - hull.points[e.v[1] as usize]).length();
            println!(
                "   edge {:?} len {len:.3} -> face {other} {:?} elem {} fold {fold:.3}°",
                e.v, hull.triangles[other as usize], hull.element[other as usize]
            );
        }
    }
}

/// The sign projection (`sign_rounds`) on l_prism's quintic, whose solve leaves 80 non-jet
/// weights off Theorem 2.1's signs (the four relaxed stars at its concave edge): fewer are off
/// afterwards (none with 100 rounds, session 30), and the independent check still finds C2
/// to its bounds, exact vertex values and normals (the jets are not moved), and no hole or
/// j-sheet.
#[test]
fn sign_projection_keeps_c2_and_the_jets_on_l_prism() {
    let path = Path::new("scenes/paper1994/l_prism_quintic.toml");
    let mut scene = apatch::scene::load(path).unwrap();
    common::set_scheme(&mut scene, "sign_rounds", 100);
    let built = apatch::scene::build_scene(&scene).unwrap();
    let p = &built.solve.as_ref().unwrap().sign_projection;
    assert!(p.kept && p.off_after < p.off_before, "{p:?}");
    let r = check(&built.complex, &CheckOptions::default());
    // The check's own bounds: gradient 1e-9, Hessian 1e-7 (issue 8), vertex value 1e-9 and
    // normal 1e-7.
    assert!(r.passed(), "{:?}", r.failures());
    assert_eq!((r.holes.crossing, r.sheets.j_multi_patches), (0, 0));
}

/// `sign_rounds`, `balance_edges` and `tangent_clearance` are read from the scene; bad values
/// (a clearance above the slope moved apexes get, 0.02, could never be met) name the key and
/// the scene file.
#[test]
fn sign_rounds_and_balance_edges_are_scene_keys() {
    let scene = Path::new("x/scene.toml");
    let table: toml::Table = toml::from_str(
        "type = \"quintic-c2\"\nsign_rounds = 7\nbalance_edges = true\ntangent_clearance = 0.01\nsign_program = true",
    )
    .unwrap();
    let o = QuinticOptions::from_toml(&table, scene).unwrap();
    assert_eq!((o.sign_rounds, o.balance_edges), (7, true));
    assert!(o.sign_program && !QuinticOptions::default().sign_program);
    assert_eq!(o.tangent_clearance, 0.01);
    assert_eq!(QuinticOptions::default().sign_rounds, 0);
    assert!(!QuinticOptions::default().balance_edges);
    assert_eq!(QuinticOptions::default().tangent_clearance, 0.0);
    for bad in [
        "sign_rounds = -1",
        "sign_rounds = 2.5",
        "balance_edges = 1",
        "tangent_clearance = 0.05",
        "tangent_clearance = -0.01",
        "tangent_clearance = true",
        "sign_program = 1",
    ] {
        let table: toml::Table = toml::from_str(bad).unwrap();
        let e = QuinticOptions::from_toml(&table, scene)
            .unwrap_err()
            .to_string();
        let key = bad.split(' ').next().unwrap();
        assert!(e.contains(key) && e.contains("x/scene.toml"), "{bad}: {e}");
    }
}

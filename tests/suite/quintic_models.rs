//! C2 quintic scheme on the inner hull (`hull::inner`) of the test polyhedra and real models.

use apatch::check::{check, CheckOptions};
use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{self, NormalMethod};
use apatch::scheme::quintic_c2::{build_with_stats, QuinticOptions};
use std::path::Path;

/// The scheme's defaults, with `LIFT=x`, `CURV=x`, `SIGNS=1`, `LU=0` and `JOINT=1` in the
/// environment overriding the lift, the curvature, the sign pins, the L-U completion and the
/// joint stars, `RELAX=0` turning off the relaxed stars, `CONSISTENT=1` the consistent
/// stars, `HSIGNS=1` the Hessian sign fit, `TANGENTS=1` the tangent containment and
/// `STAR_TAU` the stars' near-null threshold, `REPAIR=1` the hole repair and
/// `REPAIR_HESSIANS=0` its Hessian passes off, `THICKEN=0` the sliver edge tetrahedra left
/// as they are, `BALANCE=1` the balanced edge points and `SIGN_ROUNDS` the sign projection's
/// rounds, `SIGN_PROGRAM=1` its linear program (HiGHS with the feature `highs`, else the
/// interior point method), `TANGENT_CLEARANCE` the quintic's `tangent_clearance`,
/// `SIGN_TARGETS` its `sign_targets`, `JOINT_SIGN_ROUNDS` its `joint_sign_rounds`,
/// `JOINT_SIGN_FIT` its `joint_sign_fit`, `JOINT_SIGN_BOUNDARY` its
/// `joint_sign_boundary`, `JOINT_MEET_TOLERANCE` its `joint_meet_tolerance`, `JOINT_LOCAL_MEET=1` its
/// `joint_local_meet`, `REPAIR_WIDEN` its `repair_widen`, `REPAIR_ELEVATE` its
/// `repair_elevate` (with the default margins), `HESSIAN_NORMAL` its `hessian_normal`, `HESSIAN_COST` its
/// `hessian_cost`, `HESSIAN_COLUMN_FLAT` its `hessian_column_flat` (to explore).
fn options() -> QuinticOptions {
    QuinticOptions {
        lift: std::env::var("LIFT")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(apatch::scheme::quintic_c2::LIFT),
        signs: std::env::var("SIGNS").is_ok_and(|s| s == "1"),
        curvature: std::env::var("CURV")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(1.0),
        complete_lu_pairs: std::env::var("LU").map_or(true, |s| s != "0"),
        joint_stars: std::env::var("JOINT").is_ok_and(|s| s == "1"),
        relax_stars: std::env::var("RELAX").map_or(true, |s| s != "0"),
        consistent_stars: std::env::var("CONSISTENT").is_ok_and(|s| s == "1"),
        hessian_signs: std::env::var("HSIGNS").is_ok_and(|s| s == "1"),
        contain_tangents: std::env::var("TANGENTS").is_ok_and(|s| s == "1"),
        tangent_clearance: std::env::var("TANGENT_CLEARANCE")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0.0),
        zero_groups: std::env::var("ZERO").is_ok_and(|s| s == "1"),
        star_tau: std::env::var("STAR_TAU")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0.0),
        repair_holes: std::env::var("REPAIR").is_ok_and(|s| s == "1"),
        repair_hessians: match std::env::var("REPAIR_HESSIANS").as_deref() {
            Ok("0") => apatch::scheme::quintic_c2::HessianRepair::Off,
            Ok("all") => apatch::scheme::quintic_c2::HessianRepair::All,
            _ => apatch::scheme::quintic_c2::HessianRepair::Last,
        },
        repair_widen: std::env::var("REPAIR_WIDEN")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(apatch::scheme::quintic_c2::holes::WIDEN),
        repair_elevate: std::env::var("REPAIR_ELEVATE")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0),
        repair_margins: apatch::scheme::quintic_c2::REPAIR_MARGINS.to_vec(),
        hessian_normal: std::env::var("HESSIAN_NORMAL")
            .ok()
            .and_then(|x| apatch::scheme::quintic_c2::normalpart::HessianNormal::named(&x))
            .unwrap_or_default(),
        hessian_cost: std::env::var("HESSIAN_COST")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(1.0),
        hessian_column_flat: std::env::var("HESSIAN_COLUMN_FLAT")
            .ok()
            .and_then(|x| x.parse().ok()),
        hessian_column_points: Vec::new(),
        joint_meet_stall: None,
        thicken_edges: std::env::var("THICKEN").map_or(true, |s| s != "0"),
        balance_edges: std::env::var("BALANCE").is_ok_and(|s| s == "1"),
        joint_sign_rounds: std::env::var("JOINT_SIGN_ROUNDS")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0),
        joint_sign_fit: std::env::var("JOINT_SIGN_FIT")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0),
        joint_sign_boundary: std::env::var("JOINT_SIGN_BOUNDARY")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(1.0),
        joint_meet_tolerance: std::env::var("JOINT_MEET_TOLERANCE")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0.0),
        joint_local_meet: std::env::var("JOINT_LOCAL_MEET").is_ok_and(|s| s == "1"),
        // The default rows; `APATCH_FACE_BETA` picks others here as in any build.
        face_beta: apatch::scheme::quintic_c2::beta::FaceBeta::default(),
        // The default thresholds; `APATCH_PRECISE_PIVOT` picks another here as in any build.
        precise_pivot: None,
        sign_rounds: std::env::var("SIGN_ROUNDS")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0),
        sign_program: std::env::var("SIGN_PROGRAM").is_ok_and(|s| s == "1"),
        sign_targets: std::env::var("SIGN_TARGETS")
            .ok()
            .and_then(|x| x.parse().ok())
            .unwrap_or(0.0),
    }
}

/// The inner hull of a loaded model with its default vertex normals and hull options: what a
/// scene without `[scheme]` hull keys builds.
fn default_hull(m: &mesh::Mesh) -> apatch::hull::simplicial::SimplicialHull {
    let normals = mesh::vertex_normals(m, NormalMethod::default_for(m)).unwrap();
    inner::build(m, &normals, &InnerOptions::default()).unwrap()
}

/// Issue 8's C2 acceptance, on the checker's relative measures: gradient jumps ≤ 1e-9 and
/// Hessian jumps ≤ 1e-7 across every shared face.
fn assert_c2(r: &apatch::check::CheckReport) {
    assert!(r.gradient_jump.worst <= 1e-9, "{:?}", r.gradient_jump);
    assert!(r.hessian_jump.worst <= 1e-7, "{:?}", r.hessian_jump);
}

fn run(name: &str) -> Result<String, String> {
    let path = Path::new("scenes/models").join(name);
    let (m, report) = mesh::load(&path).map_err(|e| e.to_string())?;
    report.require(true).map_err(|e| e.to_string())?;
    let normals =
        mesh::vertex_normals(&m, NormalMethod::default_for(&m)).map_err(|e| e.to_string())?;
    let hull = inner::build(&m, &normals, &InnerOptions::default()).map_err(|e| e.to_string())?;
    let t = std::time::Instant::now();
    let (c, stats) = build_with_stats(&hull, &options()).map_err(|e| e.to_string())?;
    let secs = t.elapsed().as_secs_f64();
    let r = check(&c, &CheckOptions::default());
    Ok(format!(
        "{} patches, build {secs:.2} s, {stats:?}; grad {:.2e} hess {:.2e} value {:.2e} angle {:.2e} multi-sheet {} of {} lines, {} patches; j-lines {} multi {} in {} of {} patches; failures {:?}",
        c.patches.len(),
        r.gradient_jump.worst,
        r.hessian_jump.worst,
        r.interpolation.value.worst,
        r.interpolation.normal_angle.worst,
        r.sheets.multi_root_lines,
        r.sheets.vertex_lines,
        r.sheets.multi_sheet_patches,
        r.sheets.j_lines,
        r.sheets.j_multi_lines,
        r.sheets.j_multi_patches,
        r.sheets.j_patches,
        r.failures()
    ))
}

#[test]
#[ignore = "exploration: MODEL=substring"]
fn explore_all() {
    let only = std::env::var("MODEL").unwrap_or_default();
    let mut names: Vec<String> = std::fs::read_dir("scenes/models")
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".obj") && n.contains(&only))
        .collect();
    names.sort();
    for name in names {
        match run(&name) {
            Ok(s) => eprintln!("{name}: {s}"),
            Err(e) => eprintln!("{name}: ERROR {e}"),
        }
    }
}

/// The acceptance on every model whose inner hull the scheme builds today: C1 jumps
/// ≤ 1e-9, Hessian jumps ≤ 1e-7 (the checker's relative measures), vertex values and normals
/// interpolated (rounding-level tolerances of the checker's defaults), the solve's own residual
/// at rounding level. Non-trihedral vertices (octahedron, icosahedron), L-U pairs and
/// relaxed (coplanar) stars (l_prism, corner_poly), genus 1 (torus), and cube_poly, whose
/// staged solve is inconsistent at the number 10 weights of its bottom edges (apexes in the
/// planes of the faces) and is solved at once instead (the global fallback, a sparse group).
#[test]
fn inner_hull_models_are_c2() {
    for name in [
        "octahedron.obj",
        "icosahedron.obj",
        "l_prism.obj",
        "corner_poly.obj",
        "torus_quad12x8.obj",
        "cube_poly.obj",
    ] {
        let path = Path::new("scenes/models").join(name);
        let (m, _) = mesh::load(&path).unwrap();
        let hull = default_hull(&m);
        let (c, stats) = build_with_stats(&hull, &options()).unwrap();
        // No single-sided face tetrahedron has a base weight the data fix with its apex's
        // sign (the torus's holes, see torus_holes_are_base_conflicts_of_the_hull).
        if !name.contains("torus") {
            assert_eq!(stats.signs.base_conflicts, 0, "{name}");
        }
        // Relative residual of the solved equations: rounding of short sums.
        assert!(stats.max_residual < 1e-12, "{name}: {stats:?}");
        let r = check(&c, &CheckOptions::default());
        assert!(
            r.gradient_jump.worst <= 1e-9,
            "{name}: {:?}",
            r.gradient_jump
        );
        assert!(r.hessian_jump.worst <= 1e-7, "{name}: {:?}", r.hessian_jump);
        // Known limitation: on l_prism and corner_poly 2 patches each (at the relaxed, coplanar
        // stars) are crossed twice along some j-lines (free weights chosen by closeness to the
        // lifted Taylor targets, not by Theorem 2.1's sign conditions); every other measure
        // must pass, and everything on the other models.
        // Known wrong: the torus has holes (`check`'s "holes": 24 single-sided non-convex
        // triangles and 432 outer faces of edge tetrahedra crossed; scenes/pending/paper1994/
        // README.md), not a C2 failure.
        let f: Vec<&str> = r
            .failures()
            .into_iter()
            .filter(|f| *f != "multiple sheets along j-lines")
            .filter(|f| !(*f == "holes" && name.contains("torus")))
            .collect();
        assert!(f.is_empty(), "{name}: {f:?}");
        if !name.contains("prism") && !name.contains("corner") && !name.contains("torus") {
            assert!(r.passed(), "{name}: {:?}", r.failures());
        }
    }
}

/// The inner hull cube_poly had before coplanar faces were merged (its top face split into two
/// triangles with their own centroids; pseudo-centroids at the two non-trihedral corners). The
/// staged solve is inconsistent there at the number 10 weights of the bottom edges (apexes in
/// the planes of both faces), so every weight is solved at once: one group of over 1000
/// weights, which goes to the sparse solver. The result must be C2 and pass `apatch check`.
#[test]
fn global_fallback_uses_sparse_solver() {
    use apatch::hull::simplicial::{PointOrigin, SimplicialHull};
    use glam::DVec3;
    let (t, s3) = (1.0 / 3.0, 1.0 / 3.0_f64.sqrt());
    let v = DVec3::new;
    let points = vec![
        v(t, t, 1.0),
        v(-t, -t, 1.0),
        v(-1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, -1.0, 0.0),
        v(0.0, 0.0, -1.0),
        v(-2.0 * t, 2.0 * t, 2.0 * t),
        v(2.0 * t, -2.0 * t, 2.0 * t),
    ];
    let normals = vec![
        DVec3::Z,
        DVec3::Z,
        -DVec3::X,
        DVec3::Y,
        DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
        v(-s3, s3, s3),
        v(s3, -s3, s3),
    ];
    let tris: [([u32; 3], DVec3); 14] = [
        ([1, 2, 5], v(-1.0, -1.0, 1.0)),
        ([7, 0, 3], v(-0.1, 1.0, 1.0)),
        ([7, 3, 2], v(-1.0, 1.0, 0.1)),
        ([7, 2, 1], v(-1.0, 0.1, 1.0)),
        ([7, 1, 0], v(-t, t, 4.0 * t)),
        ([0, 4, 3], v(1.0, 1.0, 1.0)),
        ([8, 0, 1], v(t, -t, 4.0 * t)),
        ([8, 1, 5], v(0.1, -1.0, 1.0)),
        ([8, 5, 4], v(1.0, -1.0, 0.1)),
        ([8, 4, 0], v(1.0, -0.1, 1.0)),
        ([2, 6, 5], v(-1.0, -1.0, -1.0)),
        ([2, 3, 6], v(-1.0, 1.0, -1.0)),
        ([3, 4, 6], v(1.0, 1.0, -1.0)),
        ([4, 5, 6], v(1.0, -1.0, -1.0)),
    ];
    let hull = SimplicialHull {
        origins: vec![PointOrigin::Other; points.len()],
        points,
        normals,
        triangles: tris.iter().map(|t| t.0).collect(),
        apexes: tris.iter().map(|t| [Some(t.1), None]).collect(),
        element: (0..14).collect(),
    };
    let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    assert!(
        stats.global && stats.sparse_groups >= 1 && stats.largest_group >= 1000,
        "{stats:?}"
    );
    // Relative residual: the sparse solve stops at 1e-13 of the group's largest datum.
    assert!(stats.max_residual < 1e-12, "{stats:?}");
    let r = check(&c, &CheckOptions::default());
    assert_c2(&r);
    // Known wrong since `check` detects holes: on this former hull the surface crosses 2 of the
    // 98 boundary faces (the bases at the split top face's middle edge, depth 3e-3): the jets
    // of its coplanar points and the number 3 weights the global solve gives that edge miss
    // Theorem 2.1's base sign (`stats.signs`: 2 jet and 20 edge-middle weights). The shipped
    // cube_poly hull merges the top face and has no holes.
    let f: Vec<&str> = r.failures().into_iter().filter(|f| *f != "holes").collect();
    assert!(f.is_empty(), "{f:?}");
    assert!(r.holes.crossing <= 2, "{:?}", r.holes);
}

/// torus_quad (quad faces in 50 coplanar stars, a group of over 7000 weights) is C2 through
/// the sparse solver;
/// ignored because it takes ~8 s in release (extra evidence).
#[test]
#[ignore = "slow (~8 s release): extra evidence for the sparse solver beside global_fallback_uses_sparse_solver"]
fn torus_quad_is_c2() {
    let c = c2_of("torus_quad.obj", 7000);
    let r = check(&c, &CheckOptions::default());
    assert_c2(&r);
}

/// Builds `name`'s quintic complex and checks that the solve went through a sparse group of at
/// least `min_group` weights with a rounding-level residual.
fn c2_of(name: &str, min_group: usize) -> apatch::complex::PatchComplex {
    let path = Path::new("scenes/models").join(name);
    let (m, _) = mesh::load(&path).unwrap();
    let hull = default_hull(&m);
    let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    assert!(
        stats.sparse_groups >= 1 && stats.largest_group >= min_group,
        "{name}: {stats:?}"
    );
    // Relative residual: the sparse solve stops at 1e-13 of the group's largest datum; the
    // global measure divides by the largest weight.
    assert!(stats.max_residual < 1e-12, "{name}: {stats:?}");
    c
}

/// Exploration: `SCENE=path cargo test --release --test suite quintic_models::crack_count -- --ignored
/// --nocapture` prints the back-facing first hits of a scene (`tests/suite/scenes_all.rs` requires
/// none on every shipped 1994 scene).
#[test]
#[ignore = "exploration: SCENE=path"]
fn crack_count() {
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let complex = apatch::scene::build_complex(&sc).unwrap();
    let back = apatch::fixtures::back_facing_hits(&sc.settings, &complex).unwrap();
    eprintln!("{}: {back}", path.display());
}

/// Exploration: face patches of a scene whose zero set crosses the base triangle on T (F takes
/// the apex's sign somewhere inside the base), which opens a hole in the surface.
#[test]
#[ignore = "exploration: SCENE=path"]
fn base_crossings() {
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    let (mut bad, mut faces) = (0, 0);
    let base = |p: &apatch::complex::Patch| {
        let mut b: Vec<[u64; 3]> = p.tet[..3].iter().map(|v| v.map(f64::to_bits)).collect();
        b.sort_unstable();
        b
    };
    let mut count = std::collections::HashMap::new();
    for p in &c.patches {
        if p.role == apatch::complex::Role::Face {
            *count.entry(base(p)).or_insert(0) += 1;
        }
    }
    for (k, p) in c.patches.iter().enumerate() {
        // Single-sided face tetrahedra only: an L-U pair's base is inside the hull.
        if p.role != apatch::complex::Role::Face || count[&base(p)] > 1 {
            continue;
        }
        faces += 1;
        let n = usize::from(p.degree);
        let apex = p.weights[apatch::bb::index_of([0, 0, 0, p.degree])];
        let m = 24;
        let mut worst = 0.0_f64;
        for i in 1..m {
            for j in 1..m - i {
                let a = [
                    i as f64 / m as f64,
                    j as f64 / m as f64,
                    (m - i - j) as f64 / m as f64,
                    0.0,
                ];
                let f = apatch::bb::poly::eval(n, &p.weights, a);
                if f * apex > 0.0 {
                    worst = worst.max(f.abs());
                }
            }
        }
        if worst > 0.0 {
            bad += 1;
            if bad <= 5 {
                eprintln!("patch {k}: apex F {apex:.3e}, base F up to {worst:.3e} with its sign; tet {:?}", p.tet);
            }
        }
    }
    eprintln!(
        "{}: {bad} of {faces} single-sided face patches cross their base",
        path.display()
    );
}

/// Exploration: per patch of a scene, its j-lines crossed twice and its weights' Theorem 2.1
/// sign misses by level.
#[test]
#[ignore = "exploration: SCENE=path"]
fn jline_patches() {
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    for (k, p) in c.patches.iter().enumerate() {
        let mut one = c.clone();
        one.patches = vec![p.clone()];
        let r = check(&one, &CheckOptions::default());
        if r.sheets.j_multi_lines == 0 {
            continue;
        }
        let mi = apatch::bb::multi_indices(usize::from(p.degree));
        let apex = p.weights[apatch::bb::index_of([0, 0, 0, p.degree])];
        let s = apex.signum();
        let mut lv = String::new();
        for (i, l) in mi.iter().enumerate() {
            let level = if p.role == apatch::complex::Role::Edge {
                l[2] + l[3]
            } else {
                l[3]
            };
            let w = p.weights[i];
            let bad = (level == 0 && w * s > 1e-12) || (level >= 2 && w * s < -1e-12);
            if bad {
                lv += &format!(" {l:?}={w:.2e}");
            }
        }
        eprintln!(
            "patch {k} {:?} el {} multi {} of {} F(v2) {:.3e} F(v3) {:.3e} tet {:?} at {:?}: misses{lv}",
            p.role, p.element, r.sheets.j_multi_lines, r.sheets.j_lines,
            p.weights[apatch::bb::index_of([0, 0, p.degree, 0])], apex, p.tet, r.sheets.j_multi_at
        );
    }
}

/// The holes of the 12×8 torus come from the hull's data, not from the free weights: every
/// single-sided face patch whose zero set crosses its base triangle (F sampled on the base
/// with the apex's sign, an independent measurement of the built surface) sits on a triangle
/// that `signs::base_conflicts` flags from the normals and points of T alone (a number 1
/// weight of the base with the apex's sign, which Theorem 2.1 forbids and no free weight can
/// change), with or without the sign pins. The inner hull now gives those triangles both
/// sides itself (`hull::inner::sides`), so the test takes the inner apex away again from every
/// double-sided triangle that is not convex for its outer side: the single-sided hull the
/// torus had before.
#[test]
fn torus_holes_are_base_conflicts_of_the_hull() {
    use apatch::hull::simplicial::Side;
    use apatch::scheme::quintic_c2::{signs, system};
    let path = Path::new("scenes/models/torus_quad12x8.obj");
    let (m, _) = mesh::load(path).unwrap();
    let mut hull = default_hull(&m);
    for t in 0..hull.triangles.len() {
        if hull.apexes[t].iter().all(Option::is_some) {
            let mut one = hull.clone();
            one.apexes[t][Side::Inner as usize] = None;
            if signs::base_conflicts(&one)
                .iter()
                .any(|c| c.triangle == t as u32)
            {
                hull.apexes[t][Side::Inner as usize] = None;
            }
        }
    }
    let conflicts = signs::base_conflicts(&hull);
    let flagged: std::collections::HashSet<u32> = conflicts.iter().map(|c| c.triangle).collect();
    assert!(!flagged.is_empty());
    let (tets, _) = system::tetrahedra(&hull).unwrap();
    for pins in [false, true] {
        let o = QuinticOptions {
            signs: pins,
            complete_lu_pairs: false,
            ..QuinticOptions::default()
        };
        let (c, stats) = build_with_stats(&hull, &o).unwrap();
        // Theorem 2.1's count agrees: the jets miss their sign exactly on flagged triangles'
        // edges (number 1 weights and their Hessian neighbours on the same edges).
        assert!(stats.signs.violated_by_stage[0] > 0, "{stats:?}");
        let mut crossing = 0;
        for (k, p) in c.patches.iter().enumerate() {
            let t = &tets[k];
            let single = hull.apexes[t.triangle as usize]
                .iter()
                .filter(|a| a.is_some())
                .count()
                == 1;
            if p.role != apatch::complex::Role::Face || !single {
                continue;
            }
            let apex = p.weights[apatch::bb::index_of([0, 0, 0, 5])];
            let m = 24;
            let mut crosses = false;
            for i in 1..m {
                for j in 1..m - i {
                    let a = [i, j, m - i - j].map(|x| x as f64 / m as f64);
                    let f = p.value_bary([a[0], a[1], a[2], 0.0]);
                    // Far above rounding (F is O(1e-2) on these bases).
                    if f * apex > 1e-12 {
                        crosses = true;
                    }
                }
            }
            if crosses {
                crossing += 1;
                assert!(
                    flagged.contains(&t.triangle),
                    "patch {k} crosses its base on unflagged triangle {}",
                    t.triangle
                );
            }
        }
        // And every flagged triangle does cross: the prediction is exact.
        assert_eq!(crossing, flagged.len(), "pins {pins}");
        assert_eq!(stats.signs.base_conflicts, conflicts.len());
        eprintln!(
            "pins {pins}: {crossing} crossing patches, {} flagged triangles, {} conflicts",
            flagged.len(),
            conflicts.len()
        );
    }
    // With the L-U completion (the default) every flagged triangle gets its partner
    // tetrahedron and no face tetrahedron's base is crossed any more.
    let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    assert_eq!(stats.lu_completed, flagged.len(), "{stats:?}");
    assert_eq!(stats.signs.base_conflicts, 0, "{stats:?}");
    let r = check(&c, &CheckOptions::default());
    assert_eq!(
        r.holes.crossing_by_role.get("face").copied().unwrap_or(0),
        0,
        "{:?}",
        r.holes
    );
}

/// Exploration: `SCENE=path PATCH=k`: the weights of patch k on its faces through the apex
/// side (λ_0 = 0, λ_1 = 0) and its tetrahedron.
#[test]
#[ignore = "exploration: SCENE=path PATCH=k"]
fn patch_faces() {
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let k: usize = std::env::var("PATCH").unwrap().parse().unwrap();
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    let p = &c.patches[k];
    eprintln!("patch {k} {:?} tet {:?}", p.role, p.tet);
    for (i, l) in apatch::bb::multi_indices(5).iter().enumerate() {
        if l[0] == 0 || l[1] == 0 {
            eprintln!("{l:?} {:.4e}", p.weights[i]);
        }
    }
}

/// Theorem 2.1 (k = 1) holds for every weight of every patch on the convex test polyhedra:
/// read from the built complex alone (each patch's side from its apex weight, F > 0 outside),
/// face patches have base weights (λ_q = 0) ≤ 0 and weights with λ_q ≥ 2 ≥ 0, edge patches
/// the same by μ_q + μ_s; so each is a j-patch by the theorem, not only by sampling. The
/// scheme's own count (`stats.signs`) agrees. (On the octahedron, the prisms and the torus the
/// determined star weights of appendices D and E miss their signs: docs/quintic.md.)
#[test]
fn theorem_2_1_holds_on_convex_models() {
    for name in [
        "cube.obj",
        "tetrahedron.obj",
        "icosahedron.obj",
        "dodecahedron.obj",
        "cube_poly.obj",
    ] {
        let path = Path::new("scenes/models").join(name);
        let (m, _) = mesh::load(&path).unwrap();
        let hull = default_hull(&m);
        let (c, stats) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
        assert_eq!(stats.signs.violated(), 0, "{name}: {:?}", stats.signs);
        let wmax = c
            .patches
            .iter()
            .flat_map(|p| p.weights.iter())
            .fold(0.0_f64, |a, w| a.max(w.abs()));
        // Zero weights (F = 0 at T's points) carry rounding of the blossoms: 1e-12 relative.
        let tiny = 1e-12 * wmax;
        let mi = apatch::bb::multi_indices(5);
        for (k, p) in c.patches.iter().enumerate() {
            let apex = p.weights[apatch::bb::index_of([0, 0, 0, 5])];
            // Every patch here lies outside T (single-sided convex hull): apex F > 0.
            assert!(apex > 0.0, "{name} patch {k}");
            for (i, l) in mi.iter().enumerate() {
                let level = if p.role == apatch::complex::Role::Edge {
                    l[2] + l[3]
                } else {
                    l[3]
                };
                let w = p.weights[i];
                let ok = match level {
                    0 => w <= tiny,
                    1 => true,
                    _ => w >= -tiny,
                };
                assert!(ok, "{name} patch {k} ({:?}) weight {l:?} = {w:e}", p.role);
            }
        }
    }
}

/// Issue 8, the 12×8 torus: without `relax_stars` the determined star weights of appendices D
/// and E are negative on outer faces [p q s] of edge tetrahedra and the surface leaves the hull
/// there (holes); relaxing the stars with such misses (their edge middles and Hessians solved
/// with them, closest to the targets) removes every crossing while C2 stays exact. Measured
/// twice: by `check`'s holes (certified by BB coefficients and subdivision) and by sampling F
/// on every boundary face of the hull here (independent of both the scheme and the checker).
#[test]
fn relaxed_stars_close_the_torus_holes() {
    let path = Path::new("scenes/models/torus_quad12x8.obj");
    let (m, _) = mesh::load(path).unwrap();
    let hull = default_hull(&m);
    let mut crossed = Vec::new();
    for relax in [false, true] {
        let o = QuinticOptions {
            relax_stars: relax,
            ..QuinticOptions::default()
        };
        let (c, stats) = build_with_stats(&hull, &o).unwrap();
        let r = check(&c, &CheckOptions::default());
        assert_c2(&r);
        assert_eq!(r.sheets.j_multi_patches, 0, "relax {relax}");
        let sampled = boundary_faces_crossed(&c);
        eprintln!(
            "relax {relax}: {} relaxed for signs, holes {:?}, sampled {sampled}",
            stats.relaxed_for_signs, r.holes.crossing_by_role
        );
        crossed.push((r.holes.crossing, sampled));
        if relax {
            assert!(stats.relaxed_for_signs > 0, "{stats:?}");
        }
    }
    // Before: hundreds of crossed faces (384 on `realtri`'s hull); after: none.
    assert!(crossed[0].0 > 100 && crossed[0].1 > 100, "{crossed:?}");
    assert_eq!(crossed[1], (0, 0), "{crossed:?}");
}

/// Boundary faces of the complex (faces of one patch only) on which F, sampled on a lattice
/// of 15 steps, takes the patch's apex-side sign at one point and the other sign at another
/// (the surface crosses the face). Values within 1e-12 of the largest weight count as zero
/// (F = 0 at the points of T, which lie on the faces).
fn boundary_faces_crossed(c: &apatch::complex::PatchComplex) -> usize {
    crossed_boundary_faces(c).0.len()
}

/// The crossed boundary faces of [`boundary_faces_crossed`], each as (patch, opposite corner),
/// with the largest weight magnitude that scales "zero": a lattice of 15 steps per edge, and
/// "zero" is 1e-12 of the complex's largest weight (round-off of the degree-5 evaluation).
fn crossed_boundary_faces(c: &apatch::complex::PatchComplex) -> (Vec<(usize, usize)>, f64) {
    apatch::fixtures::crossed_boundary_faces(c, 15, 1e-12, apatch::fixtures::SignScale::Complex)
}

/// Exploration: every boundary face of a scene's complex that the surface crosses (as in
/// `boundary_faces_crossed`), with the weights on it that miss Theorem 2.1's sign (k = 1,
/// the patch's apex-side sign from its apex weight), each with its multi-index, level, value
/// and the largest multiplicity of a point of T in it (≥ 3: a jet weight, fixed by the data).
#[test]
#[ignore = "exploration: SCENE=path"]
fn boundary_crossing_causes() {
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    let (crossed, wmax) = crossed_boundary_faces(&c);
    let mi = apatch::bb::multi_indices(5);
    let mut by_kind: std::collections::BTreeMap<String, usize> = Default::default();
    for (k, opp) in crossed {
        let p = &c.patches[k];
        let edge = p.role == apatch::complex::Role::Edge;
        let n_t = if edge { 2 } else { 3 };
        let s = p.weights[apatch::bb::index_of([0, 0, 0, 5])].signum();
        let mut misses = String::new();
        for (i, l) in mi.iter().enumerate() {
            if l[opp] != 0 {
                continue;
            }
            let level = if edge { l[2] + l[3] } else { l[3] };
            let w = p.weights[i];
            let bad = (level == 0 && w * s > 1e-12 * wmax) || (level >= 2 && w * s < -1e-12 * wmax);
            if bad {
                let mult = l[..n_t].iter().max().copied().unwrap_or(0);
                let kind = match mult {
                    3.. => "jet",
                    2 if l[..n_t].iter().filter(|&&x| x == 2).count() == 2 => "edge-middle",
                    2 => "star",
                    _ => "far",
                };
                *by_kind
                    .entry(format!("{:?} opp {opp} level {level} {kind}", p.role))
                    .or_insert(0) += 1;
                misses += &format!(" {l:?}={w:.2e}({kind})");
            }
        }
        eprintln!(
            "patch {k} {:?} el {} face opp {opp} crossed; misses{misses}",
            p.role, p.element
        );
    }
    eprintln!("{by_kind:#?}");
}

/// letter_P_poly (annular caps, L-U pairs next to single-sided triangles): the estimated
/// shape operator bends the surface out through flat bases of the hull (number 2 weights of
/// the base edges with the apex's sign). With `hessian_signs` (each point's Hessian moved,
/// least, so its number 2 weights meet Theorem 2.1) and the scene's curvature scale, the
/// surface crosses no boundary face and no j-line twice, and stays C2; the same build without
/// the fit crosses bases (an independent count by sampling F on every boundary face).
#[test]
fn letter_p_hessian_signs_close_the_holes() {
    let path = Path::new("scenes/models/letter_P_poly.obj");
    let (m, _) = mesh::load(path).unwrap();
    let hull = default_hull(&m);
    let mut crossed = Vec::new();
    for fit in [false, true] {
        let o = QuinticOptions {
            hessian_signs: fit,
            curvature: 0.4,
            ..QuinticOptions::default()
        };
        let (c, stats) = build_with_stats(&hull, &o).unwrap();
        let r = check(&c, &CheckOptions::default());
        assert_c2(&r);
        if fit {
            assert!(stats.hessian_fit.moved > 0, "{stats:?}");
            assert!(r.passed(), "{:?}", r.failures());
            assert_eq!(r.sheets.j_multi_patches, 0);
        }
        crossed.push(boundary_faces_crossed(&c));
    }
    assert!(crossed[0] > 0, "{crossed:?}");
    assert_eq!(crossed[1], 0, "{crossed:?}");
}

/// A weight's class for [`sign_miss_classes`]: the tetrahedron's kind (face tetrahedron of a
/// single-sided triangle or of an L-U pair, outer or inner; edge tetrahedron) and the domain
/// point's pattern: the multiplicities of the points of T (largest first) | the share of the
/// vertices off T (apex q; for an edge tetrahedron q and its midpoint s), with the scheme's
/// stage and the paper's number where the pattern fixes it.
fn weight_class(p: &apatch::complex::Patch, lu: bool, l: [u8; 4]) -> String {
    let edge = p.role == apatch::complex::Role::Edge;
    let n_t = if edge { 2 } else { 3 };
    let mut t: Vec<u8> = l[..n_t].to_vec();
    t.sort_unstable_by(|a, b| b.cmp(a));
    let off: Vec<u8> = l[n_t..].to_vec();
    let top = t[0];
    let twos = t.iter().filter(|&&x| x == 2).count();
    let what = match (top, twos) {
        (5, _) => "jet no.0",
        (4, _) => "jet no.1",
        (3, _) => "jet no.2",
        (2, 2) if off.iter().sum::<u8>() == 0 || (!edge && off[0] == 0) => {
            "edge middle no.3 (free)"
        }
        (2, 2) => "edge middle no.4",
        (2, _) => "star (no.5-7, 9: determined)",
        _ if !edge && t == [1, 1, 0] && off[0] == 3 => "face middle (no.10/11)",
        _ if !edge => "far face (no.8, 12, 13, 16: free; L-U inner: C2)",
        _ if t == [1, 1] => "face middle (no.10/11)",
        _ => "rest of edge tet (no.14, 15, 17, free)",
    };
    let kind = match (p.role, lu) {
        (apatch::complex::Role::Edge, _) => "edge tet".to_string(),
        (_, true) => "face tet L-U".to_string(),
        _ => "face tet single".to_string(),
    };
    format!("{kind:15} {t:?}|{off:?} {what}")
}

/// Exploration: which weights miss Theorem 2.1's signs (k = 1, as [`jline_patches`]) on a
/// scene's complex, by tetrahedron kind and domain-point class ([`weight_class`]): weights
/// with a condition, misses, misses on boundary faces of the hull (faces of one patch), misses
/// on crossed boundary faces (holes), and misses in patches crossed twice along a j-line.
#[test]
#[ignore = "exploration: SCENE=path"]
fn sign_miss_classes() {
    use apatch::complex::Role;
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let c = apatch::scene::build_complex(&sc).unwrap();
    let key = |v: [f64; 3]| v.map(f64::to_bits);
    let face_key = |p: &apatch::complex::Patch, opp: usize| {
        let mut f: Vec<[u64; 3]> = (0..4)
            .filter(|&k| k != opp)
            .map(|k| key(p.tet[k]))
            .collect();
        f.sort_unstable();
        [f[0], f[1], f[2]]
    };
    let mut users: std::collections::HashMap<[[u64; 3]; 3], usize> = Default::default();
    for p in &c.patches {
        for opp in 0..4 {
            *users.entry(face_key(p, opp)).or_insert(0) += 1;
        }
    }
    let (crossed, wmax) = crossed_boundary_faces(&c);
    let crossed: std::collections::HashSet<(usize, usize)> = crossed.into_iter().collect();
    // Patches crossed twice along a j-line, each checked alone.
    let mut jmulti = vec![false; c.patches.len()];
    for (k, p) in c.patches.iter().enumerate() {
        let mut one = apatch::complex::PatchComplex::new(&c.scheme);
        one.continuity = c.continuity;
        one.patches = vec![p.clone()];
        jmulti[k] = check(&one, &CheckOptions::default()).sheets.j_multi_lines > 0;
    }
    let mi = apatch::bb::multi_indices(5);
    // [with a condition, missed, missed on a boundary face, on a crossed one, in a j-patch]
    let mut table: std::collections::BTreeMap<String, [usize; 5]> = Default::default();
    for (k, p) in c.patches.iter().enumerate() {
        let edge = p.role == Role::Edge;
        let lu = !edge && users[&face_key(p, 3)] == 2;
        let s = p.weights[apatch::bb::index_of([0, 0, 0, 5])].signum();
        for (i, &l) in mi.iter().enumerate() {
            let level = if edge { l[2] + l[3] } else { l[3] };
            let req = match level {
                0 if lu => 0.0,
                0 => -s,
                1 => 0.0,
                _ => s,
            };
            if req == 0.0 {
                continue;
            }
            let row = table.entry(weight_class(p, lu, l)).or_default();
            row[0] += 1;
            // Zero up to the solves' rounding (as `sign_stats`).
            if req * p.weights[i] >= -1e-12 * wmax {
                continue;
            }
            row[1] += 1;
            let faces: Vec<usize> = (0..4).filter(|&o| l[o] == 0).collect();
            if faces.iter().any(|&o| users[&face_key(p, o)] == 1) {
                row[2] += 1;
            }
            if faces.iter().any(|&o| crossed.contains(&(k, o))) {
                row[3] += 1;
            }
            if jmulti[k] {
                row[4] += 1;
            }
        }
    }
    eprintln!(
        "{}: {} crossed boundary faces, {} j-line patches",
        path.display(),
        crossed.len(),
        jmulti.iter().filter(|&&b| b).count()
    );
    eprintln!("| class | with a sign | missed | on a boundary face | on a crossed face | in a j-line patch |");
    for (k, r) in &table {
        if r[1] > 0 {
            eprintln!(
                "| {k} | {} | {} | {} | {} | {} |",
                r[0], r[1], r[2], r[3], r[4]
            );
        }
    }
}

/// Exploration (issue 8): rank and σ_min/σ_max of the vertex-star systems (appendices D and E)
/// of a scene's hull for each placement of the edge tetrahedra's shared point s.
/// `SCENE=path [EVERY=k] [RULES=mid,lift:0.3,ratio:0.3] cargo test --release --test
/// quintic_models star_conditioning -- --ignored --nocapture`.
#[test]
#[ignore = "exploration: SCENE=path"]
fn star_conditioning() {
    use apatch::hull::simplicial::EdgePoint;
    use apatch::scheme::quintic_c2::{dense, system};
    let path = std::path::PathBuf::from(std::env::var("SCENE").unwrap());
    let sc = apatch::scene::load(&path).unwrap();
    let hull = apatch::scene::inner_hull(&sc).unwrap().unwrap();
    let (hull, _) = apatch::scheme::cubic_c1::sided::complete_lu_pairs(&hull);
    let every: usize = std::env::var("EVERY")
        .ok()
        .and_then(|x| x.parse().ok())
        .unwrap_or(1);
    let rules = std::env::var("RULES").unwrap_or_else(|_| "mid,lift:0.3,lift:-0.3".into());
    for r in rules.split(',') {
        let rule = match r.split_once(':') {
            None => EdgePoint::Midpoint,
            Some(("lift", t)) => EdgePoint::Lift(t.parse().unwrap()),
            Some(("ratio", t)) => EdgePoint::Ratio(t.parse().unwrap()),
            Some(other) => panic!("unknown rule {other:?}"),
        };
        let (tets, _) = system::tetrahedra_with(&hull, rule).unwrap();
        let sys = system::assemble(&tets, hull.points.len() as u32).unwrap();
        let stars = sys.star_systems();
        let mut ratios: Vec<f64> = Vec::new();
        let mut shapes: std::collections::BTreeMap<(usize, usize, usize), usize> =
            Default::default();
        let mut deficient = 0;
        let mut next: Vec<f64> = Vec::new();
        if let Ok(dir) = std::env::var("STAR_DUMP") {
            // One star per shape as JSON for offline analysis.
            let mut seen = std::collections::HashSet::new();
            for st in &stars {
                if seen.insert((st.rows, st.cols)) {
                    let cols: Vec<String> = st
                        .unknowns
                        .iter()
                        .map(|(t, l)| {
                            let tt = &tets[*t as usize];
                            format!(
                                "[{t}, \"{:?}\", \"{:?}\", {:?}, {:?}, {:?}]",
                                tt.role,
                                tt.side,
                                tt.gid,
                                l,
                                tt.pts.map(|p| p.to_array())
                            )
                        })
                        .collect();
                    let js = format!(
                        "{{\"point\": {}, \"rows\": {}, \"cols\": {}, \"matrix\": {:?}, \"unknowns\": [{}]}}",
                        st.point,
                        st.rows,
                        st.cols,
                        st.matrix,
                        cols.join(", ")
                    );
                    let f = format!("{dir}/star_{r}_{}x{}.json", st.rows, st.cols);
                    std::fs::write(f, js).unwrap();
                }
            }
        }
        for st in stars.iter().step_by(every) {
            let s = dense::singular_values(&st.matrix, st.rows, st.cols);
            // Numerical rank: singular values above 1e-10 of the largest (the structural
            // zeros sit at 1e-16 and below, the smallest others at 1e-6 and above).
            let rank = s.iter().filter(|&&x| x > 1e-10 * s[0]).count();
            *shapes
                .entry((st.rows, st.cols, st.rows.min(st.cols) - rank))
                .or_insert(0) += 1;
            let k = st.rows.min(st.cols);
            let ratio = s[k - 1] / s[0];
            if ratio < 1e-12 {
                deficient += 1;
            }
            ratios.push(ratio);
            // Beside the structural null vector of appendix D's chain (docs/quintic.md): the
            // conditioning of the rest.
            next.push(s[rank.max(1) - 1] / s[0]);
        }
        next.sort_unstable_by(f64::total_cmp);
        let qn = |f: f64| next[((next.len() - 1) as f64 * f) as usize];
        println!(
            "{r}: smallest σ/σmax above the rank drop: min {:.2e} 10% {:.2e} median {:.2e} 90% {:.2e}",
            qn(0.0),
            qn(0.1),
            qn(0.5),
            qn(0.9)
        );
        ratios.sort_unstable_by(f64::total_cmp);
        let q = |f: f64| ratios[((ratios.len() - 1) as f64 * f) as usize];
        println!(
            "{r}: {} stars sampled of {}, (rows, cols, rank drop): count {shapes:?}, σmin/σmax < 1e-12: {deficient}; min {:.2e} 10% {:.2e} median {:.2e} 90% {:.2e} max {:.2e}",
            ratios.len(),
            stars.len(),
            q(0.0),
            q(0.1),
            q(0.5),
            q(0.9),
            q(1.0)
        );
    }
}

/// The 64-sided cylinder of `scenes/models/cylinder_rounded.obj` (radius 0.5, height 1, 8 rows
/// of triangle pairs a side, one 64-gon a cap) with exact coordinates.
fn exact_cylinder() -> mesh::Mesh {
    let (n, rows) = (64_u32, 8_u32);
    let mut p = Vec::new();
    for k in 0..=rows {
        for i in 0..n {
            let t = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            let z = -0.5 + f64::from(k) / f64::from(rows);
            p.push(glam::DVec3::new(0.5 * t.cos(), 0.5 * t.sin(), z));
        }
    }
    let mut f: Vec<Vec<u32>> = Vec::new();
    for k in 0..rows {
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            f.push(vec![a, b, b + n]);
            f.push(vec![a, b + n, a + n]);
        }
    }
    f.push((0..n).rev().collect());
    f.push((0..n).map(|i| rows * n + i).collect());
    mesh::Mesh::new(p, f)
}

/// Mean and largest distance from the surface samples of `a` to the nearest of `reference`
/// (a surface's dense samples), over the bounding-box diagonal of the cylinder (√3).
fn sample_gap(a: &apatch::complex::PatchComplex, reference: &[glam::DVec3]) -> (f64, f64) {
    let sa = apatch::check::distance::surface_samples(a, 4);
    let d: Vec<f64> = sa
        .iter()
        .map(|x| {
            reference
                .iter()
                .map(|y| x.distance_squared(*y))
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .collect();
    let diag = 3.0_f64.sqrt();
    (
        d.iter().sum::<f64>() / d.len() as f64 / diag,
        d.iter().fold(0.0_f64, |m, v| m.max(*v)) / diag,
    )
}

/// The rounded cylinder (coordinates to 4 decimals, as fandisk's) with the quintic's defaults
/// crosses its hull at the caps' rims; every star solved with its edge middles and Hessian
/// (`joint_stars`) and Theorem 2.1's signs pinned inside those groups (`signs`) pass
/// `apatch check`, and the surface stays where the exact cylinder's is.
#[test]
fn rounded_cylinder_passes_with_joint_stars_and_pins() {
    let (m, _) = mesh::load(Path::new("scenes/models/cylinder_rounded.obj")).unwrap();
    let hull = default_hull(&m);
    let exact_hull = default_hull(&exact_cylinder());
    let (reference, _) = build_with_stats(&exact_hull, &QuinticOptions::default()).unwrap();
    assert!(check(&reference, &CheckOptions::default()).passed());
    let (torn, _) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    let pinned_options = QuinticOptions {
        joint_stars: true,
        signs: true,
        ..QuinticOptions::default()
    };
    let (pinned, _) = build_with_stats(&hull, &pinned_options).unwrap();
    let r = check(&pinned, &CheckOptions::default());
    assert_c2(&r);
    assert!(r.passed(), "{:?}", r.failures());
    assert!(boundary_faces_crossed(&torn) > 0);
    assert_eq!(boundary_faces_crossed(&pinned), 0);
    // The surfaces measured against the exact cylinder's with the defaults. The joint solve
    // differs from the staged one by itself (on the exact cylinder: mean 1.1e-3, max 3.1e-3 of
    // the diagonal), so the rounded cylinder is held to that and not to zero: rounding by
    // 5e-5 must change the pinned surface by less than half of it again. The torn default
    // lies 5.4e-2 off at its caps' flaps (staged solve with the pins only: 2.5e-2; the sign
    // program's scalloped cones: 5.1e-2).
    let (exact_pinned, _) = build_with_stats(&exact_hull, &pinned_options).unwrap();
    let dense = apatch::check::distance::surface_samples(&reference, 12);
    let own = sample_gap(&exact_pinned, &dense);
    let pinned_gap = sample_gap(&pinned, &dense);
    let torn_gap = sample_gap(&torn, &dense);
    assert!(
        pinned_gap.0 <= 1.5 * own.0 && pinned_gap.1 <= 1.5 * own.1,
        "{pinned_gap:?} {own:?}"
    );
    assert!(
        torn_gap.1 > 5.0 * pinned_gap.1,
        "{torn_gap:?} {pinned_gap:?}"
    );
}

/// The largest principal curvature of F's level set at every vertex of `c` (the largest
/// |eigenvalue| of H restricted to the tangent plane of the complex's normal, over |∇F|), read
/// from the Hessian of every patch with a corner there and the median taken: a signed distance
/// to the surface has the surface's curvature here.
fn tangent_curvatures(c: &apatch::complex::PatchComplex) -> Vec<f64> {
    use glam::DVec3;
    c.vertices
        .iter()
        .zip(&c.normals)
        .map(|(v, n)| {
            let (v, n) = (DVec3::from(*v), DVec3::from(*n).normalize());
            let (t1, t2) = n.any_orthonormal_pair();
            let mut at: Vec<f64> = c
                .patches
                .iter()
                .filter(|p| p.tet.iter().any(|q| DVec3::from(*q) == v))
                .map(|p| {
                    let h = p.hessian(v);
                    let (a, b, d) = (t1.dot(h * t1), t1.dot(h * t2), t2.dot(h * t2));
                    // Eigenvalues of the symmetric 2×2 [[a, b], [b, d]].
                    let (mid, half) = ((a + d) / 2.0, ((a - d) * (a - d) / 4.0 + b * b).sqrt());
                    (mid.abs() + half) / p.gradient(v).length()
                })
                .collect();
            assert!(!at.is_empty(), "no patch at vertex {v}");
            at.sort_by(f64::total_cmp);
            at[at.len() / 2]
        })
        .collect()
}

/// `hessian_cost` prices the relaxed Hessians in the joint stars' solve and their sign pins.
/// The rounded cylinder has radius 0.5, so a signed distance's level set curves by 2 across
/// its sides, and the estimated jets say so. At cost 1 (the default: weight by weight) the
/// joint stars bend the Hessians where their number 2 weights are cheap: the level set curves
/// ~8 at the points (measured 8.0–8.1). At cost 100 the points keep the estimate's curvature
/// and the scene still passes `check`. (Between the points the priced surface's mean
/// curvature varies more, docs/quintic.md session 68: the key moves the curvature, it does
/// not make the surface fairer, and no shipped scene sets it.)
#[test]
fn priced_hessians_keep_the_rounded_cylinders_curvature_at_its_points() {
    let (m, _) = mesh::load(Path::new("scenes/models/cylinder_rounded.obj")).unwrap();
    let hull = default_hull(&m);
    let free = QuinticOptions {
        joint_stars: true,
        signs: true,
        ..QuinticOptions::default()
    };
    let priced = QuinticOptions {
        hessian_cost: 100.0,
        ..free.clone()
    };
    let (bent, _) = build_with_stats(&hull, &free).unwrap();
    let (kept, _) = build_with_stats(&hull, &priced).unwrap();
    let largest = |c: &[f64]| c.iter().fold(0.0_f64, |a, x| a.max(*x));
    let (bent_k, kept_k) = (tangent_curvatures(&bent), tangent_curvatures(&kept));
    // Twice the cylinder's 2 is far beyond any rounding: the free solve's ~8 is a choice.
    assert!(largest(&bent_k) > 4.0, "{bent_k:?}");
    // The estimate's 2 (the normals' angle-weighted average and the rounded points perturb the
    // jets' shape operator by well under 1%), with 5% room for what the pins still move.
    assert!(largest(&kept_k) < 2.1, "{kept_k:?}");
    let r = check(&kept, &CheckOptions::default());
    assert_c2(&r);
    assert!(r.passed(), "{:?}", r.failures());
    let exact_hull = default_hull(&exact_cylinder());
    let (reference, _) = build_with_stats(&exact_hull, &QuinticOptions::default()).unwrap();
    let dense = apatch::check::distance::surface_samples(&reference, 12);
    let (bent_gap, kept_gap) = (sample_gap(&bent, &dense), sample_gap(&kept, &dense));
    // The mean and largest distance from the exact cylinder's staged surface, over the
    // diagonal (measured: mean 5.2e-4 priced, 1.1e-3 free; largest 4.0e-3 and 3.2e-3): the
    // priced surface is nearer on the whole, and its largest gap stays within the 1.5× of the
    // free one that `rounded_cylinder_passes_with_joint_stars_and_pins` allows for rounding.
    assert!(
        kept_gap.0 < bent_gap.0 && kept_gap.1 <= 1.5 * bent_gap.1,
        "{kept_gap:?} {bent_gap:?}"
    );
}

/// The scenes that solve every star with its edge middles and Hessian and pin Theorem 2.1's
/// signs inside those groups (`joint_stars`, `signs`) meet the theorem weight by weight: no
/// weight off the sign its tetrahedron asks (k = 1), so every patch is single-sheeted by the
/// theorem; with the defaults the same hulls leave weights off (the stars' determined
/// weights) and pass only by the check's sampling.
#[test]
fn joint_pinned_scenes_meet_theorem_2_1_weight_by_weight() {
    for name in ["octahedron", "torus_quad", "torus_quad12x8"] {
        let path = format!("scenes/paper1994/{name}_quintic.toml");
        let sc = apatch::scene::load(Path::new(&path)).unwrap();
        let hull = apatch::scene::inner_hull(&sc).unwrap().unwrap();
        let apatch::scene::Model::Mesh { scheme, .. } = &sc.model else {
            panic!("{path}: a mesh scene");
        };
        let o = QuinticOptions::from_toml(scheme, &sc.path).unwrap();
        assert!(o.joint_stars && o.signs, "{path}");
        let (c, stats) = build_with_stats(&hull, &o).unwrap();
        assert_eq!(stats.signs.violated(), 0, "{path}: {:?}", stats.signs);
        let r = check(&c, &CheckOptions::default());
        assert_c2(&r);
        assert!(r.passed(), "{path}: {:?}", r.failures());
        let (_, plain) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
        assert!(plain.signs.violated() > 0, "{path}: {:?}", plain.signs);
    }
}

/// `sign_targets` moves the targets of the weights with one of Theorem 2.1's signs into that
/// sign before each group is solved. On the rounded cylinder's staged solve (no pins) fewer
/// weights end off their signs (the solve's count; measured: 1072 → 976 at 1 median, 704 at
/// 3), the check finds no more holes, and C2 and the interpolation are kept: the targets only
/// choose among the solutions of the same equations.
#[test]
fn sign_targets_leave_fewer_weights_off_their_signs() {
    let (m, _) = mesh::load(Path::new("scenes/models/cylinder_rounded.obj")).unwrap();
    let hull = default_hull(&m);
    let (plain, s0) = build_with_stats(&hull, &QuinticOptions::default()).unwrap();
    let moved = QuinticOptions {
        sign_targets: 1.0,
        ..QuinticOptions::default()
    };
    let (biased, s1) = build_with_stats(&hull, &moved).unwrap();
    assert!(
        s1.signs.violated() < s0.signs.violated(),
        "{} → {}",
        s0.signs.violated(),
        s1.signs.violated()
    );
    // Not more holes either (the check's count, independent of the solve's).
    let r = check(&biased, &CheckOptions::default());
    assert_c2(&r);
    // The check's own interpolation bounds (relative |F| 1e-9, 1e-7 rad).
    assert!(
        r.interpolation.value.worst <= 1e-9 && r.interpolation.normal_angle.worst <= 1e-7,
        "{r}"
    );
    let r0 = check(&plain, &CheckOptions::default());
    assert!(r.holes.crossing <= r0.holes.crossing, "{r} vs {r0}");
    assert_ne!(
        serde_json::to_string(&plain).unwrap(),
        serde_json::to_string(&biased).unwrap()
    );
}

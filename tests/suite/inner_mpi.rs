//! mpi_poly's inner hull (1994, `hull::inner`): nearly flat folds and needle faces.
//!
//! The survey (`cargo test --test suite inner_mpi:: -- --ignored --nocapture`) prints the hull
//! violations of `scenes/paper1994/mpi_poly.toml` by kind and by the input element their
//! triangles were built for, for the raw hull and the hull the cubic scheme fills.

use crate::common;

use apatch::hull::inner::{self, HullViolation, InnerOptions};
use apatch::hull::simplicial::{PointOrigin, SimplicialHull};
use apatch::mesh::{self, NormalMethod};
use glam::DVec3;
use std::collections::BTreeMap;
use std::path::Path;

/// The triangles of T a violation names (its own, and every "triangle N" in its message).
fn named_triangles(v: &HullViolation) -> Vec<u32> {
    let mut out: Vec<u32> = v.triangle.into_iter().collect();
    let words: Vec<&str> = v.message.split_whitespace().collect();
    for w in words.windows(2) {
        if w[0] == "triangle" {
            if let Ok(t) = w[1].trim_end_matches([',', ':', ')']).parse::<u32>() {
                if !out.contains(&t) {
                    out.push(t);
                }
            }
        }
    }
    out
}

/// Prints the violations of `hull` by kind, by element and by the input vertex nearest to the
/// centroid of each named triangle (elements of step (5') cells are edges, so the element
/// tally mixes vertex and edge numbers; the nearest vertex does not).
fn tally(label: &str, hull: &SimplicialHull, input: &[DVec3]) -> usize {
    let v = inner::verify(hull);
    let mut kinds: BTreeMap<String, usize> = BTreeMap::new();
    let mut elements: BTreeMap<u32, usize> = BTreeMap::new();
    let mut near: BTreeMap<usize, usize> = BTreeMap::new();
    for x in &v {
        let mut seen_near = Vec::new();
        for t in named_triangles(x) {
            let c = hull.triangles[t as usize]
                .iter()
                .map(|&i| hull.points[i as usize])
                .sum::<DVec3>()
                / 3.0;
            let k = (0..input.len())
                .min_by(|&a, &b| (input[a] - c).length().total_cmp(&(input[b] - c).length()))
                .unwrap();
            if !seen_near.contains(&k) {
                seen_near.push(k);
                *near.entry(k).or_default() += 1;
            }
        }
        *kinds.entry(format!("{:?}", x.kind)).or_default() += 1;
        let mut seen = Vec::new();
        for t in named_triangles(x) {
            let e = hull.element[t as usize];
            if !seen.contains(&e) {
                seen.push(e);
                *elements.entry(e).or_default() += 1;
            }
        }
    }
    let mut by_count: Vec<(u32, usize)> = elements.into_iter().collect();
    by_count.sort_by_key(|&(e, n)| (std::cmp::Reverse(n), e));
    eprintln!("{label}: {} violations {kinds:?}", v.len());
    eprintln!("  by element: {:?}", &by_count[..by_count.len().min(30)]);
    let mut near: Vec<(usize, usize)> = near.into_iter().collect();
    near.sort_by_key(|&(e, n)| (std::cmp::Reverse(n), e));
    eprintln!(
        "  by nearest input vertex: {:?}",
        &near[..near.len().min(30)]
    );
    if std::env::var("MPI_VERBOSE").is_ok() {
        for x in &v {
            eprintln!("    {:?}: {}", x.kind, x.message);
        }
        for (i, (p, o)) in hull.points.iter().zip(&hull.origins).enumerate() {
            let o = match o {
                PointOrigin::Centroid { face } => format!("centroid of face {face}"),
                PointOrigin::CornerGuard { face } => format!("guard of face {face}"),
                PointOrigin::PseudoCentroid { vertex } => format!("C_0 of vertex {vertex}"),
                PointOrigin::Other => "other".into(),
            };
            eprintln!("    point {i}: {p:.4} n {:.4} {o}", hull.normals[i]);
        }
        for (t, tri) in hull.triangles.iter().enumerate() {
            eprintln!(
                "    triangle {t} {tri:?} element {} apexes {:?}",
                hull.element[t], hull.apexes[t]
            );
        }
    }
    v.len()
}

#[test]
#[ignore = "survey for humans: prints mpi_poly's hull violations by kind and element"]
fn mpi_poly_survey() {
    let path = Path::new("scenes/models/mpi_poly.obj");
    let (m, _) = mesh::load(path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    eprintln!(
        "raw hull: {} points, {} triangles, split {:?}, star {:?}, unseparable {:?}",
        hull.points.len(),
        hull.triangles.len(),
        rep.split_faces,
        rep.star_faces,
        rep.unseparable
    );
    eprintln!("near guards (face, vertex): {:?}", rep.near_guards);
    if std::env::var("MPI_VERBOSE").is_ok() {
        let merged = inner::coplanar::merge_coplanar(&m);
        let net = inner::guardnet::GuardNet::build(
            &merged,
            inner::decompose::convex_pieces(&merged).unwrap(),
        );
        for (i, f) in net.pieces.faces.iter().enumerate() {
            eprintln!(
                "    piece {i} of face {} region {}: {f:?} center {:.4}",
                merged.face_parent[net.pieces.parent[i] as usize],
                net.region[i],
                net.pieces.center[i]
            );
        }
        eprintln!("    nets {:?} fallback {:?}", net.nets, net.fallback);
        for c in &net.cells {
            eprintln!("    cell {:?} guards {:?}", c.v, c.g);
        }
    }
    tally("raw hull", &hull, &m.positions);
    let scene = apatch::scene::load(Path::new("scenes/paper1994/mpi_poly.toml")).unwrap();
    let prepared = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    tally("scheme's hull", &prepared, &m.positions);
}

/// A prism of height `h` over a U (arms `arm` long, 1 wide, gap 1): its caps are no star
/// (the arms hide each other's tips), so they get a corner guard net, and the side faces'
/// single centroids lie h/2 from the caps' edges.
fn u_prism(h: f64, arm: f64) -> apatch::mesh::Mesh {
    let outline = [
        (0.0, 0.0),
        (3.0, 0.0),
        (3.0, arm),
        (2.0, arm),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, arm),
        (0.0, arm),
    ];
    let n = outline.len() as u32;
    let mut p = Vec::new();
    for z in [0.0, h] {
        p.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, z)));
    }
    let mut faces = vec![(0..n).rev().collect::<Vec<u32>>(), (n..2 * n).collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, j + n, i + n]);
    }
    apatch::mesh::Mesh::new(p, faces)
}

/// A tall U prism (20 high over unit edges): its caps get a corner guard net, and the step
/// (5') cells along the caps' edges have a side face's centroid, 10 away, as their single
/// guard. With the cells' apexes lifted by a fifth of that distance (2, over edges 1 long) their
/// tetrahedra overlapped their neighbours' (44 violations); lifted by the local scale
/// (`guardnet::CELL_LIFT_REACH`) the hull is smoothable and T is a sphere.
#[test]
fn tall_u_prism_cells_lift_by_the_local_scale() {
    use apatch::hull::inner::verify::euler_characteristic;
    for arm in [3.0, 5.0] {
        let m = u_prism(20.0, arm);
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
        // Both caps are split for a guard net (the feature under test).
        assert_eq!(rep.split_faces, vec![(0, 3), (1, 3)]);
        let v = inner::verify(&hull);
        assert!(
            v.is_empty(),
            "arm {arm}: {} violations, first {:?}",
            v.len(),
            v.first()
        );
        assert_eq!(euler_characteristic(&hull), Some(2));
    }
}

/// mpi_poly's step (5') cell over edge 19–70 (one triangle: face 0's guards round vertex 19
/// and 70, face 13's centroid) was slid along the edge to bring its edge tetrahedra's midpoint
/// over the net edge, to 0.27 of the edge: behind vertex 19's own step (5) apex at 0.30, so
/// the two tetrahedra overlapped (14 violations). Slid again clear of the corner apexes
/// (`guardnet::SLIDE_GAP`, only where the first slide overlaps), it overlaps nothing.
#[test]
fn mpi_poly_cell_stays_clear_of_its_corner_apexes() {
    let path = Path::new("scenes/models/mpi_poly.obj");
    let (m, _) = mesh::load(path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let hull = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
    let is = |p: u32, f: u32| match hull.origins[p as usize] {
        PointOrigin::Centroid { face } | PointOrigin::CornerGuard { face } => face == f,
        _ => false,
    };
    // The cell: element 19, one point of face 13 and two of face 0 (vertex 19's own fan
    // triangles hold its pseudo-centroid instead).
    let cells: Vec<usize> = (0..hull.triangles.len())
        .filter(|&t| {
            let tri = hull.triangles[t];
            hull.element[t] == 19
                && tri.iter().filter(|&&p| is(p, 13)).count() == 1
                && tri.iter().filter(|&&p| is(p, 0)).count() == 2
        })
        .collect();
    assert_eq!(cells.len(), 1, "{cells:?}");
    let named = format!("triangle {} ", cells[0]);
    let overlaps: Vec<String> = inner::verify(&hull)
        .into_iter()
        .filter(|v| format!("{} ", v.message).contains(&named))
        .map(|v| v.message)
        .collect();
    assert!(overlaps.is_empty(), "{overlaps:#?}");
}

/// Needle face 35's guard net leaves one piece's guard without a corner (the assignment gives
/// each region corner ONE guard); that point, (0, 1.43, 4.01), had no triangle, so no patch
/// interpolated it and `apatch check` failed vertex value 1.9e-3 / normal 0.37 there. Every
/// point of T must be a corner of a triangle of T; the unassigned guard is dropped.
#[test]
fn mpi_poly_every_point_of_t_has_a_triangle() {
    let path = Path::new("scenes/models/mpi_poly.obj");
    let (m, _) = mesh::load(path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let mut used = vec![false; hull.points.len()];
    for t in &hull.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    let orphans: Vec<(usize, DVec3, PointOrigin)> = (0..used.len())
        .filter(|&i| !used[i])
        .map(|i| (i, hull.points[i], hull.origins[i]))
        .collect();
    assert!(
        orphans.is_empty(),
        "points of T without a triangle: {orphans:?}"
    );
    assert_eq!(hull.normals.len(), hull.points.len());
    assert_eq!(hull.origins.len(), hull.points.len());
    // The dropped guard: exactly the one of face 35 (before the fix it was point 50).
    assert_eq!(rep.unused_points, vec![50]);
    // And no point of T lies there any more (0.01: the next points of T are ≥ 0.3 away).
    let target = DVec3::new(0.0, 1.430335, 4.006873);
    assert!(hull.points.iter().all(|p| (*p - target).length() > 0.01));
}

/// Star face 8 of mpi_poly meets face 0 flat to 0.1° along edge 1–74, and face 0's guard
/// changes along that edge (a step (5') cell), while face 8's single kernel guard lies 11.9
/// from corner 74 (edges 1.5 and 15.5). Vertex 74's step (3) triangle [G_1, G_12, G_9] then
/// folded back 150° under the cell across G_1G_12 (normals (−1, 0, 0) and (0.87, 0.29, −0.40))
/// and ~100 raw violations sat round it. With a guard of face 8 of its own near V_74
/// (`hull::inner::nearguard`) no triangle of T at corner 74 folds against a neighbour and the
/// raw hull loses those overlaps.
#[test]
fn mpi_poly_corner_74_gets_its_own_guard_of_face_8() {
    let path = Path::new("scenes/models/mpi_poly.obj");
    let (m, _) = mesh::load(path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    assert_eq!(rep.near_guards, vec![(8, 74)]);
    let v74 = m.positions[74];
    // Face 8's guards: the kernel guard and the new one, in the face's plane.
    let guards: Vec<usize> = (0..hull.points.len())
        .filter(|&i| matches!(hull.origins[i], PointOrigin::CornerGuard { face: 8 }))
        .collect();
    assert_eq!(guards.len(), 2, "{guards:?}");
    let near = *guards
        .iter()
        .min_by(|&&a, &&b| {
            (hull.points[a] - v74)
                .length()
                .total_cmp(&(hull.points[b] - v74).length())
        })
        .unwrap();
    let face8 = &m.faces[8];
    let n8 = apatch::mesh::geometry::area_vector(&m.positions, face8).normalize();
    let mean = face8
        .iter()
        .map(|&v| m.positions[v as usize])
        .sum::<DVec3>()
        / face8.len() as f64;
    // Half the shorter edge (1.5) on the bisector, or less where halved: within 1 of V_74.
    assert!((hull.points[near] - v74).length() < 1.0);
    // In face 8's plane up to rounding of the projection (coordinates ~10).
    assert!(n8.dot(hull.points[near] - mean).abs() < 1e-9);
    // No triangle of corner 74 folds back against a triangle sharing one of its edges (the
    // fold was 150°: cosine −0.87; −0.7 is a fold beyond 134°). T does turn by 122° (cosine
    // −0.53) round face 8's net edge N–G_12 between the cells over edges 1–74 and 74–77: face
    // 8 collapses onto its guard net, and T wraps round it from face 0's side to face 7's.
    let normal = |t: usize| {
        let [a, b, c] = hull.triangles[t].map(|i| hull.points[i as usize]);
        (b - a).cross(c - a).normalize()
    };
    let at74: Vec<usize> = (0..hull.triangles.len())
        .filter(|&t| hull.element[t] == 74)
        .collect();
    assert!(!at74.is_empty());
    for &t in &at74 {
        for s in 0..hull.triangles.len() {
            let shared = hull.triangles[t]
                .iter()
                .filter(|p| hull.triangles[s].contains(p))
                .count();
            if s != t && shared == 2 {
                let c = normal(t).dot(normal(s));
                assert!(c > -0.7, "triangles {t} and {s} fold: cosine {c}");
            }
        }
    }
    // The raw hull: 331 violations before, 295 with the guard, 282 with `clearance`'s nudge,
    // 211 since `clearance` lifts by the shortest move (the step (5') cell over edge 73–83
    // rose 4.5 along its normal; the rest are the needles', bucket (b)); at most 10 name a
    // triangle of corner 74 (44 before). Since session 25 the raw hull has 300: zero-convex
    // edges between two corner guards ask their triangles for both sides too
    // (`sides::join_across_zero_edges`), and the apexes rebuilt over their bases overlap
    // until the apex search (which the scene sets) moves them; the scene's hull below has 2.
    // Since session 26 those edges are joined only with the apex search (the nut quintic's
    // holes), so this raw hull has 223. The bounds leave the counts no room to grow back.
    let v = inner::verify(&hull);
    assert!(v.len() <= 223, "{} violations", v.len());
    let named74 = v
        .iter()
        .filter(|x| {
            named_triangles(x)
                .iter()
                .any(|t| at74.contains(&(*t as usize)))
        })
        .count();
    assert!(named74 <= 10, "{named74} violations at corner 74");
    // The hull the cubic scheme fills: it moved apexes that lay a hair (the faces' 8e-5
    // non-planarity) beyond a far guard's tangent plane by 0.02 × their distance, and the moved
    // tetrahedra overlapped (408 violations before, 396 with the guard); nudged over the planes
    // in the hull (`clearance`), the scheme moves only those whose nudge would flatten an edge
    // tetrahedron (`clearance::keeps_edge_tets`: needle face 44's edge (66, 60)), which adds
    // 8 violations (211 raw, 219 after the scheme's moves) but no degenerate tetrahedron; the
    // bound is the count's (2 since session 25's apex search: ridge and midpoint planes,
    // missed tangent planes; 219 before, 288 before the shortest lift, 396 before the nudges).
    let scene = apatch::scene::load(Path::new("scenes/paper1994/mpi_poly.toml")).unwrap();
    let prepared = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    // Since session 26 the scene cleans the model (`model.clean`) and gives every polygon a
    // guard net (`all_flat_nets`): its hull verifies.
    let w = inner::verify(&prepared);
    assert!(w.is_empty(), "{} violations: {:?}", w.len(), w.first());
    assert!(
        w.iter().all(|x| x.kind != inner::ViolationKind::Degenerate),
        "{:?}",
        w.iter()
            .find(|x| x.kind == inner::ViolationKind::Degenerate)
    );
}

/// The cubic scene (cleaned, guard nets everywhere) checked as `apatch check` does: no
/// boundary face crossed. Its last 4 holes were the faces of an edge tetrahedron beside a
/// two-triangle step (5') cell over a concave edge, whose apex (the midpoint of a trihedral
/// corner's apex at V and the edge's midpoint) lay on the edge itself, in both tangent planes;
/// the cells over concave edges now take their apexes into the polyhedron
/// (`guardnet::cell_lift`).
#[test]
fn mpi_poly_scene_has_no_holes() {
    let scene = apatch::scene::load(Path::new("scenes/paper1994/mpi_poly.toml")).unwrap();
    let built = apatch::scene::build_scene(&scene).unwrap();
    let report = apatch::check::check(&built.complex, &apatch::check::CheckOptions::default());
    assert_eq!(report.holes.crossing, 0, "{:?}", report.holes);
    // And single sheeted along every j-line: its last one crossed twice at corner 71, an L-U
    // pair's outer apex on all three tangent planes over a base with a concave edge, now
    // moved off the planes (`cubic_c1::tangent`). So the scene passes `check`.
    assert_eq!(report.sheets.j_multi_lines, 0, "{:?}", report.sheets);
    assert!(report.passed(), "{:?}", report.failures());
    assert!(inner::verify(built.hull.as_ref().unwrap()).is_empty());
}

/// The quintic scene is C2 on the cubic's cleaned model and valid hull: its singular
/// stars are relaxed (`consistent_stars = false`). With `consistent_stars = true` (session 26)
/// the stars' consistency conditions over-determine the flat nets' edge-middle groups (9051
/// and 20247 equations of full row rank, residual 37 of 33), the staged solve fails and the
/// whole-model solve misses C2 (gradient jump 3.6e-9, Hessian 1.5e-6), so this fails.
///
/// The scene places s where C1/C2 extrapolate least (`balance_edges`) and projects the weights
/// towards Theorem 2.1's signs (`sign_rounds`). Here with 60 rounds instead of the scene's 300
/// (the same effect, a third of the time): the projection must keep C2 and the jets (vertex
/// values and normals), leave fewer weights off their signs, and leave fewer holes and
/// j-sheets than the same scene without it (session 30: 487 + 177 without, 114 + 23 with 60
/// rounds, 98 + 9 with 300; the scene stayed pending for those). Since session 32 the scene
/// also moves apexes off the flat faces' tangent planes (`tangent_clearance`, 98 + 9 → 49 + 7
/// with 300 rounds), and the apex search after those moves must leave the hull valid.
#[test]
fn mpi_poly_quintic_scene_is_c2() {
    let path = Path::new("scenes/paper1994/mpi_poly_quintic.toml");
    let mut scene = apatch::scene::load(path).unwrap();
    // The projection rounds, not the scene's linear program.
    common::set_scheme(&mut scene, "sign_program", false);
    common::set_scheme(&mut scene, "sign_rounds", 60);
    let built = apatch::scene::build_scene(&scene).unwrap();
    let report = apatch::check::check(&built.complex, &apatch::check::CheckOptions::default());
    let failures = report.failures();
    // The check's own tolerances (gradient 1e-9, Hessian 1e-7 relative: issue 8's bounds).
    for continuity in ["value jump", "gradient jump", "hessian jump"] {
        assert!(
            !failures.contains(&continuity),
            "{continuity}: {failures:?}"
        );
    }
    assert!(!failures.contains(&"vertex value"), "{failures:?}");
    assert!(!failures.contains(&"vertex normal"), "{failures:?}");
    assert!(inner::verify(built.hull.as_ref().unwrap()).is_empty());
    let p = &built.solve.as_ref().unwrap().sign_projection;
    assert!(p.kept && p.off_after < p.off_before, "{p:?}");
    assert!(built.solve.as_ref().unwrap().tangent_moved > 0);
    common::set_scheme(&mut scene, "sign_rounds", 0);
    let plain = apatch::scene::build_scene(&scene).unwrap();
    let before = apatch::check::check(&plain.complex, &apatch::check::CheckOptions::default());
    let defects = |r: &apatch::check::CheckReport| r.holes.crossing + r.sheets.j_multi_patches;
    assert!(
        defects(&report) < defects(&before),
        "holes and j-sheets {} with the projection, {} without",
        defects(&report),
        defects(&before)
    );
}

/// Balancing s on the apexes' lines (`balance_edges`) on the quintic scene's hull, whose T has
/// needle triangles in its flat nets (C1 extrapolation from a face into an edge tetrahedron up
/// to 64 at the midpoint, 16 balanced: `cargo test --release --test suite quintic_c2::needle_survey
/// -- --ignored --nocapture`): the largest weight falls at least fourfold (session 30: 3.4e3
/// at the midpoints, 5.0e2 balanced) and C2 holds.
#[test]
fn mpi_poly_quintic_balanced_edges_shrink_the_weights() {
    let path = Path::new("scenes/paper1994/mpi_poly_quintic.toml");
    let mut scene = apatch::scene::load(path).unwrap();
    // The projection rounds, not the scene's linear program.
    common::set_scheme(&mut scene, "sign_program", false);
    // The session-30 polyhedron, whose face 8 has the 0.9° needles: the nearly coplanar faces
    // kept apart (`model.clean_coplanar`, session 32, merges face 8 into its plane's other
    // pieces; the largest weights there are 1.1e3 at the midpoints and 3.0e2 balanced).
    if let apatch::scene::Model::Mesh { clean: Some(c), .. } = &mut scene.model {
        c.coplanar_angle = 0.0;
    }
    let largest = |c: &apatch::complex::PatchComplex| {
        c.patches
            .iter()
            .flat_map(|p| p.weights.iter())
            .fold(0.0_f64, |m, w| m.max(w.abs()))
    };
    let mut build = |balance: bool| {
        common::set_scheme(&mut scene, "sign_rounds", 0);
        common::set_scheme(&mut scene, "balance_edges", balance);
        apatch::scene::build_scene(&scene).unwrap().complex
    };
    let (mid, balanced) = (build(false), build(true));
    let (a, b) = (largest(&mid), largest(&balanced));
    assert!(
        b < 0.25 * a,
        "largest weight {b} balanced, {a} at the midpoints"
    );
    let report = apatch::check::check(&balanced, &apatch::check::CheckOptions::default());
    let failures = report.failures();
    for continuity in ["value jump", "gradient jump", "hessian jump"] {
        assert!(
            !failures.contains(&continuity),
            "{continuity}: {failures:?}"
        );
    }
}

/// `model.clean` on mpi_poly (the quintic scene's tolerance, 1e-3 of the diagonal) leaves a
/// closed polyhedron with planar faces and no needle: checked on the result directly, not on
/// the clean's own report.
#[test]
fn mpi_poly_cleaned_has_no_needles_and_planar_faces() {
    let path = Path::new("scenes/models/mpi_poly.obj");
    let (raw, _) = apatch::mesh::load(path).unwrap();
    let (m, report, changes) = apatch::scene::polyhedron_1994(
        path,
        Some(apatch::mesh::CleanOptions {
            relative: 1e-3,
            coplanar_angle: 0.0,
        }),
    )
    .unwrap();
    let changes = changes.unwrap();
    inner::closed::require_closed(&m, &report).unwrap();
    // Narrowest face: the least distance of a corner to an edge of its face not at it.
    let narrowest = |m: &apatch::mesh::Mesh| {
        let mut least = f64::INFINITY;
        for f in &m.faces {
            let n = f.len();
            let p = |k: usize| m.positions[f[k % n] as usize];
            for k in 0..n {
                for e in 0..n {
                    if e == k || (e + 1) % n == k {
                        continue;
                    }
                    let (a, b) = (p(e), p(e + 1));
                    let t = ((p(k) - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    least = least.min((a + t * (b - a)).distance(p(k)));
                }
            }
        }
        least
    };
    // The file's needles are 0.002 wide; the cleaned faces' narrowest is 0.3 (measured: 0.33).
    assert!(narrowest(&raw) < 0.005, "{}", narrowest(&raw));
    assert!(narrowest(&m) > 0.3, "{}", narrowest(&m));
    // Planar: every corner within 1e-9 of the plane through three of its face's corners (the
    // hull's coplanarity tests work at 1e-9 of the model; the clean aims at 1e-13 of the
    // diagonal, reached to ~1e-10 here, and this three-point fit rounds on its own).
    for f in &m.faces {
        let p = |k: usize| m.positions[f[k] as usize];
        let (a, b, c) = (p(0), p(1), p(2));
        let n = (b - a).cross(c - a).normalize();
        for &v in f {
            let d = (m.positions[v as usize] - a).dot(n).abs();
            assert!(d < 1e-8, "face {f:?}: corner {v} {d:e} off");
        }
    }
    // Every cleaned vertex lies within the weld distance (1e-3 × the diagonal 34.77) of a
    // vertex of the file.
    for q in &m.positions {
        let d = raw
            .positions
            .iter()
            .map(|p| p.distance(*q))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 0.035, "{q}: {d}");
    }
    assert!(
        changes.merged_faces >= 2 && changes.welded == 13,
        "{changes:?}"
    );
}

/// The near guards fire only at mpi_poly's corner 74: no model of `scenes/paper1994` (their
/// hulls are unchanged) gets one.
#[test]
fn near_guards_leave_the_passing_models_alone() {
    for model in [
        "letter_P_poly",
        "hallway_corner",
        "star_prism",
        "l_prism",
        "corner_poly",
        "cube_poly",
        "double_torus_poly",
        "torus_quad",
        "nut_pyvista",
    ] {
        let path = format!("scenes/models/{model}.obj");
        let (m, _) = mesh::load(Path::new(&path)).unwrap();
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let (_, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
        assert!(rep.near_guards.is_empty(), "{model}: {:?}", rep.near_guards);
    }
}

/// `tangent_clearance` on the quintic scene (`sign_rounds = 60` as above): apexes that lie on a
/// tangent plane of their triangle's points (Algorithm 1 puts them on the polyhedron's edges,
/// so on flat faces' planes) are moved to the slope 0.02, the apex search clears the overlaps
/// that makes (14 on mpi_poly), C2 holds, and fewer boundary faces are crossed than with the
/// clearance off (session 32, 300 rounds: 98 → 49 holes, 9 → 7 j-sheets). Heavy (two builds
/// and checks, ~1 min in release): `cargo test --release --test suite inner_mpi:: -- --ignored`.
#[test]
#[ignore = "heavy: two mpi_poly quintic builds"]
fn mpi_poly_quintic_tangent_clearance_halves_the_holes() {
    let path = Path::new("scenes/paper1994/mpi_poly_quintic.toml");
    let mut scene = apatch::scene::load(path).unwrap();
    // The projection rounds, not the scene's linear program.
    common::set_scheme(&mut scene, "sign_program", false);
    common::set_scheme(&mut scene, "sign_rounds", 60);
    let cleared = apatch::scene::build_scene(&scene).unwrap();
    let with = apatch::check::check(&cleared.complex, &apatch::check::CheckOptions::default());
    assert!(inner::verify(cleared.hull.as_ref().unwrap()).is_empty());
    for continuity in ["value jump", "gradient jump", "hessian jump"] {
        assert!(!with.failures().contains(&continuity), "{continuity}");
    }
    common::set_scheme(&mut scene, "tangent_clearance", 0.0);
    let plain = apatch::scene::build_scene(&scene).unwrap();
    let without = apatch::check::check(&plain.complex, &apatch::check::CheckOptions::default());
    assert!(
        with.holes.crossing < without.holes.crossing,
        "holes {} with the clearance, {} without",
        with.holes.crossing,
        without.holes.crossing
    );
}

/// The scene built as it is (its sign program on), the program's report asserted
/// used and kept, with fewer than a quarter of the solve's misses left; and its check.
fn scene_with_sign_program() -> (apatch::scene::BuiltScene, apatch::check::CheckReport) {
    let path = Path::new("scenes/paper1994/mpi_poly_quintic.toml");
    let scene = apatch::scene::load(path).unwrap();
    let built = apatch::scene::build_scene(&scene).unwrap();
    let p = &built.solve.as_ref().unwrap().sign_projection;
    assert!(p.program && p.kept, "{p:?}");
    assert!(4 * p.off_after < p.off_before, "{p:?}");
    let report = apatch::check::check(&built.complex, &apatch::check::CheckOptions::default());
    (built, report)
}

/// The scene as it is in the default build, where the sign program is solved by the pure-Rust
/// interior point method and then again with reweighted costs (sessions 34–35; `cargo test
/// --release --test suite inner_mpi::interior -- --ignored`, about 10 CPU-min): `apatch check` passes
/// as a whole (C1/C2 and the jets to issue 8's bounds, no hole, no j-sheet, one sheet per
/// patch) and the hull verifies. One solve without the reweighting left 3 holes and 1 j-sheet
/// (session 34: the interior solution is the optimal face's centre, misses spread over many
/// conditions; HiGHS's vertex has none). Also held by `scenes_all`'s heavy test; this one
/// asserts the program's report too.
#[cfg(not(feature = "highs"))]
#[test]
#[ignore = "slow (~10 CPU-min): the interior point method on mpi_poly's quintic"]
fn mpi_poly_quintic_interior_point_sign_program() {
    // Fewer than a quarter of the solve's misses left (measured: 590 of 3619).
    let (built, report) = scene_with_sign_program();
    // Every check at its own tolerance (gradient 1e-9, Hessian 1e-7 relative: issue 8's
    // bounds; holes, sheets and j-sheets none).
    assert!(report.failures().is_empty(), "{:?}", report.failures());
    assert_eq!(report.holes.crossing, 0, "{:?}", report.holes);
    assert_eq!(report.sheets.j_multi_patches, 0, "{:?}", report.sheets);
    assert!(inner::verify(built.hull.as_ref().unwrap()).is_empty());
}

/// The scene as it is, with the sign program (`sign_program`, sessions 33–34; only
/// with the cargo feature `highs`: `cargo test --release --features highs --test suite inner_mpi::
/// sign_program`, about 70 s): the linear program leaves far fewer weights off their signs
/// than the solve (3619 → 750, misses on the hull's boundary faces costing
/// `project::BOUNDARY_COST`), and `apatch check` passes as a whole: C1/C2 and the jets to
/// issue 8's bounds, no hole (1000 projection rounds left 24; the program with equal costs 1),
/// no j-sheet (7), one sheet per patch; and the hull verifies.
#[cfg(feature = "highs")]
#[test]
fn mpi_poly_quintic_sign_program_passes_the_check() {
    // Fewer than a quarter of the solve's misses left (measured: 750 of 3619).
    let (built, report) = scene_with_sign_program();
    // Every check at its own tolerance (gradient 1e-9, Hessian 1e-7 relative: issue 8's
    // bounds; holes, sheets and j-sheets none).
    assert!(report.failures().is_empty(), "{:?}", report.failures());
    assert_eq!(report.holes.crossing, 0, "{:?}", report.holes);
    assert_eq!(report.sheets.j_multi_patches, 0, "{:?}", report.sheets);
    assert!(inner::verify(built.hull.as_ref().unwrap()).is_empty());
}

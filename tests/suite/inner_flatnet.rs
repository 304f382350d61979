//! Zero-coplanar corner guard nets on large flat regions (Appendix B, Algorithm 3).

use apatch::hull::inner::{self, coplanar, decompose, guardnet::GuardNet, InnerOptions};
use apatch::mesh::{self, convexity::polygon_is_convex, geometry::area_vector, NormalMethod};
use std::path::Path;

use apatch::check::{check, CheckOptions};
use apatch::fixtures;
use apatch::hull::inner::flatnet;
use apatch::mesh::Mesh;
use apatch::scheme::cubic_c1::{self, CubicOptions};
use glam::DVec3;

/// fandisk (validated) with its angle-weighted vertex normals, as its scene loads it.
fn fandisk() -> (Mesh, Vec<DVec3>) {
    let (m, report) = mesh::load(Path::new("scenes/models/fandisk.obj")).unwrap();
    report.require(true).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    (m, normals)
}

/// A prism (height 1) over the outline `outline` (counter-clockwise seen from +z): caps
/// triangulated (ear clipping: coplanar input triangles, as fandisk's flat regions) and one
/// quadrilateral per outline edge.
fn prism(outline: &[(f64, f64)]) -> Mesh {
    let n = outline.len() as u32;
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        p.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, z)));
    }
    let mut faces = Vec::new();
    let mut scratch = Vec::new();
    for cap in [(0..n).rev().collect::<Vec<u32>>(), (n..2 * n).collect()] {
        mesh::ear_clip(&p, &cap, &mut scratch, &mut faces);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, j + n, i + n]);
    }
    Mesh::new(p, faces)
}

/// A quarter annulus (radii 2 and 10, 24 and 4 segments) with straight ends: a large flat
/// non-convex cap whose corners on the outer arc have edges 0.65 long, far (more than
/// `GUARD_REACH` = 5 of their edges) from the cap's points of T without flat nets.
fn quarter_annulus() -> Vec<(f64, f64)> {
    let q = std::f64::consts::FRAC_PI_2;
    let mut out: Vec<(f64, f64)> = (0..=24)
        .map(|i| {
            let a = q * f64::from(i) / 24.0;
            (10.0 * a.cos(), 10.0 * a.sin())
        })
        .collect();
    out.extend((0..=4).rev().map(|i| {
        let a = q * f64::from(i) / 4.0;
        (2.0 * a.cos(), 2.0 * a.sin())
    }));
    out
}

/// Builds the hull of `m`, checks the flat nets formed on both caps, that the hull verifies
/// and closes with genus 0, that every triangle of T outside the zero coplanar groups is
/// short, and that the cubic surface on it is C1 (`check`'s jumps). Returns the hull's
/// triangle count.
fn flat_caps_pass(m: &Mesh) -> usize {
    let normals = mesh::vertex_normals(m, NormalMethod::Angle).unwrap();
    let (hull, rep) = inner::build_with_report(m, &normals, &InnerOptions::default()).unwrap();
    assert_eq!(rep.flat_nets, 2, "both caps get a zero coplanar group");
    let v = inner::verify(&hull);
    assert!(
        v.is_empty(),
        "{} violations: {:?}",
        v.len(),
        &v[..v.len().min(4)]
    );
    assert_eq!(inner::verify::euler_characteristic(&hull), Some(2));
    // Triangles of T off the caps' planes (corners, cells) reach no farther than 1.5 × the
    // longest edge of the prism (outline or vertical edge, from the wall quadrilaterals) at
    // their corner (`element`): the guards sit near their corners. (With one point of T per
    // cap, the arc corners' triangles reached 6–10 across edges of 1.)
    let mut reach = vec![0.0f64; m.positions.len()];
    for f in m.faces.iter().filter(|f| f.len() == 4) {
        for k in 0..4 {
            let (a, b) = (f[k] as usize, f[(k + 1) % 4] as usize);
            let l = (m.positions[a] - m.positions[b]).length();
            reach[a] = reach[a].max(l);
            reach[b] = reach[b].max(l);
        }
    }
    for (t, tri) in hull.triangles.iter().enumerate() {
        let p = tri.map(|i| hull.points[i as usize]);
        let flat = p.iter().all(|q| q.z == 0.0) || p.iter().all(|q| q.z == 1.0);
        if flat {
            continue;
        }
        let len = (p[1] - p[0])
            .length()
            .max((p[2] - p[1]).length())
            .max((p[0] - p[2]).length());
        let e = reach[hull.element[t] as usize];
        // 1.5: a corner's triangle joins points of T at most about one edge from the corner
        // (guards a quarter edge inside the cap, wall centroids half an edge away).
        assert!(len <= 1.5 * e, "triangle {t}: {len} > 1.5 × {e}");
    }
    let prepared = cubic_c1::prepare_hull(&hull, &CubicOptions::default());
    let v = inner::verify(&prepared.hull);
    assert!(v.is_empty(), "prepared: {:?}", &v[..v.len().min(4)]);
    let complex = cubic_c1::build(&prepared.hull, &CubicOptions::default()).unwrap();
    let r = check(&complex, &CheckOptions::default());
    // C1 across every shared face, values and normals interpolated, within check's own
    // tolerances (the flat-edge equations of the zero coplanar groups are consistent: all
    // their number 2 weights are 0).
    for (what, m, tol) in [
        ("value jump", &r.value_jump, r.options.value_tolerance),
        ("gradient jump", &r.gradient_jump, r.options.jump_tolerance),
    ] {
        assert!(m.worst <= tol, "{what} {} > {tol}: {:?}", m.worst, m.at);
    }
    assert_eq!(r.faces.overshared, 0);
    // Known: `check` still finds the surface crossing boundary faces of edge tetrahedra at
    // the four corners where the long end walls meet the arcs and next to the zero coplanar
    // groups' edges (holes, see scenes/pending/paper1994/README.md); not asserted here.
    hull.triangles.len()
}

/// The quarter annulus prism: its caps' far corners get their own guards and the caps' interior
/// a zero coplanar group; the hull verifies and the cubic surface is C1 (`check`).
#[test]
fn quarter_annulus_caps_get_zero_coplanar_groups() {
    let m = prism(&quarter_annulus());
    flat_caps_pass(&m);
    // Every guard lies within a quarter of its corner's shorter edge (the corner guard circle).
    let (merged, counts) = coplanar::merge_coplanar_counted(&m);
    let mut net = GuardNet::build(&merged, decompose::convex_pieces(&merged).unwrap());
    let flat = flatnet::spread_guards(&mut net, &merged, &counts);
    assert_eq!(flat.groups.len(), 2);
    for g in &flat.groups {
        let k = g.corners.len();
        for (i, (&v, &q)) in g.corners.iter().zip(&g.guards).enumerate() {
            let p = |j: usize| merged.positions[g.corners[j % k] as usize];
            let e = (p(i + 1) - p(i))
                .length()
                .min((p(i + k - 1) - p(i)).length());
            let d = (net.pieces.center[q as usize] - merged.positions[v as usize]).length();
            // Rounding of the projection onto the plane only.
            assert!(
                d <= flatnet::GUARD_RADIUS * e * (1.0 + 1e-9),
                "corner {v}: {d} vs {e}"
            );
        }
        assert_eq!(g.triangles.len(), k - 2);
    }
}

/// fandisk's six large merged flat regions (27–112 corners) get zero coplanar groups, and so do
/// small merged strips whose one point of T folded a corner's fan (`FOLD_GAP`) or whose
/// diagonals across a nearly flat edge miss it (`flatnet::diagonal_misses`); the hull's
/// violations drop to about 1.5 % of what one far point of T per region gave. The regions
/// whose triangles of T still overlap then get flat nets one at a time while that lowers the
/// violations (`hull::inner::overlapnet`): the two 9-corner strips along the 90° edges (input
/// faces 8463, 10573) and the two regions of input faces 3075, 3079.
#[test]
fn fandisk_flat_regions_get_zero_coplanar_groups() {
    let (m, normals) = fandisk();
    let options = InnerOptions::default();
    let (hull, rep) = inner::build_with_report(&m, &normals, &options).unwrap();
    assert_eq!(rep.flat_nets, 16);
    assert_eq!(rep.overlap_nets, vec![3075, 3079, 8463, 10573]);
    assert_eq!(inner::verify::euler_characteristic(&hull), Some(2));
    let v = inner::verify(&hull);
    // Measured 181 (242 before `overlapnet`, 419 before the strip guards' reach across the
    // strip and the diagonal test, 763 before the fold test, 17294 on the raw hull before
    // `flatnet`); the bound leaves room for other changes to the hull, far below what long
    // triangles over the flat regions gave.
    assert!(v.len() < 500, "{} violations", v.len());
    // The forced nets are kept only where they lower the count: below the hull without them.
    let none = std::collections::BTreeSet::new();
    let (base, base_rep) = inner::build_forced(&m, &normals, &options, &none).unwrap();
    assert_eq!(base_rep.flat_nets, 12);
    let before = inner::verify(&base).len();
    assert!(v.len() < before, "{} violations, {before} without", v.len());
}

/// fandisk's hull verifies with the apex search (`apex_search = true` in its scene,
/// `hull::inner::reapex`): the hull the cubic patches fill (`scene::inner_hull`: the inner
/// build, the cubic's apex changes, the search again) has no violation of Definition 3.6 or
/// Lemmas 4.1-4.3 and no unsigned edge tetrahedron, where the same scene without the key has
/// 181 violations (measured; the premise is only that it has some).
#[test]
fn fandisk_hull_verifies_after_the_apex_search() {
    let path = Path::new("scenes/paper1994/fandisk.toml");
    let scene = apatch::scene::load(path).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let v = inner::verify(&hull);
    assert!(
        v.is_empty(),
        "{} violations, first {:?}",
        v.len(),
        v.first()
    );
    // Every edge tetrahedron's shared point s (the midpoint of the two apexes) lies on its own
    // apex's side of its triangle, recounted from the coordinates (measured: 185 edge
    // tetrahedra did not before the search; the edges of all 46 holes had one).
    let edges = hull.edges().unwrap();
    let mut unsigned = 0;
    for e in edges.iter().filter(|e| e.faces[1] != u32::MAX) {
        for side in 0..2 {
            let [Some(q0), Some(q1)] = e.faces.map(|f| hull.apexes[f as usize][side]) else {
                continue;
            };
            let s = 0.5 * (q0 + q1);
            for (f, q) in [(e.faces[0], q0), (e.faces[1], q1)] {
                let p = hull.triangles[f as usize].map(|i| hull.points[i as usize]);
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                if n.dot(s - p[0]) * n.dot(q - p[0]) <= 0.0 {
                    unsigned += 1;
                }
            }
        }
    }
    assert_eq!(unsigned, 0);
    let mut off = scene.clone();
    let apatch::scene::Model::Mesh { scheme, .. } = &mut off.model else {
        panic!("fandisk's scene is a mesh scene");
    };
    assert_eq!(
        scheme.remove("apex_search"),
        Some(toml::Value::Boolean(true))
    );
    let plain = apatch::scene::inner_hull(&off).unwrap().unwrap();
    assert!(
        !inner::verify(&plain).is_empty(),
        "premise: the search has work"
    );
}

/// fandisk's strip 1313 (input face 1376: 10 corners along a 3° fold, six straight; its guards
/// met across the strip before) and its non-convex neighbour 445 (input face 456: straight
/// corners 468, 391, 321 on the fold, one kernel guard at the far end, so the diagonals from it
/// to the faces across the fold pass beside their edges) get zero coplanar groups.
#[test]
fn fandisk_strips_along_the_fold_get_zero_coplanar_groups() {
    let (m, normals) = fandisk();
    let (merged, counts) = coplanar::merge_coplanar_counted(&m);
    let mut net = GuardNet::build(&merged, decompose::convex_pieces(&merged).unwrap());
    let flat = flatnet::spread_guards_folded(&mut net, &merged, &counts, Some(&normals));
    let input: Vec<u32> = flat
        .groups
        .iter()
        .map(|g| merged.face_parent[g.face as usize])
        .collect();
    for rep in [1376, 456] {
        assert!(
            input.contains(&rep),
            "input face {rep}: groups of {input:?}"
        );
    }
    // One guard per corner, each a quarter of the corner's reach or less from it (the strip is
    // 0.019 wide: every guard stays within 0.01 of its corner).
    for g in flat.groups.iter().filter(|g| g.face == 1313) {
        for (&v, &q) in g.corners.iter().zip(&g.guards) {
            let d = (net.pieces.center[q as usize] - merged.positions[v as usize]).length();
            assert!(d < 0.01, "corner {v}: guard {d} away");
        }
    }
}

#[test]
#[ignore = "exploration for humans: fandisk's flat regions and violations"]
fn explore_fandisk() {
    let (m, normals) = fandisk();
    let merged = coplanar::merge_coplanar(&m);
    eprintln!(
        "input {} faces, merged {}",
        m.faces.len(),
        merged.faces.len()
    );
    let mut big: Vec<(usize, usize, bool, bool)> = Vec::new();
    for (f, face) in merged.faces.iter().enumerate() {
        if face.len() > 4 {
            let n = area_vector(&merged.positions, face).normalize();
            let convex = polygon_is_convex(&merged.positions, face);
            let star = decompose::kernel_guard(&merged.positions, face, n).is_some();
            big.push((f, face.len(), convex, star));
        }
    }
    for b in &big {
        eprintln!(
            "merged face {} corners {} convex {} star {}",
            b.0, b.1, b.2, b.3
        );
    }
    let pieces = decompose::convex_pieces(&merged).unwrap();
    eprintln!(
        "split {:?}\nstar {:?}\nfar_star {:?}",
        pieces.split,
        pieces.star.iter().map(|x| x.0).collect::<Vec<_>>(),
        pieces.far_star.iter().map(|x| x.0).collect::<Vec<_>>()
    );
    let net = GuardNet::build(&merged, pieces);
    eprintln!("nets {:?} fallback {:?}", net.nets, net.fallback);
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    eprintln!("flat nets {}", rep.flat_nets);
    // Merged polygon size per representative input face.
    let mut size = std::collections::HashMap::new();
    for (f, face) in merged.faces.iter().enumerate() {
        size.insert(merged.face_parent[f], face.len());
    }
    let v = inner::verify(&hull);
    let mut kinds = std::collections::BTreeMap::new();
    for x in &v {
        *kinds.entry(format!("{:?}", x.kind)).or_insert(0) += 1;
    }
    eprintln!("{} violations {kinds:?}", v.len());
    use apatch::hull::simplicial::PointOrigin;
    let class = |t: usize| -> String {
        let tri = hull.triangles[t];
        let mut big = None;
        let mut guards = 0;
        let mut pc = 0;
        for &p in &tri {
            match hull.origins[p as usize] {
                PointOrigin::CornerGuard { face } | PointOrigin::Centroid { face } => {
                    let s = size.get(&face).copied().unwrap_or(3);
                    if s >= 5 {
                        big = Some(big.map_or(face, |b: u32| b.min(face)));
                    }
                    if matches!(hull.origins[p as usize], PointOrigin::CornerGuard { .. }) {
                        guards += 1;
                    }
                }
                PointOrigin::PseudoCentroid { .. } => pc += 1,
                PointOrigin::Other => {}
            }
        }
        match big {
            Some(f) => format!("big{}:g{guards}p{pc}", size[&f]),
            None => format!("small:g{guards}p{pc}"),
        }
    };
    let mut per = std::collections::BTreeMap::new();
    let mut per_tri = std::collections::HashMap::new();
    for x in &v {
        let ts = triangles_named(x);
        for t in ts {
            *per.entry(class(t)).or_insert(0) += 1;
            *per_tri.entry(t).or_insert(0) += 1;
        }
    }
    eprintln!("references by triangle class: {per:?}");
    let mut worst: Vec<_> = per_tri.into_iter().collect();
    worst.sort_by_key(|x| (std::cmp::Reverse(x.1), x.0));
    for &(t, n) in worst.iter().take(12) {
        let tri = hull.triangles[t];
        let pts = tri.map(|i| hull.points[i as usize]);
        let len = (pts[1] - pts[0])
            .length()
            .max((pts[2] - pts[1]).length())
            .max((pts[0] - pts[2]).length());
        eprintln!(
            "  triangle {t} ({}) element {} refs {n} longest {len:.4} origins {:?}",
            class(t),
            hull.element[t],
            tri.map(|i| hull.origins[i as usize])
        );
    }
}

#[test]
#[ignore = "survey for humans: which models get flat nets"]
fn survey_flat_nets() {
    for e in std::fs::read_dir("scenes/models").unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        if !name.ends_with(".obj") {
            continue;
        }
        let (m, report) = mesh::load(&Path::new("scenes/models").join(&name)).unwrap();
        if report.require(true).is_err() {
            continue;
        }
        let Ok(normals) = mesh::vertex_normals(&m, NormalMethod::default_for(&m)) else {
            continue;
        };
        match inner::build_with_report(&m, &normals, &InnerOptions::default()) {
            Ok((_, rep)) => eprintln!("{name}: flat nets {}", rep.flat_nets),
            Err(e) => eprintln!("{name}: {e}"),
        }
    }
}

#[test]
#[ignore = "exploration for humans: where fandisk's crossed boundary faces are"]
fn explore_fandisk_holes() {
    // `HOLES_SCENE=path` for another cubic scene (mpi_poly, spot_control_cage).
    let path =
        std::env::var("HOLES_SCENE").unwrap_or_else(|_| "scenes/paper1994/fandisk.toml".into());
    let sc = apatch::scene::load(Path::new(&path)).unwrap();
    let built = apatch::scene::build_scene(&sc).unwrap();
    classify_holes(&built.hull.unwrap(), &built.complex);
}

fn classify_holes(
    hull: &apatch::hull::simplicial::SimplicialHull,
    c: &apatch::complex::PatchComplex,
) {
    use apatch::hull::simplicial::PointOrigin;
    let edges = hull.edges().unwrap();
    let kind = |t: usize| -> String {
        let tri = hull.triangles[t];
        let o = tri.map(|i| hull.origins[i as usize]);
        let faces: Vec<Option<u32>> = o
            .iter()
            .map(|x| match x {
                PointOrigin::CornerGuard { face } | PointOrigin::Centroid { face } => Some(*face),
                _ => None,
            })
            .collect();
        let g = o
            .iter()
            .filter(|x| matches!(x, PointOrigin::CornerGuard { .. }))
            .count();
        let p = o
            .iter()
            .filter(|x| matches!(x, PointOrigin::PseudoCentroid { .. }))
            .count();
        let same = faces.iter().all(|f| f.is_some() && *f == faces[0]);
        format!("g{g}p{p}{}", if same { "flat" } else { "" })
    };
    // An edge patch's element is its edge of T; a face patch's is an input vertex, so its
    // triangle is the one whose points are the tetrahedron's base.
    let base_triangle = |p: &apatch::complex::Patch| -> usize {
        (0..hull.triangles.len())
            .find(|&t| {
                hull.triangles[t]
                    .iter()
                    .zip(&p.tet)
                    .all(|(&i, &q)| hull.points[i as usize] == DVec3::from(q))
            })
            .expect("a face patch's base is a triangle of T")
    };
    let mut by = std::collections::BTreeMap::new();
    // Per-patch scale 1e-9: signs beyond rounding of each patch's own weights.
    let (crossed, _) = fixtures::crossed_boundary_faces(c, 15, 1e-9, fixtures::SignScale::Patch);
    for (k, opp) in crossed {
        let p = &c.patches[k];
        let label = match p.role {
            apatch::complex::Role::Edge => {
                let e = &edges[p.element as usize];
                let ks: Vec<String> = e
                    .faces
                    .iter()
                    .filter(|&&f| f != u32::MAX)
                    .map(|&f| kind(f as usize))
                    .collect();
                format!("edge[{}] opp{opp}", ks.join("|"))
            }
            _ => format!("face[{}] opp{opp}", kind(base_triangle(p))),
        };
        if std::env::var("VERBOSE").is_ok() {
            let (pts, tris): (Vec<u32>, Vec<u32>) = match p.role {
                apatch::complex::Role::Edge => {
                    let e = &edges[p.element as usize];
                    (e.v.to_vec(), e.faces.to_vec())
                }
                _ => {
                    let t = base_triangle(p);
                    (hull.triangles[t].to_vec(), vec![t as u32])
                }
            };
            eprintln!(
                "{label} patch {k} points {pts:?} tris {tris:?} apexes {:?}",
                tris.iter()
                    .filter(|&&f| f != u32::MAX)
                    .map(|&f| hull.apexes[f as usize])
                    .collect::<Vec<_>>()
            );
            // The crossed face's weights (multi-indices without the opposite vertex).
            let face: Vec<String> = apatch::bb::multi_indices(p.degree as usize)
                .into_iter()
                .enumerate()
                .filter(|(_, m)| m[opp] == 0)
                .map(|(k, m)| format!("{m:?}={:.3e}", p.weights[k]))
                .collect();
            eprintln!("    tet {:?}\n    face {}", p.tet, face.join(" "));
            for &v in &pts {
                eprintln!(
                    "    point {v} {:?} normal {:?} origin {:?}",
                    hull.points[v as usize], hull.normals[v as usize], hull.origins[v as usize]
                );
            }
            for &f in tris.iter().filter(|&&f| f != u32::MAX) {
                let t = hull.triangles[f as usize];
                let q = t.map(|i| hull.points[i as usize]);
                let n = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
                let dots: Vec<f64> = t.iter().map(|&i| n.dot(hull.normals[i as usize])).collect();
                eprintln!(
                    "    tri {f} {t:?} n {n:?} n·n_v {dots:?} origins {:?}",
                    t.map(|i| hull.origins[i as usize])
                );
            }
        }
        *by.entry(label).or_insert(0) += 1;
    }
    eprintln!("crossed boundary faces by kind: {by:#?}");
}

#[test]
#[ignore = "exploration"]
fn explore_annulus() {
    let m = prism(&quarter_annulus());
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let hull = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
    let prepared = cubic_c1::prepare_hull(&hull, &CubicOptions::default());
    let complex = cubic_c1::build(&prepared.hull, &CubicOptions::default()).unwrap();
    let r = check(&complex, &CheckOptions::default());
    eprintln!(
        "violations {} failures {:?}",
        inner::verify(&prepared.hull).len(),
        r.failures()
    );
    eprintln!("holes {:?}", r.holes);
    eprintln!("grad {:?}", r.gradient_jump);
    classify_holes(&prepared.hull, &complex);
}

#[test]
#[ignore = "exploration for humans: the small merged faces at fandisk's worst fans"]
fn explore_fandisk_small_faces() {
    let (m, report) = mesh::load(Path::new("scenes/models/fandisk.obj")).unwrap();
    report.require(true).unwrap();
    let merged = coplanar::merge_coplanar(&m);
    for rep in [1185u32, 1186, 1376, 1808, 4924, 2903, 856, 456, 709, 1377] {
        let Some(f) = merged.face_parent.iter().position(|&p| p == rep) else {
            eprintln!("rep {rep}: not a representative");
            continue;
        };
        let face = &merged.faces[f];
        let p = |i: usize| merged.positions[face[i % face.len()] as usize];
        let n = face.len();
        let c = (0..n).map(p).sum::<DVec3>() / n as f64;
        let mut s = String::new();
        let mut worst: f64 = 0.0;
        #[allow(clippy::needless_range_loop)] // k indexes the corners and p(k ± 1)
        for k in 0..n {
            let e = (p(k + 1) - p(k))
                .length()
                .max((p(k + n - 1) - p(k)).length());
            worst = worst.max((p(k) - c).length() / e);
            let ang = (p(k + 1) - p(k))
                .angle_between(p(k + n - 1) - p(k))
                .to_degrees();
            s += &format!(
                " {}:{:.4}@{:.5} ang {ang:.1}\n",
                face[k],
                (p(k + 1) - p(k)).length(),
                p(k)
            );
        }
        eprintln!(
            "rep {rep} merged {f} corners {n} convex {} reach {worst:.2} edges{s}",
            polygon_is_convex(&merged.positions, face)
        );
    }
}

#[test]
#[ignore = "exploration for humans: violations at fandisk's worst fans"]
fn explore_fandisk_worst_fans() {
    let (m, normals) = fandisk();
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let v = inner::verify(&hull);
    for t in [3213usize, 3735, 2741] {
        let tri = hull.triangles[t];
        eprintln!(
            "triangle {t} element {} origins {:?}",
            hull.element[t],
            tri.map(|i| hull.origins[i as usize])
        );
        for &p in &tri {
            eprintln!(
                "   point {p} at {:.5} n {:.3}",
                hull.points[p as usize], hull.normals[p as usize]
            );
        }
        eprintln!("   apexes {:?}", hull.apexes[t]);
        let key = format!("triangle {t} ");
        for x in v.iter().filter(|x| x.message.contains(&key)).take(8) {
            eprintln!("   {}", x.message);
        }
    }
    for c in [8793u32, 8621] {
        let n = hull.normals[c as usize];
        for (t, tri) in hull.triangles.iter().enumerate() {
            if tri.contains(&c) {
                let [a, b, d] = tri.map(|k| hull.points[k as usize]);
                let nt = (b - a).cross(d - a).normalize();
                eprintln!(
                    "  fan of {c}: triangle {t} {:?} n_t {:.3} n.n_t {:.3}",
                    tri.map(|i| hull.origins[i as usize]),
                    nt,
                    n.dot(nt)
                );
            }
        }
    }
    for (f, face) in m.faces.iter().enumerate() {
        if face.contains(&641) {
            let nf = area_vector(&m.positions, face).normalize();
            eprintln!("  input face {f} {face:?} n {nf:.3}");
        }
    }
    for e in [550usize, 641, 468, 2576] {
        eprintln!("vertex {e} at {:.5} n {:.3}", m.positions[e], normals[e]);
    }
}

/// fandisk's strip [550, 640, 847, 1384, 1385, 641] is straight at corner 641 and its vertex
/// mean lies 4° from 641's edge to 1385: with one point of T for the strip, vertex 641's fan
/// turned 211° between two consecutive points and its triangle [C_0, C_1186, C_1185] was
/// inverted. The fold now gives the strip a flat net (`flatnet::FOLD_GAP`), and every triangle
/// of T at 641's pseudo-centroid faces the side of 641's vertex normal.
#[test]
fn fandisk_folded_strip_fan_is_an_umbrella() {
    use apatch::hull::simplicial::PointOrigin;
    let (m, normals) = fandisk();
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let c0 = hull
        .origins
        .iter()
        .position(|o| matches!(o, PointOrigin::PseudoCentroid { vertex: 641 }))
        .expect("vertex 641 has a pseudo-centroid") as u32;
    let n = normals[641].normalize();
    let mut fan = 0;
    for tri in hull.triangles.iter().filter(|t| t.contains(&c0)) {
        let [a, b, c] = tri.map(|k| hull.points[k as usize]);
        let nt = (b - a).cross(c - a).normalize();
        // The fan's faces are within 4° of each other (normals (0, -0.10, -0.995) and
        // (0, -0.16, -0.988)); before the fix one triangle had n_t . n_V = -0.99.
        assert!(
            nt.dot(n) > 0.5,
            "triangle {tri:?}: n_t . n_V = {}",
            nt.dot(n)
        );
        fan += 1;
    }
    assert!(fan >= 3, "{fan} triangles at 641's pseudo-centroid");
}

#[test]
#[ignore = "exploration for humans: corners of chosen merged faces (FACES=rep,rep) and their diagonals"]
fn explore_fandisk_diagonals() {
    let (m, normals) = fandisk();
    let (merged, counts) = coplanar::merge_coplanar_counted(&m);
    let mut net = GuardNet::build(&merged, decompose::convex_pieces(&merged).unwrap());
    let flat = flatnet::spread_guards_folded(&mut net, &merged, &counts, Some(&normals));
    let reps: Vec<u32> = std::env::var("FACES")
        .unwrap_or_default()
        .split(',')
        .filter_map(|x| x.parse().ok())
        .collect();
    let pos = &merged.positions;
    for rep in reps {
        let Some(f) = merged.face_parent.iter().position(|&p| p == rep) else {
            continue;
        };
        let face = &merged.faces[f];
        let nf = area_vector(pos, face).normalize();
        eprintln!(
            "rep {rep} face {f} corners {} merged {} convex {} flatnet {} n {nf:.3}",
            face.len(),
            counts[f],
            polygon_is_convex(pos, face),
            flat.groups.iter().any(|g| g.face == f as u32)
        );
        for &v in face {
            let fan = net.fan(v).unwrap();
            let n = normals[v as usize];
            let cmin = fan
                .faces
                .iter()
                .map(|&g| net.pieces.normal[g as usize].dot(n))
                .fold(1.0, f64::min);
            let m = fan.faces.len();
            let Some(at) = fan
                .faces
                .iter()
                .position(|&q| net.pieces.parent[q as usize] == f as u32)
            else {
                continue;
            };
            let g = net.pieces.center[fan.faces[at] as usize];
            let a = pos[v as usize];
            let mut s = String::new();
            for (w, other) in [
                (fan.ring[at], fan.faces[(at + m - 1) % m]),
                (fan.ring[(at + 1) % m], fan.faces[(at + 1) % m]),
            ] {
                let c = net.pieces.center[other as usize];
                let (d1, d2, r) = (pos[w as usize] - a, c - g, a - g);
                let (a11, a12, a22) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
                let (b1, b2) = (d1.dot(r), d2.dot(r));
                let det = a11 * a22 - a12 * a12;
                let t = (a12 * b2 - a22 * b1) / det;
                let ss = (a11 * b2 - a12 * b1) / det;
                s += &format!(
                    " [to {w} len {:.4} across face {} t {t:.2} s {ss:.2}]",
                    d1.length(),
                    merged.face_parent[net.pieces.parent[other as usize] as usize]
                );
            }
            eprintln!("  corner {v} at {a:.4} fan {m} cos_min {cmin:.4} point {g:.4}{s}",);
        }
    }
}

#[test]
#[ignore = "exploration for humans: how the triangles in fandisk's violations meet (shared edge, vertex, none)"]
fn explore_fandisk_pairs() {
    let (m, normals) = fandisk();
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let v = inner::verify(&hull);
    let tri_normal = |t: usize| {
        let [a, b, c] = hull.triangles[t].map(|i| hull.points[i as usize]);
        (b - a).cross(c - a).normalize()
    };
    let mut kinds = std::collections::BTreeMap::new();
    for x in &v {
        let ts = triangles_named(x);
        let key = if ts.len() == 2 {
            let (a, b) = (hull.triangles[ts[0]], hull.triangles[ts[1]]);
            let shared = a.iter().filter(|p| b.contains(p)).count();
            let cos = tri_normal(ts[0]).dot(tri_normal(ts[1]));
            let origin = |t: [u32; 3]| {
                t.map(|p| match hull.origins[p as usize] {
                    apatch::hull::simplicial::PointOrigin::PseudoCentroid { .. } => 'p',
                    apatch::hull::simplicial::PointOrigin::CornerGuard { .. } => 'g',
                    apatch::hull::simplicial::PointOrigin::Centroid { .. } => 'c',
                    _ => 'o',
                })
                .iter()
                .collect::<String>()
            };
            if std::env::var("VERBOSE").is_ok() {
                eprintln!(
                    "{} {} shared {shared} cos {cos:.3} {} | {}",
                    ts[0],
                    ts[1],
                    origin(a),
                    origin(b)
                );
            }
            format!("shared{shared} cos<0:{}", cos < 0.0)
        } else {
            format!("{} triangles", ts.len())
        };
        *kinds.entry(key).or_insert(0) += 1;
    }
    eprintln!("{} violations: {kinds:?}", v.len());
}

#[test]
#[ignore = "exploration for humans: folds of T between pseudo-centroid pairs on the nut and fandisk"]
fn explore_pseudo_centroid_folds() {
    use apatch::hull::simplicial::PointOrigin;
    for name in ["nut_pyvista.obj", "fandisk.obj"] {
        let (m, report) = mesh::load(&Path::new("scenes/models").join(name)).unwrap();
        report.require(true).unwrap();
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
        let n = |t: usize| {
            let [a, b, c] = hull.triangles[t].map(|i| hull.points[i as usize]);
            (b - a).cross(c - a).normalize()
        };
        let pc = |i: u32| matches!(hull.origins[i as usize], PointOrigin::PseudoCentroid { .. });
        let mut hist = [0usize; 10];
        for e in hull.edges().unwrap() {
            if e.faces[1] == u32::MAX || pc(e.v[0]) || pc(e.v[1]) {
                continue;
            }
            let [f, g] = e.faces.map(|f| f as usize);
            let third = |t: usize| {
                *hull.triangles[t]
                    .iter()
                    .find(|&&p| p != e.v[0] && p != e.v[1])
                    .unwrap()
            };
            if !pc(third(f)) || !pc(third(g)) {
                continue;
            }
            let c = n(f).dot(n(g));
            hist[((c + 1.0) * 5.0).clamp(0.0, 9.0) as usize] += 1;
            if c < 0.5 {
                let pf = hull.points[e.v[0] as usize];
                let d = hull.points[third(g) as usize];
                let valley = (d - pf).dot(n(f)) > 0.0;
                eprintln!(
                    "{name}: edge {:?} cos {c:.3} valley {valley} apexes {:?}",
                    e.v,
                    hull.apexes[f].map(|a| a.is_some())
                );
            }
        }
        eprintln!("{name}: cos histogram (bins of 0.2 from -1) {hist:?}");
    }
}

#[test]
#[ignore = "exploration for humans: fandisk's violations with one overlapping region at a time given a flat net"]
fn explore_fandisk_forced_one_by_one() {
    let (m, normals) = fandisk();
    let o = InnerOptions::default();
    let none = std::collections::BTreeSet::new();
    let (hull, rep) = inner::build_forced(&m, &normals, &o, &none).unwrap();
    let v = inner::verify(&hull);
    let faces = inner::overlapnet::overlapping_faces(&hull, &v);
    eprintln!(
        "base {} violations, {} nets, candidates {faces:?}",
        v.len(),
        rep.flat_nets
    );
    for f in faces {
        let one = std::iter::once(f).collect();
        let (h, r) = inner::build_forced(&m, &normals, &o, &one).unwrap();
        if r.flat_nets == rep.flat_nets {
            continue;
        }
        eprintln!(
            "face {f}: nets {} violations {}",
            r.flat_nets,
            inner::verify(&h).len()
        );
    }
}

#[test]
#[ignore = "exploration for humans: points, normals and apexes of chosen triangles of fandisk's hull (TRIS=a,b)"]
fn explore_fandisk_triangles() {
    let (m, normals) = fandisk();
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    for t in std::env::var("TRIS")
        .unwrap_or_default()
        .split(',')
        .filter_map(|x| x.parse::<usize>().ok())
    {
        eprintln!("triangle {t} element {}", hull.element[t]);
        for p in hull.triangles[t] {
            let i = p as usize;
            eprintln!(
                "  point {p} {:?} at {:.5} n {:.4}",
                hull.origins[i], hull.points[i], hull.normals[i]
            );
        }
        eprintln!("  apexes {:?}", hull.apexes[t]);
    }
}

/// The hull triangles a violation names (its message's "triangle N"), sorted, as indices.
fn triangles_named(v: &apatch::hull::inner::verify::HullViolation) -> Vec<usize> {
    apatch::hull::inner::overlapnet::named_triangles(v)
        .into_iter()
        .map(|t| t as usize)
        .collect()
}

/// fandisk flattened at 6e-5 of its diagonal (`model.flatten`): its large flat faces become
/// polygons of 61–70 corners whose guard assignment fails, so `GuardNet::build` serves them
/// by their convex pieces (24 of them for 61 corners), each far from most corners; fan
/// triangles from the fine curved triangles beside them to those far points overlapped
/// everywhere (39440 violations before the apex search, 14064 after). Such polygons now get
/// a flat net too (`flatnet`: the run of a polygon's pieces in a corner's fan becomes one
/// entry): every merged polygon of at least 20 corners has one corner guard per corner, and
/// the raw hull (no apex search: it takes 30 s more here; `apatch check` on a flattened copy
/// of `scenes/paper1994/fandisk.toml` shows it ends at 0) has 1089 violations (`verify`,
/// independent of the builder), bounded below 3000: far under the 39440 of the pieces.
#[test]
fn flattened_fandisk_polygons_get_flat_nets() {
    use apatch::hull::simplicial::PointOrigin;
    let (m, _) = fandisk();
    let (m, report) = mesh::flatten::flatten(&m, 6e-5);
    assert!(report.regions > 0);
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let merged = coplanar::merge_coplanar(&m);
    let mut large = 0;
    for (f, face) in merged.faces.iter().enumerate() {
        if face.len() < 20 {
            continue;
        }
        large += 1;
        let parent = merged.face_parent[f];
        let guards = hull
            .origins
            .iter()
            .filter(|o| **o == PointOrigin::CornerGuard { face: parent })
            .count();
        assert_eq!(guards, face.len(), "polygon of input face {parent}");
    }
    // The four polygons that fell back to their pieces, and more.
    assert!(large >= 4, "{large} polygons of 20 corners or more");
    let v = inner::verify(&hull);
    assert!(v.len() < 3000, "{} violations", v.len());
}

/// Smallest angle (degrees) of every triangle of T whose three points are corner guards (or
/// inner points) of one flat polygon: the flat nets' triangles, by input face.
fn net_angles(
    hull: &apatch::hull::simplicial::SimplicialHull,
) -> std::collections::BTreeMap<u32, Vec<f64>> {
    use apatch::hull::simplicial::PointOrigin;
    let mut out: std::collections::BTreeMap<u32, Vec<f64>> = Default::default();
    for tri in &hull.triangles {
        let face = |i: u32| match hull.origins[i as usize] {
            PointOrigin::CornerGuard { face } => Some(face),
            _ => None,
        };
        let Some(f) = face(tri[0]) else { continue };
        if tri.iter().any(|&i| face(i) != Some(f)) {
            continue;
        }
        let v = tri.map(|i| hull.points[i as usize]);
        let a = crate::common::corner_angles(v)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        out.entry(f).or_default().push(a);
    }
    out
}

/// fandisk flattened as its pending quintic scene's best run is (6e-5 of the diagonal,
/// regions of 20 faces or more), with its angle-weighted normals.
fn flattened_fandisk() -> (Mesh, Vec<DVec3>) {
    let (m, _) = fandisk();
    let (m, _) = mesh::flatten::flatten_with(
        &m,
        mesh::flatten::FlattenOptions {
            relative: 6e-5,
            min_faces: 20,
        },
    );
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    (m, normals)
}

/// The flat nets' needles: their triangles with an angle below 5°.
fn needles(h: &apatch::hull::simplicial::SimplicialHull) -> usize {
    net_angles(h)
        .values()
        .flatten()
        .filter(|&&a| a < 5.0)
        .count()
}

/// `flat_net_angle`: fandisk flattened as its pending quintic scene is (6e-5 of the diagonal,
/// regions of 20 faces or more) has flat nets whose guard polygons are sampled every 0.019
/// along one side and far more coarsely along others, so the nets' triangulations of their
/// guards alone are fans of needles (down to 0.5°); the quintic's C2 conditions extrapolate
/// from such face tetrahedra by up to 265 of their sizes, and fandisk's joint solve missed its
/// rows next to them. With `flat_net_angle = 20` the nets get points of T inside
/// (`hull::inner::netmesh`): far fewer needles are left (those that remain stand on sides
/// the polygon's straight edges make long, which the nets keep), every corner keeps its guard,
/// the inner points lie in their face's plane with its normal, and the hull stays closed and
/// of genus 0 with no more violations (`verify`, before the apex search) than without.
#[test]
fn flat_net_angle_removes_most_needles_of_flattened_fandisk() {
    use apatch::hull::simplicial::PointOrigin;
    let (m, normals) = flattened_fandisk();
    let plain = InnerOptions::default();
    let refined = InnerOptions {
        flat_net_angle: 20.0,
        ..InnerOptions::default()
    };
    let (h0, r0) = inner::build_with_report(&m, &normals, &plain).unwrap();
    let (h1, r1) = inner::build_with_report(&m, &normals, &refined).unwrap();
    assert_eq!(r0.flat_nets, r1.flat_nets);
    let (n0, n1) = (needles(&h0), needles(&h1));
    eprintln!(
        "needles {n0} -> {n1}, points {} -> {}",
        h0.points.len(),
        h1.points.len()
    );
    // Measured 142 -> 52.
    assert!(n0 > 100 && 2 * n1 < n0, "needles {n0} -> {n1}");
    // Every guard of h0 is still there (inner points come on top).
    let count = |h: &apatch::hull::simplicial::SimplicialHull| {
        h.origins
            .iter()
            .filter(|o| matches!(o, PointOrigin::CornerGuard { .. }))
            .count()
    };
    assert!(count(&h1) > count(&h0));
    // Inner points: on their polygon's plane, with its normal. A guard of the same face is
    // the plane's reference; the face is flat to rounding (`flatten` made it exact up to
    // 1e-15 of unit coordinates), so 1e-12 is rounding with room.
    for (i, o) in h1.origins.iter().enumerate() {
        let PointOrigin::CornerGuard { face } = *o else {
            continue;
        };
        let first = h1
            .origins
            .iter()
            .position(|x| *x == PointOrigin::CornerGuard { face })
            .unwrap();
        let n = h1.normals[first];
        assert!((h1.normals[i] - n).length() < 1e-12, "point {i}");
        assert!(
            n.dot(h1.points[i] - h1.points[first]).abs() < 1e-12,
            "point {i}"
        );
    }
    assert_eq!(inner::verify::euler_characteristic(&h1), Some(2));
    let (v0, v1) = (inner::verify(&h0).len(), inner::verify(&h1).len());
    // Measured 266 -> 263 (the apex search clears them all).
    assert!(v1 <= v0, "violations {v0} -> {v1}");
}

/// `straight_corners`: flattened fandisk's merged polygons meet along two straight creases
/// whose inner vertices `coplanar` drops (each is between only two polygons), leaving polygon
/// edges 0.81 and 0.52 long beside edges of 0.019: the nets' triangles and the step (5') cells
/// on them are needles that no inner point can mend (52 left with `flat_net_angle = 20`). Kept
/// as corners of both nets (with a guard in each and cells, no corner triangles), no net
/// triangle is below 5° any more, and the hull stays closed and of genus 0 with no more
/// violations (`verify`, before the apex search) than without.
#[test]
fn straight_corners_split_fandisks_long_creases() {
    let (m, normals) = flattened_fandisk();
    let refined = InnerOptions {
        flat_net_angle: 20.0,
        ..InnerOptions::default()
    };
    let straight = InnerOptions {
        straight_corners: true,
        ..refined.clone()
    };
    let (h0, _) = inner::build_with_report(&m, &normals, &refined).unwrap();
    let (h1, r1) = inner::build_with_report(&m, &normals, &straight).unwrap();
    // The two creases' inner vertices, one every 0.019: about 42 and 26; more on the shorter
    // creases between nets (measured 120 in all).
    assert!(r1.straight_corners >= 60, "{}", r1.straight_corners);
    let (n0, n1) = (needles(&h0), needles(&h1));
    // Measured 52 -> 0.
    assert!(n0 > 40 && n1 == 0, "needles {n0} -> {n1}");
    assert_eq!(inner::verify::euler_characteristic(&h1), Some(2));
    let (v0, v1) = (inner::verify(&h0).len(), inner::verify(&h1).len());
    // Measured 266 -> 263 (the apex search clears them all).
    assert!(v1 <= v0, "violations {v0} -> {v1}");
}

//! Near-duplicate vertex rings (subdivision cages' crease trick, spot_control_cage's horn
//! bases) merged into one corner of T before the inner hull (`hull::inner::close`, scene key
//! `scheme.merge_close`).

use apatch::check::{check, CheckOptions};
use apatch::hull::inner::{self, InnerOptions, ViolationKind};
use apatch::mesh::{self, Mesh, NormalMethod};
use glam::DVec3;
use std::collections::HashMap;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

/// An n-gonal "horn" standing on a block, joined through a crease ring: the block (radius 2,
/// z from −1 to its top rim at z = −0.5) slopes up to the valley ring A (radius 1, z = 0); a
/// strip of sliver quads leads from A to ring B, `gap` inwards and `gap` up (turned by `twist`
/// radians: the slivers are then bent), from which the horn's walls rise to its top at z = 1.
/// With `gap` = 0 the two rings coincide: the polyhedron the merge should give. Every vertex of
/// A and B has four faces (two slivers), like the cage's horn-base rings.
fn horn(n: usize, gap: f64, twist: f64) -> Mesh {
    let mut positions = Vec::new();
    let mut ring = |radius: f64, z: f64, turn: f64| -> Vec<u32> {
        (0..n)
            .map(|k| {
                let a = TAU * k as f64 / n as f64 + turn;
                positions.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
                (positions.len() - 1) as u32
            })
            .collect()
    };
    let bottom = ring(2.0, -1.0, 0.0);
    let rim = ring(2.0, -0.5, 0.0);
    let a = ring(1.0, 0.0, 0.0);
    let b = ring(1.0 - gap, gap, twist);
    let top = ring(1.0, 1.0, 0.0);
    let mut faces = vec![bottom.iter().rev().copied().collect::<Vec<u32>>()];
    for k in 0..n {
        let j = (k + 1) % n;
        faces.push(vec![bottom[k], bottom[j], rim[j], rim[k]]);
        faces.push(vec![rim[k], rim[j], a[j], a[k]]);
        if gap > 0.0 {
            faces.push(vec![a[k], a[j], b[j], b[k]]);
            faces.push(vec![b[k], b[j], top[j], top[k]]);
        } else {
            faces.push(vec![a[k], a[j], top[j], top[k]]);
        }
    }
    faces.push(top);
    Mesh::new(positions, faces)
}

/// Writes `mesh` as an OBJ and a cubic-c1 scene with the extra `[scheme]` lines `scheme` into a
/// fresh directory under the system's temporary directory; returns the scene's path.
fn write_scene(name: &str, mesh: &Mesh, scheme: &str) -> PathBuf {
    apatch::fixtures::write_cubic_scene("apatch_inner_cage", name, mesh, scheme, [0.0, 0.0, 0.0])
}

/// The scene's hull violations and whether its cubic surface passes `check` (C1 jumps ≤ 1e-9
/// relative, interpolation, no j-sheets, no holes): what `apatch check` decides.
fn verdict(path: &Path) -> (usize, bool) {
    let scene = apatch::scene::load(path).unwrap();
    let complex = apatch::scene::build_complex(&scene).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let violations = inner::verify(&hull).len();
    let passed = check(&complex, &CheckOptions::default()).passed();
    // The scene's directory is this test's own (`write_scene`).
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    (violations, passed)
}

/// A crease ring of near-duplicate vertices (1e-3 apart, flat or bent slivers) fails as it is:
/// T folds back between each close pair, tetrahedra overlap, the surface leaves the hull. With
/// `merge_close` (0.002 of the diagonal 5.8: 0.012, above the rings' 1.4e-3 and far below
/// every other edge, ≥ 0.39) each pair is one corner of T: the hull verifies and the surface
/// passes `check`, as the polyhedron with the rings made one (gap 0, independent truth that
/// the merged geometry is sound) does. Measured when written: 504 (flat) and 2224 (bent)
/// violations without the merge.
#[test]
fn close_crease_ring_fails_alone_and_passes_merged() {
    let (v, passed) = verdict(&write_scene("one_ring", &horn(8, 0.0, 0.0), ""));
    assert!(v == 0 && passed, "the single ring: {v} violations");
    for (name, twist) in [("flat", 0.0), ("bent", 0.01)] {
        let m = horn(8, 1e-3, twist);
        let (v, passed) = verdict(&write_scene(name, &m, ""));
        assert!(v > 0 && !passed, "{name}: the unmerged ring passed");
        let merged = write_scene(&format!("{name}_merged"), &m, "merge_close = 0.002");
        let (v, passed) = verdict(&merged);
        assert!(v == 0 && passed, "{name} merged: {v} violations");
    }
}

/// What the merge does to the mesh: every A/B pair becomes one vertex (the lower index, at
/// its own place: no vertex moves), the slivers drop out, the rest is the single-ring
/// polyhedron's faces, and the hull's report lists the clusters.
#[test]
fn merge_collapses_each_pair_and_drops_the_slivers() {
    let n = 8;
    let m = horn(n, 1e-3, 0.01);
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let c = inner::close::merge_close_vertices(&m, &normals, 0.002)
        .unwrap()
        .unwrap();
    let (a0, b0) = (2 * n as u32, 3 * n as u32);
    let want: Vec<Vec<u32>> = (0..n as u32).map(|k| vec![a0 + k, b0 + k]).collect();
    assert_eq!(c.clusters, want);
    assert_eq!(c.mesh.positions, m.positions);
    let slivers: Vec<u32> = (0..n as u32).map(|k| 3 + 4 * k).collect();
    assert_eq!(c.dropped_faces, slivers);
    let single = horn(n, 0.0, 0.0);
    // The merged faces are the single-ring polyhedron's (its unused ring B numbered alike).
    assert_eq!(c.mesh.faces, single.faces);
    let options = InnerOptions {
        merge_close: 0.002,
        ..InnerOptions::default()
    };
    let (_, report) = inner::build_with_report(&m, &normals, &options).unwrap();
    assert_eq!(report.merged_clusters, want);
    // Off (the default): nothing is merged.
    assert!(inner::close::merge_close_vertices(&m, &normals, 0.0)
        .unwrap()
        .is_none());
}

/// The key is read as a share of the bounding-box diagonal in [0, 0.05]; out of range or of
/// the wrong type is an error naming the key.
#[test]
fn merge_close_key_is_parsed_and_checked() {
    let read = |s: &str| {
        let t: toml::Table = toml::from_str(s).unwrap();
        InnerOptions::from_toml(&t, Path::new("s.toml"))
    };
    assert_eq!(read("merge_close = 0.004").unwrap().merge_close, 0.004);
    assert_eq!(read("").unwrap().merge_close, 0.0);
    for bad in [
        "merge_close = -1e-3",
        "merge_close = 0.2",
        "merge_close = true",
    ] {
        let e = read(bad).unwrap_err().to_string();
        assert!(e.contains("merge_close"), "{bad}: {e}");
    }
}

/// spot_control_cage with its scene's `merge_close = 0.005`: the 8 horn-base clusters merge,
/// no edge of T is nonconvex (Lemma 4.1; there were 18 before the merge), and the sideways
/// saddle corners' normals are turned to face their fans (`hull::inner::umbrella`): every
/// turned pseudo-centroid's normal faces each of its fan triangles by at least what it did
/// before, and the overlaps drop from 2155 (no merge) and 594 (merge alone) to at most 352
/// (450 with the umbrella normals, 436 once steep corners end no split diagonal,
/// `planar::STEEP_CORNER`, 352 with nearly coplanar pieces at folded corners joined,
/// `planar::JOIN_ANGLE`; the bound only guards against a regression, the cage still fails
/// `check`).
#[test]
fn spot_control_cage_merged_and_umbrella_normals() {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let options = InnerOptions {
        merge_close: 0.005,
        ..InnerOptions::default()
    };
    let (hull, report) = inner::build_with_report(&m, &normals, &options).unwrap();
    // The merged hull without the scene's searches (`split_search`, `corner_search`: their
    // own tests below start from it; building the scene's searched hull here took ~55 s).
    let v = inner::verify(&hull);
    let count = |k: ViolationKind| v.iter().filter(|x| x.kind == k).count();
    assert_eq!(count(ViolationKind::EdgeNonconvex), 0);
    assert!(count(ViolationKind::Intersecting) <= 352, "{}", v.len());
    assert_eq!(report.merged_clusters.len(), 8);
    assert!(!report.umbrella_normals.is_empty());
    for &i in &report.umbrella_normals {
        let n = hull.normals[i as usize];
        let apatch::hull::simplicial::PointOrigin::PseudoCentroid { vertex } =
            hull.origins[i as usize]
        else {
            panic!("point {i} is no pseudo-centroid");
        };
        // n_V as the corner step had it (Appendix C may have rotated it).
        let given = report
            .adjusted_normals
            .iter()
            .find(|(w, _)| *w == vertex)
            .map_or(normals[vertex as usize], |(_, n)| *n);
        let least = |n: DVec3| {
            hull.triangles
                .iter()
                .filter(|t| t.contains(&i))
                .map(|t| {
                    let [a, b, c] = t.map(|k| hull.points[k as usize]);
                    n.dot((b - a).cross(c - a).normalize())
                })
                .fold(f64::INFINITY, f64::min)
        };
        assert!(
            least(n) > least(given),
            "point {i}: {} <= {}",
            least(n),
            least(given)
        );
    }
}

/// At the cage's vertex 104 (on the symmetry plane, normal (0, −1, 0)) the quads 85 and 175
/// stand almost edge-on to the normal (cosine 0.05 < `planar::STEEP_CORNER`; 88 and 178:
/// 0.28): they are split by the diagonal that does not end at 104, so its fan in T gets one
/// point of T from each of them (two each before, a few degrees apart seen along n_V, their
/// face tetrahedra overlapping: 68 violations named 104), and no violation names 104 any more. Over the whole cage, every split quad with one steep corner
/// (its input normal's cosine with the quad's area normal below the bound, the other three
/// not) and not joined back whole is cut by the diagonal that avoids it (independent recount
/// from the split mesh).
#[test]
fn spot_control_cage_steep_corners_end_no_diagonal() {
    // The split rules alone: the scene's `corner_search` re-cuts corners after them (104 among
    // them, whose recut fan overlaps elsewhere), which is not what this test is about.
    let path = Path::new("scenes/paper1994/spot_control_cage.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("corner_search = true", "corner_search = false");
    let scene = apatch::scene::parse(&text, path).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let by_face = fan_points_by_face(&hull, 104);
    let mut faces: Vec<u32> = by_face.keys().copied().collect();
    faces.sort_unstable();
    assert_eq!(faces, vec![85, 88, 175, 178]);
    assert_eq!(by_face[&85].len(), 1, "{by_face:?}");
    assert_eq!(by_face[&175].len(), 1, "{by_face:?}");
    let v = inner::verify(&hull);
    assert!(
        v.iter().all(|x| !elements(&x.message).contains(&104)),
        "{}",
        v.len()
    );
    // Independent recount on the split mesh (the merge keeps vertex numbers).
    let (merged, split) = merged_and_split();
    let mut checked = 0;
    for sf in split
        .faces
        .iter()
        .filter(|f| f.triangles == 2 && f.joined == 0)
    {
        let quad = &merged.mesh.faces[sf.face as usize];
        let nf = apatch::mesh::geometry::area_vector(&merged.mesh.positions, quad).normalize();
        let steep: Vec<bool> = quad
            .iter()
            .map(|&w| merged.normals[w as usize].dot(nf) < inner::planar::STEEP_CORNER)
            .collect();
        if steep.iter().filter(|&&s| s).count() != 1 {
            continue;
        }
        let k = steep.iter().position(|&s| s).unwrap();
        // The split's triangles are the quad's corners; the steep corner is in only one.
        let holding = split
            .mesh
            .faces
            .iter()
            .zip(&split.mesh.face_parent)
            .filter(|(f, _)| f.len() == 3 && f.contains(&quad[k]))
            .filter(|(f, _)| f.iter().all(|w| quad.contains(w)))
            .count();
        assert_eq!(holding, 1, "quad {} corner {}", sf.face, quad[k]);
        checked += 1;
    }
    assert!(checked > 0);
}

/// The points of T from each input face in the fan of the pseudo-centroid of `vertex`.
fn fan_points_by_face(
    hull: &apatch::hull::simplicial::SimplicialHull,
    vertex: u32,
) -> HashMap<u32, Vec<u32>> {
    use apatch::hull::simplicial::PointOrigin;
    let c0 = hull
        .origins
        .iter()
        .position(|o| *o == PointOrigin::PseudoCentroid { vertex })
        .unwrap() as u32;
    let mut by_face: HashMap<u32, Vec<u32>> = HashMap::new();
    for t in hull.triangles.iter().filter(|t| t.contains(&c0)) {
        for &k in t {
            if let PointOrigin::Centroid { face } | PointOrigin::CornerGuard { face } =
                hull.origins[k as usize]
            {
                let l = by_face.entry(face).or_default();
                if !l.contains(&k) {
                    l.push(k);
                }
            }
        }
    }
    by_face
}

/// Folded corners (input normal below one of their polygons, so Appendix C turns it) whose
/// bent polygon splits into two nearly coplanar triangles meeting there get one piece, one
/// point of T, from them (`planar::JOIN_ANGLE`): the cage's vertex 52 (face −0.81 below its
/// normal) from its pentagon 36 (pieces 1.3° apart; two points of T before, 8° apart seen
/// along the turned normal, the fan triangle between them edge-on, n·n_t = 0.16) and vertex 12
/// from its quad 29, and their mirrors 161 and 121. Independent recount: the split's report
/// names exactly those four faces as joined, and the violations naming 52 fall from 91 to at
/// most 28 (measured 28; a regression guard, the corner still has overlaps). The ranked
/// splits' hull (the scene's options without `split_search`, which may re-split face 36).
#[test]
fn spot_control_cage_folded_corners_join_flat_pieces() {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let options = InnerOptions {
        merge_close: 0.005,
        ..InnerOptions::default()
    };
    let hull = inner::build(&m, &normals, &options).unwrap();
    for (vertex, face) in [(52, 36), (161, 126), (12, 29), (121, 119)] {
        let by_face = fan_points_by_face(&hull, vertex);
        assert_eq!(by_face[&face].len(), 1, "vertex {vertex}: {by_face:?}");
    }
    let v = inner::verify(&hull);
    let at_52 = v
        .iter()
        .filter(|x| elements(&x.message).contains(&52))
        .count();
    assert!(at_52 <= 28, "{at_52}");
    let (merged, split) = merged_and_split();
    let mut joined: Vec<u32> = split
        .faces
        .iter()
        .filter(|f| f.joined > 0)
        .map(|f| merged.mesh.face_parent[f.face as usize])
        .collect();
    joined.sort_unstable();
    assert_eq!(joined, vec![29, 36, 119, 126]);
}

/// The cage as its scene's hull starts: close vertices merged (`merge_close = 0.005`, the
/// vertex numbers kept) and bent polygons split with the merged normals, as
/// `hull::inner` does; for recounts independent of the hull.
fn merged_and_split() -> (inner::close::CloseMerge, inner::planar::PlanarSplit) {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let merged = inner::close::merge_close_vertices(&m, &normals, 0.005)
        .unwrap()
        .unwrap();
    let split = inner::planar::split_nonplanar_steep(
        &merged.mesh,
        inner::planar::DEFAULT_TOLERANCE,
        Some(&merged.normals),
    )
    .unwrap();
    (merged, split)
}

/// The elements (input vertices) a violation message names.
fn elements(message: &str) -> Vec<u32> {
    apatch::hull::inner::retriangulate::named_elements(message)
}

/// Survey: a scene's hull violations by kind, by element and by element pair (default the
/// cage; `CAGE_SCENE=path` for another).
/// `cargo test --release --test suite inner_cage::survey -- --ignored --nocapture`
#[test]
#[ignore = "survey: prints hull violations by kind and location"]
fn survey_cage_violations() {
    let path = std::env::var("CAGE_SCENE")
        .unwrap_or_else(|_| "scenes/paper1994/spot_control_cage.toml".into());
    let scene = apatch::scene::load(Path::new(&path)).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let v = inner::verify(&hull);
    let mut by_kind: HashMap<ViolationKind, usize> = HashMap::new();
    let mut by_element: HashMap<u32, usize> = HashMap::new();
    let mut by_pair: HashMap<(u32, u32), usize> = HashMap::new();
    for x in &v {
        *by_kind.entry(x.kind).or_default() += 1;
        let e = elements(&x.message);
        for &k in &e {
            *by_element.entry(k).or_default() += 1;
        }
        if let [a, b] = e[..] {
            *by_pair.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    println!("{} violations: {by_kind:?}", v.len());
    let mut els: Vec<_> = by_element.into_iter().collect();
    els.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    println!("by element: {:?}", &els[..els.len().min(40)]);
    let mut pairs: Vec<_> = by_pair.into_iter().collect();
    pairs.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    println!("by pair: {:?}", &pairs[..pairs.len().min(30)]);
    for x in v.iter().filter(|x| x.kind != ViolationKind::Intersecting) {
        println!("  {:?}: {}", x.kind, x.message);
    }
}

/// Dump: a scene's hull (after the cubic scheme's apex moves) as JSON for offline analysis:
/// `CAGE_SCENE=… HULL_DUMP=out.json cargo test --release --test suite inner_cage::dump -- --ignored`.
#[test]
#[ignore = "writes a hull dump for analysis"]
fn dump_hull() {
    let path = std::env::var("CAGE_SCENE")
        .unwrap_or_else(|_| "scenes/paper1994/spot_control_cage.toml".into());
    let out = std::env::var("HULL_DUMP").unwrap_or_else(|_| "/tmp/hull_dump.json".into());
    let scene = apatch::scene::load(Path::new(&path)).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let v3 = |p: DVec3| format!("[{:e},{:e},{:e}]", p.x, p.y, p.z);
    let origin = |o: &apatch::hull::simplicial::PointOrigin| {
        use apatch::hull::simplicial::PointOrigin::*;
        match o {
            Centroid { face } => format!("[\"C\",{face}]"),
            CornerGuard { face } => format!("[\"G\",{face}]"),
            PseudoCentroid { vertex } => format!("[\"P\",{vertex}]"),
            Other => "[\"O\",0]".into(),
        }
    };
    let list = |v: Vec<String>| format!("[{}]", v.join(","));
    let apex = |a: &Option<DVec3>| a.map_or("null".into(), v3);
    let json = format!(
        "{{\"points\":{},\"normals\":{},\"origins\":{},\"triangles\":{},\"apexes\":{},\"element\":{}}}",
        list(hull.points.iter().map(|&p| v3(p)).collect()),
        list(hull.normals.iter().map(|&p| v3(p)).collect()),
        list(hull.origins.iter().map(origin).collect()),
        list(hull.triangles.iter().map(|t| format!("{t:?}")).collect()),
        list(
            hull.apexes
                .iter()
                .map(|a| format!("[{},{}]", apex(&a[0]), apex(&a[1])))
                .collect()
        ),
        list(hull.element.iter().map(|e| e.to_string()).collect()),
    );
    std::fs::write(out, json).unwrap();
}

/// `split_search` (`hull::inner::retriangulate`): where the hull of the ranked splits fails
/// `verify` (320 violations on the cage since the mouth slit's flips, 358 before), the splits
/// of bent polygons at the named corners are chosen by rebuilding and verifying. Independent
/// recount: `verify` on the hull built with the search's forced splits gives exactly the count
/// the search reports, strictly below the ranked hull's (measured 320 → 298, every one an
/// overlap; 358 → 291 before the flips); every forced split names a split polygon and an index
/// among its triangulations; without the key nothing is searched.
#[test]
fn spot_control_cage_split_search_lowers_violations() {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let ranked = InnerOptions {
        merge_close: 0.005,
        ..InnerOptions::default()
    };
    let (plain, report) = inner::build_with_report(&m, &normals, &ranked).unwrap();
    assert_eq!(report.retriangulated, Default::default());
    let before = inner::verify(&plain).len();
    let searched = InnerOptions {
        split_search: true,
        ..ranked
    };
    let (hull, report) = inner::build_with_report(&m, &normals, &searched).unwrap();
    let s = &report.retriangulated;
    assert_eq!(s.before, before);
    assert_eq!(inner::verify(&hull).len(), s.after);
    // A regression guard at the measured 298 (no apex search here: the hull still fails).
    assert!(
        s.after < s.before && s.after <= 298,
        "{} -> {}",
        s.before,
        s.after
    );
    assert!(inner::verify(&hull)
        .iter()
        .all(|v| v.kind == ViolationKind::Intersecting));
    assert!(!s.forced.is_empty() && s.trials <= inner::retriangulate::MAX_TRIALS);
    let (merged, split) = merged_and_split();
    for (face, f) in &s.forced {
        let k = split
            .faces
            .iter()
            .position(|sf| sf.face == *face)
            .unwrap_or_else(|| panic!("face {face} was not split"));
        assert!(f.triangulation < split.candidates[k]);
        assert!(merged.mesh.faces[*face as usize].len() > 3);
    }
}

/// The `split_search` key: a boolean, off by default; any other type is an error naming it.
#[test]
fn split_search_key_is_parsed_and_checked() {
    let read = |s: &str| {
        let t: toml::Table = toml::from_str(s).unwrap();
        InnerOptions::from_toml(&t, Path::new("s.toml"))
    };
    assert!(read("split_search = true").unwrap().split_search);
    assert!(!read("").unwrap().split_search);
    for bad in ["split_search = 1", "split_search = \"yes\""] {
        let e = read(bad).unwrap_err().to_string();
        assert!(e.contains("split_search"), "{bad}: {e}");
    }
}

/// `corner_search` (`hull::inner::recut`), in turns with `split_search`: where the searched
/// splits' hull still fails `verify`, the corners the violations name are re-cut (n_V turned
/// further towards the direction most above its faces, α per corner) by rebuilding and
/// verifying. Independent recount: `verify` on the returned hull gives exactly the count the
/// search reports, strictly below where it started (measured 298 → 114 since the mouth slit's
/// flips, all overlaps; the bound guards against a regression); every re-cut corner is a vertex
/// of the cage, α in (0, 1) and turn in [0, 1]. Without the key nothing is re-cut.
#[test]
fn spot_control_cage_corner_search_lowers_violations() {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let split = InnerOptions {
        merge_close: 0.005,
        split_search: true,
        ..InnerOptions::default()
    };
    let (plain, report) = inner::build_with_report(&m, &normals, &split).unwrap();
    assert_eq!(report.recut, Default::default());
    let before = inner::verify(&plain).len();
    let options = InnerOptions {
        corner_search: true,
        ..split
    };
    let (hull, report) = inner::build_with_report(&m, &normals, &options).unwrap();
    let s = &report.recut;
    let v = inner::verify(&hull);
    assert_eq!(v.len(), s.after);
    assert_eq!(s.before, before);
    assert!(
        s.after < s.before && s.after <= 114,
        "{} -> {}",
        s.before,
        s.after
    );
    assert!(v.iter().all(|x| x.kind == ViolationKind::Intersecting));
    assert!(!s.cuts.is_empty());
    for (vertex, cut) in &s.cuts {
        assert!((*vertex as usize) < m.positions.len(), "vertex {vertex}");
        assert!((0.0..=1.0).contains(&cut.turn));
        assert!(cut.alpha.is_none_or(|a| a > 0.0 && a < 1.0));
    }
    // The apex search (`apex_search`, `hull::inner::reapex`) on that hull, as the build runs
    // it: `verify` recounts what it reports (measured 114 -> 0 since its deepest-point
    // position, 54 -> 14 before; the bound guards against a regression), and only apexes
    // moved: T, its points and normals are the same.
    let (moved, log) = inner::search_apexes(hull.clone(), false);
    let w = inner::verify(&moved);
    assert_eq!(log.before, v.len());
    assert_eq!(log.after, w.len());
    assert!(w.is_empty(), "{} -> {}", v.len(), w.len());
    assert!(w.iter().all(|x| x.kind == ViolationKind::Intersecting));
    assert!(!log.moved.is_empty());
    assert_eq!(moved.triangles, hull.triangles);
    assert_eq!(moved.points, hull.points);
    assert_eq!(moved.normals, hull.normals);
    assert_ne!(moved.apexes, hull.apexes);
}

/// The `corner_search` and `apex_search` keys: booleans, off by default; any other type is an
/// error naming the key.
#[test]
fn corner_search_key_is_parsed_and_checked() {
    let read = |s: &str| {
        let t: toml::Table = toml::from_str(s).unwrap();
        InnerOptions::from_toml(&t, Path::new("s.toml"))
    };
    assert!(read("corner_search = true").unwrap().corner_search);
    assert!(!read("").unwrap().corner_search);
    assert!(read("apex_search = true").unwrap().apex_search);
    assert!(!read("").unwrap().apex_search);
    for key in ["corner_search", "apex_search"] {
        for bad in [format!("{key} = 1"), format!("{key} = \"yes\"")] {
            let e = read(&bad).unwrap_err().to_string();
            assert!(e.contains(key), "{bad}: {e}");
        }
    }
}

/// Survey: what the cage's corner search (`corner_search`, `hull::inner::recut`) kept.
/// `cargo test --release --test suite inner_cage::recut_survey -- --ignored --nocapture`
#[test]
#[ignore = "survey: prints the corner search's cuts"]
fn recut_survey() {
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let options = InnerOptions {
        merge_close: 0.005,
        split_search: true,
        corner_search: true,
        ..InnerOptions::default()
    };
    let (hull, report) = inner::build_with_report(&m, &normals, &options).unwrap();
    println!("split search: {:?}", report.retriangulated);
    println!("corner search: {:?}", report.recut);
    let v = inner::verify(&hull);
    let mut by_element: HashMap<u32, usize> = HashMap::new();
    for x in &v {
        for k in elements(&x.message) {
            *by_element.entry(k).or_default() += 1;
        }
    }
    let mut els: Vec<_> = by_element.into_iter().collect();
    els.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    println!("{} violations; by element: {els:?}", v.len());
}

/// The scene's searches from the ranked splits (`split_search = false`, `corner_search`,
/// `apex_search`): the hull the scene builds verifies (Definition 3.6, Lemmas 4.1–4.3: no
/// violation of any kind; measured 140 overlaps before the apex search, 0 after). The same
/// searches after the split search verify too since the mouth slit's flips and the apex
/// search's deepest point (session 23 they stopped there at 14 overlaps, and the scene turned
/// the split search off; it stays off, being the slower path). `verify` is the independent
/// check.
#[test]
fn spot_control_cage_hull_verifies_with_and_without_the_split_search() {
    let path = Path::new("scenes/paper1994/spot_control_cage.toml");
    let scene = apatch::scene::load(path).unwrap();
    let hull = apatch::scene::inner_hull(&scene).unwrap().unwrap();
    let v = inner::verify(&hull);
    assert!(v.is_empty(), "{} violations: {:?}", v.len(), v.first());
    // The same scene with the split search first.
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("split_search = false", "split_search = true");
    let split = apatch::scene::parse(&text, path).unwrap();
    let hull = apatch::scene::inner_hull(&split).unwrap().unwrap();
    let w = inner::verify(&hull);
    assert!(w.is_empty(), "{} violations: {:?}", w.len(), w.first());
}

/// The mouth slit (faces 85 and 88, 0.005 apart, meeting at edge 102–104) and its mirror
/// (175 / 178 at 185–104): in the scene's hull (`build_with_report` with the scene's options,
/// the apex search included) the edge of T between the walls' centroids is gone and the
/// pseudo-centroids at the slit's bottom are joined instead (`hull::inner::slit`: 2 flips, the
/// report says so), each of the bottom edge's two triangles faces all three of its vertex
/// normals, and the hull verifies (the apexes under the 0.02-thick lip come from the apex
/// search's deepest point; without it 32 overlaps were left there). Independent of the
/// builder: edges and facing are recounted from the hull's points, normals and origins.
#[test]
fn spot_control_cage_mouth_slit_runs_along_its_bottom() {
    use apatch::hull::simplicial::PointOrigin;
    let (m, _) = mesh::load(Path::new("scenes/models/spot_control_cage.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let options = InnerOptions {
        merge_close: 0.005,
        split_search: false,
        corner_search: true,
        apex_search: true,
        ..InnerOptions::default()
    };
    let (hull, report) = inner::build_with_report(&m, &normals, &options).unwrap();
    println!(
        "slits flipped {}; corner search {} -> {}; apex search {} -> {}",
        report.flipped_slits,
        report.recut.before,
        report.recut.after,
        report.reapex.before,
        report.reapex.after
    );
    assert_eq!(report.flipped_slits, 2);
    let v = inner::verify(&hull);
    assert!(v.is_empty(), "{} violations: {:?}", v.len(), v.first());
    let points_of = |o: PointOrigin| -> Vec<u32> {
        (0..hull.points.len() as u32)
            .filter(|&i| hull.origins[i as usize] == o)
            .collect()
    };
    let joined = |a: &[u32], b: &[u32]| -> Vec<usize> {
        hull.triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| {
                (0..3).any(|k| {
                    let (x, y) = (t[k], t[(k + 1) % 3]);
                    a.contains(&x) && b.contains(&y) || a.contains(&y) && b.contains(&x)
                })
            })
            .map(|(i, _)| i)
            .collect()
    };
    let centroid = |face| points_of(PointOrigin::Centroid { face });
    let corner = |vertex| points_of(PointOrigin::PseudoCentroid { vertex });
    for (walls, bottom) in [([85, 88], [102, 104]), ([175, 178], [185, 104])] {
        assert!(
            joined(&centroid(walls[0]), &centroid(walls[1])).is_empty(),
            "T still crosses the slit between faces {walls:?}"
        );
        let tris = joined(&corner(bottom[0]), &corner(bottom[1]));
        assert_eq!(tris.len(), 2, "bottom {bottom:?}: {tris:?}");
        for t in tris {
            let p = hull.triangles[t].map(|i| hull.points[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            for i in hull.triangles[t] {
                // The flip's own bound (`slit::FACING_MIN`): facing, not merely not against.
                assert!(
                    n.dot(hull.normals[i as usize]) >= 0.05,
                    "triangle {t}, point {i}"
                );
            }
        }
    }
}

//! Zero-coplanar corner guard nets on large flat regions (Appendix B, Algorithm 3).

use apatch::hull::inner::{self, coplanar, decompose, guardnet::GuardNet, InnerOptions};
use apatch::mesh::{self, convexity::polygon_is_convex, geometry::area_vector, NormalMethod};
use std::path::Path;

#[test]
#[ignore = "exploration for humans: fandisk's flat regions and violations"]
fn explore_fandisk() {
    let (m, report) = mesh::load(Path::new("scenes/models/fandisk.obj")).unwrap();
    report.require(true).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
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
        let mut ts = Vec::new();
        let msg = &x.message;
        let mut rest = msg.as_str();
        while let Some(i) = rest.find("triangle ") {
            rest = &rest[i + 9..];
            let num: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
            if let Ok(t) = num.parse::<usize>() {
                ts.push(t);
            }
        }
        ts.sort_unstable();
        ts.dedup();
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

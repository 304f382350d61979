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
    let (hull, _) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    let v = inner::verify(&hull);
    let mut kinds = std::collections::BTreeMap::new();
    let mut by_face = std::collections::BTreeMap::new();
    for x in &v {
        *kinds.entry(format!("{:?}", x.kind)).or_insert(0) += 1;
        if let Some(t) = x.triangle {
            for &p in &hull.triangles[t as usize] {
                if let apatch::hull::simplicial::PointOrigin::CornerGuard { face }
                | apatch::hull::simplicial::PointOrigin::Centroid { face } =
                    hull.origins[p as usize]
                {
                    *by_face.entry(face).or_insert(0) += 1;
                }
            }
        }
    }
    let mut bf: Vec<_> = by_face.into_iter().collect();
    bf.sort_by_key(|x| std::cmp::Reverse(x.1));
    eprintln!("{} violations {kinds:?}", v.len());
    eprintln!(
        "by input face of a centroid/guard of the triangle: {:?}",
        &bf[..bf.len().min(30)]
    );
    for x in v.iter().take(5) {
        eprintln!("  {}", x.message);
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

//! Trihedral saddle corners of the inner hull (double_torus_poly).

use apatch::hull::inner::{self, InnerOptions};
use apatch::hull::simplicial::{PointOrigin, SimplicialHull};
use apatch::mesh::convexity::edge_convexity_1994;
use apatch::mesh::{self, NormalMethod};
use glam::DVec3;
use std::path::Path;

fn load(name: &str) -> (apatch::mesh::Mesh, Vec<DVec3>) {
    let path = Path::new("scenes/models").join(name);
    let (m, _) = mesh::load(&path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::default_for(&m)).unwrap();
    (m, normals)
}

fn orient(a: DVec3, b: DVec3, c: DVec3, q: DVec3) -> f64 {
    (b - a).cross(c - a).dot(q - a)
}

fn dump_element(hull: &SimplicialHull, el: u32) {
    for (t, tri) in hull.triangles.iter().enumerate() {
        if hull.element[t] != el {
            continue;
        }
        let p = tri.map(|i| hull.points[i as usize]);
        let n = tri.map(|i| hull.normals[i as usize]);
        let cls: Vec<String> = (0..3)
            .map(|k| {
                format!(
                    "({},{}):{:?}",
                    tri[k],
                    tri[(k + 1) % 3],
                    edge_convexity_1994(p[k], n[k], p[(k + 1) % 3], n[(k + 1) % 3])
                )
            })
            .collect();
        let ap: Vec<String> = hull.apexes[t]
            .iter()
            .map(|q| match q {
                Some(q) => format!("{:.3e}", orient(p[0], p[1], p[2], *q)),
                None => "-".into(),
            })
            .collect();
        let org: Vec<String> = tri
            .iter()
            .map(|&i| match hull.origins[i as usize] {
                PointOrigin::Centroid { face } => format!("C{face}"),
                PointOrigin::CornerGuard { face } => format!("G{face}"),
                PointOrigin::PseudoCentroid { vertex } => format!("P{vertex}"),
                PointOrigin::Other => "O".into(),
            })
            .collect();
        let l = [0, 1, 2].map(|k| (p[(k + 1) % 3] - p[k]).length());
        let area2 = (p[1] - p[0]).cross(p[2] - p[0]).length();
        let lmax = l[0].max(l[1]).max(l[2]);
        eprintln!("  tri {t} {tri:?} {org:?} {cls:?} apex orient {ap:?}");
        eprintln!(
            "     lens {:.3} {:.3} {:.3} min altitude/lmax {:.3} normal {:.3}",
            l[0],
            l[1],
            l[2],
            area2 / lmax / lmax,
            (p[1] - p[0]).cross(p[2] - p[0]).normalize()
        );
        for (k, &i) in tri.iter().enumerate() {
            eprintln!("     p{k} {} n {:.3}", p[k], hull.normals[i as usize]);
        }
        for q in hull.apexes[t].iter().flatten() {
            eprintln!("     apex {q:.4}");
        }
    }
}

#[test]
#[ignore = "diagnostic survey for humans"]
fn survey_double_torus() {
    let (m, normals) = load("double_torus_poly.obj");
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
    eprintln!(
        "cases {:?} sides {:?} flips {}",
        rep.cases, rep.sides, rep.flipped_folds
    );
    let v = inner::verify(&hull);
    eprintln!("{} violations", v.len());
    for x in &v {
        eprintln!("VIOL {:?}: {}", x.kind, x.message);
    }
    eprintln!(
        "unseparable {:?} adjusted {:?}",
        rep.unseparable, rep.adjusted_normals
    );
    let edges = hull.edges().unwrap();
    for (ei, e) in edges.iter().enumerate() {
        if ![
            435usize, 835, 849, 862, 870, 1197, 1255, 1280, 1281, 1283, 1297, 1298,
        ]
        .contains(&ei)
        {
            continue;
        }
        eprintln!(
            "EDGE {ei} {:?} faces {:?} elements {} {}",
            e.v, e.faces, hull.element[e.faces[0] as usize], hull.element[e.faces[1] as usize]
        );
    }
    let mut bad = 0;
    for (t, tri) in hull.triangles.iter().enumerate() {
        for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
            let Some(q) = hull.apexes[t][side] else {
                continue;
            };
            for &i in tri {
                let (p, n) = (hull.points[i as usize], hull.normals[i as usize]);
                let h = sign * n.dot(q - p);
                if h <= 0.0 {
                    bad += 1;
                    eprintln!(
                        "TANG tri {t} el {} side {side} point {i} h {h:.3e}",
                        hull.element[t]
                    );
                }
            }
        }
    }
    eprintln!(
        "{bad} apexes on the wrong side of a base vertex's tangent plane; lifted {}",
        rep.lifted_apexes
    );
    let complex = apatch::scheme::cubic_c1::build(&hull, &Default::default()).unwrap();
    let r = apatch::check::check(&complex, &Default::default());
    eprintln!("HOLES {:?}", r.holes);
    let topo = mesh::Topology::new(m.positions.len(), &m.faces);
    let els: Vec<u32> = std::env::var("ELS")
        .unwrap_or("1,138,205,211,213,221,222".into())
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    for &el in &els {
        let fan = topo.vertex_fan(el).unwrap();
        eprintln!(
            "element {el} at {} n {:.3} valence {}",
            m.positions[el as usize],
            normals[el as usize],
            fan.faces.len()
        );
        for (i, &f) in fan.faces.iter().enumerate() {
            let face = &m.faces[f as usize];
            let k = face.iter().position(|&x| x == el).unwrap();
            let nrm = mesh::geometry::area_vector(&m.positions, face).normalize();
            let ang = mesh::geometry::corner_angle(&m.positions, face, k, nrm).to_degrees();
            let w = fan.ring[(i + 1) % fan.ring.len()];
            let g = fan.faces[(i + 1) % fan.faces.len()];
            let gf = &m.faces[g as usize];
            let gc = gf.iter().map(|&x| m.positions[x as usize]).sum::<DVec3>() / gf.len() as f64;
            let dih = nrm.dot(gc - m.positions[el as usize]);
            eprintln!(
                "   face {f} ({} sides) angle {ang:.1}; edge to {w} next face {g}: {}",
                face.len(),
                if dih < 0.0 { "convex" } else { "concave" }
            );
        }
        dump_element(&hull, el);
    }
}

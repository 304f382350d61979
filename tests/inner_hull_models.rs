//! The inner hull (1994) on every model in `scenes/models/`: builds (or gives a clear error) and
//! `verify` accepts it.

use apatch::hull::inner::{self, verify::euler_characteristic, InnerOptions};
use apatch::mesh::{self, NormalMethod};
use std::path::Path;

fn run(name: &str) -> Result<(usize, Vec<String>), String> {
    let path = Path::new("scenes/models").join(name);
    let (m, report) = mesh::load(&path).map_err(|e| e.to_string())?;
    report.require(true).map_err(|e| e.to_string())?;
    let normals =
        mesh::vertex_normals(&m, NormalMethod::default_for(&m)).map_err(|e| e.to_string())?;
    let (hull, rep) = inner::build_with_report(&m, &normals, &InnerOptions::default())
        .map_err(|e| e.to_string())?;
    let v = inner::verify(&hull);
    let topo = mesh::Topology::new(m.positions.len(), &m.faces);
    let chi = m.positions.len() as i64 - topo.edges.len() as i64 + m.faces.len() as i64;
    let mut msgs: Vec<String> = v
        .iter()
        .map(|x| format!("{:?}: {}", x.kind, x.message))
        .collect();
    if euler_characteristic(&hull) != Some(chi) {
        msgs.push(format!("euler {:?} != {chi}", euler_characteristic(&hull)));
    }
    eprintln!(
        "{name}: {} tris, cases {:?}, adjusted {}, split {}, unsep {}",
        hull.triangles.len(),
        rep.cases,
        rep.adjusted_normals.len(),
        rep.split_faces.len(),
        rep.unseparable.len()
    );
    Ok((hull.triangles.len(), msgs))
}

#[test]
#[ignore = "exploration"]
fn explore_all() {
    for e in std::fs::read_dir("scenes/models").unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        let only = std::env::var("MODEL").unwrap_or_default();
        if !name.ends_with(".obj") || !name.contains(&only) {
            continue;
        }
        match run(&name) {
            Ok((n, msgs)) => {
                let mut kinds = std::collections::BTreeMap::new();
                for m in &msgs {
                    *kinds
                        .entry(m.split(':').next().unwrap().to_string())
                        .or_insert(0) += 1;
                }
                eprintln!(
                    "  {name}: {n} triangles, {} violations {kinds:?}",
                    msgs.len()
                );
                for m in msgs.iter().take(8) {
                    eprintln!("    {m}");
                }
            }
            Err(e) => eprintln!("  {name}: ERROR {e}"),
        }
    }
}

#[test]
#[ignore = "exploration"]
fn debug_one() {
    let name = std::env::var("MODEL").unwrap();
    let tri: usize = std::env::var("TRI").unwrap().parse().unwrap();
    let path = Path::new("scenes/models").join(&name);
    let (m, _) = mesh::load(&path).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::default_for(&m)).unwrap();
    let hull = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
    let t = hull.triangles[tri];
    let e = hull.element[tri] as usize;
    eprintln!("vertex {e} at {} n {}", m.positions[e], normals[e]);
    for &i in &t {
        eprintln!(
            "  point {i} {:?} at {} n {}",
            hull.origins[i as usize], hull.points[i as usize], hull.normals[i as usize]
        );
    }
    eprintln!("  apexes {:?}", hull.apexes[tri]);
    for &i in &t {
        let (p, n) = (hull.points[i as usize], hull.normals[i as usize]);
        let others: Vec<f64> = t
            .iter()
            .map(|&j| hull.points[j as usize])
            .chain(hull.apexes[tri].iter().flatten().copied())
            .map(|x| n.dot(x - p))
            .collect();
        eprintln!("  at {i}: {others:?}");
    }
}

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
        if !name.ends_with(".obj") {
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
                for m in msgs.iter().take(3) {
                    eprintln!("    {m}");
                }
            }
            Err(e) => eprintln!("  {name}: ERROR {e}"),
        }
    }
}

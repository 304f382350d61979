//! Cross-check of the mesh module's own OBJ parser against tobj (an independent reader, built
//! with f64 positions): on every model shipped in `scenes/models/`, both see the same polygons
//! at the same places. Faces are compared as sorted lists of (arity, centroid), since our loader
//! welds duplicate vertices and may re-orient faces, which changes indices and corner order but
//! not where a face is.

use apatch::mesh;
use std::path::Path;

type Key = (usize, [f64; 3]);

fn sorted(mut v: Vec<Key>) -> Vec<Key> {
    v.sort_by(|a, b| {
        a.0.cmp(&b.0)
            .then(a.1[0].total_cmp(&b.1[0]))
            .then(a.1[1].total_cmp(&b.1[1]))
            .then(a.1[2].total_cmp(&b.1[2]))
    });
    v
}

fn centroid(points: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let mut c = [0.0; 3];
    let mut n = 0.0;
    for p in points {
        for k in 0..3 {
            c[k] += p[k];
        }
        n += 1.0;
    }
    c.map(|x| x / n)
}

fn tobj_faces(path: &Path) -> Vec<Key> {
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj(path, &opts).expect("tobj reads every shipped model");
    let mut out = Vec::new();
    for m in models {
        let mesh = &m.mesh;
        let pos = |i: u32| {
            let i = i as usize * 3;
            [
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            ]
        };
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut at = 0;
        for a in arities {
            let face = &mesh.indices[at..at + a];
            out.push((a, centroid(face.iter().map(|&i| pos(i)))));
            at += a;
        }
    }
    sorted(out)
}

fn our_faces(path: &Path) -> Vec<Key> {
    let (m, _) = mesh::load(path).unwrap_or_else(|e| panic!("{e}"));
    // A vertex split off a non-manifold vertex (`split_vertex`) is appended with the line of its
    // original and moved a relative 1e-6 into its fan: put it back where the file has it, so both
    // readers see the file's coordinates.
    let mut by_line = std::collections::HashMap::new();
    for (v, &line) in m.vertex_lines.iter().enumerate() {
        by_line.entry(line).or_insert(v);
    }
    let file_position = |i: u32| m.positions[by_line[&m.vertex_lines[i as usize]]].to_array();
    sorted(
        m.faces
            .iter()
            .map(|f| (f.len(), centroid(f.iter().map(|&i| file_position(i)))))
            .collect(),
    )
}

#[test]
fn own_obj_parser_agrees_with_tobj() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    files.sort();
    assert!(files.len() >= 10);
    for f in files {
        let (a, b) = (tobj_faces(&f), our_faces(&f));
        assert_eq!(a.len(), b.len(), "{}: face count", f.display());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.0, y.0, "{}: arity", f.display());
            // Same decimal input parsed to f64 by both readers, summed in possibly another
            // corner order: a few ulps of the coordinates' magnitude.
            let scale = 1.0 + x.1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for k in 0..3 {
                assert!(
                    (x.1[k] - y.1[k]).abs() <= 1e-12 * scale,
                    "{}: centroid {:?} vs {:?}",
                    f.display(),
                    x.1,
                    y.1
                );
            }
        }
    }
}

use apatch::hull::outer::{self, refine::RefineMesh, HullOptions, NO_FACE};
use apatch::mesh::{self, Mesh, NormalMethod};
use glam::DVec3;
use std::collections::HashMap;

fn subdivide(pos: &[DVec3], tris: &[[u32; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (emap, face_edges) = outer::edge_map(pos.len(), tris).unwrap();
    let index: HashMap<(u32, u32), usize> = emap
        .iter()
        .enumerate()
        .map(|(i, (v, _))| ((v[0].min(v[1]), v[0].max(v[1])), i))
        .collect();
    let third = |f: u32, a: u32, b: u32| -> u32 {
        *tris[f as usize]
            .iter()
            .find(|&&v| v != a && v != b)
            .unwrap()
    };
    let mut bnd: HashMap<u32, Vec<u32>> = HashMap::new();
    for (v, faces) in &emap {
        if faces[1] == NO_FACE {
            bnd.entry(v[0]).or_default().push(v[1]);
            bnd.entry(v[1]).or_default().push(v[0]);
        }
    }
    let p = |i: u32| pos[i as usize];
    let wing = |f: u32, x: u32, z: u32| -> DVec3 {
        let y = third(f, x, z);
        match emap[index[&(x.min(z), x.max(z))]].1 {
            [g, h] if h != NO_FACE => {
                let o = if g == f { h } else { g };
                p(third(o, x, z))
            }
            _ => p(x) + p(z) - p(y),
        }
    };
    let mut out = pos.to_vec();
    let mut newv = vec![0u32; emap.len()];
    for (e, ([a, b], [f0, f1])) in emap.iter().enumerate() {
        let (a, b, f0, f1) = (*a, *b, *f0, *f1);
        let pm = if f1 == NO_FACE {
            let outer = |v: u32, other: u32| -> Option<u32> {
                let nb = bnd.get(&v)?;
                (nb.len() == 2).then(|| if nb[0] == other { nb[1] } else { nb[0] })
            };
            match (outer(a, b), outer(b, a)) {
                (Some(x), Some(y)) if x != y => (9.0 * (p(a) + p(b)) - p(x) - p(y)) / 16.0,
                _ => 0.5 * (p(a) + p(b)),
            }
        } else {
            let k = third(f0, a, b);
            let l = third(f1, a, b);
            0.5 * (p(a) + p(b)) + 0.125 * (p(k) + p(l))
                - (wing(f0, a, k) + wing(f0, b, k) + wing(f1, a, l) + wing(f1, b, l)) / 16.0
        };
        newv[e] = out.len() as u32;
        out.push(pm);
    }
    let mut nt = Vec::new();
    for (f, t) in tris.iter().enumerate() {
        let m: [u32; 3] = std::array::from_fn(|c| newv[face_edges[f][c] as usize]);
        nt.push([t[0], m[0], m[2]]);
        nt.push([m[0], t[1], m[1]]);
        nt.push([m[2], m[1], t[2]]);
        nt.push([m[0], m[1], m[2]]);
    }
    (out, nt)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .map_or("scenes/models/teapot_npm.obj", |s| s.as_str());
    let eps: f64 = args.get(2).map_or(0.05, |s| s.parse().unwrap());
    let rounds: usize = args.get(3).map_or(4, |s| s.parse().unwrap());
    let levels: usize = args.get(4).map_or(1, |s| s.parse().unwrap());
    let nmeth: NormalMethod = std::env::var("NORMALS")
        .unwrap_or("angle".into())
        .parse()
        .unwrap();
    let (m, _) = mesh::load(path.as_ref()).unwrap();
    let tri = mesh::triangulate(&m);
    let mut pos = tri.positions.clone();
    let mut tris: Vec<[u32; 3]> = tri.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    for _ in 0..levels {
        let (p, t) = subdivide(&pos, &tris);
        pos = p;
        tris = t;
    }
    let sm = Mesh::new(pos.clone(), tris.iter().map(|t| t.to_vec()).collect());
    let vn = mesh::vertex_normals(&sm, nmeth).unwrap();
    let nt = tris.len() as u32;
    let mut rm = RefineMesh {
        positions: pos,
        normals: vn,
        triangles: tris,
        origin: (0..nt).collect(),
    };
    let hopts = HullOptions { epsilon: eps };
    for round in 0..=rounds {
        let hull = match outer::build(&rm.positions, &rm.triangles, &rm.normals, &hopts) {
            Ok(h) => h,
            Err(e) => {
                println!("build error {e}");
                return;
            }
        };
        let bad = hull.bad_edges(&rm.positions, &rm.triangles);
        println!(
            "round {round}: {} vertices {} tris, {} bad edges",
            rm.positions.len(),
            rm.triangles.len(),
            bad.len()
        );
        for &e in bad.iter().take(if round == rounds { 10 } else { 3 }) {
            let ed = hull.edges[e as usize];
            let [f0, f1] = ed.faces.map(|f| f as usize);
            println!(
                "  at {:.3?} edge {}-{} n·n {:.3} tmin {:.3e}/{:.3e} tmax {:.3e}/{:.3e} eps {:.3e}",
                rm.positions[ed.v[0] as usize],
                ed.v[0],
                ed.v[1],
                hull.faces[f0].normal.dot(hull.faces[f1].normal),
                hull.faces[f0].t_min,
                hull.faces[f1].t_min,
                hull.faces[f0].t_max,
                hull.faces[f1].t_max,
                hull.faces[f0].epsilon
            );
        }
        if bad.is_empty() || round == rounds {
            break;
        }
        split_edges2(&mut rm, &bad, std::env::var("MID").is_ok()).unwrap();
    }
}

fn split_edges2(
    mesh: &mut RefineMesh,
    edges: &[u32],
    midpoint: bool,
) -> apatch::error::Result<usize> {
    let (emap, _) = outer::edge_map(mesh.positions.len(), &mesh.triangles)?;
    let mut touched = vec![false; mesh.triangles.len()];
    let mut split = 0;
    let third = |tri: &[u32; 3], a: u32, b: u32| -> u32 {
        *tri.iter().find(|&&v| v != a && v != b).unwrap_or(&a)
    };
    // The wing vertex across edge (x, y) from triangle `f`.
    let wing = |f: u32, x: u32, y: u32, tris: &[[u32; 3]]| -> Option<u32> {
        let (_, faces) = emap
            .iter()
            .find(|(v, _)| (v[0] == x && v[1] == y) || (v[0] == y && v[1] == x))?;
        let g = if faces[0] == f { faces[1] } else { faces[0] };
        (g != NO_FACE).then(|| third(&tris[g as usize], x, y))
    };
    for &e in edges {
        let ([a, b], [f0, f1]) = emap[e as usize];
        if f1 == NO_FACE || touched[f0 as usize] || touched[f1 as usize] {
            continue;
        }
        let tris = mesh.triangles.clone();
        let k = third(&tris[f0 as usize], a, b);
        let l = third(&tris[f1 as usize], a, b);
        let wings = [
            wing(f0, a, k, &tris),
            wing(f0, b, k, &tris),
            wing(f1, a, l, &tris),
            wing(f1, b, l, &tris),
        ];
        let p = |i: u32| mesh.positions[i as usize];
        let n = |i: u32| mesh.normals[i as usize];
        let (pm, nm) = if !midpoint && wings.iter().all(Option::is_some) {
            let w: Vec<u32> = wings.iter().map(|x| x.unwrap_or(a)).collect();
            let pm = 0.5 * (p(a) + p(b)) + 0.125 * (p(k) + p(l))
                - (p(w[0]) + p(w[1]) + p(w[2]) + p(w[3])) / 16.0;
            let nm = 0.5 * (n(a) + n(b)) + 0.125 * (n(k) + n(l))
                - (n(w[0]) + n(w[1]) + n(w[2]) + n(w[3])) / 16.0;
            (pm, nm)
        } else {
            (0.5 * (p(a) + p(b)), n(a) + n(b))
        };
        let nm = nm
            .try_normalize()
            .or_else(|| (n(a) + n(b)).try_normalize())
            .unwrap_or(n(a));
        // Every corner normal must stay strictly above the four new triangles; otherwise
        // split at the plain midpoint (new triangles in the old planes, normal n_a + n_b).
        let above = |pm: DVec3, nm: DVec3| -> bool {
            [(a, k), (b, k), (a, l), (b, l)].iter().all(|&(x, z)| {
                let f = (p(x) - pm).cross(p(z) - pm);
                let s = n(x) + n(z) + nm;
                let f = if f.dot(s) < 0.0 { -f } else { f };
                let Some(f) = f.try_normalize() else {
                    return false;
                };
                [n(x), n(z), nm].iter().all(|v| f.dot(*v) > 1e-9)
            })
        };
        let (pm, nm) = if above(pm, nm) {
            (pm, nm)
        } else {
            let mid = 0.5 * (p(a) + p(b));
            (mid, (n(a) + n(b)).try_normalize().unwrap_or(n(a)))
        };
        let m = mesh.positions.len() as u32;
        mesh.positions.push(pm);
        mesh.normals.push(nm);
        for f in [f0, f1] {
            let tri = mesh.triangles[f as usize];
            let c = (0..3)
                .find(|&c| {
                    let (x, y) = (tri[c], tri[(c + 1) % 3]);
                    (x == a && y == b) || (x == b && y == a)
                })
                .unwrap_or(0);
            let (x, y, z) = (tri[c], tri[(c + 1) % 3], tri[(c + 2) % 3]);
            mesh.triangles[f as usize] = [x, m, z];
            mesh.triangles.push([m, y, z]);
            mesh.origin.push(mesh.origin[f as usize]);
            touched[f as usize] = true;
            touched.push(true);
        }
        split += 1;
    }
    Ok(split)
}

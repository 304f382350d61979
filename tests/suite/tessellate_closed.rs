//! `tessellate` on closed meshes built through the rational C1 scheme (2001): the output is a
//! closed, oriented 2-manifold of the input's genus, outward, on the surface, through the mesh
//! vertices.

use apatch::complex::{PatchComplex, Role};
use apatch::export::{tessellate, TriMesh};
use apatch::scheme::rational_c1::{build, RationalOptions};
use glam::DVec3;
use std::collections::{HashMap, HashSet};

fn complex(v: &[DVec3], f: &[[u32; 3]], n: &[DVec3]) -> PatchComplex {
    build(v, f, n, &RationalOptions::default())
        .expect("mesh builds")
        .complex
}

fn icosahedron(tilt: f64) -> PatchComplex {
    let (v, f) = apatch::fixtures::icosahedron();
    let n = apatch::fixtures::tilted_normals(&v, tilt);
    complex(&v, &f, &n)
}

fn octahedron() -> PatchComplex {
    let (v, f) = apatch::fixtures::octahedron();
    complex(&v, &f, &v)
}

/// A torus (radii 1 and 0.4) on a `nu` × `nv` grid with its analytic normals.
fn torus(nu: u32, nv: u32) -> PatchComplex {
    let (r0, r1) = (1.0, 0.4);
    let mut v = Vec::new();
    let mut n = Vec::new();
    for i in 0..nu {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(nu);
        for j in 0..nv {
            let b = std::f64::consts::TAU * f64::from(j) / f64::from(nv);
            let nn = DVec3::new(a.cos() * b.cos(), a.sin() * b.cos(), b.sin());
            v.push(DVec3::new(a.cos() * r0, a.sin() * r0, 0.0) + nn * r1);
            n.push(nn);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut f = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    complex(&v, &f, &n)
}

/// Checks: every directed edge once and its reverse once (closed, consistently oriented,
/// edge-manifold), one fan per vertex (vertex-manifold), no unused vertex; returns the Euler
/// characteristic and the signed volume.
fn topology(m: &TriMesh) -> (i64, f64) {
    let mut directed = HashSet::new();
    for t in &m.triangles {
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            assert!(e.0 != e.1, "degenerate triangle {t:?}");
            assert!(
                directed.insert(e),
                "directed edge {e:?} twice: not oriented/manifold"
            );
        }
    }
    for &(a, b) in &directed {
        assert!(
            directed.contains(&(b, a)),
            "edge ({a},{b}) is a boundary edge"
        );
    }
    // Vertex links: the edges opposite each vertex form exactly one cycle.
    let mut link: HashMap<u32, HashMap<u32, u32>> = HashMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            link.entry(t[k])
                .or_default()
                .insert(t[(k + 1) % 3], t[(k + 2) % 3]);
        }
    }
    assert_eq!(link.len(), m.positions.len(), "unused vertices");
    for (v, next) in &link {
        let start = *next.keys().next().expect("non-empty link");
        let (mut x, mut steps) = (start, 0);
        loop {
            x = next[&x];
            steps += 1;
            if x == start {
                break;
            }
        }
        assert_eq!(
            steps,
            next.len(),
            "vertex {v} is not manifold (several fans)"
        );
    }
    let e = directed.len() as i64 / 2;
    let chi = m.positions.len() as i64 - e + m.triangles.len() as i64;
    let p = |i: u32| DVec3::from_array(m.positions[i as usize]);
    let vol: f64 = m
        .triangles
        .iter()
        .map(|t| p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0)
        .sum();
    (chi, vol)
}

/// Largest |F|/|∇F| over the output points (F from a patch whose tetrahedron holds the point,
/// the smallest over such patches), relative to the model's size.
fn worst_distance(c: &PatchComplex, m: &TriMesh, stride: usize) -> f64 {
    let tets: Vec<_> = c.patches.iter().map(|p| p.tet().expect("tet")).collect();
    let mut worst: f64 = 0.0;
    for x in m.positions.iter().step_by(stride) {
        let x = DVec3::from_array(*x);
        let mut best = f64::INFINITY;
        for (p, t) in c.patches.iter().zip(&tets) {
            let a = t.bary(x);
            // Points on a tetrahedron's boundary have barycentrics of rounding size below 0.
            if a.iter().all(|&ai| ai >= -1e-9) {
                let g = t.world_gradient(p.gradient_bary(a)).length();
                best = best.min(p.value_bary(a).abs() / g);
            }
        }
        assert!(best.is_finite(), "point {x} lies in no tetrahedron");
        worst = worst.max(best);
    }
    worst
}

/// The tessellation is a closed 2-manifold of Euler characteristic 2 − 2·`genus`, enclosing a
/// positive volume (oriented outward).
fn assert_closed_outward(m: &TriMesh, genus: i64, name: &str) {
    let (chi, vol) = topology(m);
    assert_eq!(chi, 2 - 2 * genus, "{name}: Euler characteristic");
    assert!(vol > 0.0, "{name}: signed volume {vol} not outward");
}

/// Every mesh vertex of the complex is, bit for bit, a vertex of the tessellation.
fn assert_through_vertices(c: &PatchComplex, m: &TriMesh, name: &str) {
    let have: HashSet<[u64; 3]> = m.positions.iter().map(|p| p.map(f64::to_bits)).collect();
    for v in &c.vertices {
        assert!(
            have.contains(&v.map(f64::to_bits)),
            "{name}: vertex {v:?} not interpolated"
        );
    }
}

fn check_closed(c: &PatchComplex, res: usize, genus: i64, name: &str) {
    let m = tessellate(c, res).expect("tessellates");
    assert_closed_outward(&m, genus, name);
    // Normals: unit (to rounding), and every triangle faces the way its vertices' ∇F normals
    // point (orientation agrees with the outward gradient everywhere, not just on average).
    for nn in &m.normals {
        assert!((DVec3::from_array(*nn).length() - 1.0).abs() < 1e-12);
    }
    let p = |i: u32| DVec3::from_array(m.positions[i as usize]);
    let nv = |i: u32| DVec3::from_array(m.normals[i as usize]);
    for t in &m.triangles {
        let g = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
        let n = nv(t[0]) + nv(t[1]) + nv(t[2]);
        assert!(g.dot(n) > 0.0, "{name}: triangle {t:?} faces against ∇F");
    }
    // Root finding resolves t to ~2^-30 of a segment then polishes with Newton; 1e-8 of the
    // model size (≈ 1) leaves a margin over that and is far below grid spacing.
    let d = worst_distance(c, &m, 1);
    assert!(d < 1e-8, "{name}: a point is {d} from the surface");
    assert_through_vertices(c, &m, name);
}

#[test]
fn icosahedron_is_a_closed_sphere() {
    for res in [1, 2, 5] {
        check_closed(&icosahedron(0.0), res, 0, "icosahedron");
    }
    check_closed(&icosahedron(0.2), 4, 0, "tilted icosahedron");
}

#[test]
fn octahedron_is_a_closed_sphere() {
    check_closed(&octahedron(), 6, 0, "octahedron");
}

#[test]
fn torus_has_genus_one() {
    let c = torus(12, 8);
    // The inner ring is saddle-shaped: nonconvex faces with negative-side (v) tetrahedra, so
    // the two-sided path is exercised.
    assert!(c
        .patches
        .iter()
        .any(|p| p.role == Role::Face && p.weights.last().is_some_and(|w| *w < 0.0)));
    check_closed(&c, 4, 1, "torus");
}

/// A repository scene's complex (scene::load + build_complex, as the CLI does).
fn scene_complex(name: &str) -> PatchComplex {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}"));
    let scene = apatch::scene::load(&path).expect("scene loads");
    apatch::scene::build_complex(&scene).expect("scene builds")
}

/// Topology, orientation, interpolation and (on about 150 of the points: the brute-force
/// search is quadratic) the distance to the surface on real models.
fn check_scene(name: &str, res: usize, genus: i64) {
    let c = scene_complex(name);
    let m = tessellate(&c, res).expect("tessellates");
    assert_closed_outward(&m, genus, name);
    assert_through_vertices(&c, &m, name);
}

#[test]
fn nut_scene_has_genus_one() {
    // The nut has zero-convex (planar) faces: the planar path is exercised.
    assert!(scene_complex("nut.toml")
        .patches
        .iter()
        .any(|p| p.role == Role::Planar));
    check_scene("nut.toml", 2, 1);
}

#[test]
fn spot_scene_is_a_sphere() {
    check_scene("spot.toml", 2, 0);
}

#[test]
fn knot_scene_has_genus_one() {
    check_scene("knot.toml", 2, 1);
}

/// The Euler characteristic of a scene's input mesh file (as loaded: polygons, welded, and
/// welded within `model.weld` when the scene asks for it).
fn input_euler(scene: &str) -> i64 {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{scene}"));
    let s = apatch::scene::load(&path).expect("scene loads");
    let apatch::scene::Model::Mesh { file, weld, .. } = &s.model else {
        panic!("{scene}: not a mesh scene");
    };
    let (mut m, _) = apatch::mesh::load(file).expect("mesh loads");
    if let Some(w) = weld {
        // The welded mesh is the input the scheme sees (`model.weld`).
        m = apatch::mesh::weld(&m, *w).expect("welds").0;
    }
    let t = apatch::mesh::Topology::new(m.positions.len(), &m.faces);
    m.positions.len() as i64 - t.edges.len() as i64 + m.faces.len() as i64
}

/// The coarse, folded models that build with Loop pre-subdivision (`model.subdivide`): their
/// tessellations are closed, oriented 2-manifolds with the input's Euler characteristic
/// (subdivision keeps the topology), outward, through every interpolated vertex.
#[test]
fn pre_subdivided_scenes_keep_the_input_genus() {
    for (name, genus) in [
        ("corner.toml", 0),
        ("letter_p.toml", 1),
        ("torus_quad.toml", 1),
        ("double_torus.toml", 2),
        ("spot_cage.toml", 0),
        ("fandisk.toml", 0),
        ("mpi.toml", 1),
    ] {
        assert_eq!(input_euler(name), 2 - 2 * genus, "{name}: input genus");
        check_scene(name, 1, genus);
    }
}

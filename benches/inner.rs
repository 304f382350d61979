//! Inner hull (1994) build throughput on a torus of 100 000 planar quads (400 × 250): every
//! vertex has valence 4, so the whole of Algorithm 1 steps (4)–(5) runs; also `verify` on it.
//!
//! Run: `cargo bench --bench inner -- --warm-up-time 1 --measurement-time 2`

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{self, Mesh, NormalMethod};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;

/// A torus of `nu` × `nv` quads between meridians and parallels (planar isosceles trapezoids).
fn quad_torus(nu: usize, nv: usize) -> Mesh {
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let a = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let b = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = 1.0 + 0.4 * b.cos();
            positions.push(DVec3::new(r * a.cos(), r * a.sin(), 0.4 * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut faces = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    mesh::from_polygons(positions, faces)
        .expect("valid torus")
        .0
}

fn bench(c: &mut Criterion) {
    let m = quad_torus(400, 250);
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let opts = InnerOptions::default();
    let mut g = c.benchmark_group("inner_hull_100k_quads");
    g.sample_size(10);
    g.throughput(Throughput::Elements(m.faces.len() as u64));
    g.bench_function("build", |b| {
        b.iter(|| inner::build(black_box(&m), black_box(&normals), &opts).unwrap())
    });
    let hull = inner::build(&m, &normals, &opts).unwrap();
    let violations = inner::verify(&hull);
    eprintln!(
        "{} faces, {} hull triangles, {} violations; first: {:?}",
        m.faces.len(),
        hull.triangles.len(),
        violations.len(),
        violations.first()
    );
    g.bench_function("verify", |b| {
        b.iter(|| inner::verify(black_box(&hull)).len())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

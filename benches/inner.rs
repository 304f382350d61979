//! Inner hull (1994) build throughput on a torus of 100 000 planar quads (400 × 250): every
//! vertex has valence 4, so the whole of Algorithm 1 steps (4)–(5) runs; also `verify` on it.
//!
//! Run: `cargo bench --bench inner -- --warm-up-time 1 --measurement-time 2`

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{self, NormalMethod};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let m = apatch::fixtures::quad_torus(400, 250);
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

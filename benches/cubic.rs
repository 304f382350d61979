//! Build throughput of the 1994 C¹ cubic scheme on a ~100k-face generated model (a torus of
//! 320 × 320 quads, valence-4 vertices: Algorithm 1 step (4) at every vertex).
//! Run: `cargo bench --bench cubic -- --warm-up-time 1 --measurement-time 2`.
//! `inner_hull+cubic` is the whole pipeline from the mesh; `cubic` the scheme alone on a
//! prebuilt hull. Throughput is in input faces per second.

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{vertex_normals, NormalMethod};
use apatch::scheme::cubic_c1::{build, CubicOptions};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn bench(c: &mut Criterion) {
    let mesh = apatch::fixtures::quad_torus(320, 320);
    let normals = vertex_normals(&mesh, NormalMethod::Angle).expect("normals");
    let hull = inner::build(&mesh, &normals, &InnerOptions::default()).expect("hull");
    let mut g = c.benchmark_group("cubic_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(mesh.faces.len() as u64));
    g.bench_function("torus_quads_102k/cubic", |b| {
        b.iter(|| build(&hull, &CubicOptions::default()).expect("builds"))
    });
    g.bench_function("torus_quads_102k/inner_hull+cubic", |b| {
        b.iter(|| {
            let h = inner::build(&mesh, &normals, &InnerOptions::default()).expect("hull");
            build(&h, &CubicOptions::default()).expect("builds")
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

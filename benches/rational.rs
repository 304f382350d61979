//! Build throughput of the rational C¹ scheme on ~100k-triangle generated models.
//! Run: `cargo bench --bench rational -- --warm-up-time 1 --measurement-time 2`.

use apatch::scheme::rational_c1::{build, RationalOptions};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;

fn noisy_sphere(levels: usize, amp: f64) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>) {
    let (v, f) = apatch::fixtures::icosahedron();
    let (mut v, f) = apatch::fixtures::subdivide_sphere(&v, &f, levels);
    // Seeded radial noise; normals: the exact sphere's (smooth data on a bumpy mesh).
    let mut s = 12345u64;
    let n = v.clone();
    for p in &mut v {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let r = ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
        *p *= 1.0 + amp * r;
    }
    (v, f, n)
}

fn torus(m: usize, k: usize) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>) {
    apatch::fixtures::torus(1.0, 0.4, m, k)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("rational_build");
    g.sample_size(10);
    for (name, (v, f, n)) in [
        ("sphere_82k", noisy_sphere(6, 0.0)),
        ("noisy_sphere_82k", noisy_sphere(6, 0.002)),
        ("torus_100k", torus(224, 224)),
    ] {
        g.throughput(Throughput::Elements(f.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| build(&v, &f, &n, &RationalOptions::default()).expect("builds"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

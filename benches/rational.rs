//! Build throughput of the rational C¹ scheme on ~100k-triangle generated models.
//! Run: `cargo bench --bench rational -- --warm-up-time 1 --measurement-time 2`.

use apatch::scheme::rational_c1::{build, RationalOptions};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use std::collections::HashMap;

fn noisy_sphere(levels: usize, amp: f64) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>) {
    let (mut v, mut f) = apatch::fixtures::icosahedron();
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        for t in &f {
            let mut m = |a: u32, b: u32| -> u32 {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    v.push((v[a as usize] + v[b as usize]).normalize());
                    (v.len() - 1) as u32
                })
            };
            let (ab, bc, ca) = (m(t[0], t[1]), m(t[1], t[2]), m(t[2], t[0]));
            nf.extend([[t[0], ab, ca], [t[1], bc, ab], [t[2], ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
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
    let (big, small) = (1.0, 0.4);
    let mut v = Vec::new();
    let mut n = Vec::new();
    for i in 0..m {
        let u = i as f64 / m as f64 * std::f64::consts::TAU;
        for j in 0..k {
            let w = j as f64 / k as f64 * std::f64::consts::TAU;
            let dir = DVec3::new(u.cos(), u.sin(), 0.0);
            let nn = dir * w.cos() + DVec3::Z * w.sin();
            v.push(dir * big + nn * small);
            n.push(nn);
        }
    }
    let id = |i: usize, j: usize| ((i % m) * k + (j % k)) as u32;
    let mut f = Vec::new();
    for i in 0..m {
        for j in 0..k {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f, n)
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

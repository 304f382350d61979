//! Build throughput of the rational C¹ scheme on ~100k-triangle generated models.
//! Run: `cargo bench --bench rational -- --warm-up-time 1 --measurement-time 2`.
//!
//! Before the criterion group (wall time only) it prints, per model, the median of
//! `APATCH_BENCH_ROUNDS` (default 5) builds on 1 and on 2 threads, interleaved so that both
//! thread counts see the same machine load: triangles per wall second and triangles per
//! CPU-second (process CPU time, which on the shared machine is far steadier than wall time),
//! with the load average before and after. `APATCH_BENCH_ROUNDS=0` skips it.

#[path = "support/cpu.rs"]
mod cpu;

use apatch::scheme::rational_c1::{build, RationalOptions};
use cpu::{cpu_seconds, load_average, median};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use std::time::Instant;

type Model = (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>);

fn noisy_sphere(levels: usize, amp: f64) -> Model {
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

fn torus(m: usize, k: usize) -> Model {
    apatch::fixtures::torus(1.0, 0.4, m, k)
}

fn models() -> Vec<(&'static str, Model)> {
    vec![
        ("sphere_82k", noisy_sphere(6, 0.0)),
        ("noisy_sphere_82k", noisy_sphere(6, 0.002)),
        ("torus_100k", torus(224, 224)),
    ]
}

/// The 1-, 5- and 15-minute load averages (Linux), or "?".
/// Median triangles per wall second and per CPU-second on 1 and 2 threads (see the module
/// docs). The dropping of each result is outside the measured span.
fn cpu_report(models: &[(&'static str, Model)]) {
    let rounds: usize = std::env::var("APATCH_BENCH_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    if rounds == 0 {
        return;
    }
    let pools: Vec<rayon::ThreadPool> = [1, 2]
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("thread pool")
        })
        .collect();
    println!(
        "rational_build per CPU-second, load average {}",
        load_average()
    );
    for (name, (v, f, n)) in models {
        let mut wall = [Vec::new(), Vec::new()];
        let mut cpu = [Vec::new(), Vec::new()];
        for _ in 0..rounds {
            for (k, pool) in pools.iter().enumerate() {
                let (t, c) = (Instant::now(), cpu_seconds());
                let b = pool.install(|| build(v, f, n, &RationalOptions::default()));
                let (t, c) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
                drop(b.expect("builds"));
                wall[k].push(f.len() as f64 / t);
                cpu[k].push(f.len() as f64 / c);
            }
        }
        for k in 0..2 {
            println!(
                "  {name}, {} thread(s): {:.0} triangles/s wall, {:.0} triangles per CPU-second \
                 (medians of {rounds})",
                k + 1,
                median(wall[k].clone()),
                median(cpu[k].clone())
            );
        }
    }
    println!("  load average after: {}", load_average());
}

fn bench(c: &mut Criterion) {
    let models = models();
    cpu_report(&models);
    let mut g = c.benchmark_group("rational_build");
    g.sample_size(10);
    for (name, (v, f, n)) in &models {
        g.throughput(Throughput::Elements(f.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| build(v, f, n, &RationalOptions::default()).expect("builds"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

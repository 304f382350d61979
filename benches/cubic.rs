//! Build throughput of the 1994 C¹ cubic scheme on a ~100k-face generated model (a torus of
//! 320 × 320 quads, valence-4 vertices: Algorithm 1 step (4) at every vertex).
//! Run: `cargo bench --bench cubic -- --warm-up-time 1 --measurement-time 2`.
//!
//! Before the criterion group it prints, like `benches/rational.rs`, the median input faces per
//! wall second and per CPU-second of the inner hull, the cubic scheme and both together, on 1
//! and 2 threads measured in the same rounds (`APATCH_BENCH_ROUNDS`, default 3; 0 skips): on a
//! shared, loaded machine wall time mostly measures the other processes, CPU time does not.
//! `inner_hull+cubic` is the whole pipeline from the mesh; `cubic` the scheme alone on a
//! prebuilt hull. Throughput is in input faces per second.

#[path = "support/cpu.rs"]
mod cpu;

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{vertex_normals, Mesh, NormalMethod};
use apatch::scheme::cubic_c1::{build, CubicOptions};
use cpu::{cpu_seconds, load_average, median};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use std::time::Instant;

/// Median faces per wall second and per CPU-second of the hull, the scheme and both, on 1 and
/// 2 threads. Results are dropped outside the measured spans.
fn cpu_report(mesh: &Mesh, normals: &[DVec3]) {
    let rounds: usize = std::env::var("APATCH_BENCH_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    if rounds == 0 {
        return;
    }
    let faces = mesh.faces.len() as f64;
    println!(
        "cubic_build on {} quads, per CPU-second, load average {}",
        mesh.faces.len(),
        load_average()
    );
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        // [hull, scheme, both] × [wall, cpu] faces per second.
        let mut rates: [[Vec<f64>; 2]; 3] = Default::default();
        for _ in 0..rounds {
            let (t0, c0) = (Instant::now(), cpu_seconds());
            let hull = pool.install(|| inner::build(mesh, normals, &InnerOptions::default()));
            let (t1, c1) = (Instant::now(), cpu_seconds());
            let hull = hull.expect("hull");
            let (t2, c2) = (Instant::now(), cpu_seconds());
            let complex = pool.install(|| build(&hull, &CubicOptions::default()));
            let (t3, c3) = (Instant::now(), cpu_seconds());
            drop(complex.expect("builds"));
            let spans = [
                ((t1 - t0).as_secs_f64(), c1 - c0),
                ((t3 - t2).as_secs_f64(), c3 - c2),
                ((t1 - t0 + (t3 - t2)).as_secs_f64(), c1 - c0 + c3 - c2),
            ];
            for (r, (wall, cpu)) in rates.iter_mut().zip(spans) {
                r[0].push(faces / wall);
                r[1].push(faces / cpu);
            }
        }
        for (name, r) in ["inner hull", "cubic scheme", "hull + scheme"]
            .iter()
            .zip(&rates)
        {
            println!(
                "  {name}, {threads} thread(s): {:.0} faces/s wall, {:.0} faces per CPU-second \
                 (medians of {rounds})",
                median(r[0].clone()),
                median(r[1].clone())
            );
        }
    }
    println!("  load average after: {}", load_average());
}

fn bench(c: &mut Criterion) {
    let mesh = apatch::fixtures::quad_torus(320, 320);
    let normals = vertex_normals(&mesh, NormalMethod::Angle).expect("normals");
    cpu_report(&mesh, &normals);
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

//! Build timings on generated ~100k-triangle models (ignored by default; speed figures belong
//! to `benches/rational.rs`, this prints one build per model with its stage counts).
//! Run: `cargo test --release --test suite rational_throughput:: -- --ignored --nocapture`
//! (each model is built on 1 and then 2 threads in the same process; `APATCH_THREADS=n` for
//! only n). Besides wall time it prints the
//! process CPU time of the build (from `/proc/self/stat`, Linux only): on a shared, loaded
//! machine the wall time mostly measures the other processes, CPU time / threads does not.
//! `APATCH_TORUS=n` builds only the n × n torus (peak memory at several sizes).
//! `APATCH_STAGE_TIMES=1` makes the build print the cumulative wall time and the process CPU
//! time (all threads) at the end of each stage (hull, intersection test, faces, edge
//! tetrahedra, edge bounds, free values, final edge check, patch emission, freeing), to find
//! the costly and the serial ones. The load average is printed before and after.

use crate::rational_support as support;

use apatch::scheme::rational_c1::{build, RationalOptions};
use std::time::Instant;

/// User + system CPU seconds of this process (None where /proc is missing).
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 11 and 12 after the name; in ticks of
    // 1/100 s (USER_HZ on Linux).
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

#[test]
#[ignore = "timing run, not a check"]
fn build_throughput() {
    // APATCH_TORUS=<n>: only the n × n torus, for peak-memory runs at several sizes
    // (`/usr/bin/time -v`).
    let models = match std::env::var("APATCH_TORUS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        Some(n) => vec![support::torus(1.0, 0.4, n, n)],
        None => vec![
            support::sphere_model("sphere/6", 6),
            support::torus(1.0, 0.4, 224, 224),
        ],
    };
    // APATCH_THREADS=<n>: only that many threads (default: 1 then 2, in the same process, so
    // both figures see the same machine load).
    let threads: Vec<usize> = match std::env::var("APATCH_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        Some(n) => vec![n],
        None => vec![1, 2],
    };
    let load = || {
        std::fs::read_to_string("/proc/loadavg")
            .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
            .unwrap_or_else(|_| "?".into())
    };
    eprintln!("load average before: {}", load());
    for m in models {
        for &n in &threads {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("thread pool");
            let c0 = cpu_seconds();
            let t = Instant::now();
            let b = pool.install(|| {
                build(
                    &m.positions,
                    &m.triangles,
                    &m.normals,
                    &RationalOptions::default(),
                )
                .unwrap()
            });
            let s = t.elapsed().as_secs_f64();
            let cpu = c0.zip(cpu_seconds()).map_or(f64::NAN, |(a, b)| b - a);
            eprintln!(
                "{} ({n} threads): {} triangles, {} patches, refined {}, {:.3} s wall, {:.0} \
                 triangles/s wall, {:.2} s CPU, {:.0} triangles per CPU second",
                m.name,
                m.triangles.len(),
                b.complex.patches.len(),
                b.refined_edges,
                s,
                m.triangles.len() as f64 / s,
                cpu,
                m.triangles.len() as f64 / cpu
            );
            drop(b);
        }
    }
    eprintln!("load average after: {}", load());
}

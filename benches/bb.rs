//! Micro-benchmarks of the tracer's hot path: restrict a patch to a segment, then find the
//! first root. Run: `cargo bench --bench bb -- --warm-up-time 1 --measurement-time 2`.
//!
//! On a shared, loaded machine wall time overstates the cost; `APATCH_BENCH_CPU=1` measures
//! this thread's CPU time instead (`CLOCK_THREAD_CPUTIME_ID`, Linux).

use apatch::bb::{num_coeffs, poly, rational, uni, Tet};
use apatch::complex::RationalTerm;
use apatch::fixtures::{quadric_weights, Quadric};
use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;

fn tet() -> [DVec3; 4] {
    [
        DVec3::new(-1.0, -0.8, -0.6),
        DVec3::new(1.3, -0.7, -0.4),
        DVec3::new(0.1, 1.4, -0.5),
        DVec3::new(0.0, 0.1, 1.5),
    ]
}

/// A sphere's weights of degree `n` and a segment through the tetrahedron that crosses it
/// once (enters inside, leaves outside).
fn sphere_case(n: usize) -> (Vec<f64>, [f64; 4], [f64; 4]) {
    let v = tet();
    let t = Tet::new(v).expect("tetrahedron");
    let q = Quadric::sphere(DVec3::ZERO, 0.5);
    let w = quadric_weights(&q, &v, n);
    let a0 = t.bary(DVec3::new(0.05, 0.02, 0.0));
    let a1 = t.bary(DVec3::new(0.3, 0.25, 0.9));
    (w, a0, a1)
}

/// CPU time of the calling thread, in nanoseconds.
#[derive(Clone, Copy)]
struct ThreadCpuTime;

#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

extern "C" {
    fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
}

/// Linux's CLOCK_THREAD_CPUTIME_ID.
const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

fn thread_cpu_ns() -> u64 {
    let mut ts = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes to it.
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

struct NsFormatter;

impl ValueFormatter for NsFormatter {
    fn scale_values(&self, _typical: f64, _values: &mut [f64]) -> &'static str {
        "ns (cpu)"
    }
    fn scale_throughputs(
        &self,
        _typical: f64,
        _t: &Throughput,
        _values: &mut [f64],
    ) -> &'static str {
        "ns (cpu)"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns() - start
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &NsFormatter
    }
}

fn bench<M: Measurement + 'static>(c: &mut Criterion<M>) {
    for n in [3usize, 5] {
        let (w, a0, a1) = sphere_case(n);
        let mut out = [0.0; 16];
        let len = poly::restrict(n, &w, a0, a1, &mut out);
        assert!(
            uni::first_root(&out[..len]).is_some(),
            "the segment must hold a root"
        );
        c.bench_function(&format!("restrict+first_root degree {n}"), |b| {
            b.iter(|| {
                let mut out = [0.0; 16];
                let len = poly::restrict(n, black_box(&w), black_box(a0), black_box(a1), &mut out);
                uni::first_root(&out[..len])
            })
        });
        c.bench_function(&format!("restrict degree {n}"), |b| {
            b.iter(|| {
                let mut out = [0.0; 16];
                poly::restrict(n, black_box(&w), black_box(a0), black_box(a1), &mut out);
                out
            })
        });
        let coeffs = out;
        c.bench_function(&format!("first_root degree {n}"), |b| {
            b.iter(|| uni::first_root(black_box(&coeffs[..len])))
        });
    }

    // A segment through the whole sphere: two roots, so the search must subdivide.
    for n in [3usize, 5] {
        let v = tet();
        let t = Tet::new(v).expect("tetrahedron");
        let w = quadric_weights(&Quadric::sphere(DVec3::ZERO, 0.5), &v, n);
        let a0 = t.bary(DVec3::new(-0.45, -0.3, -0.2));
        let a1 = t.bary(DVec3::new(0.45, 0.3, 0.2));
        c.bench_function(&format!("restrict+first_root two roots degree {n}"), |b| {
            b.iter(|| {
                let mut out = [0.0; 16];
                let len = poly::restrict(n, black_box(&w), black_box(a0), black_box(a1), &mut out);
                uni::first_root(&out[..len])
            })
        });
    }

    // The 2001 face patch: cubic plus one rational term (degree 5 once cleared).
    let (w, a0, a1) = sphere_case(3);
    let mut w = w;
    w[apatch::bb::index_of([1, 1, 1, 0])] = 0.0;
    let face = [RationalTerm {
        index: [1, 1, 1, 0],
        terms: [
            (0.2, [0, 1, 1, 0]),
            (-0.1, [1, 0, 1, 0]),
            (0.05, [1, 1, 0, 0]),
        ]
        .into(),
    }];
    let mut out = [0.0; 16];
    let len = rational::segment_poly(3, &w, &face, a0, a1, &mut out);
    assert_eq!(len, 6);
    assert!(
        uni::first_root(&out[..len]).is_some(),
        "the segment must hold a root"
    );
    c.bench_function("rational face segment_poly+first_root", |b| {
        b.iter(|| {
            let mut out = [0.0; 16];
            let len = rational::segment_poly(
                3,
                black_box(&w),
                &face,
                black_box(a0),
                black_box(a1),
                &mut out,
            );
            uni::first_root(&out[..len])
        })
    });

    // Early exit: no sign change (a segment far outside the sphere).
    let n = 3;
    let v = tet();
    let t = Tet::new(v).expect("tetrahedron");
    let q = Quadric::sphere(DVec3::new(-0.8, -0.6, -0.4), 0.1);
    let w = quadric_weights(&q, &v, n);
    assert_eq!(w.len(), num_coeffs(n));
    let a0 = t.bary(DVec3::new(0.3, 0.3, 0.3));
    let a1 = t.bary(DVec3::new(0.0, 0.2, 1.2));
    let mut out = [0.0; 16];
    let len = poly::restrict(n, &w, a0, a1, &mut out);
    assert!(out[..len].iter().all(|&x| x > 0.0), "no sign change wanted");
    let coeffs = out;
    c.bench_function("first_root early exit degree 3", |b| {
        b.iter(|| uni::first_root(black_box(&coeffs[..len])))
    });
    c.bench_function("restrict+first_root early exit degree 3", |b| {
        b.iter(|| {
            let mut out = [0.0; 16];
            let len = poly::restrict(n, black_box(&w), black_box(a0), black_box(a1), &mut out);
            uni::first_root(&out[..len])
        })
    });
}

fn main() {
    if std::env::var_os("APATCH_BENCH_CPU").is_some() {
        let mut c = Criterion::default()
            .with_measurement(ThreadCpuTime)
            .configure_from_args();
        bench(&mut c);
        c.final_summary();
    } else {
        let mut c = Criterion::default()
            .with_measurement(WallTime)
            .configure_from_args();
        bench(&mut c);
        c.final_summary();
    }
}

//! Loading and validating a generated 1-million-triangle torus (OBJ text in memory):
//! parse + weld + orient + validate, then Loop normals.
//!
//! Run: `cargo bench --bench mesh -- --warm-up-time 1 --measurement-time 2`

use apatch::mesh::{self, Format, NormalMethod};
use criterion::{criterion_group, criterion_main, Criterion};
use std::fmt::Write;
use std::hint::black_box;
use std::path::Path;

/// OBJ text of a torus with `nu` × `nv` quads split into 2·nu·nv triangles.
fn torus_obj(nu: usize, nv: usize) -> String {
    let mut s = String::with_capacity(nu * nv * 60);
    for i in 0..nu {
        let a = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let b = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = 1.0 + 0.4 * b.cos();
            writeln!(s, "v {} {} {}", r * a.cos(), r * a.sin(), 0.4 * b.sin()).unwrap();
        }
    }
    let id = |i: usize, j: usize| (i % nu) * nv + (j % nv) + 1;
    for i in 0..nu {
        for j in 0..nv {
            let (p, q, r, t) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            writeln!(s, "f {p} {q} {r}\nf {p} {r} {t}").unwrap();
        }
    }
    s
}

fn bench(c: &mut Criterion) {
    let text = torus_obj(1000, 500);
    let mut g = c.benchmark_group("mesh_1M_triangles");
    g.sample_size(10);
    g.bench_function("load_validate", |b| {
        b.iter(|| {
            let (m, r) = mesh::load_bytes(
                black_box(text.as_bytes()),
                Format::Obj,
                Path::new("torus.obj"),
            )
            .unwrap();
            assert_eq!(m.faces.len(), 1_000_000);
            assert!(r.findings.is_empty());
            m
        })
    });
    let (m, _) = mesh::load_bytes(text.as_bytes(), Format::Obj, Path::new("torus.obj")).unwrap();
    g.bench_function("loop_normals", |b| {
        b.iter(|| mesh::vertex_normals(black_box(&m), NormalMethod::Loop).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Build timings on generated ~100k-triangle models (ignored by default; speed figures belong
//! to `benches/rational.rs`, this prints one build per model with its stage counts).
//! Run: `cargo test --release --test rational_throughput -- --ignored --nocapture`.

#[path = "rational_support.rs"]
mod support;

use apatch::scheme::rational_c1::{build, RationalOptions};
use std::time::Instant;

#[test]
#[ignore = "timing run, not a check"]
fn build_throughput() {
    for m in [
        support::sphere_model("sphere/6", 6),
        support::torus(1.0, 0.4, 224, 224),
    ] {
        let t = Instant::now();
        let b = build(
            &m.positions,
            &m.triangles,
            &m.normals,
            &RationalOptions::default(),
        )
        .unwrap();
        let s = t.elapsed().as_secs_f64();
        eprintln!(
            "{}: {} triangles, {} patches, refined {}, {:.3} s, {:.0} triangles/s",
            m.name,
            m.triangles.len(),
            b.complex.patches.len(),
            b.refined_edges,
            s,
            m.triangles.len() as f64 / s
        );
    }
}

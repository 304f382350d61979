//! Tracing throughput of C2 quintic vs C1 cubic A-patches on the same inner hull, model and
//! camera, in the same run: `cargo bench --bench quintic` (plain harness; prints a table).
//!
//! For each model the hull (`hull::inner`) is built once; `scheme::cubic_c1::build` and
//! `scheme::quintic_c2::build` fill it; both complexes are rendered with the camera of
//! `scenes/paper1994/<model>.toml` at 512×512, 1 spp, 1 thread, in `normal` mode (primary rays
//! only) and `shaded` mode (with shadow rays). The figure is primary rays per CPU-second (the
//! machine is shared), each measurement rendering for at least 0.4 CPU-s (the CPU clock ticks
//! at 10 ms and one 512×512 frame takes 50–100 ms, which made single-frame figures vary by
//! ±15 %); cubic and quintic are measured in 5 interleaved rounds and quintic/cubic is the
//! median of the per-round ratios, printed with its range (target ≥ 50 %).

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{self, NormalMethod};
use apatch::scene;
use apatch::scheme::{cubic_c1, quintic_c2};
use apatch::trace::{self, Geometry, Mode, RenderSettings};
use std::path::Path;
use std::sync::atomic::AtomicBool;

#[path = "support/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

/// Settings of one measurement: 512×512, 1 spp, 1 thread, `mode`.
fn bench_settings(settings: &RenderSettings, mode: Mode) -> RenderSettings {
    let mut s = settings.clone();
    s.camera = s.camera.resized(512, 512).unwrap();
    s.spp = 1;
    s.threads = 1;
    s.mode = mode;
    s
}

/// Renders `geo` repeatedly until at least `min_cpu` CPU-seconds have passed; returns primary
/// rays per CPU-second and the share of pixels hit. Long enough runs make the 10 ms tick of
/// the CPU clock a small error (0.4 s: ±2.5 %).
fn rays_per_cpu_second(geo: &Geometry, s: &RenderSettings, min_cpu: f64) -> (f64, f64) {
    let rays = 512.0 * 512.0;
    let c0 = cpu_seconds();
    let mut frames = 0.0;
    loop {
        let f = trace::render(geo, s, &|| {}, &AtomicBool::new(false)).unwrap();
        frames += 1.0;
        let hit = f.pixels.iter().filter(|p| p.alpha > 0.0).count() as f64 / rays;
        let cpu = cpu_seconds() - c0;
        if cpu >= min_cpu || cpu.is_nan() {
            return (frames * rays / cpu.max(0.01), hit);
        }
    }
}

/// Median of `v` (sorted in place).
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Interleaved measurement rounds per model and mode.
const ROUNDS: usize = 5;
/// CPU-seconds of rendering per measurement.
const MIN_CPU: f64 = 0.4;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["icosahedron", "dodecahedron", "torus_quad12x8", "cube_poly"] {
        let sc = match scene::load(&root.join(format!("scenes/paper1994/{name}.toml"))) {
            Ok(s) => s,
            Err(e) => {
                println!("{name}: {e:#}");
                continue;
            }
        };
        let path = root.join(format!("scenes/models/{name}.obj"));
        let (m, _) = mesh::load(&path).unwrap();
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let hull = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
        let cubic = cubic_c1::build(&hull, &cubic_c1::CubicOptions::default());
        let quintic = quintic_c2::build(&hull, &quintic_c2::QuinticOptions::default());
        let (Ok(cubic), Ok(quintic)) = (cubic, quintic) else {
            println!("{name}: a scheme does not build");
            continue;
        };
        let gc = Geometry::new(&cubic).unwrap();
        let gq = Geometry::new(&quintic).unwrap();
        println!("{name}: {} patches in both complexes", cubic.patches.len());
        for mode in [Mode::Normal, Mode::Shaded] {
            // Interleaved rounds (cubic, quintic, cubic, …) so both see the same load of the
            // shared machine; the ratio is taken per round and the median reported with its
            // range.
            let st = bench_settings(&sc.settings, mode);
            let (mut cs, mut qs, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
            let (mut c_hit, mut q_hit) = (0.0, 0.0);
            for _ in 0..ROUNDS {
                let (c, ch) = rays_per_cpu_second(&gc, &st, MIN_CPU);
                let (q, qh) = rays_per_cpu_second(&gq, &st, MIN_CPU);
                cs.push(c);
                qs.push(q);
                ratios.push(q / c);
                (c_hit, q_hit) = (ch, qh);
            }
            let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ratios.iter().copied().fold(0.0, f64::max);
            println!(
                "  {mode:?}: cubic {:.3} M rays/CPU-s ({:.0} % hit), quintic {:.3} M rays/CPU-s ({:.0} % hit): quintic/cubic = {:.0} % (median of {ROUNDS} interleaved rounds; range {:.0}–{:.0} %)",
                median(&mut cs) / 1e6,
                100.0 * c_hit,
                median(&mut qs) / 1e6,
                100.0 * q_hit,
                100.0 * median(&mut ratios),
                100.0 * lo,
                100.0 * hi
            );
        }
    }
}

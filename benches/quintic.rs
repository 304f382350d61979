//! Tracing throughput of C2 quintic vs C1 cubic A-patches on the same inner hull, model and
//! camera, in the same run: `cargo bench --bench quintic` (plain harness; prints a table).
//!
//! For each model the hull (`hull::inner`) is built once; `scheme::cubic_c1::build` and
//! `scheme::quintic_c2::build` fill it; both complexes are rendered with the camera of
//! `scenes/paper1994/<model>.toml` at 512×512, 1 spp, 1 thread, in `normal` mode (primary rays
//! only) and `shaded` mode (with shadow rays), best of three; the figure is primary rays per
//! CPU-second (the machine is shared), and quintic/cubic is the ratio the issue asks about
//! (target ≥ 50 %).

use apatch::hull::inner::{self, InnerOptions};
use apatch::mesh::{self, NormalMethod};
use apatch::scene;
use apatch::scheme::{cubic_c1, quintic_c2};
use apatch::trace::{self, Geometry, Mode, RenderSettings};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// CPU seconds used by this process so far (Linux `/proc/self/stat`, 100 ticks/s), or NaN.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    let Some(rest) = stat.rsplit_once(')').map(|r| r.1) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| {
        f.get(i)
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (tick(11) + tick(12)) / 100.0
}

/// Best-of-three primary rays per CPU-second (and per wall second) of `geo` in `mode`.
fn rays_per_second(geo: &Geometry, settings: &RenderSettings, mode: Mode) -> (f64, f64, f64) {
    let mut s = settings.clone();
    s.camera = s.camera.resized(512, 512).unwrap();
    s.spp = 1;
    s.threads = 1;
    s.mode = mode;
    let rays = 512.0 * 512.0;
    let (mut best_cpu, mut best_wall, mut hit) = (0.0_f64, 0.0_f64, 0.0);
    for _ in 0..3 {
        let (t, c) = (Instant::now(), cpu_seconds());
        let f = trace::render(geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
        let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
        best_cpu = best_cpu.max(rays / cpu.max(0.01));
        best_wall = best_wall.max(rays / wall);
        hit = f.pixels.iter().filter(|p| p.alpha > 0.0).count() as f64 / rays;
    }
    (best_cpu, best_wall, hit)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["icosahedron", "dodecahedron", "torus_quad12x8"] {
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
            let (c_cpu, c_wall, c_hit) = rays_per_second(&gc, &sc.settings, mode);
            let (q_cpu, q_wall, q_hit) = rays_per_second(&gq, &sc.settings, mode);
            println!(
                "  {mode:?}: cubic {:.3} M rays/CPU-s ({:.3} wall, {:.0} % hit), quintic {:.3} M rays/CPU-s ({:.3} wall, {:.0} % hit): quintic/cubic = {:.0} %",
                c_cpu / 1e6,
                c_wall / 1e6,
                100.0 * c_hit,
                q_cpu / 1e6,
                q_wall / 1e6,
                100.0 * q_hit,
                100.0 * q_cpu / c_cpu
            );
        }
    }
}

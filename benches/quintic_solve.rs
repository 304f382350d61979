//! Speed of the C2 quintic solve (issue 8): `cargo bench --bench quintic_solve` (plain harness;
//! prints a table). `SCENES=a.toml,b.toml` picks the scenes (default: the nut's pending quintic
//! scene, whose build takes ~10 CPU-s; the knot's takes minutes).
//!
//! For each scene: its vertex-star systems (`System::star_systems`, rows scaled to unit norm as
//! the solve's near-null pass scales them) and their near-null left singular vectors
//! (`dense::near_null_left` at σ ≤ 1e-3 σ_max, the scenes' `star_tau`), serially and on the
//! global rayon pool (`RAYON_NUM_THREADS`), then the whole build
//! (`quintic_c2::build_with_stats`). CPU seconds (the machine is shared; on a loaded machine
//! wall time mostly measures the other processes) and wall seconds. A checksum of the singular
//! values found shows that both ways compute the same numbers.

use apatch::scheme::quintic_c2::{self, dense, system, QuinticOptions};
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

#[path = "support/cpu.rs"]
mod cpu;
use cpu::{cpu_seconds, load_average};

/// The scenes' near-null threshold (`star_tau`).
const TAU: f64 = 1e-3;

/// A star's matrix with its rows scaled to unit norm (as `System::near_null_conditions`).
fn scaled(st: &system::StarSystem) -> Vec<f64> {
    let (m, n) = (st.rows, st.cols);
    let mut a = st.matrix.clone();
    for i in 0..m {
        let r = a[i * n..(i + 1) * n]
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        for x in &mut a[i * n..(i + 1) * n] {
            *x /= r;
        }
    }
    a
}

/// Sum of the singular values and of the vectors' first entries' magnitudes found: equal bits
/// for equal results.
fn checksum(found: &[Vec<(f64, Vec<f64>)>]) -> (usize, f64) {
    let mut count = 0;
    let mut sum = 0.0;
    for f in found {
        for (s, u) in f {
            count += 1;
            sum += s + u.first().map_or(0.0, |x| x.abs());
        }
    }
    (count, sum)
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scenes: Vec<PathBuf> = std::env::var("SCENES").map_or_else(
        |_| vec![root.join("scenes/paper1994/nut_quintic.toml")],
        |s| s.split(',').map(PathBuf::from).collect(),
    );
    println!(
        "threads {}, load {}",
        rayon::current_num_threads(),
        load_average()
    );
    println!("| scene | stars | shape (first) | SVDs serial CPU-s | SVDs parallel CPU-s (wall) | near-null vectors | build CPU-s (wall) |");
    println!("| --- | ---: | --- | ---: | ---: | ---: | ---: |");
    for path in scenes {
        let sc = apatch::scene::load(&path).unwrap();
        let apatch::scene::Model::Mesh { scheme, .. } = &sc.model else {
            panic!("{}: not a mesh scene", path.display());
        };
        let options = QuinticOptions::from_toml(scheme, &path).unwrap();
        let hull = apatch::scene::inner_hull(&sc).unwrap().unwrap();
        // The hull the build fills (without `contain_tangents`, which no such scene sets).
        let (completed, _) = apatch::scheme::cubic_c1::sided::complete_lu_pairs(&hull);
        let completed = if options.zero_groups {
            quintic_c2::flat::zero_coplanar_groups(&completed).0
        } else {
            completed
        };
        let (tets, _) = system::tetrahedra(&completed).unwrap();
        let sys = system::assemble(&tets, completed.points.len() as u32).unwrap();
        let stars = sys.star_systems();
        let mats: Vec<Vec<f64>> = stars.iter().map(scaled).collect();
        let svd = |k: usize| dense::near_null_left(&mats[k], stars[k].rows, stars[k].cols, TAU);

        let c0 = cpu_seconds();
        let serial: Vec<_> = (0..stars.len()).map(svd).collect();
        let serial_cpu = cpu_seconds() - c0;

        let (c0, w0) = (cpu_seconds(), Instant::now());
        let parallel: Vec<_> = (0..stars.len()).into_par_iter().map(svd).collect();
        let (par_cpu, par_wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        let (count, sum) = checksum(&serial);
        assert_eq!(
            (count, sum.to_bits()),
            {
                let (c, s) = checksum(&parallel);
                (c, s.to_bits())
            },
            "serial and parallel singular vectors differ"
        );

        let (c0, w0) = (cpu_seconds(), Instant::now());
        let built = quintic_c2::build_with_stats(&hull, &options);
        let (build_cpu, build_wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        assert!(built.is_ok(), "{}: build failed", path.display());
        let shape = stars
            .first()
            .map_or_else(String::new, |s| format!("{} × {}", s.rows, s.cols));
        println!(
            "| {} | {} | {shape} | {serial_cpu:.2} | {par_cpu:.2} ({par_wall:.2}) | {count} | {build_cpu:.2} ({build_wall:.2}) |",
            path.file_stem().unwrap_or_default().to_string_lossy(),
            stars.len(),
        );
        if let Ok(file) = std::env::var("STAR_DUMP") {
            // Opt-in: the scaled star matrices as little-endian binary (per star m, n as u64,
            // then the m·n entries row-major), for offline experiments with the SVD.
            let mut b: Vec<u8> = Vec::new();
            for (st, a) in stars.iter().zip(&mats) {
                b.extend((st.rows as u64).to_le_bytes());
                b.extend((st.cols as u64).to_le_bytes());
                for x in a {
                    b.extend(x.to_le_bytes());
                }
            }
            std::fs::write(&file, b).unwrap();
        }
    }
}

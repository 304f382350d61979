//! `apatch::compare` statistics against independent truth: analytic answers for constant
//! offsets, brute-force formulas, and a direct window-by-window SSIM.

use apatch::compare::{self, ssim, Image, Options};

/// Seeded splitmix64 → uniform [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn image(w: usize, h: usize, names: &[&str], f: &mut dyn FnMut(usize, usize) -> f32) -> Image {
    Image {
        width: w,
        height: h,
        channels: names
            .iter()
            .enumerate()
            .map(|(c, n)| ((*n).to_string(), (0..w * h).map(|i| f(c, i)).collect()))
            .collect(),
    }
}

fn smooth(w: usize, h: usize) -> Image {
    image(w, h, &["A", "B", "G", "R"], &mut |c, i| {
        let (x, y) = ((i % w) as f32, (i / w) as f32);
        0.5 + 0.3 * (0.2 * x + 0.1 * c as f32).sin() * (0.15 * y).cos()
    })
}

#[test]
fn constant_offset_gives_known_rmse_and_psnr() {
    let a = smooth(40, 30);
    let off = 0.125f32; // exactly representable: the differences are exact in f32
    let mut b = a.clone();
    for (_, v) in &mut b.channels {
        for x in v.iter_mut() {
            *x += off;
        }
    }
    let r = compare::compare(&a, &b, &Options::default()).unwrap();
    let names: Vec<&str> = r.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["R", "G", "B", "A"]);
    for c in r.channels.iter().chain(std::iter::once(&r.all)) {
        // a + 0.125 rounds in f32 (values near 0.5–0.8 have ulp 6e-8), so the difference is
        // 0.125 within a few ulps.
        assert!((c.rmse - 0.125).abs() < 1e-6, "{c:?}");
        assert!((c.mean_abs - 0.125).abs() < 1e-6);
        assert!((c.max_abs - 0.125).abs() < 1e-6);
        // PSNR = 10 log10(1 / 0.125²) = 18.0618 dB; 1e-4 dB covers the f32 rounding above.
        let want = 20.0 * 8f64.log10();
        assert!((c.psnr.unwrap() - want).abs() < 1e-4, "{c:?}");
        assert_eq!(c.above_threshold, 1.0);
    }
    // --peak 2 adds 20 log10(2) dB.
    let opts = Options {
        peak: 2.0,
        ..Options::default()
    };
    let r2 = compare::compare(&a, &b, &opts).unwrap();
    assert!((r2.all.psnr.unwrap() - r.all.psnr.unwrap() - 20.0 * 2f64.log10()).abs() < 1e-9);
    // A threshold above the offset counts no pixel.
    let opts = Options {
        threshold: 0.2,
        ..Options::default()
    };
    assert_eq!(
        compare::compare(&a, &b, &opts).unwrap().all.above_threshold,
        0.0
    );
}

#[test]
fn identical_images_have_infinite_psnr_and_unit_ssim() {
    let a = smooth(23, 17);
    let r = compare::compare(&a, &a, &Options::default()).unwrap();
    assert_eq!(r.all.rmse, 0.0);
    assert_eq!(r.all.psnr, None);
    assert_eq!(r.ssim, 1.0);
    let json = serde_json::to_value(&r).unwrap();
    assert!(json["all"]["psnr"].is_null());
    assert_eq!(json["ssim_on"], "luminance");
}

#[test]
fn random_differences_match_brute_force() {
    let (w, h) = (31, 19);
    let mut rng = Rng(7);
    let a = image(w, h, &["R", "G", "B"], &mut |_, _| rng.next() as f32);
    let b = image(w, h, &["R", "G", "B"], &mut |_, _| rng.next() as f32);
    let opts = Options {
        threshold: 0.5,
        ..Options::default()
    };
    let r = compare::compare(&a, &b, &opts).unwrap();
    let mut all_sq = 0.0;
    let mut any_above = vec![false; w * h];
    for (k, name) in ["R", "G", "B"].iter().enumerate() {
        let (x, y) = (a.channel(name).unwrap(), b.channel(name).unwrap());
        let d: Vec<f64> = x
            .iter()
            .zip(y)
            .map(|(p, q)| f64::from(*p) - f64::from(*q))
            .collect();
        let mse = d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64;
        let above = d.iter().filter(|v| v.abs() > 0.5).count();
        for (i, v) in d.iter().enumerate() {
            any_above[i] |= v.abs() > 0.5;
        }
        all_sq += mse;
        let c = &r.channels[k];
        assert_eq!(c.name, *name);
        // Same sums in another order: agreement to rounding (1e-12 relative).
        assert!((c.rmse - mse.sqrt()).abs() < 1e-12);
        assert!((c.psnr.unwrap() + 10.0 * mse.log10()).abs() < 1e-9);
        assert_eq!(c.above_threshold, above as f64 / (w * h) as f64);
        let max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert_eq!(c.max_abs, max);
    }
    assert!((r.all.rmse - (all_sq / 3.0).sqrt()).abs() < 1e-12);
    let share = any_above.iter().filter(|&&x| x).count() as f64 / (w * h) as f64;
    assert_eq!(r.all.above_threshold, share);
}

/// SSIM straight from the definition: for each valid window position, weighted means,
/// variances and covariance with the 2-D Gaussian exp(−(dx² + dy²)/(2σ²)) normalised over the
/// window.
fn direct_ssim(a: &[f64], b: &[f64], w: usize, h: usize, peak: f64) -> f64 {
    let r = 5usize.min((w.min(h) - 1) / 2) as i64;
    let mut g = Vec::new();
    for dy in -r..=r {
        for dx in -r..=r {
            g.push((-((dx * dx + dy * dy) as f64) / (2.0 * 1.5 * 1.5)).exp());
        }
    }
    let gs: f64 = g.iter().sum();
    let (c1, c2) = ((0.01 * peak).powi(2), (0.03 * peak).powi(2));
    let (mut sum, mut n) = (0.0, 0);
    for cy in r..h as i64 - r {
        for cx in r..w as i64 - r {
            let idx = |dx: i64, dy: i64| ((cy + dy) as usize) * w + (cx + dx) as usize;
            let mut k = 0;
            let (mut mx, mut my) = (0.0, 0.0);
            for dy in -r..=r {
                for dx in -r..=r {
                    mx += g[k] / gs * a[idx(dx, dy)];
                    my += g[k] / gs * b[idx(dx, dy)];
                    k += 1;
                }
            }
            let (mut vx, mut vy, mut cxy) = (0.0, 0.0, 0.0);
            k = 0;
            for dy in -r..=r {
                for dx in -r..=r {
                    let (p, q) = (a[idx(dx, dy)] - mx, b[idx(dx, dy)] - my);
                    vx += g[k] / gs * p * p;
                    vy += g[k] / gs * q * q;
                    cxy += g[k] / gs * p * q;
                    k += 1;
                }
            }
            sum += ((2.0 * mx * my + c1) * (2.0 * cxy + c2))
                / ((mx * mx + my * my + c1) * (vx + vy + c2));
            n += 1;
        }
    }
    sum / f64::from(n)
}

#[test]
fn ssim_matches_a_direct_implementation() {
    let mut rng = Rng(42);
    for (w, h) in [(40usize, 30usize), (12, 20), (7, 5), (1, 1)] {
        let a: Vec<f64> = (0..w * h)
            .map(|i| 0.5 + 0.4 * ((i % w) as f64 * 0.3).sin())
            .collect();
        let b: Vec<f64> = a.iter().map(|v| v + 0.1 * (rng.next() - 0.5)).collect();
        let fast = ssim::ssim(&a, &b, w, h, 1.0);
        let slow = direct_ssim(&a, &b, w, h, 1.0);
        // Separable filtering and E[x²] − E[x]² vs centred sums: same quantity, different
        // rounding (values ~1, ≤ 121-term sums): 1e-9 is far above the rounding, far below
        // any real discrepancy.
        assert!((fast - slow).abs() < 1e-9, "{w}×{h}: {fast} vs {slow}");
        assert!(fast < 1.0, "{w}×{h}: noise must lower SSIM ({fast})");
        assert_eq!(ssim::ssim(&a, &a, w, h, 1.0), 1.0);
    }
}

#[test]
fn ssim_falls_with_noise_level() {
    let (w, h) = (48, 48);
    let a: Vec<f64> = (0..w * h)
        .map(|i| 0.5 + 0.3 * ((i % w) as f64 * 0.2).cos() * ((i / w) as f64 * 0.25).sin())
        .collect();
    let mut last = 1.0;
    for amp in [0.01, 0.05, 0.2, 0.5] {
        let mut rng = Rng(3);
        let b: Vec<f64> = a.iter().map(|v| v + amp * (rng.next() - 0.5)).collect();
        let s = ssim::ssim(&a, &b, w, h, 1.0);
        assert!(s < last, "amplitude {amp}: {s} not below {last}");
        last = s;
    }
}

#[test]
fn channel_selection_and_errors() {
    let a = smooth(8, 8);
    let mut b = a.clone();
    b.channels.retain(|(n, _)| n != "A");
    b.channels.push(("Z".into(), vec![0.0; 64]));
    let r = compare::compare(&a, &b, &Options::default()).unwrap();
    let names: Vec<&str> = r.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        ["R", "G", "B"],
        "default: common colour channels only"
    );

    let only = |list: &[&str]| Options {
        channels: Some(list.iter().map(|s| (*s).to_string()).collect()),
        ..Options::default()
    };
    let e = compare::compare(&a, &b, &only(&["A"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("channel A is missing from the second image"),
        "{e}"
    );
    let r = compare::compare(&a, &a, &only(&["G"])).unwrap();
    assert_eq!(r.channels.len(), 1);
    assert_eq!(r.ssim_on, "mean of G");

    let small = smooth(8, 7);
    let e = compare::compare(&a, &small, &Options::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sizes differ: 8×8 vs 8×7"), "{e}");

    let z = image(8, 8, &["Z"], &mut |_, _| 0.0);
    let e = compare::compare(&z, &z, &Options::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no common colour channel"), "{e}");
}

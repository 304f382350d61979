//! `apatch compare`: error statistics between two EXR renders (e.g. apatch vs Mitsuba), with
//! optional difference and side-by-side pictures.
//!
//! Exit code 0 when the comparison ran (whatever the numbers), 2 on errors (unreadable files,
//! different sizes, missing channels).

use anyhow::anyhow;
use apatch::compare::{self, picture, Options, Report};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// First image (EXR), e.g. the apatch render.
    pub a: PathBuf,
    /// Second image (EXR), e.g. the reference render.
    pub b: PathBuf,
    /// Channels to compare, comma-separated (default: those of R,G,B,A present in both).
    #[arg(long, value_delimiter = ',')]
    pub channels: Option<Vec<String>>,
    /// Peak value for PSNR (dB = 10·log10(peak²/MSE), on linear values) and SSIM's range.
    #[arg(long, default_value_t = 1.0)]
    pub peak: f64,
    /// Absolute difference above which a pixel counts as differing.
    #[arg(long, default_value_t = 0.01)]
    pub threshold: f64,
    /// Write the false-colour difference picture (PNG, with legend).
    #[arg(long)]
    pub diff: Option<PathBuf>,
    /// Write a side-by-side PNG: first | second | difference.
    #[arg(long)]
    pub side_by_side: Option<PathBuf>,
    /// Upper end of the difference colour scale (default: the largest difference).
    #[arg(long)]
    pub diff_scale: Option<f64>,
    /// Print JSON instead of text (infinite PSNR is `null`).
    #[arg(long)]
    pub json: bool,
}

/// Runs `apatch compare`.
pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    if let Some(s) = args.diff_scale {
        if !(s.is_finite() && s > 0.0) {
            return Err(anyhow!("--diff-scale: must be a positive number, got {s}"));
        }
    }
    let a = compare::read_exr(&args.a)?;
    let b = compare::read_exr(&args.b)?;
    let opts = Options {
        channels: args.channels.clone(),
        peak: args.peak,
        threshold: args.threshold,
    };
    let report = compare::compare(&a, &b, &opts)?;
    if args.diff.is_some() || args.side_by_side.is_some() {
        let names: Vec<String> = report.channels.iter().map(|c| c.name.clone()).collect();
        let diff = compare::max_abs_per_pixel(&a, &b, &names);
        let scale = args.diff_scale.unwrap_or(if report.all.max_abs > 0.0 {
            report.all.max_abs
        } else {
            1.0
        });
        if let Some(p) = &args.diff {
            picture::diff_picture(&diff, a.width, a.height, scale).write_png(p)?;
        }
        if let Some(p) = &args.side_by_side {
            picture::side_by_side(&a, &b, &names, &diff, scale).write_png(p)?;
        }
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_text(&args, &report);
    }
    Ok(ExitCode::SUCCESS)
}

fn print_text(args: &CompareArgs, r: &Report) {
    println!(
        "{} vs {}: {}×{}, peak {}, threshold {}",
        args.a.display(),
        args.b.display(),
        r.width,
        r.height,
        r.peak,
        r.threshold
    );
    println!(
        "{:<10} {:>12} {:>10} {:>12} {:>12} {:>9}",
        "channel", "rmse", "psnr dB", "mean |d|", "max |d|", "> thr"
    );
    for c in r.channels.iter().chain(std::iter::once(&r.all)) {
        let psnr = c
            .psnr
            .map_or_else(|| "inf".to_string(), |p| format!("{p:.2}"));
        println!(
            "{:<10} {:>12.4e} {:>10} {:>12.4e} {:>12.4e} {:>8.3}%",
            c.name,
            c.rmse,
            psnr,
            c.mean_abs,
            c.max_abs,
            100.0 * c.above_threshold
        );
    }
    println!("ssim ({}): {:.6}", r.ssim_on, r.ssim);
}

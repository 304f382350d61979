//! `apatch render`: ray trace a scene file to PNG and EXR.

use anyhow::{anyhow, Context};
use apatch::scene;
use apatch::trace::{self, Geometry, Mode};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Arguments of `apatch render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML).
    pub input: PathBuf,
    /// Output file (.png or .exr); the other format is written beside it.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Image size and samples per pixel.
    #[command(flatten)]
    pub film: super::FilmArgs,
    /// Shading mode: shaded, normal, depth, patch, isophote, zebra, curvature.
    #[arg(long)]
    pub mode: Option<String>,
    /// Curvature mode: colour span ±this (default: the image's 99th percentile of |curvature|);
    /// the same value for two renders puts them on one scale.
    #[arg(long, value_parser = range)]
    pub curvature_range: Option<f64>,
    /// Worker threads (0 = all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Replay one pixel "x,y": print its samples' result instead of rendering.
    #[arg(long)]
    pub pixel: Option<String>,
}

/// `--curvature-range`: a number that [`scene::curvature_range`] accepts.
fn range(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    scene::curvature_range(v)
}

static CANCEL: AtomicBool = AtomicBool::new(false);

/// Runs `apatch render`.
pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    let mut scene = scene::load(&args.input)?;
    let s = &mut scene.settings;
    args.film.apply(s)?;
    if let Some(m) = &args.mode {
        s.mode = m.parse::<Mode>().map_err(|e| anyhow!("--mode: {e}"))?;
    }
    if let Some(t) = args.threads {
        s.threads = t;
    }
    if let Some(r) = args.curvature_range {
        s.options.curvature_range = Some(r);
    }
    if let Some(o) = args.output {
        scene::check_output(&o).map_err(|e| anyhow!("--output: {e}"))?;
        scene.output = o;
    }

    let start = Instant::now();
    let complex = super::with_progress(|| scene::build_complex(&scene))?;
    let geo = Geometry::new(&complex).map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    let built = start.elapsed();

    if let Some(p) = &args.pixel {
        let (x, y) = p
            .split_once(',')
            .and_then(|(x, y)| Some((x.trim().parse().ok()?, y.trim().parse().ok()?)))
            .ok_or_else(|| anyhow!("--pixel: expected x,y"))?;
        let s = &scene.settings;
        if x >= s.camera.width || y >= s.camera.height {
            return Err(anyhow!("--pixel: ({x}, {y}) is outside the image"));
        }
        println!("{:?}", trace::render_pixel(&geo, s, x, y));
        return Ok(ExitCode::SUCCESS);
    }

    let _ = ctrlc::set_handler(|| CANCEL.store(true, Ordering::Relaxed));
    let s = &scene.settings;
    // One line before the (terminal-only) progress bar: says what runs, and tells scripts and
    // tests that rendering has started and Ctrl-C is now handled.
    eprintln!(
        "apatch: rendering {}×{} at {} spp, {} patches (Ctrl-C stops without writing)",
        s.camera.width,
        s.camera.height,
        s.spp,
        complex.patches.len()
    );
    let bar = indicatif::ProgressBar::new(u64::from(s.camera.height));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} rows, ETA {eta}",
        )
        .map_err(|e| anyhow!("{e}"))?,
    );
    let render_start = Instant::now();
    let result = trace::render(&geo, s, &|| bar.inc(1), &CANCEL);
    bar.finish_and_clear();
    let Ok(frame) = result else {
        eprintln!("apatch: interrupted, no output written");
        return Ok(ExitCode::from(130));
    };
    let secs = render_start.elapsed().as_secs_f64();

    let (png, exr) = match scene.output.extension().and_then(|e| e.to_str()) {
        Some("exr") => (scene.output.with_extension("png"), scene.output.clone()),
        _ => (scene.output.clone(), scene.output.with_extension("exr")),
    };
    if let Some(dir) = png.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    trace::write_exr(&frame, &exr)?;
    trace::write_png(&frame, &png)?;
    let rays = f64::from(s.camera.width) * f64::from(s.camera.height) * f64::from(s.spp);
    eprintln!(
        "{} patches, build {:.2} s, render {:.2} s ({:.2} M primary rays/s), wrote {} and {}",
        complex.patches.len(),
        built.as_secs_f64(),
        secs,
        rays / secs / 1e6,
        png.display(),
        exr.display()
    );
    if s.mode == Mode::Curvature {
        eprintln!(
            "{} curvature colour range: ±{:.6}{}",
            if s.options.gaussian {
                "Gaussian"
            } else {
                "mean"
            },
            frame.range,
            if s.options.curvature_range.is_some() {
                " (fixed)"
            } else {
                ""
            }
        );
    }
    Ok(ExitCode::SUCCESS)
}

//! The film: samples per pixel with a box filter (the plain mean over the pixel area, as
//! Mitsuba's `box` rfilter), rows rendered in parallel inside a local rayon pool, then a
//! deterministic finishing pass for the modes that need the whole image (depth range, lines,
//! stripes, curvature range).
//!
//! Sample k of pixel (x, y) sits at an R2 low-discrepancy offset rotated by a hash of (x, y):
//! every pixel's samples depend only on (x, y, k), so the image is bit-identical for any number
//! of threads.
//!
//! Scene usage:
//! ```toml
//! [film]
//! spp = 16
//! filter = "box"
//! ```

use super::camera::Camera;
use super::intersect::Geometry;
use super::shade::{self, hash01, Lighting, Mode, ModeOptions};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Everything a render needs besides the geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// The sensor.
    pub camera: Camera,
    /// Samples per pixel (≥ 1).
    pub spp: u32,
    /// What to show.
    pub mode: Mode,
    /// Options of the line and curvature modes.
    pub options: ModeOptions,
    /// Material and emitters.
    pub lighting: Lighting,
    /// Worker threads (0 = all cores).
    pub threads: usize,
}

/// One finished pixel. `rgb` and `alpha` are means over all samples (background contributes
/// 0); `depth`, `normal`, `position` and `value` are means over the samples that hit (0 where
/// none did); `patch` is the patch of the pixel's first hitting sample, −1 where none hit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pixel {
    /// Linear RGB.
    pub rgb: [f32; 3],
    /// Coverage.
    pub alpha: f32,
    /// Distance along the ray from its near-clip origin.
    pub depth: f32,
    /// World normal.
    pub normal: [f32; 3],
    /// World position.
    pub position: [f32; 3],
    /// Patch index or −1.
    pub patch: f32,
    /// The mode's own values (see [`Mode::value_channels`]).
    pub value: [f32; 2],
}

/// A rendered image.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The mode rendered.
    pub mode: Mode,
    /// Row-major pixels, top row first.
    pub pixels: Vec<Pixel>,
    /// The symmetric range ±`range` the colour map spans (curvature), or the depth range's
    /// far end (depth); 0 otherwise.
    pub range: f64,
}

/// The render was stopped before it finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("render interrupted")]
pub struct Interrupted;

/// Renders the whole image.
///
/// `progress` is called once per finished row (from worker threads); rendering stops at the
/// next row once `cancel` becomes true.
///
/// # Errors
/// [`Interrupted`] when cancelled; a pool that cannot start is reported as interrupted too.
pub fn render(
    geo: &Geometry,
    settings: &RenderSettings,
    progress: &(dyn Fn() + Sync),
    cancel: &AtomicBool,
) -> Result<Frame, Interrupted> {
    let (w, h) = (
        settings.camera.width as usize,
        settings.camera.height as usize,
    );
    let mut pixels = vec![Pixel::default(); w * h];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads)
        .build()
        .map_err(|_| Interrupted)?;
    pool.install(|| {
        pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            if cancel.load(Ordering::Relaxed) {
                return;
            }
            for (x, px) in row.iter_mut().enumerate() {
                *px = render_pixel(geo, settings, x as u32, y as u32);
            }
            progress();
        });
    });
    if cancel.load(Ordering::Relaxed) {
        return Err(Interrupted);
    }
    let mut frame = Frame {
        width: settings.camera.width,
        height: settings.camera.height,
        mode: settings.mode,
        pixels,
        range: 0.0,
    };
    finish(&mut frame, &settings.options);
    Ok(frame)
}

/// Renders pixel (x, y) alone (before the finishing pass): what [`render`] computes for it,
/// for replaying one pixel.
#[must_use]
pub fn render_pixel(geo: &Geometry, settings: &RenderSettings, x: u32, y: u32) -> Pixel {
    let cam = &settings.camera;
    let mode = settings.mode;
    let opts = &settings.options;
    let mut rgb = DVec3::ZERO;
    let mut hits = 0u32;
    let mut depth = 0.0;
    let mut normal = DVec3::ZERO;
    let mut position = DVec3::ZERO;
    let mut value = [0.0f64; 2];
    let mut patch = -1.0f32;
    let (h0, h1) = (hash01(x, y, 0, 0), hash01(x, y, 0, 1));
    let light_dir = settings.lighting.lights.iter().find_map(|l| match l {
        shade::Light::Directional { direction, .. } => Some(-*direction),
        _ => None,
    });
    for k in 0..settings.spp {
        // R2 sequence, Cranley–Patterson rotated per pixel.
        let u = (h0 + f64::from(k) * 0.754_877_666_246_692_7).fract();
        let v = (h1 + f64::from(k) * 0.569_840_290_998_053_2).fract();
        let (o, d) = cam.ray(f64::from(x) + u, f64::from(y) + v);
        let Some(hit) = geo.intersect(o, d, 0.0, f64::INFINITY) else {
            continue;
        };
        let s = shade::surface(geo, &hit, o, d, mode == Mode::Curvature);
        hits += 1;
        if patch < 0.0 {
            patch = hit.patch as f32;
        }
        depth += hit.t;
        normal += s.n;
        position += s.p;
        let rnd = [hash01(x, y, k, 2), hash01(x, y, k, 3)];
        let facing = s.n.dot(-d).abs();
        match mode {
            Mode::Shaded => rgb += shade::radiance(geo, &settings.lighting, &s, d, rnd),
            Mode::Normal => rgb += (s.n + 1.0) * 0.5,
            Mode::Depth | Mode::Zebra | Mode::Curvature => {}
            Mode::Patch => {
                let i = hit.patch as usize;
                rgb += shade::patch_colour(geo.roles[i], hit.patch) * (0.25 + 0.75 * facing);
            }
            Mode::Isophote => {
                let dir = if opts.isophote_light {
                    light_dir.unwrap_or(-d)
                } else {
                    -d
                };
                value[0] += s.n.dot(dir.normalize());
                rgb += if opts.over_shaded {
                    shade::radiance(geo, &settings.lighting, &s, d, rnd)
                } else {
                    DVec3::splat(0.9)
                };
            }
        }
        match mode {
            Mode::Zebra => {
                let r = d - 2.0 * d.dot(s.n) * s.n;
                value[0] += r.dot(cam.y);
            }
            Mode::Curvature => {
                value[0] += s.mean;
                value[1] += s.gaussian;
            }
            _ => {}
        }
    }
    let inv_spp = 1.0 / f64::from(settings.spp);
    let inv_hits = if hits > 0 { 1.0 / f64::from(hits) } else { 0.0 };
    let f = |x: f64| if x.is_finite() { x as f32 } else { 0.0 };
    let v3 = |v: DVec3, s: f64| [f(v.x * s), f(v.y * s), f(v.z * s)];
    Pixel {
        rgb: v3(rgb, inv_spp),
        alpha: f(f64::from(hits) * inv_spp),
        depth: f(depth * inv_hits),
        normal: v3(normal, inv_hits),
        position: v3(position, inv_hits),
        patch,
        value: [f(value[0] * inv_hits), f(value[1] * inv_hits)],
    }
}

/// The curvature map's span when none is fixed: the 99th percentile of |curvature| (component
/// `k`) over the covered pixels, so that a few near-singular pixels do not wash out the map;
/// 1 when that is zero.
fn image_curvature_range(frame: &Frame, k: usize) -> f32 {
    let mut mags: Vec<f32> = frame
        .pixels
        .iter()
        .filter(|p| p.alpha > 0.0)
        .map(|p| p.value[k].abs())
        .collect();
    mags.sort_by(f32::total_cmp);
    let range = mags
        .get(mags.len().saturating_sub(1) * 99 / 100)
        .copied()
        .unwrap_or(0.0);
    if range > 0.0 {
        range
    } else {
        1.0
    }
}

/// Applies the whole-image step of each mode.
fn finish(frame: &mut Frame, opts: &ModeOptions) {
    let (w, h) = (frame.width as usize, frame.height as usize);
    match frame.mode {
        Mode::Depth => {
            let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
            for p in frame.pixels.iter().filter(|p| p.alpha > 0.0) {
                lo = lo.min(p.depth);
                hi = hi.max(p.depth);
            }
            let span = (hi - lo).max(f32::MIN_POSITIVE);
            for p in frame.pixels.iter_mut().filter(|p| p.alpha > 0.0) {
                let g = 1.0 - 0.8 * (p.depth - lo) / span;
                p.rgb = [g * p.alpha; 3];
            }
            frame.range = f64::from(hi);
        }
        Mode::Curvature => {
            let k = usize::from(opts.gaussian);
            // A fixed range needs no look at the image.
            #[allow(clippy::cast_possible_truncation)]
            let range = opts
                .curvature_range
                .map_or_else(|| image_curvature_range(frame, k), |r| r as f32);
            for p in frame.pixels.iter_mut().filter(|p| p.alpha > 0.0) {
                let c = shade::diverging(f64::from(p.value[k] / range));
                p.rgb = [
                    c.x as f32 * p.alpha,
                    c.y as f32 * p.alpha,
                    c.z as f32 * p.alpha,
                ];
            }
            frame.range = f64::from(range);
        }
        Mode::Isophote | Mode::Zebra => {
            let scale = f64::from(opts.lines.max(1)) * 0.5;
            let phase: Vec<f64> = frame
                .pixels
                .iter()
                .map(|p| (f64::from(p.value[0]) + 1.0) * scale)
                .collect();
            let hit: Vec<bool> = frame.pixels.iter().map(|p| p.alpha > 0.0).collect();
            for y in 0..h {
                for x in 0..w {
                    let i = y * w + x;
                    if !hit[i] {
                        continue;
                    }
                    let g = phase_gradient(&phase, &hit, w, h, x, y).max(1e-9);
                    let f = phase[i] - phase[i].floor();
                    let dist = f.min(1.0 - f) / g; // pixels to the nearest level
                    let p = &mut frame.pixels[i];
                    if frame.mode == Mode::Isophote {
                        let cover = (opts.line_width * 0.5 + 0.5 - dist).clamp(0.0, 1.0) as f32;
                        for c in &mut p.rgb {
                            *c *= 1.0 - cover;
                        }
                    } else {
                        let odd = phase[i].floor().rem_euclid(2.0) == 1.0;
                        let blend = (0.5 - dist).clamp(0.0, 0.5);
                        let inside = if odd { 0.05 } else { 0.95 };
                        let v = inside + (0.95 + 0.05 - 2.0 * inside) * blend;
                        p.rgb = [(v * f64::from(p.alpha)) as f32; 3];
                    }
                }
            }
        }
        Mode::Patch if opts.patch_boundaries => {
            let ids: Vec<f32> = frame.pixels.iter().map(|p| p.patch).collect();
            for y in 0..h {
                for x in 0..w {
                    let i = y * w + x;
                    if ids[i] < 0.0 {
                        continue;
                    }
                    let edge = (x + 1 < w && ids[i + 1] >= 0.0 && ids[i + 1] != ids[i])
                        || (y + 1 < h && ids[i + w] >= 0.0 && ids[i + w] != ids[i]);
                    if edge {
                        for c in &mut frame.pixels[i].rgb {
                            *c *= 0.35;
                        }
                    }
                }
            }
        }
        _ => {}
    }
}

/// |∇phase| in pixel units at (x, y), from neighbours that hit (central where possible).
fn phase_gradient(phase: &[f64], hit: &[bool], w: usize, h: usize, x: usize, y: usize) -> f64 {
    let i = y * w + x;
    let diff = |a: Option<usize>, b: Option<usize>| -> f64 {
        match (a.filter(|&k| hit[k]), b.filter(|&k| hit[k])) {
            (Some(a), Some(b)) => (phase[b] - phase[a]) * 0.5,
            (Some(a), None) => phase[i] - phase[a],
            (None, Some(b)) => phase[b] - phase[i],
            (None, None) => 0.0,
        }
    };
    let gx = diff(
        x.checked_sub(1).map(|k| y * w + k),
        (x + 1 < w).then(|| i + 1),
    );
    let gy = diff(
        y.checked_sub(1).map(|k| k * w + x),
        (y + 1 < h).then(|| i + w),
    );
    gx.hypot(gy)
}

//! Comparing two renders: per-channel error statistics, SSIM on luminance, and pictures of the
//! difference (`apatch compare`).
//!
//! ## Definitions (a contract)
//! For a channel c with values a_i, b_i over the N pixels:
//! - `rmse` = sqrt(Σ (a_i − b_i)² / N);
//! - `psnr` = 10·log10(peak² / MSE) in dB, on the linear values, with `peak` = 1.0 unless the
//!   user chooses another; identical channels have an infinite PSNR, written `null` in JSON and
//!   `inf` in text;
//! - `mean_abs` = Σ |a_i − b_i| / N, `max_abs` = max |a_i − b_i|;
//! - `above_threshold` = share of pixels with |a_i − b_i| > threshold (0 ≤ share ≤ 1).
//!
//! The `all` row pools every compared channel (N·channels values); its `above_threshold` counts a
//! pixel when any of its channels differs by more than the threshold.
//! SSIM is computed once, on luminance (see [`ssim`]).
//!
//! Images are compared as stored: apatch and Mitsuba both write colours premultiplied by
//! coverage (composited over black), so no un-premultiplication happens here.

pub mod picture;
pub mod ssim;

use anyhow::{anyhow, bail, Context};
use serde::Serialize;
use std::path::Path;

/// One image: named channels of `width × height` linear samples, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Channels in the file's order (EXR sorts them by name), each `width·height` samples.
    pub channels: Vec<(String, Vec<f32>)>,
}

impl Image {
    /// The samples of the channel called `name`, if present.
    #[must_use]
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The channel names, in the image's order.
    #[must_use]
    pub fn names(&self) -> Vec<&str> {
        self.channels.iter().map(|(n, _)| n.as_str()).collect()
    }
}

/// Reads every channel of a one-part, one-layer EXR file (f16, f32 and u32 samples are all
/// converted to f32).
///
/// # Errors
/// Unreadable or non-EXR files, multi-layer files, and non-finite samples (naming the channel
/// and the pixel).
pub fn read_exr(path: &Path) -> anyhow::Result<Image> {
    let img = exr::prelude::read_all_flat_layers_from_file(path)
        .map_err(|e| anyhow!("{}: not a readable EXR file ({e})", path.display()))?;
    if img.layer_data.len() != 1 {
        bail!(
            "{}: has {} layers; only one-layer EXR files can be compared",
            path.display(),
            img.layer_data.len()
        );
    }
    let layer = &img.layer_data[0];
    let (width, height) = (layer.size.width(), layer.size.height());
    let mut channels = Vec::with_capacity(layer.channel_data.list.len());
    for c in &layer.channel_data.list {
        let name = c.name.to_string();
        let n = c.sample_data.len();
        let values: Vec<f32> = (0..n)
            .map(|i| c.sample_data.value_by_flat_index(i).to_f32())
            .collect();
        if values.len() != width * height {
            bail!(
                "{}: channel {name} has {} samples for {width}×{height} pixels (subsampled channels are not supported)",
                path.display(),
                values.len()
            );
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            bail!(
                "{}: channel {name} pixel ({}, {}) is {}",
                path.display(),
                i % width,
                i / width,
                values[i]
            );
        }
        channels.push((name, values));
    }
    Ok(Image {
        width,
        height,
        channels,
    })
}

/// Settings of a comparison.
#[derive(Clone, Debug)]
pub struct Options {
    /// Channels to compare; `None` = those of R, G, B, A present in both images.
    pub channels: Option<Vec<String>>,
    /// Peak value for PSNR and SSIM's dynamic range (default 1.0: linear colour).
    pub peak: f64,
    /// Absolute difference above which a pixel counts in `above_threshold`.
    pub threshold: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            channels: None,
            peak: 1.0,
            threshold: 0.01,
        }
    }
}

/// Error statistics of one channel (or of all compared channels pooled).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ChannelStats {
    /// Channel name (`all` for the pooled row).
    pub name: String,
    /// Root mean square error.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB; `None` (JSON `null`) when the channels are identical.
    pub psnr: Option<f64>,
    /// Mean absolute error.
    pub mean_abs: f64,
    /// Maximum absolute error.
    pub max_abs: f64,
    /// Share of pixels whose absolute error exceeds the threshold.
    pub above_threshold: f64,
}

/// The result of comparing two images.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Peak used for PSNR and SSIM.
    pub peak: f64,
    /// Threshold used for `above_threshold`.
    pub threshold: f64,
    /// One row per compared channel, in the order compared.
    pub channels: Vec<ChannelStats>,
    /// All compared channels pooled.
    pub all: ChannelStats,
    /// Mean SSIM of the luminance images (1 for identical images).
    pub ssim: f64,
    /// What SSIM was computed on: `luminance` (Rec. 709 from R, G, B) or `mean of <channels>`.
    pub ssim_on: String,
}

/// The channels to compare: the user's list (each must exist in both images) or, by default,
/// those of R, G, B, A present in both.
///
/// # Errors
/// A requested channel missing from either image, or no common colour channel.
pub fn select_channels(a: &Image, b: &Image, opts: &Options) -> anyhow::Result<Vec<String>> {
    match &opts.channels {
        Some(list) => {
            if list.is_empty() {
                bail!("--channels: empty list");
            }
            for name in list {
                for (img, which) in [(a, "first"), (b, "second")] {
                    if img.channel(name).is_none() {
                        bail!(
                            "channel {name} is missing from the {which} image (it has {})",
                            img.names().join(",")
                        );
                    }
                }
            }
            Ok(list.clone())
        }
        None => {
            let common: Vec<String> = ["R", "G", "B", "A"]
                .iter()
                .filter(|n| a.channel(n).is_some() && b.channel(n).is_some())
                .map(|n| (*n).to_string())
                .collect();
            if common.is_empty() {
                bail!(
                    "no common colour channel (R, G, B, A): first image has {}, second has {}; choose with --channels",
                    a.names().join(","),
                    b.names().join(",")
                );
            }
            Ok(common)
        }
    }
}

/// Accumulates one channel's statistics.
fn stats(name: &str, pairs: &[(&[f32], &[f32])], opts: &Options, pixels: usize) -> ChannelStats {
    let (mut sq, mut abs, mut max) = (0.0f64, 0.0f64, 0.0f64);
    let mut above = vec![false; pixels];
    let mut count = 0usize;
    for (a, b) in pairs {
        for (i, (&x, &y)) in a.iter().zip(b.iter()).enumerate() {
            let d = (f64::from(x) - f64::from(y)).abs();
            sq += d * d;
            abs += d;
            max = max.max(d);
            if d > opts.threshold {
                above[i] = true;
            }
            count += 1;
        }
    }
    let n = count.max(1) as f64;
    let mse = sq / n;
    ChannelStats {
        name: name.to_string(),
        rmse: mse.sqrt(),
        psnr: (mse > 0.0).then(|| 10.0 * (opts.peak * opts.peak / mse).log10()),
        mean_abs: abs / n,
        max_abs: max,
        above_threshold: above.iter().filter(|&&x| x).count() as f64 / pixels.max(1) as f64,
    }
}

/// The scalar image SSIM is computed on: Rec. 709 luminance when R, G, B are all compared,
/// otherwise the mean of the compared channels. Returns the description too.
#[must_use]
pub fn luminance(img: &Image, names: &[String]) -> (Vec<f64>, String) {
    let has = |n: &str| names.iter().any(|x| x == n);
    let n = img.width * img.height;
    if has("R") && has("G") && has("B") {
        let (r, g, b) = (
            img.channel("R").unwrap_or(&[]),
            img.channel("G").unwrap_or(&[]),
            img.channel("B").unwrap_or(&[]),
        );
        let y = (0..n)
            .map(|i| 0.2126 * f64::from(r[i]) + 0.7152 * f64::from(g[i]) + 0.0722 * f64::from(b[i]))
            .collect();
        return (y, "luminance".to_string());
    }
    let chans: Vec<&[f32]> = names.iter().filter_map(|c| img.channel(c)).collect();
    let k = chans.len().max(1) as f64;
    let y = (0..n)
        .map(|i| chans.iter().map(|c| f64::from(c[i])).sum::<f64>() / k)
        .collect();
    (y, format!("mean of {}", names.join(",")))
}

/// Compares `a` with `b` (see the module docs for the definitions).
///
/// # Errors
/// Different sizes, missing channels, or a peak/threshold that is not a positive/non-negative
/// finite number.
pub fn compare(a: &Image, b: &Image, opts: &Options) -> anyhow::Result<Report> {
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "image sizes differ: {}×{} vs {}×{}",
            a.width,
            a.height,
            b.width,
            b.height
        );
    }
    if !(opts.peak.is_finite() && opts.peak > 0.0) {
        bail!("--peak: must be a positive number, got {}", opts.peak);
    }
    if !(opts.threshold.is_finite() && opts.threshold >= 0.0) {
        bail!(
            "--threshold: must be a non-negative number, got {}",
            opts.threshold
        );
    }
    let names = select_channels(a, b, opts)?;
    let pixels = a.width * a.height;
    let pair = |n: &str| -> anyhow::Result<(&[f32], &[f32])> {
        Ok((
            a.channel(n).context("channel vanished")?,
            b.channel(n).context("channel vanished")?,
        ))
    };
    let mut rows = Vec::new();
    let mut pooled = Vec::new();
    for n in &names {
        let p = pair(n)?;
        rows.push(stats(n, &[p], opts, pixels));
        pooled.push(p);
    }
    let all = stats("all", &pooled, opts, pixels);
    let (ya, on) = luminance(a, &names);
    let (yb, _) = luminance(b, &names);
    let s = ssim::ssim(&ya, &yb, a.width, a.height, opts.peak);
    Ok(Report {
        width: a.width,
        height: a.height,
        peak: opts.peak,
        threshold: opts.threshold,
        channels: rows,
        all,
        ssim: s,
        ssim_on: on,
    })
}

/// Per-pixel maximum absolute difference over the named channels (the quantity the difference
/// picture shows).
#[must_use]
pub fn max_abs_per_pixel(a: &Image, b: &Image, names: &[String]) -> Vec<f64> {
    let mut d = vec![0.0f64; a.width * a.height];
    for n in names {
        if let (Some(x), Some(y)) = (a.channel(n), b.channel(n)) {
            for (i, (&p, &q)) in x.iter().zip(y.iter()).enumerate() {
                d[i] = d[i].max((f64::from(p) - f64::from(q)).abs());
            }
        }
    }
    d
}

//! Writing frames: EXR (all data) and PNG (8-bit sRGB). Both go to a temporary file in the
//! target directory that is renamed into place only when complete, so an interrupted or failed
//! write leaves no partial output.
//!
//! ## EXR channels (a contract)
//! One part, one layer, f32 samples, `SMALL_LOSSLESS` compression:
//! - `R`, `G`, `B`: linear radiance (or the mode's colours), mean over the pixel's samples;
//! - `A`: coverage (fraction of samples that hit);
//! - `Z`: distance along the ray from its near-clip origin, mean over hitting samples;
//! - `normal.X/Y/Z`: world normal ∇F/|∇F| (not flipped toward the camera), mean over hits;
//! - `position.X/Y/Z`: world hit point, mean over hits;
//! - `patch.id`: index of the patch hit by the pixel's first hitting sample;
//! - the mode's values: `isophote.value` (n·d), `zebra.value` (reflected direction · camera
//!   up), `curvature.mean` and `curvature.gaussian`.
//!
//! Where no sample hits: A = 0, Z = normal = position = mode values = 0 and `patch.id` = −1.
//! No channel ever holds NaN or infinity.

use super::film::Frame;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// The temporary sibling of `path` used while writing it.
#[must_use]
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

fn commit(tmp: &Path, path: &Path, result: anyhow::Result<()>) -> anyhow::Result<()> {
    match result.and_then(|()| {
        std::fs::rename(tmp, path).with_context(|| format!("{}: cannot rename", path.display()))
    }) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(tmp);
            Err(e)
        }
    }
}

/// Named channels of `frame` in the contract's order.
#[must_use]
pub fn channels(frame: &Frame) -> Vec<(String, Vec<f32>)> {
    let mut out: Vec<(String, Vec<f32>)> = Vec::new();
    let mut push = |name: &str, f: &dyn Fn(&super::film::Pixel) -> f32| {
        out.push((name.to_string(), frame.pixels.iter().map(f).collect()));
    };
    push("R", &|p| p.rgb[0]);
    push("G", &|p| p.rgb[1]);
    push("B", &|p| p.rgb[2]);
    push("A", &|p| p.alpha);
    push("Z", &|p| p.depth);
    push("normal.X", &|p| p.normal[0]);
    push("normal.Y", &|p| p.normal[1]);
    push("normal.Z", &|p| p.normal[2]);
    push("position.X", &|p| p.position[0]);
    push("position.Y", &|p| p.position[1]);
    push("position.Z", &|p| p.position[2]);
    push("patch.id", &|p| p.patch);
    for (k, name) in frame.mode.value_channels().iter().enumerate() {
        push(name, &|p| p.value[k]);
    }
    out
}

/// Writes `frame` as a one-part EXR at `path` (see the module docs for the channels).
///
/// # Errors
/// I/O and encoding failures, naming the file.
pub fn write_exr(frame: &Frame, path: &Path) -> anyhow::Result<()> {
    use exr::prelude::*;
    let size = (frame.width as usize, frame.height as usize);
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels(frame)
        .into_iter()
        .map(|(name, data)| AnyChannel::new(name.as_str(), FlatSamples::F32(data)))
        .collect();
    let layer = Layer::new(
        size,
        LayerAttributes::named("apatch"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    let tmp = temp_path(path);
    let result = image
        .write()
        .to_file(&tmp)
        .with_context(|| format!("{}: cannot write EXR", path.display()));
    commit(&tmp, path, result)
}

/// The sRGB transfer curve of a linear value in [0, 1].
#[must_use]
pub fn srgb(x: f32) -> f32 {
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes `frame` as an 8-bit sRGB PNG with alpha. Colours are un-premultiplied by coverage
/// before encoding (PNG alpha is straight).
///
/// # Errors
/// I/O and encoding failures, naming the file.
pub fn write_png(frame: &Frame, path: &Path) -> anyhow::Result<()> {
    let mut bytes = Vec::with_capacity(frame.pixels.len() * 4);
    let q = |x: f32| (x * 255.0 + 0.5).clamp(0.0, 255.0) as u8;
    for p in &frame.pixels {
        let a = p.alpha;
        let un = |c: f32| if a > 0.0 { c / a } else { 0.0 };
        bytes.extend_from_slice(&[
            q(srgb(un(p.rgb[0]))),
            q(srgb(un(p.rgb[1]))),
            q(srgb(un(p.rgb[2]))),
            q(a),
        ]);
    }
    let tmp = temp_path(path);
    let result = image::save_buffer_with_format(
        &tmp,
        &bytes,
        frame.width,
        frame.height,
        image::ExtendedColorType::Rgba8,
        image::ImageFormat::Png,
    )
    .with_context(|| format!("{}: cannot write PNG", path.display()));
    commit(&tmp, path, result)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_matches_the_standard() {
        // Linear 0.5 encodes to 188/255 (crates.md); exact constants of the standard curve.
        assert_eq!((srgb(0.5) * 255.0).round(), 188.0);
        assert_eq!(srgb(0.0), 0.0);
        assert!((srgb(1.0) - 1.0).abs() < 1e-6);
    }
}

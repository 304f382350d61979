//! Pictures of a comparison, as 8-bit sRGB PNGs written atomically (temporary file + rename):
//! - the false-colour difference image: per-pixel maximum absolute difference over the compared
//!   channels, mapped black → purple → orange → pale yellow over [0, scale], with a legend strip
//!   below it (the colour bar, "0" at its left end and the scale value at its right end, drawn
//!   with a built-in 3×5 pixel font);
//! - the side-by-side image: first image | second image | difference (left to right), with the
//!   same legend below. The first two panels show R, G, B (linear, sRGB-encoded, clamped to
//!   [0, 1]) or, without colour channels, the grey mean of the compared channels.

use super::{luminance, Image};
use crate::trace::output::{srgb, temp_path};
use anyhow::Context;
use std::path::Path;

/// An 8-bit RGB raster.
#[derive(Clone, Debug)]
pub struct Raster {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major RGB bytes.
    pub rgb: Vec<[u8; 3]>,
}

impl Raster {
    /// A raster filled with `fill`.
    #[must_use]
    pub fn new(width: usize, height: usize, fill: [u8; 3]) -> Self {
        Self {
            width,
            height,
            rgb: vec![fill; width * height],
        }
    }

    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            self.rgb[y * self.width + x] = c;
        }
    }

    fn blit(&mut self, src: &Raster, x0: usize, y0: usize) {
        for y in 0..src.height {
            for x in 0..src.width {
                self.set(x0 + x, y0 + y, src.rgb[y * src.width + x]);
            }
        }
    }

    /// Writes the raster as an RGB PNG via a temporary file renamed into place.
    ///
    /// # Errors
    /// I/O and encoding failures, naming the file.
    pub fn write_png(&self, path: &Path) -> anyhow::Result<()> {
        let bytes: Vec<u8> = self.rgb.iter().flatten().copied().collect();
        let tmp = temp_path(path);
        let result = image::save_buffer_with_format(
            &tmp,
            &bytes,
            u32::try_from(self.width).context("image too wide")?,
            u32::try_from(self.height).context("image too tall")?,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .with_context(|| format!("{}: cannot write PNG", path.display()))
        .and_then(|()| {
            std::fs::rename(&tmp, path)
                .with_context(|| format!("{}: cannot rename", path.display()))
        });
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }
}

/// The false colour of t ∈ [0, 1] (clamped): black at 0, pale yellow at 1, monotone in
/// brightness.
#[must_use]
pub fn false_colour(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [70.0, 20.0, 120.0],
        [190.0, 50.0, 90.0],
        [250.0, 150.0, 30.0],
        [255.0, 255.0, 190.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let s = t * (STOPS.len() - 1) as f64;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f64;
    let mut c = [0u8; 3];
    for k in 0..3 {
        c[k] = (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    }
    c
}

/// 3×5 glyphs, one row per 3-bit number (bit 2 = left column).
fn glyph(ch: char) -> Option<[u8; 5]> {
    Some(match ch {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        'e' => [0, 7, 7, 4, 7],
        _ => return None,
    })
}

/// Pixel scale of the font.
const FONT: usize = 2;

/// Width in pixels of `text` drawn with [`draw_text`].
#[must_use]
pub fn text_width(text: &str) -> usize {
    text.chars().count() * 4 * FONT
}

/// Draws `text` (digits, `.`, `-`, `+`, `e`; other characters leave a gap) with its top-left
/// corner at (x, y).
pub fn draw_text(r: &mut Raster, text: &str, x: usize, y: usize, colour: [u8; 3]) {
    for (k, ch) in text.chars().enumerate() {
        let Some(g) = glyph(ch) else { continue };
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) != 0 {
                    for dy in 0..FONT {
                        for dx in 0..FONT {
                            r.set(x + (k * 4 + col) * FONT + dx, y + row * FONT + dy, colour);
                        }
                    }
                }
            }
        }
    }
}

/// A short label for a legend value: plain decimals between 0.01 and 1000, else `1.23e-4`.
#[must_use]
pub fn label(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if (0.01..1000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// Height of the legend strip in pixels.
pub const LEGEND_HEIGHT: usize = 4 + 10 + 3 + 5 * FONT + 4;

/// The legend strip of `width` pixels for the scale [0, `scale`].
#[must_use]
pub fn legend(width: usize, scale: f64) -> Raster {
    let mut r = Raster::new(width, LEGEND_HEIGHT, [40, 40, 40]);
    let bar = width.saturating_sub(8).max(1);
    for x in 0..bar {
        let c = false_colour(x as f64 / (bar.max(2) - 1) as f64);
        for y in 4..14 {
            r.set(4 + x, y, c);
        }
    }
    let white = [230, 230, 230];
    draw_text(&mut r, "0", 4, 17, white);
    let s = label(scale);
    draw_text(
        &mut r,
        &s,
        (4 + bar).saturating_sub(text_width(&s)),
        17,
        white,
    );
    r
}

/// Minimum picture width so the legend's labels fit.
const MIN_WIDTH: usize = 96;

/// The difference panel (no legend): `diff` mapped over [0, scale].
#[must_use]
pub fn diff_panel(diff: &[f64], width: usize, height: usize, scale: f64) -> Raster {
    let mut r = Raster::new(width, height, [0, 0, 0]);
    for (i, &d) in diff.iter().enumerate() {
        r.rgb[i] = false_colour(if scale > 0.0 { d / scale } else { 0.0 });
    }
    r
}

/// The false-colour difference picture with its legend.
#[must_use]
pub fn diff_picture(diff: &[f64], width: usize, height: usize, scale: f64) -> Raster {
    let w = width.max(MIN_WIDTH);
    let mut out = Raster::new(w, height + LEGEND_HEIGHT, [40, 40, 40]);
    out.blit(&diff_panel(diff, width, height, scale), 0, 0);
    out.blit(&legend(w, scale), 0, height);
    out
}

/// The display panel of one image: sRGB of R, G, B, or grey of the compared channels' mean.
#[must_use]
pub fn image_panel(img: &Image, names: &[String]) -> Raster {
    let q = |x: f64| (f64::from(srgb(x as f32)) * 255.0).round() as u8;
    let mut r = Raster::new(img.width, img.height, [0, 0, 0]);
    if let (Some(cr), Some(cg), Some(cb)) = (img.channel("R"), img.channel("G"), img.channel("B")) {
        for i in 0..img.width * img.height {
            r.rgb[i] = [
                q(f64::from(cr[i])),
                q(f64::from(cg[i])),
                q(f64::from(cb[i])),
            ];
        }
    } else {
        let (y, _) = luminance(img, names);
        for (i, v) in y.iter().enumerate() {
            let g = q(*v);
            r.rgb[i] = [g, g, g];
        }
    }
    r
}

/// Gap between side-by-side panels, in pixels.
pub const GAP: usize = 4;

/// The side-by-side picture: `a` | `b` | difference, legend below.
#[must_use]
pub fn side_by_side(a: &Image, b: &Image, names: &[String], diff: &[f64], scale: f64) -> Raster {
    let (w, h) = (a.width, a.height);
    let total = (3 * w + 2 * GAP).max(MIN_WIDTH);
    let mut out = Raster::new(total, h + LEGEND_HEIGHT, [40, 40, 40]);
    out.blit(&image_panel(a, names), 0, 0);
    out.blit(&image_panel(b, names), w + GAP, 0);
    out.blit(&diff_panel(diff, w, h, scale), 2 * (w + GAP), 0);
    out.blit(&legend(total, scale), 0, h);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn false_colour_brightness_is_monotone() {
        // Sum of channels must never decrease along the map (a readable scale).
        let mut last = -1i32;
        for k in 0..=100 {
            let c = false_colour(f64::from(k) / 100.0);
            let s = i32::from(c[0]) + i32::from(c[1]) + i32::from(c[2]);
            assert!(s >= last, "brightness drops at {k}");
            last = s;
        }
        assert_eq!(false_colour(0.0), [0, 0, 0]);
    }

    #[test]
    fn labels_use_only_drawable_characters() {
        for v in [0.0, 1e-7, 0.012_345, 0.5, 1.0, 12.5, 4567.0, 2.5e12] {
            let s = label(v);
            assert!(s.chars().all(|c| glyph(c).is_some()), "{v} → {s}");
        }
        assert_eq!(label(0.5), "0.5");
        assert_eq!(label(1e-4), "1.00e-4");
    }

    #[test]
    fn legend_label_pixels_are_drawn() {
        let r = legend(120, 0.5);
        let lit = r.rgb.iter().filter(|c| **c == [230, 230, 230]).count();
        // "0" has 11 lit cells and "0.5" 11 + 1 + 13, each FONT² pixels.
        assert_eq!(lit, (11 + 11 + 1 + 13) * FONT * FONT);
    }
}

//! Structural similarity (SSIM, Wang, Bovik, Sheikh and Simoncelli 2004) of two scalar images.
//!
//! The standard settings: a Gaussian window of σ = 1.5 pixels truncated to 11×11 (radius 5),
//! normalised to sum 1; C1 = (0.01·L)², C2 = (0.03·L)² with L the peak value. Local statistics
//! are evaluated only where the whole window lies inside the image ("valid" positions) and the
//! SSIM map is averaged over them. Images smaller than 11 pixels in a direction use the largest
//! odd window that fits (radius ⌊(min(w, h) − 1)/2⌋), so even a 1×1 image has a value.

/// Gaussian standard deviation of the window, in pixels.
pub const SIGMA: f64 = 1.5;
/// Largest window radius (11×11 window).
pub const MAX_RADIUS: usize = 5;

/// The window radius used for a `width × height` image.
#[must_use]
pub fn radius(width: usize, height: usize) -> usize {
    MAX_RADIUS.min((width.min(height).max(1) - 1) / 2)
}

/// Normalised 1-D Gaussian weights for offsets −r..=r.
#[must_use]
pub fn weights(r: usize) -> Vec<f64> {
    let w: Vec<f64> = (0..=2 * r)
        .map(|k| {
            let d = k as f64 - r as f64;
            (-d * d / (2.0 * SIGMA * SIGMA)).exp()
        })
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|x| x / s).collect()
}

/// Separable "valid" filtering of a row-major image; returns (values, out_w, out_h).
fn filter(img: &[f64], w: usize, h: usize, k: &[f64]) -> (Vec<f64>, usize, usize) {
    let n = k.len();
    let (ow, oh) = (w + 1 - n, h + 1 - n);
    let mut rows = vec![0.0; ow * h];
    for y in 0..h {
        let line = &img[y * w..(y + 1) * w];
        for x in 0..ow {
            rows[y * ow + x] = k.iter().zip(&line[x..x + n]).map(|(a, b)| a * b).sum();
        }
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = k
                .iter()
                .enumerate()
                .map(|(j, a)| a * rows[(y + j) * ow + x])
                .sum();
        }
    }
    (out, ow, oh)
}

/// Mean SSIM of images `a` and `b` (row-major, `width × height`) with dynamic range `peak`.
/// Returns 1 for identical images; values lie in [−1, 1].
///
/// # Panics
/// If the slices do not hold `width · height` values (a programming error, not user input).
#[must_use]
pub fn ssim(a: &[f64], b: &[f64], width: usize, height: usize, peak: f64) -> f64 {
    assert_eq!(a.len(), width * height);
    assert_eq!(b.len(), width * height);
    if width == 0 || height == 0 {
        return 1.0;
    }
    let k = weights(radius(width, height));
    let c1 = (0.01 * peak).powi(2);
    let c2 = (0.03 * peak).powi(2);
    let prod = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        a.iter().zip(b).map(|(&x, &y)| f(x, y)).collect()
    };
    let (ma, ow, oh) = filter(a, width, height, &k);
    let (mb, _, _) = filter(b, width, height, &k);
    let (maa, _, _) = filter(&prod(&|x, _| x * x), width, height, &k);
    let (mbb, _, _) = filter(&prod(&|_, y| y * y), width, height, &k);
    let (mab, _, _) = filter(&prod(&|x, y| x * y), width, height, &k);
    let mut sum = 0.0;
    for i in 0..ow * oh {
        let (mx, my) = (ma[i], mb[i]);
        let vx = maa[i] - mx * mx;
        let vy = mbb[i] - my * my;
        let cxy = mab[i] - mx * my;
        sum +=
            ((2.0 * mx * my + c1) * (2.0 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
    }
    sum / (ow * oh) as f64
}

//! Shading of one camera sample: lights and material with Mitsuba's meaning, and the per-sample
//! values of every mode. Runs only for the closest hit of each sample.
//!
//! - `directional` (`direction` = the way light travels, `irradiance` E): L = ρ/π·E·max(0, n·l).
//! - `point` (`position`, `intensity` I): L = ρ/π·I/r²·max(0, n·l).
//! - `constant` (`radiance` L_e): one cosine-weighted direction per sample, estimate ρ·L_e·V.
//!
//! All three cast shadow rays. Like Mitsuba's one-sided `diffuse` BSDF, a surface seen from its
//! inside (n·view ≤ 0, n = ∇F/|∇F| pointing out of the solid) reflects nothing.
//!
//! Scene usage:
//! ```toml
//! [material]
//! albedo = [0.8, 0.8, 0.8]
//! [[lights]]
//! type = "directional"
//! direction = [-1, -1, -1]
//! irradiance = 3.0
//! [[lights]]
//! type = "constant"
//! radiance = 0.2
//! ```

use super::intersect::{Geometry, Hit};
use crate::complex::Role;
use glam::DVec3;

/// A light source (Mitsuba emitter).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Parallel light travelling along `direction` (unit), irradiance per RGB channel.
    Directional {
        /// Unit direction of travel.
        direction: DVec3,
        /// Irradiance E (RGB).
        irradiance: DVec3,
    },
    /// Isotropic point light.
    Point {
        /// Position.
        position: DVec3,
        /// Radiant intensity I (RGB).
        intensity: DVec3,
    },
    /// Uniform environment.
    Constant {
        /// Radiance (RGB).
        radiance: DVec3,
    },
}

/// What the image shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Mitsuba `direct` integrator with a `diffuse` BSDF (linear radiance).
    Shaded,
    /// World normal mapped to (n + 1)/2.
    Normal,
    /// Distance along the ray, grey (near bright).
    Depth,
    /// Colour by patch: face patches warm, edge patches cool, others grey.
    Patch,
    /// Lines of constant n·d.
    Isophote,
    /// Reflection lines of parallel stripes.
    Zebra,
    /// Mean or Gaussian curvature with a diverging colour map.
    Curvature,
}

impl std::str::FromStr for Mode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "shaded" => Mode::Shaded,
            "normal" => Mode::Normal,
            "depth" => Mode::Depth,
            "patch" => Mode::Patch,
            "isophote" => Mode::Isophote,
            "zebra" => Mode::Zebra,
            "curvature" => Mode::Curvature,
            _ => {
                return Err(format!(
                    "`{s}` is not one of shaded, normal, depth, patch, isophote, zebra, curvature"
                ))
            }
        })
    }
}

impl Mode {
    /// EXR channel names of the mode's own values (up to two).
    #[must_use]
    pub fn value_channels(self) -> &'static [&'static str] {
        match self {
            Mode::Isophote => &["isophote.value"],
            Mode::Zebra => &["zebra.value"],
            Mode::Curvature => &["curvature.mean", "curvature.gaussian"],
            _ => &[],
        }
    }
}

/// Options of the line and curvature modes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeOptions {
    /// Number of isophote lines over n·d ∈ [−1, 1] (or stripes for zebra).
    pub lines: u32,
    /// Line width in pixels.
    pub line_width: f64,
    /// Isophotes of n·(towards light) (true) or n·(towards eye) (false).
    pub isophote_light: bool,
    /// Draw isophotes over the shaded image (true) or alone on white (false).
    pub over_shaded: bool,
    /// Colour the curvature image by the Gaussian (true) or mean (false) curvature.
    pub gaussian: bool,
    /// Draw patch-boundary lines in `patch` mode.
    pub patch_boundaries: bool,
    /// The curvature colour map's span ±range; `None`: the image's own 99th percentile of
    /// |curvature|. A fixed range puts renders of different surfaces on one scale (the cubic
    /// and quintic panels of one model).
    pub curvature_range: Option<f64>,
}

impl Default for ModeOptions {
    fn default() -> Self {
        ModeOptions {
            lines: 16,
            line_width: 1.5,
            isophote_light: true,
            over_shaded: true,
            gaussian: false,
            patch_boundaries: true,
            curvature_range: None,
        }
    }
}

/// Surface data at a hit (shading step of the closest hit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Hit point.
    pub p: DVec3,
    /// Unit normal ∇F/|∇F|.
    pub n: DVec3,
    /// Mean curvature (positive for a sphere with outward normal).
    pub mean: f64,
    /// Gaussian curvature.
    pub gaussian: f64,
}

/// Normal and curvatures at `hit` on the ray `o + t·d`; curvature only when `curvature`.
#[must_use]
pub fn surface(geo: &Geometry, hit: &Hit, o: DVec3, d: DVec3, curvature: bool) -> Surface {
    let patch = geo.patches.get(hit.patch as usize);
    let p = o + hit.t * d;
    let (g, h) = if curvature {
        let (_, g, h) = patch.derivatives(&hit.bary);
        (g, h)
    } else {
        (patch.value_gradient(&hit.bary).1, glam::DMat3::ZERO)
    };
    let len = g.length();
    let n = if len > 0.0 && len.is_finite() {
        g / len
    } else {
        -d
    };
    let (mut mean, mut gaussian) = (0.0, 0.0);
    if curvature && len > 0.0 && len.is_finite() {
        // H = (|∇F|² tr Hess − ∇Fᵀ Hess ∇F) / (2|∇F|³); K = ∇Fᵀ adj(Hess) ∇F / |∇F|⁴.
        let tr = h.x_axis.x + h.y_axis.y + h.z_axis.z;
        mean = (len * len * tr - g.dot(h * g)) / (2.0 * len * len * len);
        let adj = adjugate(&h);
        gaussian = g.dot(adj * g) / (len * len * len * len);
        if !mean.is_finite() || !gaussian.is_finite() {
            mean = 0.0;
            gaussian = 0.0;
        }
    }
    Surface {
        p,
        n,
        mean,
        gaussian,
    }
}

fn adjugate(m: &glam::DMat3) -> glam::DMat3 {
    // adj(M) = det(M)·M⁻¹ written with cofactors (valid for singular M too).
    let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
    glam::DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b)).transpose()
}

/// A deterministic uniform number in [0, 1) for (pixel, sample, dimension).
#[must_use]
#[inline]
pub fn hash01(x: u32, y: u32, sample: u32, dim: u32) -> f64 {
    let mut z = (u64::from(x) << 32 | u64::from(y))
        ^ (u64::from(sample) << 20 | u64::from(dim)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    // splitmix64 finaliser.
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Everything the scene contributes to shading.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// Diffuse reflectance ρ (RGB).
    pub albedo: DVec3,
    /// Emitters.
    pub lights: Vec<Light>,
}

/// Offset of shadow-ray origins along the normal, relative to the scene extent.
const SHADOW_OFFSET: f64 = 1e-7;

/// Radiance reflected towards `-d` at `s` (Mitsuba `direct` with `diffuse`).
#[must_use]
pub fn radiance(
    geo: &Geometry,
    lighting: &Lighting,
    s: &Surface,
    d: DVec3,
    rnd: [f64; 2],
) -> DVec3 {
    if s.n.dot(-d) <= 0.0 {
        return DVec3::ZERO;
    }
    let eps = SHADOW_OFFSET * geo.extent().max(1e-300);
    let origin = s.p + s.n * eps;
    direct_light(lighting, s.n, origin, rnd, |l, tmax| {
        geo.occluded(origin, l, eps, tmax)
    })
}

/// The lights' contribution at a point with unit normal `n` seen from outside, one-sided
/// diffuse: the light loop of [`radiance`] for any tracer. `origin` is the shadow rays'
/// (already offset) origin; `occluded(l, tmax)` tells whether the ray `origin + t·l` meets
/// the surface before `tmax` (∞ for directional and constant emitters, the distance to a
/// point light). `rnd` samples the constant emitter's direction.
#[must_use]
#[inline]
pub fn direct_light(
    lighting: &Lighting,
    n: DVec3,
    origin: DVec3,
    rnd: [f64; 2],
    mut occluded: impl FnMut(DVec3, f64) -> bool,
) -> DVec3 {
    let rho = lighting.albedo;
    let mut out = DVec3::ZERO;
    for light in &lighting.lights {
        match *light {
            Light::Directional {
                direction,
                irradiance,
            } => {
                let l = -direction;
                let c = n.dot(l);
                if c > 0.0 && !occluded(l, f64::INFINITY) {
                    out += rho * irradiance * (c / std::f64::consts::PI);
                }
            }
            Light::Point {
                position,
                intensity,
            } => {
                let to = position - origin;
                let r2 = to.length_squared();
                let r = r2.sqrt();
                if r == 0.0 {
                    continue;
                }
                let l = to / r;
                let c = n.dot(l);
                if c > 0.0 && !occluded(l, r) {
                    out += rho * intensity * (c / (std::f64::consts::PI * r2));
                }
            }
            Light::Constant { radiance } => {
                // Cosine-weighted direction: the estimator is ρ·L·V.
                let l = cosine_direction(n, rnd);
                if !occluded(l, f64::INFINITY) {
                    out += rho * radiance;
                }
            }
        }
    }
    out
}

/// A cosine-weighted direction about the unit normal `n` from two uniform numbers (the sampling
/// of the `constant` emitter's shadow rays; public so other tracers can sample alike).
#[must_use]
pub fn cosine_direction(n: DVec3, rnd: [f64; 2]) -> DVec3 {
    let r = rnd[0].sqrt();
    let phi = 2.0 * std::f64::consts::PI * rnd[1];
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - rnd[0]).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// Colour of a patch for `patch` mode: face patches warm, edge patches cool, vertex patches
/// green, planar grey; neighbours differ in lightness by a hash of the index.
#[must_use]
pub fn patch_colour(role: Role, index: u32) -> DVec3 {
    let h = hash01(index, 0x5eed, 0, 0);
    let v = 0.55 + 0.45 * h;
    match role {
        Role::Face => DVec3::new(0.95, 0.55 + 0.3 * h, 0.25) * v,
        Role::Edge => DVec3::new(0.2, 0.45 + 0.3 * h, 0.95) * v,
        Role::Vertex => DVec3::new(0.3, 0.85, 0.35) * v,
        Role::Planar => DVec3::splat(0.7) * v,
        Role::Other => DVec3::new(0.6 + 0.4 * h, 0.6, 1.0 - 0.4 * h) * v,
    }
}

/// A diverging colour map on x ∈ [−1, 1]: blue, white at 0, red.
#[must_use]
pub fn diverging(x: f64) -> DVec3 {
    let x = if x.is_finite() {
        x.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let white = DVec3::splat(0.95);
    if x < 0.0 {
        white.lerp(DVec3::new(0.05, 0.2, 0.75), -x)
    } else {
        white.lerp(DVec3::new(0.75, 0.05, 0.05), x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_is_uniform_enough() {
        let n = 20000;
        let mean: f64 = (0..n).map(|i| hash01(i, 7, 3, 1)).sum::<f64>() / f64::from(n);
        // Standard error of a uniform mean over 20000 draws is 0.002; 5 sigma.
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }

    #[test]
    fn cosine_directions_have_mean_cosine_two_thirds() {
        let n = DVec3::new(0.3, -0.5, 0.8).normalize();
        let k = 20000;
        let mut m = 0.0;
        for i in 0..k {
            let d = cosine_direction(n, [hash01(i, 1, 0, 0), hash01(i, 1, 0, 1)]);
            assert!(d.dot(n) >= 0.0);
            m += d.dot(n);
        }
        m /= f64::from(k);
        // E[cos] under cos-weighted sampling is 2/3; sd of cos ≈ 0.24, 5 sigma ≈ 0.0085.
        assert!((m - 2.0 / 3.0).abs() < 0.01, "{m}");
    }
}

//! Mitsuba 3's `perspective` sensor: `to_world = look_at(origin, target, up)`, `fov` along
//! `fov_axis`, rays starting on the near-clip plane.
//!
//! Local +Z = f = normalize(target − origin); +X = normalize(up × f) (the image's left);
//! +Y = f × X. With tx, ty the tangents of the half field of view along the image axes, the ray
//! through film point (px, py) (pixels, origin at the top-left corner) has direction
//! d ∝ (1 − 2px/W)·tx·X + (1 − 2py/H)·ty·Y + f and starts at origin + d·near_clip/(d·f).
//!
//! Scene usage:
//! ```toml
//! [camera]
//! origin = [0, 1, 5]
//! target = [0, 0, 0]
//! up = [0, 1, 0]
//! fov = 30          # degrees
//! fov_axis = "x"    # x | y | diagonal | smaller | larger
//! width = 800
//! height = 600
//! ```

use glam::DVec3;
use std::str::FromStr;

/// The image axis the field of view is measured along (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    /// Horizontal (Mitsuba's default).
    X,
    /// Vertical.
    Y,
    /// Diagonal.
    Diagonal,
    /// The smaller image side.
    Smaller,
    /// The larger image side.
    Larger,
}

impl FromStr for FovAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "diagonal" => FovAxis::Diagonal,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            _ => {
                return Err(format!(
                    "`{s}` is not one of x, y, diagonal, smaller, larger"
                ))
            }
        })
    }
}

/// A pinhole camera with Mitsuba's conventions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub origin: DVec3,
    /// The look-at target the camera was built from (kept for exporters).
    pub target: DVec3,
    /// The up hint the camera was built from (kept for exporters).
    pub up: DVec3,
    /// Local +X (image left).
    pub x: DVec3,
    /// Local +Y (image up).
    pub y: DVec3,
    /// Local +Z (view direction).
    pub f: DVec3,
    /// tan of the half field of view along the image width.
    pub tx: f64,
    /// tan of the half field of view along the image height.
    pub ty: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance of the near-clip plane (Mitsuba default 0.01).
    pub near_clip: f64,
    /// Field of view in degrees along `fov_axis`.
    pub fov: f64,
    /// The axis `fov` is measured along.
    pub fov_axis: FovAxis,
}

impl Camera {
    /// A camera at `origin` looking at `target`; `fov` in degrees along `axis`.
    ///
    /// # Errors
    /// Coincident origin and target, `up` parallel to the view direction, fov outside (0, 180),
    /// or a zero image size.
    #[allow(clippy::too_many_arguments)]
    pub fn look_at(
        origin: DVec3,
        target: DVec3,
        up: DVec3,
        fov: f64,
        axis: FovAxis,
        width: u32,
        height: u32,
        near_clip: f64,
    ) -> Result<Self, String> {
        let f = (target - origin)
            .try_normalize()
            .ok_or("camera origin and target coincide")?;
        let x = up
            .cross(f)
            .try_normalize()
            .ok_or("camera up is parallel to the view direction")?;
        let y = f.cross(x);
        if !(fov > 0.0 && fov < 180.0) {
            return Err(format!("fov {fov} is outside (0, 180) degrees"));
        }
        if width == 0 || height == 0 {
            return Err("image width and height must be positive".into());
        }
        if !(near_clip >= 0.0 && near_clip.is_finite()) {
            return Err(format!("near_clip {near_clip} must be ≥ 0"));
        }
        let t = (fov.to_radians() * 0.5).tan();
        let (w, h) = (f64::from(width), f64::from(height));
        let (tx, ty) = match axis {
            FovAxis::X => (t, t * h / w),
            FovAxis::Y => (t * w / h, t),
            FovAxis::Diagonal => {
                let diag = w.hypot(h);
                (t * w / diag, t * h / diag)
            }
            FovAxis::Smaller => {
                if w <= h {
                    (t, t * h / w)
                } else {
                    (t * w / h, t)
                }
            }
            FovAxis::Larger => {
                if w >= h {
                    (t, t * h / w)
                } else {
                    (t * w / h, t)
                }
            }
        };
        Ok(Camera {
            origin,
            target,
            up,
            x,
            y,
            f,
            tx,
            ty,
            width,
            height,
            near_clip,
            fov,
            fov_axis: axis,
        })
    }

    /// The same camera with another image size (the field of view keeps its axis).
    ///
    /// # Errors
    /// A zero size.
    pub fn resized(&self, width: u32, height: u32) -> Result<Self, String> {
        Camera::look_at(
            self.origin,
            self.origin + self.f,
            self.y,
            self.fov,
            self.fov_axis,
            width,
            height,
            self.near_clip,
        )
    }

    /// The ray (origin on the near-clip plane, unit direction) through film point (px, py).
    #[must_use]
    #[inline]
    pub fn ray(&self, px: f64, py: f64) -> (DVec3, DVec3) {
        let u = (1.0 - 2.0 * px / f64::from(self.width)) * self.tx;
        let v = (1.0 - 2.0 * py / f64::from(self.height)) * self.ty;
        let d = (u * self.x + v * self.y + self.f).normalize();
        let o = self.origin + d * (self.near_clip / d.dot(self.f));
        (o, d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_left_is_plus_x() {
        let c = Camera::look_at(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::ZERO,
            DVec3::Y,
            60.0,
            FovAxis::X,
            200,
            100,
            0.01,
        )
        .unwrap();
        let (o, d) = c.ray(100.0, 50.0);
        // Exact arithmetic on small integers.
        assert!((d - DVec3::NEG_Z).length() < 1e-15);
        assert!((o - DVec3::new(0.0, 0.0, 4.99)).length() < 1e-15);
        // Left edge: Mitsuba's +X = up × f = y × (−z) = −x in world: the image's left.
        let (_, d) = c.ray(0.0, 50.0);
        let want = DVec3::new(-(30f64.to_radians().tan()), 0.0, -1.0).normalize();
        assert!((d - want).length() < 1e-15, "{d}");
        // Top edge looks up by the vertical half-angle atan(tx·H/W).
        let (_, d) = c.ray(100.0, 0.0);
        assert!((d.y / -d.z - 30f64.to_radians().tan() * 0.5).abs() < 1e-15);
    }
}

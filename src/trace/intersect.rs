//! Ray × patch complex: the closest hit {t, patch, barycentrics} and shadow-ray occlusion.
//! Shading (normals, curvature) is a separate, later step (`shade`).
//!
//! Per candidate patch: clip the ray to the tetrahedron (barycentric gradients), restrict F to
//! that segment (univariate Bernstein form), take the first root after `tmin`, and accept it if
//! the patch's sheet rule does; otherwise continue after the rejected root.

// Index loops over the four barycentric components read better than zipped iterators.
#![allow(clippy::needless_range_loop)]

use super::bvh::{Bounds, Bvh};
use super::patch::{CompiledPatch, PatchStore, Sheet, MAX_DEGREE};
use crate::bb::uni;
use crate::complex::{PatchComplex, Role};
use glam::DVec3;

/// The closest intersection of a ray with the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction from the ray origin.
    pub t: f64,
    /// Index of the patch in the complex.
    pub patch: u32,
    /// Barycentric coordinates of the hit point in the patch's tetrahedron.
    pub bary: [f64; 4],
}

/// A patch complex compiled for ray queries: compiled patches and a BVH over their tetrahedra.
pub struct Geometry {
    /// The compiled patches, in the complex's order.
    pub patches: PatchStore,
    /// Hull role per patch (for patch shading).
    pub roles: Vec<Role>,
    /// Mesh element per patch.
    pub elements: Vec<u32>,
    bvh: Bvh,
    /// Bounds of all tetrahedra.
    pub bounds: Bounds,
}

/// Relative widening of each tetrahedron's ray interval: neighbouring tetrahedra compute their
/// shared face's crossing from different gradients, so a root on the face must not fall in a
/// rounding gap between them.
const CLIP_PAD: f64 = 1e-9;

/// The shooting-line test accepts a root when no other root precedes it by more than this
/// (in the line parameter t ∈ [0, 1]).
const SHEET_TOL: f64 = 1e-7;

impl Geometry {
    /// Compiles every patch and builds the BVH.
    ///
    /// # Errors
    /// A message naming the first patch that cannot be compiled.
    pub fn new(complex: &PatchComplex) -> Result<Self, String> {
        let mut patches = PatchStore::with_capacity(complex.patches.len());
        let mut boxes = Vec::with_capacity(complex.patches.len());
        for (i, p) in complex.patches.iter().enumerate() {
            patches.push(p, i)?;
            let v = p.tet_points();
            let min = v[0].min(v[1]).min(v[2]).min(v[3]);
            let max = v[0].max(v[1]).max(v[2]).max(v[3]);
            if !(min.is_finite() && max.is_finite()) {
                return Err(format!("patch {i}: tetrahedron is not finite"));
            }
            boxes.push(Bounds { min, max });
        }
        let bounds = boxes.iter().fold(
            Bounds {
                min: DVec3::splat(f64::INFINITY),
                max: DVec3::splat(f64::NEG_INFINITY),
            },
            |a, b| Bounds {
                min: a.min.min(b.min),
                max: a.max.max(b.max),
            },
        );
        let bounds = if patches.is_empty() {
            Bounds {
                min: DVec3::ZERO,
                max: DVec3::ZERO,
            }
        } else {
            bounds
        };
        Ok(Geometry {
            patches,
            roles: complex.patches.iter().map(|p| p.role).collect(),
            elements: complex.patches.iter().map(|p| p.element).collect(),
            bvh: Bvh::build(&boxes),
            bounds,
        })
    }

    /// Time the BVH build took.
    #[must_use]
    pub fn bvh_build_time(&self) -> std::time::Duration {
        self.bvh.build_time
    }

    /// Bytes used by compiled patches and the BVH.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.patches.memory_bytes()
            + self.roles.len() * std::mem::size_of::<Role>()
            + self.elements.len() * 4
            + self.bvh.memory_bytes()
    }

    /// Largest extent of the bounds (the scene's length scale).
    #[must_use]
    pub fn extent(&self) -> f64 {
        (self.bounds.max - self.bounds.min).max_element()
    }

    /// The closest hit of `o + t·d` (`d` unit) with `tmin ≤ t < tmax`.
    #[must_use]
    pub fn intersect(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        self.bvh.closest(o, d, tmax, |prim, bound| {
            match self.patch_hit(prim, o, d, tmin, bound) {
                Some((t, bary)) if t < bound => {
                    if best.is_none_or(|b| t < b.t) {
                        best = Some(Hit {
                            t,
                            patch: prim as u32,
                            bary,
                        });
                    }
                    t
                }
                _ => f64::INFINITY,
            }
        });
        best
    }

    /// True when `o + t·d` meets the surface for some `tmin ≤ t < tmax`.
    #[must_use]
    pub fn occluded(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
        self.bvh.any(o, d, tmax, |prim| {
            self.patch_hit(prim, o, d, tmin, tmax).is_some()
        })
    }

    /// The first accepted root of patch `i` on `o + t·d`, tmin ≤ t ≤ tmax.
    #[must_use]
    pub fn patch_hit(
        &self,
        i: usize,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, [f64; 4])> {
        let h = self.patches.header(i);
        if h.no_zero() {
            return None;
        }
        let (t0, t1, a0, rate) = h.clip(o, d)?;
        let pad = CLIP_PAD * (t1 - t0) + 1e-14 * t0.abs().max(t1.abs()).max(1e-300);
        let (t0, t1) = (t0 - pad, t1 + pad);
        let lo_t = t0.max(tmin);
        let hi_t = t1.min(tmax);
        if lo_t > hi_t || t1 <= t0 {
            return None;
        }
        let at = |t: f64| {
            let mut b = [0.0; 4];
            for k in 0..4 {
                b[k] = a0[k] + t * rate[k];
            }
            b
        };
        let (a, b) = (at(t0), at(t1));
        let p = self.patches.get(i);
        let mut c = [0.0; MAX_DEGREE + 1];
        let n = p.segment(&a, &b, &mut c);
        let len = t1 - t0;
        let s_hi = ((hi_t - t0) / len).min(1.0);
        let mut s_lo = ((lo_t - t0) / len).max(0.0);
        for _ in 0..16 {
            let s = uni::first_root_in_tol(&c[..=n], s_lo, s_hi, p.zero_tol())?;
            let mut alpha = [0.0; 4];
            for k in 0..4 {
                alpha[k] = (1.0 - s) * a[k] + s * b[k];
            }
            if Self::sheet_accepts(&p, &alpha) {
                return Some((t0 + s * len, alpha));
            }
            // Continue just after the rejected root.
            s_lo = s + 1e-9_f64.max(4.0 * f64::EPSILON * s);
            if s_lo > s_hi {
                return None;
            }
        }
        None
    }

    /// The sheet rule of `p` at the root with barycentrics `alpha`: true when the root is on
    /// the surface.
    pub fn sheet_accepts(p: &CompiledPatch<'_>, alpha: &[f64; 4]) -> bool {
        let Sheet::Shooting { base, top } = p.sheet() else {
            return true;
        };
        let mut q = [0.0; 4];
        let mut u = [0.0; 4];
        let (mut bs, mut ts) = (0.0, 0.0);
        for k in 0..4 {
            let x = alpha[k].max(0.0);
            if base & (1 << k) != 0 {
                q[k] = x;
                bs += x;
            } else if top & (1 << k) != 0 {
                u[k] = x;
                ts += x;
            }
        }
        let t = ts / (bs + ts);
        if ts <= 1e-12 || bs <= 1e-12 || t <= SHEET_TOL {
            // On the base (t = 0: nothing precedes it) or at the top simplex.
            return true;
        }
        for k in 0..4 {
            q[k] /= bs;
            u[k] /= ts;
        }
        let mut c = [0.0; MAX_DEGREE + 1];
        let mut n = p.segment(&q, &u, &mut c);
        for _ in 0..p.base_order().min(n) {
            // G(t) = t·H(t): the base point's root of a vanishing denominator is not F's.
            n = uni::deflate_at_zero(&mut c, n + 1) - 1;
        }
        // (4.5)–(4.7): F at the base point must not have the top weight's strict sign.
        if c[0] * p.top_weight() > 0.0 {
            return false;
        }
        uni::first_root_in(&c[..=n], 0.0, t - SHEET_TOL).is_none()
    }
}

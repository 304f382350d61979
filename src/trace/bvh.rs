//! The only contact with obvhs: an 8-wide compressed BVH (`CwBvh`, obvhs' fastest traversal;
//! leaves of one primitive, so each box test that passes costs one exact ray × tetrahedron
//! clip) over f64 boxes rounded outward to f32, with closest-hit and any-hit queries whose
//! callbacks return a distance (`f64::INFINITY` = miss). Callbacks receive the caller's
//! primitive index (obvhs slots are mapped through `primitive_indices`).
//!
//! CwBvh skips boxes that end within an absolute 1e-4 of the ray origin; the traversal ray
//! therefore starts [`ORIGIN_SHIFT`] behind the caller's origin (callbacks still use the exact
//! f64 ray and enforce their own `tmin`), so a shadow ray never loses the tetrahedra around
//! its own origin, whatever the scene's scale.

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::{Boundable, BvhBuildParams};
use std::time::{Duration, Instant};

/// An axis-aligned box in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

struct Prim(Aabb);

impl Boundable for Prim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Rounds `x` to an f32 no greater (`down`) or no smaller than `x`, then moves one more ulp out.
fn round_out(x: f64, down: bool) -> f32 {
    let f = x as f32;
    let f = if down {
        if f64::from(f) > x {
            f.next_down()
        } else {
            f
        }
    } else if f64::from(f) < x {
        f.next_up()
    } else {
        f
    };
    if down {
        f.next_down()
    } else {
        f.next_up()
    }
}

/// How far behind the caller's origin the f32 traversal ray starts: ten times CwBvh's
/// absolute near cull of 1e-4.
pub const ORIGIN_SHIFT: f64 = 1e-3;

/// A bounding volume hierarchy over boxes.
pub struct Bvh {
    bvh: CwBvh,
    /// Time the build took.
    pub build_time: Duration,
}

impl Bvh {
    /// Builds over `boxes` (leaf size 1, obvhs' medium preset otherwise). Boxes are padded by
    /// 1e-5 of the whole scene's extent (plus 1e-6 of the coordinates' magnitude) before
    /// rounding: f32 rounding of a ray's origin and direction moves it by ~1e-7 of the scene
    /// size per scene size travelled, so f32 traversal never skips a box the exact ray touches.
    #[must_use]
    pub fn build(boxes: &[Bounds]) -> Self {
        let start = Instant::now();
        let (lo, hi) = boxes.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(l, h), b| (l.min(b.min), h.max(b.max)),
        );
        let extent = if boxes.is_empty() {
            0.0
        } else {
            (hi - lo).max_element()
        };
        let prims: Vec<Prim> = boxes
            .iter()
            .map(|b| {
                let pad = DVec3::splat(1e-5 * extent) + b.min.abs().max(b.max.abs()) * 1e-6;
                let lo = b.min - pad;
                let hi = b.max + pad;
                Prim(Aabb::new(
                    Vec3A::new(
                        round_out(lo.x, true),
                        round_out(lo.y, true),
                        round_out(lo.z, true),
                    ),
                    Vec3A::new(
                        round_out(hi.x, false),
                        round_out(hi.y, false),
                        round_out(hi.z, false),
                    ),
                ))
            })
            .collect();
        let mut params = BvhBuildParams::medium_build();
        params.max_prims_per_leaf = 1;
        let mut core = Duration::ZERO;
        let bvh = if prims.is_empty() {
            CwBvh::default()
        } else {
            build_cwbvh(&prims, params, &mut core)
        };
        Bvh {
            bvh,
            build_time: start.elapsed(),
        }
    }

    /// Bytes of the node and index arrays.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.len() * std::mem::size_of::<obvhs::cwbvh::node::CwBvhNode>()
            + self.bvh.primitive_indices.len() * 4
    }

    /// The f32 traversal ray: origin [`ORIGIN_SHIFT`] behind `o`, distances shifted alike.
    fn ray(o: DVec3, d: DVec3, tmax: f64) -> Ray {
        let tmax = Self::shifted(tmax);
        let o = o - ORIGIN_SHIFT * d;
        Ray::new(
            Vec3A::new(o.x as f32, o.y as f32, o.z as f32),
            Vec3A::new(d.x as f32, d.y as f32, d.z as f32),
            0.0,
            tmax,
        )
    }

    /// A caller's distance `t` as a traversal-ray bound (rounded up, so f32 culling never
    /// drops an equally close box).
    #[inline]
    fn shifted(t: f64) -> f32 {
        if t.is_finite() {
            ((t + ORIGIN_SHIFT) as f32).next_up().next_up()
        } else {
            f32::INFINITY
        }
    }

    /// Visits the primitives whose boxes the ray `o + t·d`, t < `tmax`, may touch; `hit(prim,
    /// tmax)` returns the primitive's hit distance or `f64::INFINITY`, and the query shrinks
    /// `tmax` with each hit (the callback receives the current bound). Returns the smallest
    /// distance found.
    #[inline]
    pub fn closest<F: FnMut(usize, f64) -> f64>(
        &self,
        o: DVec3,
        d: DVec3,
        tmax: f64,
        mut hit: F,
    ) -> f64 {
        if self.bvh.nodes.is_empty() {
            return f64::INFINITY;
        }
        let mut best = tmax;
        let mut found = f64::INFINITY;
        let mut rh = RayHit::none();
        let indices = &self.bvh.primitive_indices;
        self.bvh
            .ray_traverse(Self::ray(o, d, tmax), &mut rh, |_ray, slot| {
                let prim = indices[slot] as usize;
                let t = hit(prim, best);
                if t < best {
                    best = t;
                    found = t;
                    Self::shifted(t)
                } else {
                    f32::INFINITY
                }
            });
        found
    }

    /// True when some callback reports a hit (`hit(prim)` returns true); stops at the first.
    #[inline]
    pub fn any<F: FnMut(usize) -> bool>(&self, o: DVec3, d: DVec3, tmax: f64, mut hit: F) -> bool {
        if self.bvh.nodes.is_empty() {
            return false;
        }
        let indices = &self.bvh.primitive_indices;
        !self
            .bvh
            .ray_traverse_miss(Self::ray(o, d, tmax), |_ray, slot| {
                if hit(indices[slot] as usize) {
                    0.0
                } else {
                    f32::INFINITY
                }
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_out_brackets() {
        for x in [0.1, -0.1, 1.0 / 3.0, 1e10 + 0.3, 0.0] {
            assert!(f64::from(round_out(x, true)) < x);
            assert!(f64::from(round_out(x, false)) > x);
        }
    }

    #[test]
    fn closest_finds_the_nearest_box() {
        // Unit boxes along +x at 0, 2, 4, …: the hit distance is the box's entry.
        let boxes: Vec<Bounds> = (0..50)
            .map(|i| Bounds {
                min: DVec3::new(2.0 * i as f64, 0.0, 0.0),
                max: DVec3::new(2.0 * i as f64 + 1.0, 1.0, 1.0),
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let o = DVec3::new(-10.0, 0.5, 0.5);
        let d = DVec3::X;
        let t = bvh.closest(o, d, f64::INFINITY, |p, _| boxes[p].min.x - o.x);
        assert_eq!(t, 10.0);
        let t = bvh.closest(o, d, f64::INFINITY, |p, _| {
            if p < 7 {
                f64::INFINITY
            } else {
                boxes[p].min.x - o.x
            }
        });
        assert_eq!(t, 24.0);
        assert!(bvh.any(o, d, f64::INFINITY, |p| p == 30));
        assert!(!bvh.any(o, -d, f64::INFINITY, |_| true));
    }
}

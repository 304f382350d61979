//! Interpolation: F = 0 and ∇F ∥ normal at every vertex of the complex, measured in every
//! patch that has the vertex as a corner (or, failing that, contains it).

use super::eval::PatchEval;
use super::faces::{point_key, PointKey};
use super::{InterpolationStats, Location, Measure};
use crate::complex::PatchComplex;
use crate::complex_io::longest_edge;
use glam::DVec3;
use rayon::prelude::*;

/// Barycentric slack for "inside a tetrahedron" when a vertex is not a corner (rounding of the
/// barycentric map of O(1) coordinates).
const INSIDE_SLACK: f64 = 1e-12;

/// Measures every vertex of `complex`.
pub(super) fn measure(complex: &PatchComplex, evals: &[PatchEval<'_>]) -> InterpolationStats {
    let mut corners: Vec<(PointKey, u32, u8)> = evals
        .par_iter()
        .enumerate()
        .flat_map_iter(|(pi, e)| {
            let t = e.patch.tet;
            (0..4u8).map(move |k| (point_key(t[usize::from(k)]), pi as u32, k))
        })
        .collect();
    corners.par_sort_unstable();

    let per_vertex: Vec<(Measure, Measure, usize, usize)> = complex
        .vertices
        .par_iter()
        .enumerate()
        .map(|(vi, v)| {
            let key = point_key(*v);
            let lo = corners.partition_point(|c| c.0 < key);
            let hi = corners.partition_point(|c| c.0 <= key);
            let normal = complex.normals.get(vi).map(|n| DVec3::from_array(*n));
            let mut value = Measure::default();
            let mut angle = Measure::default();
            let mut visit = |pi: usize, alpha: [f64; 4]| {
                let e = &evals[pi];
                let j = e.world_jet(alpha);
                let l = longest_edge(&e.patch.tet_points());
                let at = Location::new(&[e], *v, Some(vi));
                let g = j.grad.length();
                let rel = if j.value == 0.0 {
                    0.0
                } else {
                    j.value.abs() / (g * l)
                };
                value = std::mem::take(&mut value).max(Measure::one(rel, at.clone()));
                if let Some(n) = normal {
                    let a = j.grad.cross(n).length().atan2(j.grad.dot(n));
                    angle = std::mem::take(&mut angle).max(Measure::one(a, at));
                }
            };
            if lo < hi {
                for &(_, pi, k) in &corners[lo..hi] {
                    let mut alpha = [0.0; 4];
                    alpha[usize::from(k)] = 1.0;
                    visit(pi as usize, alpha);
                }
                return (value, angle, 0, 0);
            }
            // Not a corner: measure it in every tetrahedron containing it.
            let x = DVec3::from_array(*v);
            let mut found = false;
            for (pi, e) in evals.iter().enumerate() {
                let alpha = e.bary(x);
                if alpha.iter().all(|&a| a >= -INSIDE_SLACK) {
                    found = true;
                    visit(pi, alpha);
                }
            }
            (value, angle, 1, usize::from(!found))
        })
        .collect();

    let mut stats = InterpolationStats::default();
    for (value, angle, off, out) in per_vertex {
        stats.value = std::mem::take(&mut stats.value).max(value);
        stats.normal_angle = std::mem::take(&mut stats.normal_angle).max(angle);
        stats.off_corner += off;
        stats.outside += out;
    }
    stats
}

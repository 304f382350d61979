//! Distance of a surface to the polyhedron it approximates (1994 schemes cut corners): surface
//! points are sampled per patch along its promised single-sheet lines (from the j-vertex
//! through a lattice of the opposite face, or between lattices of the j-edge and the opposite
//! edge; the first root of F on each), and each point's distance to the triangulated polyhedron
//! is taken by brute force. Largest and mean, relative to the polyhedron's bounding-box
//! diagonal.

use crate::bb::uni;
use crate::complex::PatchComplex;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

/// Largest number of (sample, triangle) pairs measured; beyond it every k-th sample is used
/// (deterministic stride), so large models stay within seconds.
pub const MAX_PAIRS: usize = 200_000_000;

/// The distance measures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DistanceStats {
    /// Surface points measured.
    pub samples: usize,
    /// Largest distance / bounding-box diagonal.
    pub max: f64,
    /// Mean distance / bounding-box diagonal.
    pub mean: f64,
    /// The bounding-box diagonal of the polyhedron.
    pub diagonal: f64,
    /// The surface point farthest from the polyhedron.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_at: Option<[f64; 3]>,
}

/// Surface points of every patch with a j-vertex or j-edge: the first root of F in (0, 1)
/// on lines through `res` lattice steps per edge (at least 3, and 4 across a face so it has an
/// interior point: the lattice of the sheet check).
#[must_use]
pub fn surface_samples(complex: &PatchComplex, res: usize) -> Vec<DVec3> {
    let res = res.max(3);
    complex
        .patches
        .par_iter()
        .flat_map_iter(|p| {
            let v = p.tet_points();
            let (from, to) = super::sheets::j_line_ends(p, res).unwrap_or_default();
            let mut pts = Vec::new();
            for a in &from {
                for b in &to {
                    let mut c = [0.0; 16];
                    let mut len = p.segment_poly_bary(*a, *b, &mut c);
                    if len == 0 {
                        continue;
                    }
                    let scale = c[..len].iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    // A root at the start (the j-vertex on the surface) is not a sample: 1e-12
                    // is far above weight round-off and far below any weight set on purpose.
                    while len > 1 && c[0].abs() <= 1e-12 * scale {
                        len = uni::deflate_at_zero(&mut c, len);
                    }
                    if let Some(t) = uni::first_root(&c[..len]) {
                        let alpha: [f64; 4] = std::array::from_fn(|k| (1.0 - t) * a[k] + t * b[k]);
                        pts.push((0..4).map(|k| alpha[k] * v[k]).sum::<DVec3>());
                    }
                }
            }
            pts
        })
        .collect()
}

/// Distance from `x` to the triangle [a b c] (closest point by regions, Ericson §5.1.5).
#[must_use]
pub fn point_triangle_distance(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, x - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = x - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (x - (a + v * ab)).length();
    }
    let cp = x - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (x - (a + w * ac)).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (x - (b + w * (c - b))).length();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (x - (a + ab * v + ac * w)).length()
}

/// Distance measures of `complex`'s surface to the polyhedron (`positions`, `triangles`),
/// sampled with `res` lattice steps per patch edge.
#[must_use]
pub fn distance_to_polyhedron(
    complex: &PatchComplex,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    res: usize,
) -> DistanceStats {
    let (lo, hi) = positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let diagonal = (hi - lo).length();
    let all = surface_samples(complex, res);
    let stride = (all.len() * triangles.len()).div_ceil(MAX_PAIRS).max(1);
    let d: Vec<(f64, DVec3)> = all
        .par_iter()
        .step_by(stride)
        .map(|&x| {
            let m = triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| positions[k as usize]);
                    point_triangle_distance(x, a, b, c)
                })
                .fold(f64::INFINITY, f64::min);
            (m, x)
        })
        .collect();
    if d.is_empty() || diagonal.is_nan() || diagonal <= 0.0 {
        return DistanceStats {
            diagonal,
            ..DistanceStats::default()
        };
    }
    let (max, at) = d
        .iter()
        .copied()
        .fold((0.0, DVec3::ZERO), |m, x| if x.0 > m.0 { x } else { m });
    DistanceStats {
        samples: d.len(),
        max: max / diagonal,
        mean: d.iter().map(|x| x.0).sum::<f64>() / d.len() as f64 / diagonal,
        diagonal,
        max_at: Some(at.to_array()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The region formula against brute-force sampling of the triangle.
    #[test]
    fn point_triangle_distance_matches_sampling() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.5, 0.4),
        );
        for x in [
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(3.0, 0.0, 0.2),
            DVec3::new(1.5, 1.5, -0.5),
            DVec3::new(0.2, 2.5, 0.4),
        ] {
            let n = 400;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    best = best.min((x - (a + u * (b - a) + v * (c - a))).length());
                }
            }
            let d = point_triangle_distance(x, a, b, c);
            // The 400-step grid is within ~2/400 of the closest point; distances are ≥ 0.3.
            assert!(d <= best + 1e-12 && best - d < 5e-3, "{x}: {d} vs {best}");
        }
    }
}

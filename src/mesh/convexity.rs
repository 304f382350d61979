//! Convexity classes of edges and faces for given vertex normals, in the sense of both papers.
//!
//! 2001 (Xu, Huang, Bajaj, §3): for an edge [p_i p_j] with unit normals n_i, n_j let
//! a = (p_j − p_i)·n_j and b = (p_i − p_j)·n_i. Then a·b ≥ 0 with one of them > 0 is *positive
//! convex*, a = b = 0 *zero convex*, a·b ≥ 0 with one < 0 *negative convex*, a·b < 0
//! *nonconvex*. A triangle is positive convex when its three edges are positive or zero convex
//! with at least one positive, zero convex when all three are zero convex, negative convex
//! likewise, and nonconvex otherwise.
//!
//! 1994 (Bajaj, Chen, Xu, Definitions 3.1–3.2): the same four classes with the normals paired
//! the other way: a = (p_j − p_i)·n_i and b = (p_i − p_j)·n_j (so for outward normals of a convex
//! solid 1994 calls the edges *negatively* convex where 2001 calls them positively convex).
//! A polygon face is also convex or not as a plane polygon (§4–5).

use super::geometry::{area_vector, corner_angle};
use glam::DVec3;
use std::f64::consts::PI;

/// a or b counts as zero when |a| ≤ ZERO_TOL · |p_j − p_i| (a is a length times a cosine, so
/// this is a relative angle of 1e-9 rad: far below modelling precision, far above rounding).
pub const ZERO_TOL: f64 = 1e-9;

/// Convexity class of an edge or a triangle (2001 paper, §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Convexity {
    /// Positive convex.
    Positive,
    /// Zero convex.
    Zero,
    /// Negative convex.
    Negative,
    /// Nonconvex.
    Nonconvex,
}

/// The 2001 class of edge [p_i p_j] with unit vertex normals n_i, n_j
/// (a = (p_j − p_i)·n_j, b = (p_i − p_j)·n_i).
#[must_use]
pub fn edge_convexity(pi: DVec3, ni: DVec3, pj: DVec3, nj: DVec3) -> Convexity {
    let d = pj - pi;
    classify(d.dot(nj), -d.dot(ni), d.length())
}

/// The 1994 class of edge [p_i p_j] (Definition 3.1: a = (p_j − p_i)·n_i, b = (p_i − p_j)·n_j).
#[must_use]
pub fn edge_convexity_1994(pi: DVec3, ni: DVec3, pj: DVec3, nj: DVec3) -> Convexity {
    let d = pj - pi;
    classify(d.dot(ni), -d.dot(nj), d.length())
}

/// The four classes from a and b for an edge of length `len`.
fn classify(a: f64, b: f64, len: f64) -> Convexity {
    let tol = ZERO_TOL * len;
    let snap = |x: f64| if x.abs() <= tol { 0.0 } else { x };
    let (a, b) = (snap(a), snap(b));
    if a == 0.0 && b == 0.0 {
        Convexity::Zero
    } else if a * b < 0.0 {
        Convexity::Nonconvex
    } else if a > 0.0 || b > 0.0 {
        Convexity::Positive
    } else {
        Convexity::Negative
    }
}

/// The class of a triangle from the classes of its three edges.
#[must_use]
pub fn face_convexity(edges: [Convexity; 3]) -> Convexity {
    use Convexity::*;
    if edges.iter().all(|&e| e == Zero) {
        Zero
    } else if edges.iter().all(|&e| e == Positive || e == Zero) {
        Positive
    } else if edges.iter().all(|&e| e == Negative || e == Zero) {
        Negative
    } else {
        Nonconvex
    }
}

/// The 2001 class of triangle (p, n) (vertices and their unit normals).
#[must_use]
pub fn triangle_convexity(p: [DVec3; 3], n: [DVec3; 3]) -> Convexity {
    face_convexity([
        edge_convexity(p[0], n[0], p[1], n[1]),
        edge_convexity(p[1], n[1], p[2], n[2]),
        edge_convexity(p[2], n[2], p[0], n[0]),
    ])
}

/// The 1994 class of triangle (p, n) (Definition 3.2 over [`edge_convexity_1994`]).
#[must_use]
pub fn triangle_convexity_1994(p: [DVec3; 3], n: [DVec3; 3]) -> Convexity {
    face_convexity([
        edge_convexity_1994(p[0], n[0], p[1], n[1]),
        edge_convexity_1994(p[1], n[1], p[2], n[2]),
        edge_convexity_1994(p[2], n[2], p[0], n[0]),
    ])
}

/// True when the polygon `face` is convex in its plane (1994 paper): every corner turns the
/// same way as the face normal (straight corners allowed) and the corners add up to (n − 2)π,
/// which excludes self-intersecting stars.
#[must_use]
pub fn polygon_is_convex(positions: &[DVec3], face: &[u32]) -> bool {
    let Some(normal) = area_vector(positions, face).try_normalize() else {
        return false;
    };
    let n = face.len();
    let mut sum = 0.0;
    for k in 0..n {
        let angle = corner_angle(positions, face, k, normal);
        if angle > PI * (1.0 + 1e-12) {
            return false;
        }
        sum += angle;
    }
    // Rounding of n angles: a relative 1e-9 of the total is ample.
    (sum - (n as f64 - 2.0) * PI).abs() <= 1e-9 * n as f64 * PI
}

#[cfg(test)]
mod tests {
    use super::*;
    use Convexity::*;

    #[test]
    fn edge_classes_from_analytic_configurations() {
        let (pi, pj) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        // Unit sphere, radial normals: a = b = 1 − pi·pj > 0.
        assert_eq!(edge_convexity(pi, pi, pj, pj), Positive);
        // Inward normals: both negative.
        assert_eq!(edge_convexity(pi, -pi, pj, -pj), Negative);
        // A plane with its normal: both exactly zero.
        let z = DVec3::Z;
        assert_eq!(edge_convexity(pi, z, pj, z), Zero);
        // One normal tilted towards the other end, one away: a > 0 > b.
        let d = (pj - pi).normalize();
        let ni = (z + 0.5 * d).normalize();
        let nj = (z + 0.5 * d).normalize();
        // a = (pj − pi)·nj > 0, b = (pi − pj)·ni < 0.
        assert_eq!(edge_convexity(pi, ni, pj, nj), Nonconvex);
        // One zero, one positive: positive; one zero, one negative: negative.
        assert_eq!(
            edge_convexity(pi, z, pj, (z + 0.5 * d).normalize()),
            Positive
        );
        assert_eq!(
            edge_convexity(pi, z, pj, (z - 0.5 * d).normalize()),
            Negative
        );
    }

    #[test]
    fn zero_tolerance_is_relative() {
        // A tilt of 1e-12 rad is "zero" at every scale; 1e-6 rad never is.
        for scale in [1e-6, 1.0, 1e6] {
            let (pi, pj) = (DVec3::ZERO, DVec3::X * scale);
            let tiny = DVec3::new(1e-12, 0.0, 1.0).normalize();
            assert_eq!(
                edge_convexity(pi, DVec3::Z, pj, tiny),
                Zero,
                "scale {scale}"
            );
            let small = DVec3::new(1e-6, 0.0, 1.0).normalize();
            assert_eq!(
                edge_convexity(pi, DVec3::Z, pj, small),
                Positive,
                "scale {scale}"
            );
        }
    }

    #[test]
    fn face_classes() {
        assert_eq!(face_convexity([Positive, Zero, Positive]), Positive);
        assert_eq!(face_convexity([Zero, Zero, Zero]), Zero);
        assert_eq!(face_convexity([Negative, Zero, Negative]), Negative);
        assert_eq!(face_convexity([Positive, Negative, Zero]), Nonconvex);
        assert_eq!(face_convexity([Positive, Positive, Nonconvex]), Nonconvex);
        let p = [DVec3::X, DVec3::Y, DVec3::Z];
        assert_eq!(triangle_convexity(p, p), Positive);
        assert_eq!(triangle_convexity(p, p.map(|v| -v)), Negative);
        // 1994 pairs the normals the other way: radial normals of a sphere give negative.
        assert_eq!(triangle_convexity_1994(p, p), Negative);
        assert_eq!(triangle_convexity_1994(p, p.map(|v| -v)), Positive);
    }

    #[test]
    fn papers_pair_normals_differently() {
        // n_i tilted, n_j vertical: 2001 looks at (p_j − p_i)·n_j = 0 and (p_i − p_j)·n_i > 0,
        // 1994 at (p_j − p_i)·n_i < 0 and (p_i − p_j)·n_j = 0.
        let (pi, pj) = (DVec3::ZERO, DVec3::X);
        let ni = DVec3::new(-0.5, 0.0, 1.0).normalize();
        assert_eq!(edge_convexity(pi, ni, pj, DVec3::Z), Positive);
        assert_eq!(edge_convexity_1994(pi, ni, pj, DVec3::Z), Negative);
    }

    #[test]
    fn polygon_convexity() {
        let pts = |xy: &[(f64, f64)]| -> Vec<DVec3> {
            xy.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
        };
        let square = pts(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert!(polygon_is_convex(&square, &[0, 1, 2, 3]));
        assert!(
            polygon_is_convex(&square, &[3, 2, 1, 0]),
            "orientation does not matter"
        );
        let with_straight = pts(&[(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert!(polygon_is_convex(&with_straight, &[0, 1, 2, 3, 4]));
        let l = pts(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]);
        assert!(!polygon_is_convex(&l, &[0, 1, 2, 3, 4, 5]));
        // Pentagram: every corner turns the same way, but it winds twice.
        let star: Vec<DVec3> = (0..5)
            .map(|k| {
                let a = std::f64::consts::TAU * (2 * k) as f64 / 5.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert!(!polygon_is_convex(&star, &[0, 1, 2, 3, 4]));
    }
}

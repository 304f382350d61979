//! Convexity classes of edges and faces for given vertex normals, in the sense of both papers.
//!
//! 2001 (Xu, Huang, Bajaj, §3): for an edge [p_i p_j] with unit normals n_i, n_j let
//! a = (p_j − p_i)·n_j and b = (p_i − p_j)·n_i. Then a·b ≥ 0 with one of them > 0 is *positive
//! convex*, a = b = 0 *zero convex*, a·b ≥ 0 with one < 0 *negative convex*, a·b < 0
//! *nonconvex*. A triangle is positive convex when its three edges are positive or zero convex
//! with at least one positive, zero convex when all three are zero convex, negative convex
//! likewise, and nonconvex otherwise.
//!
//! 1994 (Bajaj, Chen, Xu): a polygon face is convex or not as a plane polygon.

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

/// The class of edge [p_i p_j] with unit vertex normals n_i, n_j.
#[must_use]
pub fn edge_convexity(pi: DVec3, ni: DVec3, pj: DVec3, nj: DVec3) -> Convexity {
    let d = pj - pi;
    let tol = ZERO_TOL * d.length();
    let snap = |x: f64| if x.abs() <= tol { 0.0 } else { x };
    let a = snap(d.dot(nj));
    let b = snap(-d.dot(ni));
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

/// The class of triangle (p, n) (vertices and their unit normals).
#[must_use]
pub fn triangle_convexity(p: [DVec3; 3], n: [DVec3; 3]) -> Convexity {
    face_convexity([
        edge_convexity(p[0], n[0], p[1], n[1]),
        edge_convexity(p[1], n[1], p[2], n[2]),
        edge_convexity(p[2], n[2], p[0], n[0]),
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

//! C2 data at the points of T: value 0, gradient = the unit normal, and a Hessian estimated from
//! how the normals of the neighbouring points of T turn (the shape operator), so that near each
//! point F behaves like a signed distance: ∇F = n, ∇²F = dn/dx on the tangent plane, 0 along n.
//! The number 0, 1 and 2 weights of every tetrahedron at a point of T come from this 2-jet
//! ((2.5), (2.6) of the 1994 paper, computed here as the degree-5 blossom of the Taylor
//! polynomial, which is the same thing).

use crate::hull::simplicial::SimplicialHull;
use glam::{DMat3, DVec3};

/// The 2-jet of F at one point of T (value 0).
#[derive(Clone, Copy, Debug)]
pub struct Jet {
    /// The point.
    pub p: DVec3,
    /// ∇F there (the unit normal).
    pub g: DVec3,
    /// ∇²F there (symmetric).
    pub h: DMat3,
}

impl Jet {
    /// The degree-5 blossom of the Taylor polynomial T(x) = g·(x−p) + ½(x−p)ᵀH(x−p) at `args`
    /// (five points): the BB weight of T at the domain point whose multiset of tetrahedron
    /// vertices is `args`.
    #[must_use]
    pub fn blossom5(&self, args: &[DVec3; 5]) -> f64 {
        let d: Vec<DVec3> = args.iter().map(|x| *x - self.p).collect();
        let lin: f64 = d.iter().map(|v| self.g.dot(*v)).sum::<f64>() / 5.0;
        let mut quad = 0.0;
        for k in 0..5 {
            for l in k + 1..5 {
                quad += d[k].dot(self.h * d[l]);
            }
        }
        // Ten pairs, ½ from the Taylor factor.
        lin + quad / 20.0
    }
}

/// The five points whose blossom is the BB weight at multi-index `l` (|l| = 5) of the
/// tetrahedron `pts`: each corner as often as `l` names it ([`Jet::blossom5`]'s arguments).
#[must_use]
pub fn domain_args(pts: &[DVec3; 4], l: [u8; 4]) -> [DVec3; 5] {
    let mut args = [DVec3::ZERO; 5];
    let mut c = 0;
    for (i, &m) in l.iter().enumerate() {
        for _ in 0..m {
            args[c] = pts[i];
            c += 1;
        }
    }
    args
}

/// The jets at every point of `hull`, the Hessian scaled by `curvature` (1 = the estimated
/// shape operator, 0 = planar data).
///
/// The shape operator S at p is the symmetric 2×2 tensor on the tangent plane that best maps, in
/// the least-squares sense, each edge e = p_j − p of T at p to the tangential part of n_j − n
/// (each edge weighted by 1/|e|², so the fit is scale free). For a sphere of radius r with exact
/// normals it is I/r exactly.
#[must_use]
pub fn estimate(hull: &SimplicialHull, curvature: f64) -> Vec<Jet> {
    let np = hull.points.len();
    let nbrs = hull.point_neighbours();
    (0..np)
        .map(|i| {
            let p = hull.points[i];
            let n = hull.normals[i].normalize();
            let (t1, t2) = n.any_orthonormal_pair();
            // Normal equations of the 3-parameter fit (a, b, c): S = [[a, b], [b, c]].
            let mut m = [[0.0_f64; 3]; 3];
            let mut r = [0.0_f64; 3];
            for &j in &nbrs[i] {
                let e = hull.points[j as usize] - p;
                let dn = hull.normals[j as usize].normalize() - n;
                let w = 1.0 / e.length_squared().max(f64::MIN_POSITIVE);
                let (x, y) = (e.dot(t1), e.dot(t2));
                let (u, v) = (dn.dot(t1), dn.dot(t2));
                // S·(x, y) = (a x + b y, b x + c y) ≈ (u, v).
                let rows = [([x, y, 0.0], u), ([0.0, x, y], v)];
                for (row, rhs) in rows {
                    for aa in 0..3 {
                        for bb in 0..3 {
                            m[aa][bb] += w * row[aa] * row[bb];
                        }
                        r[aa] += w * row[aa] * rhs;
                    }
                }
            }
            let s = solve3(m, r).unwrap_or([0.0; 3]);
            let h = curvature
                * (s[0] * outer(t1, t1)
                    + s[1] * (outer(t1, t2) + outer(t2, t1))
                    + s[2] * outer(t2, t2));
            Jet { p, g: n, h }
        })
        .collect()
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Solves a 3×3 system by Cramer's rule; `None` when it is (nearly) singular.
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let mat = DMat3::from_cols(
        DVec3::new(m[0][0], m[1][0], m[2][0]),
        DVec3::new(m[0][1], m[1][1], m[2][1]),
        DVec3::new(m[0][2], m[1][2], m[2][2]),
    );
    let det = mat.determinant();
    let scale = m.iter().flatten().fold(0.0_f64, |a, b| a.max(b.abs()));
    if det.abs() <= 1e-12 * scale.powi(3) || !det.is_finite() {
        return None;
    }
    let x = mat.inverse() * DVec3::from_array(r);
    Some(x.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;

    /// Points of an octahedron on the sphere of radius 2 with exact normals: the shape operator is
    /// I/2 on the tangent plane and 0 along the normal.
    #[test]
    fn sphere_shape_operator() {
        let r = 2.0;
        // The regular octahedron on the unit axes: its vertices are its sphere normals.
        let (dirs, triangles) = crate::fixtures::octahedron();
        let hull = SimplicialHull {
            points: dirs.iter().map(|d| *d * r).collect(),
            normals: dirs,
            origins: vec![PointOrigin::Other; 6],
            triangles,
            apexes: vec![[None, None]; 8],
            element: vec![0; 8],
        };
        let jets = estimate(&hull, 1.0);
        for (k, j) in jets.iter().enumerate() {
            let d = hull.normals[k];
            let expect = (DMat3::IDENTITY - outer(d, d)) * (1.0 / r);
            let diff = (j.h - expect).to_cols_array();
            // Exact data, a 3×3 solve: rounding only.
            assert!(diff.iter().all(|d| d.abs() < 1e-12), "{k}: {:?}", j.h);
        }
    }

    /// The blossom on the diagonal is the Taylor polynomial.
    #[test]
    fn blossom_diagonal_is_taylor_value() {
        let jet = Jet {
            p: DVec3::new(0.1, 0.2, 0.3),
            g: DVec3::new(0.0, 0.6, 0.8),
            h: DMat3::from_cols(
                DVec3::new(1.0, 0.2, 0.0),
                DVec3::new(0.2, 0.5, 0.1),
                DVec3::new(0.0, 0.1, 0.3),
            ),
        };
        let x = DVec3::new(0.7, -0.4, 1.1);
        let d = x - jet.p;
        let t = jet.g.dot(d) + 0.5 * d.dot(jet.h * d);
        // A few dozen products of O(1) numbers.
        assert!((jet.blossom5(&[x; 5]) - t).abs() < 1e-14);
    }
}

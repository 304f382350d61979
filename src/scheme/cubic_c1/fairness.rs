//! A fairness figure for A-patch surfaces on a simplicial hull (issue 7): how far the surface
//! normal turns away from the smooth blend of the normals at the points of T.
//!
//! Over every face tetrahedron [v0 v1 v2 q] (a j-patch for its apex) the surface is sampled on
//! the lines from a lattice of the base triangle to the apex; at the first zero of F on each
//! line the unit gradient is compared with n_b = normalize(Σ b_k n_k), the blend of the three
//! vertex normals at the line's base point b (barycentric). Over every edge tetrahedron
//! [p_i p_j q s] (single sheeted between [p_i p_j] and [q s]) the lines run from (1−u)p_i + u p_j
//! to points of [q s] and the reference is normalize((1−u)n_i + u n_j). A fair surface follows
//! the blend closely (the deviation of a smooth surface from its Phong normal is second order in
//! the triangle size); a dent or a wrinkle turns the normal away from it, however small it is.
//! The figure needs only the complex (its points of T and their normals), so it measures any
//! scheme's output before and after a change.

use crate::bb::{BbPoly, Tet};
use crate::complex::{PatchComplex, Role};
use glam::DVec3;
use std::collections::HashMap;

/// Lattice steps per edge of a face tetrahedron's base (and per segment of an edge
/// tetrahedron) on which lines are shot.
pub const FAIRNESS_RES: usize = 6;

/// Normal deviations, in degrees, over the sampled surface points of one kind of patch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deviation {
    /// Surface points sampled (lines that met F = 0).
    pub samples: usize,
    /// Largest angle between the surface normal and the blended vertex normal.
    pub max: f64,
    /// Root mean square of the angle.
    pub rms: f64,
    /// 95th percentile of the angle.
    pub p95: f64,
}

/// [`fairness`]'s result: face and edge tetrahedra separately, and all together.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fairness {
    /// Over face tetrahedra.
    pub face: Deviation,
    /// Over edge tetrahedra.
    pub edge: Deviation,
    /// Over both.
    pub all: Deviation,
}

fn key(p: [f64; 3]) -> [u64; 3] {
    p.map(f64::to_bits)
}

fn summarise(mut a: Vec<f64>) -> Deviation {
    if a.is_empty() {
        return Deviation::default();
    }
    a.sort_by(f64::total_cmp);
    let n = a.len();
    let rms = (a.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
    Deviation {
        samples: n,
        max: a[n - 1],
        rms,
        p95: a[((n - 1) as f64 * 0.95).round() as usize],
    }
}

/// First zero of the cubic (or any degree) with univariate Bernstein coefficients `c` on
/// (0, 1]: the first sign change on a grid of 64 steps, refined by 60 bisections.
fn first_zero(c: &[f64]) -> Option<f64> {
    const STEPS: usize = 64;
    let f = |t: f64| crate::bb::uni::eval(c, t);
    let mut t0 = 0.0;
    let mut f0 = f(0.0);
    for k in 1..=STEPS {
        let t1 = k as f64 / STEPS as f64;
        let f1 = f(t1);
        if f0 == 0.0 && k == 1 {
            // The line starts on the surface (a base point on T's edge): skip that zero.
            t0 = t1;
            f0 = f1;
            continue;
        }
        if (f0 < 0.0) != (f1 < 0.0) || f1 == 0.0 {
            let (mut a, mut b, fa) = (t0, t1, f0);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if (f(m) < 0.0) == (fa < 0.0) {
                    a = m;
                } else {
                    b = m;
                }
            }
            return Some(0.5 * (a + b));
        }
        t0 = t1;
        f0 = f1;
    }
    None
}

/// The fairness figure of `complex` (see the module docs). Patches whose tetrahedron's points
/// of T are not among the complex's vertices, or that are degenerate, are skipped.
#[must_use]
pub fn fairness(complex: &PatchComplex) -> Fairness {
    let index: HashMap<[u64; 3], usize> = complex
        .vertices
        .iter()
        .enumerate()
        .map(|(k, &v)| (key(v), k))
        .collect();
    let normal = |p: [f64; 3]| {
        index
            .get(&key(p))
            .and_then(|&k| complex.normals.get(k))
            .map(|&n| DVec3::from_array(n).normalize_or_zero())
    };
    let res = FAIRNESS_RES;
    let mut face = Vec::new();
    let mut edge = Vec::new();
    let mut line = [0.0; 16];
    for patch in &complex.patches {
        let v = patch.tet.map(DVec3::from_array);
        let Some(tet) = Tet::new(v) else { continue };
        let poly = BbPoly::new(usize::from(patch.degree), patch.weights.clone());
        let mut sample = |a0: [f64; 4], a1: [f64; 4], n_ref: DVec3, out: &mut Vec<f64>| {
            let len = poly.restrict(a0, a1, &mut line);
            let Some(t) = first_zero(&line[..len]) else {
                return;
            };
            let a: [f64; 4] = std::array::from_fn(|k| (1.0 - t) * a0[k] + t * a1[k]);
            let Some(g) = poly.gradient(&tet, a).try_normalize() else {
                return;
            };
            let Some(n) = n_ref.try_normalize() else {
                return;
            };
            out.push(g.dot(n).clamp(-1.0, 1.0).acos().to_degrees());
        };
        match patch.role {
            Role::Face => {
                let (Some(n0), Some(n1), Some(n2)) = (
                    normal(patch.tet[0]),
                    normal(patch.tet[1]),
                    normal(patch.tet[2]),
                ) else {
                    continue;
                };
                // Interior lattice points of the base (the vertices and edges of T are where
                // the surface is interpolated; their neighbourhood is in the edge tetrahedra).
                for i in 1..res {
                    for j in 1..res - i {
                        let b = [i, j, res - i - j].map(|x| x as f64 / res as f64);
                        let n = b[0] * n0 + b[1] * n1 + b[2] * n2;
                        sample([b[0], b[1], b[2], 0.0], [0.0, 0.0, 0.0, 1.0], n, &mut face);
                    }
                }
            }
            Role::Edge => {
                let (Some(ni), Some(nj)) = (normal(patch.tet[0]), normal(patch.tet[1])) else {
                    continue;
                };
                for i in 1..res {
                    let u = i as f64 / res as f64;
                    let n = (1.0 - u) * ni + u * nj;
                    for j in 0..=res {
                        let s = j as f64 / res as f64;
                        sample([1.0 - u, u, 0.0, 0.0], [0.0, 0.0, 1.0 - s, s], n, &mut edge);
                    }
                }
            }
            _ => {}
        }
    }
    let all: Vec<f64> = face.iter().chain(&edge).copied().collect();
    Fairness {
        face: summarise(face),
        edge: summarise(edge),
        all: summarise(all),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One face patch over the triangle z = 0 with normals +z whose surface is the plane
    /// z = 0.3: the deviation is 0 everywhere; with a bump it is not.
    #[test]
    fn flat_patch_has_no_deviation_and_a_bump_has() {
        let tet = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.3, 0.3, 1.0],
        ];
        let make = |bump: f64| {
            // F = λ3 − 0.3 (linear; zero on the plane z = 0.3, normal +z), minus a bump on
            // the base's middle weight.
            let weights = crate::bb::multi_indices(3)
                .iter()
                .map(|l| {
                    let z = f64::from(l[3]) / 3.0 - 0.3;
                    if *l == [1, 1, 1, 0] {
                        z - bump
                    } else {
                        z
                    }
                })
                .collect();
            let mut c = PatchComplex::new("test");
            c.vertices = tet[..3].to_vec();
            c.normals = vec![[0.0, 0.0, 1.0]; 3];
            let mut p = crate::fixtures::plain_patch(tet.map(DVec3::from), 3, weights);
            p.role = Role::Face;
            p.jvertex = Some(3);
            c.patches.push(p);
            c
        };
        let flat = fairness(&make(0.0));
        // res 6: the interior lattice has 10 points.
        assert_eq!(flat.face.samples, 10);
        // Rounding of acos near 1 (≈ 1e-6 degrees for dot products off by 1e-16).
        assert!(flat.all.max < 1e-5, "{flat:?}");
        let bumped = fairness(&make(0.05));
        assert!(bumped.all.max > 1.0, "{bumped:?}");
    }

    #[test]
    fn first_zero_of_a_line() {
        // (1 − t)·(−1) + t·1 → zero at ½, cubic elevation: c = [−1, −1/3, 1/3, 1].
        let t = first_zero(&[-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0]).unwrap();
        // 60 bisections of a 1/64 bracket.
        assert!((t - 0.5).abs() < 1e-12);
        assert!(first_zero(&[1.0, 1.0, 1.0, 1.0]).is_none());
    }
}

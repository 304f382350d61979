//! The weights of the C¹ cubic scheme (1994, §6) on one smoothable simplicial hull.
//!
//! Notation: a face tetrahedron V = [v0 v1 v2 q] (the triangle of T in its stored order, then
//! the apex q on one side), weights a_λ, λ = (λ0 λ1 λ2 λ3), λ3 the apex's share. An edge
//! tetrahedron W = [p_i p_j q s] ([`crate::hull::simplicial::EdgeTet`]), weights w_μ,
//! μ = (μ_i μ_j μ_q μ_s). F < 0 inside, F > 0 outside; ∇F(p) = c·n(p) at every point of T.
//!
//! | weight | paper | fixed by |
//! | --- | --- | --- |
//! | a_3e_k = 0 | number 0 | F = 0 at the points of T |
//! | a_2e_k+e_l, w_2100, w_2010, w_2001, … | number 1 | (2.5): (v_l − v_k)·∇F(v_k)/3; those toward an apex have its side's sign because apexes beyond a tangent plane were moved first ([`super::tangent`]) |
//! | a_1110 | number 2 (free) | `center` × the quadratic-precision value Σ(6 edge weights)/4, then the least change keeping the blossom of an edge convex for the other side only at the side's apexes with the edge's sign ([`super::pocket`]) |
//! | a_e_k+e_l+e_q, w_1110, w_1101 | number 3 | (2.8) across [p_i p_j q], (2.10) across [p_i p_j s] and (2.8) across an L-U pair's triangle: all are values A_e(x) of one affine "edge blossom" per edge e of T ([`EdgeBlossom`]) |
//! | a_e_k+2e_q | number 4 (free) | the fair target ([`super::fair`]) on a pseudo-centroid's triangles, else the `level` rule; raised for the sign conditions |
//! | w_1011, w_0111 | number 5 | (2.8) across [p_i p_j q] |
//! | a_3e_q = F(q) | number 6 (free) | as number 4 |
//! | w_0021 | number 7 | (2.8) across [p_i p_j q] (the paper writes (2.10)) |
//! | w_1002, w_0102, w_0003 | remaining, λ ≤ 1 toward the partner | (2.10): the average of the pair's w_1011 (w_0111, w_0012) |
//! | w_0012 | remaining (free) | = w_0021 of the same tetrahedron |
//!
//! Why the edge blossom: around an edge e = [p_i p_j] of T the weights b(p_i, p_j, x) one step
//! off the edge (x = the third point of a triangle, an apex, a midpoint s) are the blossom of the
//! cubic with two arguments on the edge. C¹ across every face through e (2.8, 2.10) holds exactly
//! when they are the values at x of one affine function A_e. Its values at p_i, p_j (number 1)
//! and at the triangles' third points (number 2) fix it when the four points span space; the
//! paper's local 3×3 (single sided) or 6×8 (L-U pairs, a closed ring around e) systems then
//! have this unique solution. When T is flat at e (the singular case of the paper's matrix,
//! "coplanar adjacent triangles"), the out-of-plane slope is free: it is taken from the normals,
//! (∇F(p_i) + ∇F(p_j))/6, the slope of a linear F.
//!
//! Sign conditions (Theorem 2.1, k = 1, signs for the outer side; the inner side mirrors them):
//! a face tetrahedron is a j-patch for j = its apex when λ3 = 0 weights are ≤ 0 and λ3 ≥ 2
//! weights are ≥ 0; an edge tetrahedron is single sheeted along every segment from a point of
//! [p_i p_j] to a point of [q s] when μ_q + μ_s = 0 weights are ≤ 0 and μ_q + μ_s ≥ 2 weights
//! are ≥ 0 (the same Descartes argument: along such a segment the Bernstein coefficients are
//! positive combinations of one level each). The free weights 4 and 6 are raised until both hold.

use crate::bb::{index_of, Tet};
use glam::DVec3;

/// The affine function x ↦ A_e(x) = value + slope·(x − origin) holding the blossom values
/// b(p_i, p_j, x) of every cubic around an edge of T.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeBlossom {
    /// p_i.
    pub origin: DVec3,
    /// A_e(p_i).
    pub value: f64,
    /// ∇A_e.
    pub slope: DVec3,
    /// True when the constraints did not span space (T flat at the edge) and the slope across
    /// was taken from the normals; C¹ then requires the in-plane data to agree.
    pub flat: bool,
}

impl EdgeBlossom {
    /// A_e(x).
    #[must_use]
    pub fn at(&self, x: DVec3) -> f64 {
        self.value + self.slope.dot(x - self.origin)
    }

    /// The blossom of edge [p_i p_j]: A(p_i) = `wi` (the weight 2e_i+e_j), and A(x) = v for
    /// every `(x, v)` in `known` (p_j and the third points of the adjacent triangles).
    /// Minimum change of the prior slope `prior` subject to those constraints; a constraint
    /// that is (nearly) dependent on the earlier ones is dropped and `flat` set.
    #[must_use]
    pub fn fit(pi: DVec3, wi: f64, known: &[(DVec3, f64)], prior: DVec3) -> EdgeBlossom {
        // Gram–Schmidt on the constraint directions u_k = x_k − p_i: slope = prior + Σ c_k e_k
        // with orthonormal e_k, each constraint fixing its component along e_k.
        let mut basis: Vec<(DVec3, DVec3, f64)> = Vec::new(); // (e_k, u_k, target)
        let mut flat = false;
        for &(x, v) in known {
            let u = x - pi;
            // Projected out twice ("twice is enough"): near-dependent constraints (T nearly
            // flat at the edge, the nut's 45° faces) cancel most of u, and one pass leaves e
            // off orthogonal by ~ε·|u|/|e|, which moved the earlier constraints by ~1e-10 and
            // broke C¹ between the two sides of a triangle (a 1.5e-3 gradient jump).
            let mut e = u;
            for _ in 0..2 {
                for (b, _, _) in &basis {
                    e -= b.dot(e) * *b;
                }
            }
            let len = e.length();
            if len <= 1e-9 * u.length().max(f64::MIN_POSITIVE) || !len.is_finite() {
                flat = true;
                continue;
            }
            basis.push((e / len, u, v - wi));
        }
        // Solve for the slope: G·u_k = target_k for the kept constraints, G = prior + Σ c e_k.
        let mut slope = prior;
        for (b, _, _) in &basis {
            slope -= b.dot(slope) * *b;
        }
        // Triangular solve: u_k = Σ_{l≤k} (e_l·u_k) e_l + 0.
        let mut coef: Vec<f64> = Vec::with_capacity(basis.len());
        for (k, (ek, uk, target)) in basis.iter().enumerate() {
            let mut rest = *target - slope.dot(*uk);
            for (l, c) in coef.iter().enumerate() {
                rest -= c * basis[l].0.dot(*uk);
            }
            let _ = k;
            coef.push(rest / ek.dot(*uk));
        }
        for ((e, _, _), c) in basis.iter().zip(&coef) {
            slope += *c * *e;
        }
        // One step of iterative refinement: the constraints' residuals after rounding, solved
        // the same way and added (the slope can be large where the constraints nearly depend).
        let mut fix: Vec<f64> = Vec::with_capacity(basis.len());
        for (ek, uk, target) in &basis {
            let mut rest = *target - slope.dot(*uk);
            for (l, c) in fix.iter().enumerate() {
                rest -= c * basis[l].0.dot(*uk);
            }
            fix.push(rest / ek.dot(*uk));
        }
        for ((e, _, _), c) in basis.iter().zip(&fix) {
            slope += *c * *e;
        }
        EdgeBlossom {
            origin: pi,
            value: wi,
            slope,
            flat,
        }
    }
}

/// Index of a cubic multi-index in the crate's order.
#[must_use]
pub fn ix(l: [u8; 4]) -> usize {
    index_of(l)
}

/// e_a + e_b + e_c as a cubic multi-index.
#[must_use]
pub fn e3(a: usize, b: usize, c: usize) -> [u8; 4] {
    let mut l = [0u8; 4];
    l[a] += 1;
    l[b] += 1;
    l[c] += 1;
    l
}

/// (2.5) for a cubic: the weight 2e_k + e_l = F(v_k) + (v_l − v_k)·∇F(v_k)/3 with F(v_k) = 0.
#[must_use]
pub fn gradient_weight(vk: DVec3, gk: DVec3, vl: DVec3) -> f64 {
    (vl - vk).dot(gk) / 3.0
}

/// Bernstein coefficient of the restriction of a cubic to the segment from the centroid of the
/// face λ3 = 0 to vertex 3, level `level` (the positive combination of the λ3 = level weights).
#[must_use]
pub fn level_mean(w: &[f64], level: u8) -> f64 {
    let m = 3 - level;
    let mut sum = 0.0;
    for a in 0..=m {
        for b in 0..=m - a {
            let c = m - a - b;
            let multinomial = fact(m) / (fact(a) * fact(b) * fact(c));
            sum += w[ix([a, b, c, level])] * multinomial;
        }
    }
    sum / 3f64.powi(i32::from(m))
}

fn fact(k: u8) -> f64 {
    (1..=u32::from(k)).product::<u32>() as f64
}

/// The shared value h of the free weights a_e_k+2e_q and F(q) that puts the zero of F on the
/// segment from the base triangle's centroid to the apex at parameter `level` ∈ (0, 1), given
/// the base and first-level means `c0`, `c1` (cubic: F(t) = (1−t)³c0 + 3(1−t)²t c1 +
/// (3(1−t)t² + t³) h).
#[must_use]
pub fn level_height(c0: f64, c1: f64, level: f64) -> f64 {
    let t = level;
    let u = 1.0 - t;
    -(u * u * u * c0 + 3.0 * u * u * t * c1) / (3.0 * u * t * t + t * t * t)
}

/// Barycentric coordinates of `x` in the tetrahedron `v`, or `None` when it is degenerate.
#[must_use]
pub fn bary_in(v: [DVec3; 4], x: DVec3) -> Option<[f64; 4]> {
    Tet::new(v).map(|t| t.bary(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blossom of a known cubic (F = x·y·z + x² − y, blossom computed by polarisation)
    /// around the edge [p_i p_j] is affine in the third argument and the fit recovers it from
    /// four spanning points.
    #[test]
    fn fit_recovers_an_affine_blossom() {
        // Polar form of F(x) = x0 x1 x2 + x0² − x1 for three arguments a, b, c.
        let blossom = |a: DVec3, b: DVec3, c: DVec3| {
            (a.x * b.y * c.z
                + a.x * b.z * c.y
                + a.y * b.x * c.z
                + a.y * b.z * c.x
                + a.z * b.x * c.y
                + a.z * b.y * c.x)
                / 6.0
                + (a.x * b.x + a.x * c.x + b.x * c.x) / 3.0
                - (a.y + b.y + c.y) / 3.0
        };
        let pi = DVec3::new(0.1, 0.2, 0.3);
        let pj = DVec3::new(1.0, -0.4, 0.2);
        let x = [
            DVec3::new(0.3, 1.1, -0.5),
            DVec3::new(-0.7, 0.2, 0.9),
            DVec3::new(0.5, 0.5, 2.0),
        ];
        let known: Vec<(DVec3, f64)> = [pj, x[0], x[1]]
            .iter()
            .map(|&p| (p, blossom(pi, pj, p)))
            .collect();
        let e = EdgeBlossom::fit(pi, blossom(pi, pj, pi), &known, DVec3::new(5.0, -3.0, 1.0));
        assert!(!e.flat);
        // 1e-12: a 3×3 solve on O(1) data.
        assert!((e.at(x[2]) - blossom(pi, pj, x[2])).abs() < 1e-12);
    }

    /// With coplanar constraints the slope across the plane is the prior's.
    #[test]
    fn fit_flat_keeps_prior_across() {
        let pi = DVec3::ZERO;
        let known = [
            (DVec3::X, 1.0),
            (DVec3::Y, 2.0),
            (DVec3::new(1.0, 1.0, 0.0), 3.0),
        ];
        let e = EdgeBlossom::fit(pi, 0.0, &known, DVec3::new(0.0, 0.0, 7.0));
        assert!(e.flat);
        // Exact arithmetic on small integers.
        assert_eq!(e.slope, DVec3::new(1.0, 2.0, 7.0));
    }

    /// Nearly dependent constraints (the third point 1e-7 off the plane of the others, as on the
    /// nut's 45° faces, relative 3e-8 of the edge): every constraint still holds to rounding
    /// (one pass of Gram–Schmidt left errors of ~1e-10 on values of ~1e-7 there).
    #[test]
    fn fit_nearly_flat_holds_every_constraint() {
        let pi = DVec3::new(100.76, -88.74, -68.21);
        let frame = |a: f64, b: f64, c: f64| {
            pi + a * DVec3::new(0.6, 0.0, -0.8) + b * DVec3::Y + c * DVec3::new(0.8, 0.0, 0.6)
        };
        let known = [
            (frame(3.0, 0.2, 0.0), 3e-7),
            (frame(1.0, 2.5, 0.0), -4e-7),
            (frame(1.2, -2.4, 1e-7), 5e-7),
        ];
        let e = EdgeBlossom::fit(pi, 1e-7, &known, DVec3::new(0.3, 0.1, 0.3));
        assert!(!e.flat);
        for (x, v) in known {
            // Rounding of values ~1e-7 through a slope of size ~10 at coordinates ~100: the
            // constraint holds to ~1e-14 absolute; 1e-12 leaves room, 1e-10 was the old error.
            assert!((e.at(x) - v).abs() < 1e-12, "{} vs {v}", e.at(x));
        }
    }

    /// The level rule puts the zero where asked: evaluate the cubic at the level.
    #[test]
    fn level_height_zero_at_level() {
        let (c0, c1, t) = (-0.4, 0.1, 0.3);
        let h = level_height(c0, c1, t);
        let u = 1.0 - t;
        let f = u * u * u * c0 + 3.0 * u * u * t * c1 + 3.0 * u * t * t * h + t * t * t * h;
        // Round-off of a handful of products.
        assert!(f.abs() < 1e-15);
    }
}

//! The sign conditions of Theorem 2.1 (1994) for the quintic patches, with k = 1.
//!
//! A face tetrahedron `[p_i p_j p_k q]` is a j-patch for its apex q when, with λ_q the apex's
//! share of a weight's multi-index ("level"), the weights of levels below k have one sign and
//! those above k the other (plus the two non-triviality sums). For degree 5 the only k the
//! data allows is k = 1: the level-1 weights at the points of T, b_{4e_i+e_q} = n_i·(q − p_i)/5
//! (number 1, (2.5)), have the apex's sign because every face tetrahedron is tangent-containing
//! (Definition 3.5), so they must sit at level k, where Theorem 2.1 asks nothing. Hence:
//! - level 0 (the base triangle on T) has the sign opposite to the apex's side: F ≤ 0 on the
//!   base of an outer tetrahedron (F > 0 outside), F ≥ 0 on the base of an inner one. This is
//!   also what keeps the surface from crossing the base triangle and leaving the hull (a hole:
//!   a single-sided face tetrahedron's base is the boundary of the hull);
//! - levels 2–5 have the apex's side's sign.
//!
//! An edge tetrahedron `[p_i p_j q s]` is single sheeted along every segment from [p_i p_j] to
//! [q s] under the same conditions with the level μ_q + μ_s (along such a segment the Bernstein
//! coefficient of order r is a positive combination of the level-r weights).
//!
//! The two face tetrahedra of an L-U pair share their base, which would need both signs: the
//! base of a double-sided triangle is inside the hull and carries no condition (Theorem 2.1
//! cannot hold in both; the pair is single sheeted along the line through both apexes when F
//! changes sign once, which the scheme leaves to the targets and `apatch check` measures).

use super::system::HullTet;
use crate::complex::Role;
use crate::hull::simplicial::{Side, SimplicialHull};

/// Sign of F on the apex's side of T: +1 outside, −1 inside.
#[must_use]
pub fn side_sign(side: Side) -> i8 {
    match side {
        Side::Outer => 1,
        Side::Inner => -1,
    }
}

/// Level of multi-index `l` in `tet`: the apex's share for a face tetrahedron, μ_q + μ_s for an
/// edge tetrahedron.
#[must_use]
pub fn level(tet: &HullTet, l: [u8; 4]) -> u8 {
    match tet.role {
        Role::Edge => l[2] + l[3],
        _ => l[3],
    }
}

/// The sign Theorem 2.1 (k = 1) asks of the weight at `l` of `tet` (+1 ≥ 0, −1 ≤ 0, 0 none);
/// `double_sided`: the tetrahedron's triangle has face tetrahedra on both sides (an L-U pair).
#[must_use]
pub fn required(tet: &HullTet, l: [u8; 4], double_sided: bool) -> i8 {
    let s = side_sign(tet.side);
    match level(tet, l) {
        0 if tet.role == Role::Face && double_sided => 0,
        0 => -s,
        1 => 0,
        _ => s,
    }
}

/// Combines the requirements of the tetrahedra sharing one weight: 0 none, ±1, or
/// [`CONFLICT`] when two tetrahedra ask for opposite signs.
#[must_use]
pub fn combine(a: i8, b: i8) -> i8 {
    match (a, b) {
        (CONFLICT, _) | (_, CONFLICT) => CONFLICT,
        (0, x) | (x, 0) => x,
        (x, y) if x == y => x,
        _ => CONFLICT,
    }
}

/// Marker of a weight two tetrahedra want with opposite signs.
pub const CONFLICT: i8 = 2;

/// How the solved weights meet Theorem 2.1.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SignStats {
    /// Weights (after C0 sharing) that Theorem 2.1 asks a sign of.
    pub constrained: usize,
    /// Weights two tetrahedra ask opposite signs of (not enforced).
    pub conflicts: usize,
    /// Weights the solve pinned to their sign (their targets had the wrong one).
    pub pinned: usize,
    /// Weights whose pin made their group's equations inconsistent (not enforced).
    pub given_up: usize,
    /// Weights with the wrong sign after the solve, by the stage that fixed them: 0 the jets
    /// (number 0–2: the normals and the Hessian), 1 edge middles, 2 relaxed stars, 3 stars,
    /// 4 far face weights, 5 face middles, 6 the rest of the edge tetrahedra.
    pub violated_by_stage: [usize; 7],
    /// Patches in which some weight has the wrong sign.
    pub violating_patches: usize,
    /// [`base_conflicts`] of the hull: base weights the data fix with the apex's sign.
    pub base_conflicts: usize,
}

impl SignStats {
    /// Weights with the wrong sign, all stages.
    #[must_use]
    pub fn violated(&self) -> usize {
        self.violated_by_stage.iter().sum()
    }
}

/// A single-sided face tetrahedron whose base must carry a weight with its apex's sign.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseConflict {
    /// Hull triangle (the base).
    pub triangle: u32,
    /// The side of its only face tetrahedron.
    pub side: Side,
    /// Points of T `[a, b]` of the base edge whose number 1 weight b_{4e_a+e_b} =
    /// n_a·(p_b − p_a)/5 has the apex's sign.
    pub edge: [u32; 2],
    /// n_a·(p_b − p_a) / |p_b − p_a| (the sine of the angle of the edge above a's tangent
    /// plane, positive = toward the outer side).
    pub slope: f64,
}

/// The single-sided face tetrahedra whose base Theorem 2.1 cannot make one-signed because the
/// data fix a base weight with the apex's sign: a number 1 weight (2.5), set by the normal at a
/// point of T and the direction of a base edge. There the base edge of T runs to the apex's
/// side of the tangent plane at a (for an outer tetrahedron: the edge rises above a's tangent
/// plane, a positively convex edge in the sense of Definition 3.1), so F takes the apex's sign
/// on the base near a and the surface leaves the hull through the base triangle, whose other
/// side has no tetrahedron: a hole. No free weight can change this; the hull must put an L-U
/// pair (Definition 3.4) on such a triangle, or the normals must change.
#[must_use]
pub fn base_conflicts(hull: &SimplicialHull) -> Vec<BaseConflict> {
    let mut out = Vec::new();
    for (t, tri) in hull.triangles.iter().enumerate() {
        let sides: Vec<Side> = Side::BOTH
            .into_iter()
            .filter(|&s| hull.apexes[t][s as usize].is_some())
            .collect();
        let [side] = sides[..] else { continue };
        let sigma = f64::from(side_sign(side));
        for k in 0..3 {
            for (a, b) in [(tri[k], tri[(k + 1) % 3]), (tri[(k + 1) % 3], tri[k])] {
                let (pa, pb) = (hull.points[a as usize], hull.points[b as usize]);
                let d = pb - pa;
                let slope = hull.normals[a as usize].normalize().dot(d) / d.length();
                // Rounding of a unit dot product: a zero-convex edge (slope 0) is allowed.
                if sigma * slope > 1e-12 {
                    out.push(BaseConflict {
                        triangle: t as u32,
                        side,
                        edge: [a, b],
                        slope,
                    });
                }
            }
        }
    }
    out
}

/// What [`fit_hessians`] did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct HessianFit {
    /// Points of T whose estimated Hessian missed a sign condition and was moved.
    pub moved: usize,
    /// Sign conditions on number 2 weights (after C0 sharing, counted per tetrahedron).
    pub conditions: usize,
    /// Conditions the fitted Hessians still miss: where a point's conditions contradict each
    /// other, the ones missed by most are dropped one at a time until the rest can be met.
    pub missed: usize,
}

/// One sign condition on a Hessian in tangent coordinates: `row`·u ≥ `rhs`, u = (A, √2·B, C)
/// for H = A t1t1ᵀ + B (t1t2ᵀ + t2t1ᵀ) + C t2t2ᵀ (so |Δu| is the Frobenius distance).
struct HalfSpace {
    row: [f64; 3],
    rhs: f64,
}

/// Moves the Hessian of every point of T, as little as possible (Frobenius norm, tangent
/// tensors kept tangent), so that the number 2 weights (one point of T at multiplicity 3)
/// meet Theorem 2.1's signs (k = 1).
///
/// With the 2-jet (0, g, H) at p, the weight at the domain point p³ab is the blossom of the
/// Taylor polynomial, g·(a − p + b − p)/5 + (a − p)ᵀH(b − p)/20: linear in H. The estimated
/// shape operator follows the normals of the neighbouring points and knows nothing of the
/// hull, so on flat stars next to folds its curvature along a base edge can put that edge on
/// the apex's side of the surface (F > 0 on an outer base: the surface leaves the hull through
/// the base, a hole), or its curvature toward an apex bend the surface back before it (a
/// second crossing). Each point's conditions are half-spaces in the three entries of its
/// tangent tensor; the closest tensor in their intersection is found by Dykstra's alternating
/// projections. `sign(t, l)` is the sign the weight at multi-index `l` of `tets[t]` must have
/// (+1, −1, or 0 for none: combined over the tetrahedra that share it).
pub fn fit_hessians(
    tets: &[HullTet],
    np: u32,
    jets: &mut [super::jets::Jet],
    sign: &dyn Fn(usize, [u8; 4]) -> i8,
) -> HessianFit {
    let mut conds: Vec<Vec<(glam::DVec3, glam::DVec3, f64)>> = vec![Vec::new(); jets.len()];
    for (t, tet) in tets.iter().enumerate() {
        for k in 0..4 {
            if tet.gid[k] >= np {
                continue;
            }
            let p = tet.pts[k];
            for l in crate::bb::multi_indices(5) {
                if l[k] != 3 {
                    continue;
                }
                let g = jets[tet.gid[k] as usize].g;
                let mut other = Vec::with_capacity(2);
                let mut other_t = Vec::with_capacity(2);
                for (i, &m) in l.iter().enumerate() {
                    if i != k {
                        for _ in 0..m {
                            other.push(tet.pts[i] - p);
                            other_t.push(tet.gid[i] < np);
                        }
                    }
                }
                let (a, b) = (other[0], other[1]);
                // Rounding of a unit normal's dot product with an edge.
                let tiny = |d: glam::DVec3| 1e-12 * d.length();
                let r = sign(t, l);
                let r = if r == CONFLICT && other_t[0] && other_t[1] && a == b {
                    // On an edge [p p_j] of T with tetrahedra of both sides (next to an L-U
                    // pair): keep F along the edge on the side its number 1 weight
                    // n_p·(p_j − p)/5 already gives it (zero on a flat edge: both signs).
                    let gd = g.dot(a);
                    if gd.abs() <= tiny(a) {
                        conds[tet.gid[k] as usize].push((a, b, 1.0));
                        -1
                    } else {
                        gd.signum() as i8
                    }
                } else {
                    r
                };
                if r != 1 && r != -1 {
                    continue;
                }
                // A weight between p and a point of T whose number 1 weight has the wrong sign
                // (the edge runs to the other side of p's tangent plane: a base conflict, or a
                // face next to one): F has the wrong sign near p there whatever H is.
                let hopeless =
                    (0..2).any(|i| other_t[i] && f64::from(r) * g.dot(other[i]) < -tiny(other[i]));
                if hopeless {
                    continue;
                }
                conds[tet.gid[k] as usize].push((a, b, f64::from(r)));
            }
        }
    }
    let mut fit = HessianFit::default();
    for (jet, cs) in jets.iter_mut().zip(&conds) {
        fit.conditions += cs.len();
        if cs.is_empty() {
            continue;
        }
        let (t1, t2) = jet.g.any_orthonormal_pair();
        let coords = |m: glam::DMat3| {
            [
                t1.dot(m * t1),
                std::f64::consts::SQRT_2 * t1.dot(m * t2),
                t2.dot(m * t2),
            ]
        };
        // σ·(g·(a + b)/5 + aᵀHb/20) ≥ 0 with aᵀHb = A·a1b1 + B·(a1b2 + a2b1) + C·a2b2.
        let spaces: Vec<HalfSpace> = cs
            .iter()
            .map(|&(a, b, s)| {
                let (a1, a2, b1, b2) = (a.dot(t1), a.dot(t2), b.dot(t1), b.dot(t2));
                let row = [
                    s * a1 * b1 / 20.0,
                    s * (a1 * b2 + a2 * b1) / (20.0 * std::f64::consts::SQRT_2),
                    s * a2 * b2 / 20.0,
                ];
                HalfSpace {
                    row,
                    rhs: -s * jet.g.dot(a + b) / 5.0,
                }
            })
            .collect();
        let u0 = coords(jet.h);
        // Rounding of the conditions' products: a tensor this close meets them.
        let scale = spaces
            .iter()
            .map(|h| h.rhs.abs() + h.row.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0_f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let tol = 1e-13 * scale * (1.0 + u0.iter().map(|x| x.abs()).sum::<f64>());
        let miss = |u: &[f64; 3]| {
            spaces
                .iter()
                .filter(|h| dot3(h.row, *u) < h.rhs - tol)
                .count()
        };
        if miss(&u0) == 0 {
            continue;
        }
        // The closest tensor meeting every condition; where they contradict each other, the
        // condition missed by most at the compromise is dropped and the rest tried again.
        let mut active: Vec<usize> = (0..spaces.len()).collect();
        let u = loop {
            let sub: Vec<&HalfSpace> = active.iter().map(|&i| &spaces[i]).collect();
            let u = dykstra(&sub, u0, tol);
            let worst = active
                .iter()
                .enumerate()
                .map(|(pos, &i)| {
                    let h = &spaces[i];
                    let n = dot3(h.row, h.row).sqrt().max(f64::MIN_POSITIVE);
                    (pos, (h.rhs - dot3(h.row, u)) / n)
                })
                .max_by(|x, y| x.1.total_cmp(&y.1));
            match worst {
                Some((pos, v)) if v > tol => {
                    active.remove(pos);
                }
                _ => break u,
            }
        };
        fit.moved += 1;
        fit.missed += miss(&u);
        // Back to the tensor: the normal part of the estimate (zero) is kept.
        let (a, b, c) = (u[0], u[1] / std::f64::consts::SQRT_2, u[2]);
        let o = |x: glam::DVec3, y: glam::DVec3| glam::DMat3::from_cols(x * y.x, x * y.y, x * y.z);
        jet.h = a * o(t1, t1) + b * (o(t1, t2) + o(t2, t1)) + c * o(t2, t2);
    }
    fit
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Sweeps of [`dykstra`] at most.
const DYKSTRA_SWEEPS: usize = 5000;

/// The point of the intersection of `spaces` closest to `u0` (Dykstra's alternating
/// projections; on an empty intersection, after [`DYKSTRA_SWEEPS`] sweeps, a point between
/// them). Stops when a sweep moves nothing by more than `tol` and every half-space is met to
/// `tol`.
fn dykstra(spaces: &[&HalfSpace], u0: [f64; 3], tol: f64) -> [f64; 3] {
    let mut x = u0;
    let mut q = vec![[0.0; 3]; spaces.len()];
    for _ in 0..DYKSTRA_SWEEPS {
        let mut moved = 0.0_f64;
        for (h, qi) in spaces.iter().zip(q.iter_mut()) {
            let y = [x[0] + qi[0], x[1] + qi[1], x[2] + qi[2]];
            let nn = dot3(h.row, h.row);
            let gap = h.rhs - dot3(h.row, y);
            let z = if gap > 0.0 && nn > 0.0 {
                let f = gap / nn;
                [
                    y[0] + f * h.row[0],
                    y[1] + f * h.row[1],
                    y[2] + f * h.row[2],
                ]
            } else {
                y
            };
            *qi = [y[0] - z[0], y[1] - z[1], y[2] - z[2]];
            moved = moved.max((0..3).map(|i| (z[i] - x[i]).abs()).fold(0.0, f64::max));
            x = z;
        }
        let feasible = spaces.iter().all(|h| dot3(h.row, x) >= h.rhs - tol);
        if feasible && moved <= tol {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn tet(role: Role, side: Side) -> HullTet {
        HullTet {
            gid: [0, 1, 2, 3],
            pts: [DVec3::ZERO; 4],
            role,
            element: 0,
            triangle: 0,
            side,
        }
    }

    /// k = 1: base opposite to the apex's side, level 1 free, levels 2..5 the apex's side.
    #[test]
    fn levels_and_sides() {
        let f = tet(Role::Face, Side::Outer);
        assert_eq!(required(&f, [5, 0, 0, 0], false), -1);
        assert_eq!(required(&f, [2, 2, 1, 0], false), -1);
        assert_eq!(required(&f, [2, 2, 1, 0], true), 0);
        assert_eq!(required(&f, [4, 0, 0, 1], false), 0);
        assert_eq!(required(&f, [1, 1, 1, 2], false), 1);
        let g = tet(Role::Face, Side::Inner);
        assert_eq!(required(&g, [1, 1, 1, 2], false), -1);
        assert_eq!(required(&g, [3, 1, 1, 0], false), 1);
        let e = tet(Role::Edge, Side::Outer);
        assert_eq!(required(&e, [3, 2, 0, 0], false), -1);
        assert_eq!(required(&e, [3, 1, 1, 0], false), 0);
        assert_eq!(required(&e, [2, 1, 1, 1], false), 1);
        assert_eq!(combine(1, 0), 1);
        assert_eq!(combine(1, -1), CONFLICT);
        assert_eq!(combine(CONFLICT, 1), CONFLICT);
        assert_eq!(combine(-1, -1), -1);
    }

    /// A flat outer base with a convex estimated Hessian at one corner: F > 0 along the base
    /// edges (the surface would leave through the base). The fit meets every condition of the
    /// tetrahedron's number 2 weights, moves only that corner, and no tangent tensor on a grid
    /// that meets them is closer to the estimate (brute force).
    #[test]
    fn fit_hessians_meets_the_signs_closest_to_the_estimate() {
        use super::super::jets::Jet;
        use glam::DMat3;
        let pts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.2, 0.9, 0.0),
            DVec3::new(0.4, 0.3, 0.5),
        ];
        let t = HullTet {
            gid: [0, 1, 2, 3],
            pts,
            role: Role::Face,
            element: 0,
            triangle: 0,
            side: Side::Outer,
        };
        let n = DVec3::Z;
        let h0 = DMat3::from_diagonal(DVec3::new(1.0, 0.6, 0.0))
            + DMat3::from_cols(
                DVec3::new(0.0, 0.3, 0.0),
                DVec3::new(0.3, 0.0, 0.0),
                DVec3::ZERO,
            );
        let mut jets = vec![
            Jet {
                p: pts[0],
                g: n,
                h: h0,
            },
            Jet {
                p: pts[1],
                g: n,
                h: DMat3::ZERO,
            },
            Jet {
                p: pts[2],
                g: n,
                h: DMat3::ZERO,
            },
        ];
        let tets = [t.clone()];
        let sign = |_: usize, l: [u8; 4]| required(&t, l, false);
        let fit = fit_hessians(&tets, 3, &mut jets, &sign);
        assert_eq!((fit.moved, fit.missed), (1, 0), "{fit:?}");
        assert_eq!(jets[1].h, DMat3::ZERO);
        // The conditions at point 0, evaluated on the weights themselves.
        let weights_ok = |h: DMat3| {
            let jet = Jet { p: pts[0], g: n, h };
            crate::bb::multi_indices(5)
                .into_iter()
                .filter(|l| l[0] == 3)
                .all(|l| {
                    let args = crate::scheme::quintic_c2::jets::domain_args(&pts, l);
                    // Rounding of the fit (1e-13 of the conditions' scale).
                    f64::from(required(&t, l, false)) * jet.blossom5(&args) >= -1e-12
                })
        };
        assert!(!weights_ok(h0));
        let h = jets[0].h;
        assert!(weights_ok(h), "{h:?}");
        // Still tangent: nothing along the normal.
        assert!((h * n).length() < 1e-15 && (h.transpose() * n).length() < 1e-15);
        let dist = |m: DMat3| {
            let d = (m - h0).to_cols_array();
            d.iter().map(|x| x * x).sum::<f64>().sqrt()
        };
        let best = dist(h);
        let steps = 60;
        for i in 0..=steps {
            for j in 0..=steps {
                for k in 0..=steps {
                    let v = |x: usize| -1.5 + 3.0 * x as f64 / steps as f64;
                    let (a, b, c) = (v(i), v(j), v(k));
                    let m =
                        DMat3::from_cols(DVec3::new(a, b, 0.0), DVec3::new(b, c, 0.0), DVec3::ZERO);
                    if weights_ok(m) {
                        // Grid rounding: no grid tensor is closer than the fit by more than
                        // rounding.
                        assert!(dist(m) >= best - 1e-9, "{m:?} {} < {best}", dist(m));
                    }
                }
            }
        }
    }
}

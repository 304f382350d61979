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
#[derive(Clone, Debug, Default, PartialEq)]
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
}

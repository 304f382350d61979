//! Flatter ring normals (opt-in `scheme.ring_normals`; issue 7 follow-up, the nut's flat sides).
//!
//! Algorithm 1 step (4) gives the pseudo-centroid C_0 the vertex normal n_V ("Let n_V be the
//! normal at C_0"). Round a large planar face, T fans from the face's centroid to a ring of
//! pseudo-centroids whose normals tilt away from the face normal (up to 45° on the nut), so each
//! long fan triangle bends across the whole face. [`flatten_ring_normals`] turns each
//! pseudo-centroid's normal towards the size-weighted mean of the normals of the faces round it
//! (weights |C_i − C_0|², the square of the distance to each face's centroid: a large face pulls
//! the normal flat to itself, moving the bend into the small faces next to it), by the blend
//! factor `beta`, keeping every incident edge of T in its convexity class and the normal above
//! every face round it. The paper's §7 names the cut depth α and the weights as shape choices,
//! not the normal at C_0; this is a choice beyond it. On the nut it flattens the side faces
//! (fairness p95 on face tetrahedra 26.9° → 20.3°, distance max 2.1e-2 → 1.1e-2) but does not
//! remove the star (the fan's thin triangles remain); on curved models (torus_quad) it makes
//! the surface less fair, hence opt-in.

use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use crate::mesh::convexity::edge_convexity_1994;
use glam::DVec3;

/// Turns pseudo-centroid normals towards the size-weighted mean of their faces' normals by
/// `beta` (0 = unchanged, 1 = the mean), halving the turn until no incident edge of T changes
/// its convexity class and the normal stays [`super::above::ABOVE_MARGIN`] above every face
/// round it. Returns how many normals changed. Call after the corners, before the sides.
pub fn flatten_ring_normals(hull: &mut SimplicialHull, beta: f64) -> usize {
    if beta <= 0.0 {
        return 0;
    }
    let n = hull.points.len();
    let nbrs = hull.point_neighbours();
    let mut changed = 0;
    #[allow(clippy::needless_range_loop)] // i indexes points, normals, origins and nbrs
    for i in 0..n {
        if !matches!(hull.origins[i], PointOrigin::PseudoCentroid { .. }) {
            continue;
        }
        let p = hull.points[i];
        let faces: Vec<(DVec3, f64)> = nbrs[i]
            .iter()
            .filter(|&&j| {
                matches!(
                    hull.origins[j as usize],
                    PointOrigin::Centroid { .. } | PointOrigin::CornerGuard { .. }
                )
            })
            .map(|&j| {
                let j = j as usize;
                (hull.normals[j], (hull.points[j] - p).length_squared())
            })
            .collect();
        if faces.is_empty() {
            continue;
        }
        let Some(mean) = faces
            .iter()
            .map(|&(m, w)| w * m)
            .sum::<DVec3>()
            .try_normalize()
        else {
            continue;
        };
        let old = hull.normals[i];
        let face_normals: Vec<DVec3> = faces.iter().map(|f| f.0).collect();
        let classes: Vec<_> = nbrs[i]
            .iter()
            .map(|&j| {
                let j = j as usize;
                edge_convexity_1994(p, old, hull.points[j], hull.normals[j])
            })
            .collect();
        let mut s = beta.min(1.0);
        for _ in 0..8 {
            let Some(cand) = ((1.0 - s) * old + s * mean).try_normalize() else {
                break;
            };
            let above = super::above::clearance(cand, &face_normals) >= super::above::ABOVE_MARGIN;
            let same = nbrs[i].iter().zip(&classes).all(|(&j, &c)| {
                let j = j as usize;
                edge_convexity_1994(p, cand, hull.points[j], hull.normals[j]) == c
            });
            if above && same {
                if cand != old {
                    hull.normals[i] = cand;
                    changed += 1;
                }
                break;
            }
            s *= 0.5;
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One pseudo-centroid at the origin (normal tilted 45° between +z and +x) fanned to a far
    /// centroid of a large face (normal +z) and a near centroid of a small face (normal +x): the
    /// turned normal leans to +z as far as the edges' convexity allows; beta = 0 changes nothing.
    fn hull() -> SimplicialHull {
        let mut h = SimplicialHull::default();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        h.points = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(-10.0, 0.0, 0.5),
            DVec3::new(0.5, 0.0, -1.0),
        ];
        h.normals = vec![DVec3::new(s, 0.0, s), DVec3::Z, DVec3::X];
        h.origins = vec![
            PointOrigin::PseudoCentroid { vertex: 0 },
            PointOrigin::Centroid { face: 0 },
            PointOrigin::Centroid { face: 1 },
        ];
        h.triangles = vec![[0, 1, 2]];
        h.apexes = vec![[None, None]];
        h.element = vec![0];
        h
    }

    #[test]
    fn turns_towards_the_large_face_only_by_beta() {
        let mut h = hull();
        assert_eq!(flatten_ring_normals(&mut h, 0.0), 0);
        assert_eq!(h.normals, hull().normals);
        let class = |h: &SimplicialHull, j: usize| {
            edge_convexity_1994(h.points[0], h.normals[0], h.points[j], h.normals[j])
        };
        let classes = [class(&h, 1), class(&h, 2)];
        let before = h.normals[0].angle_between(DVec3::Z);
        assert_eq!(flatten_ring_normals(&mut h, 1.0), 1);
        let after = h.normals[0].angle_between(DVec3::Z);
        // The full turn (weights 100.25 for +z, 1.25 for +x: within 1° of +z) would make the
        // edge to the far centroid nonconvex (C_0 lies under its plane), so the turn is halved
        // once: from 45° to about 23° off +z.
        assert!(before > 44f64.to_radians(), "{before}");
        assert!(
            after > 15f64.to_radians() && after < 30f64.to_radians(),
            "{after}"
        );
        assert_eq!([class(&h, 1), class(&h, 2)], classes);
        assert!((h.normals[0].length() - 1.0).abs() < 1e-12); // unit, to rounding
                                                              // Face normals are untouched.
        assert_eq!(h.normals[1..], hull().normals[1..]);
    }
}

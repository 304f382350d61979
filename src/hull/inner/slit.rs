//! Slit bottoms of T: the diagonal flip where two faces of the polyhedron meet at a knife edge.
//!
//! Why: Algorithm 1 step (5) joins the pseudo-centroids C_0, C_0' of an edge e = VV' to the
//! centroids C_1, C_2 of its two faces, so the edge C_1C_2 of T crosses e. Where the two faces
//! are the walls of a thin slit (spot_control_cage's mouth: faces 85 and 88, normals +z and −z,
//! 0.005 apart, meeting at the slit's bottom e = 102–104), C_1 and C_2 lie on opposite walls
//! and their normals nearly oppose each other (161°). Both triangles [C_0 C_1 C_2],
//! [C_0' C_2 C_1] then lie across the slit, facing one wall's normal and against the other's
//! (n_t · n_{C_2} = −0.84, −0.89): C_2's tangent plane cuts between the inner apexes of its
//! triangles, the boundary faces of their edge tetrahedra have face weights of both signs
//! whatever the free weights are, and the patches there leave holes. [`super::unfold`] does
//! not see it: the two triangles face the same way, nothing is folded.
//!
//! The other diagonal C_0C_0' runs along e, the slit's bottom: [C_0 C_1 C_0'] lies on C_1's
//! wall and [C_0' C_2 C_0] on C_2's, each facing all its vertex normals, and the surface turns
//! round the slit's bottom between them (T folds there by the slit's own angle, as the
//! polyhedron does). [`flip_slits`] makes that flip where both old triangles face against one
//! of the edge's end normals and the new ones face all of theirs, with no edge round the
//! pseudo-centroids turned nonconvex (Definition 3.1, Lemma 4.1; they may move along their cut
//! line for it, `cuts`) and face tetrahedra on both new bases (`slit_apexes`).

use super::sides::{apexes_along, apexes_over_base};
use super::unfold::required_sides;
use super::unfold::{incidence, local_quality, place_apexes, pseudo_centroid_quad, unit_normal};
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use glam::DVec3;

/// Cosine between the normals at the two ends of an edge of T below which it may cross a
/// slit (the normals more than 120° apart; the cage's mouth: −0.95).
pub const SLIT_COS: f64 = -0.5;

/// Smallest cosine between a flipped triangle's normal and each of its vertex normals (the
/// cage's mouth: 0.11 and above).
pub const FACING_MIN: f64 = 0.05;

/// Pairs (triangle, vertex) among `tris` whose triangle faces against the vertex's normal.
fn against(hull: &SimplicialHull, tris: &[[u32; 3]]) -> usize {
    tris.iter()
        .map(|&t| match unit_normal(hull, t) {
            Some(n) => t
                .iter()
                .filter(|&&i| n.dot(hull.normals[i as usize]) < 0.0)
                .count(),
            None => 3,
        })
        .sum()
}

/// Whether every triangle of `tris` faces each of its vertex normals by at least
/// [`FACING_MIN`].
fn facing_all(hull: &SimplicialHull, tris: &[[u32; 3]]) -> bool {
    tris.iter().all(|&t| {
        unit_normal(hull, t).is_some_and(|n| {
            t.iter()
                .all(|&i| n.dot(hull.normals[i as usize]) >= FACING_MIN)
        })
    })
}

/// Moves tried for the pseudo-centroids at the new edge's ends, C_0 = V + λ (C_0 − V), nearest
/// to where they are first. Across a slit's bottom the new edge is almost perpendicular to
/// both end normals (the cage's P_102P_104: a = 0.0036, b = −0.0005), so its class turns on
/// a few thousandths of the edge's length: λ in eighths from 1/4 to 3/2 (λ > 1 cuts deeper,
/// along the same line; C_0 stays between V and V̄ while λ (1 − α) ≤ 1, for every λ here when
/// α ≥ 1/3).
fn cuts() -> Vec<(f64, f64)> {
    let steps: Vec<f64> = (2..=12).map(|k| f64::from(k) / 8.0).collect();
    let mut pairs: Vec<(f64, f64)> = steps
        .iter()
        .flat_map(|&a| steps.iter().map(move |&b| (a, b)))
        .collect();
    pairs.sort_by(|x, y| {
        let d = |p: &(f64, f64)| (p.0 - 1.0).abs() + (p.1 - 1.0).abs();
        d(x).total_cmp(&d(y))
    });
    pairs
}

/// Tilts tried for a flipped triangle's face tetrahedra whose vertex tangent plane is too
/// steep to meet over the base: the direction N + β n_s (N the triangle's normal, n_s the
/// vertex normal that faces it least), in order.
const TILTS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];

/// Face tetrahedra for a flipped triangle on the sides its edges ask for: over its base
/// ([`apexes_over_base`]), or, where the slit's bottom has a vertex normal almost in the
/// triangle's plane (the cage's P_104: n · N = 0.10, the apex would rise 1.4 times the base
/// along N), leaning towards that normal, which reaches its tangent plane sooner and points
/// into the slit's bottom (module docs).
fn slit_apexes(hull: &SimplicialHull, t: [u32; 3]) -> Option<[Option<DVec3>; 2]> {
    let base = t.map(|i| hull.points[i as usize]);
    let normals = t.map(|i| hull.normals[i as usize]);
    let req = required_sides(hull, t);
    let req = if req[0] || req[1] { req } else { [true, false] };
    if let Some(a) = apexes_over_base(base, normals, req) {
        return Some(a);
    }
    let nt = unit_normal(hull, t)?;
    let steep = normals
        .iter()
        .copied()
        .min_by(|a, b| a.dot(nt).total_cmp(&b.dot(nt)))?;
    TILTS.iter().find_map(|&beta| {
        let up = (nt + beta * steep).try_normalize()?;
        apexes_along(base, normals, req, up)
    })
}

/// Whether point `i` of T is a face's point (a centroid or a corner guard).
fn on_face(hull: &SimplicialHull, i: u32) -> bool {
    matches!(
        hull.origins[i as usize],
        PointOrigin::Centroid { .. } | PointOrigin::CornerGuard { .. }
    )
}

/// Flips every edge of T that crosses a slit between two face points (module docs).
/// `positions` are the polyhedron's vertices (the V of every pseudo-centroid). Returns the
/// number of flips.
pub fn flip_slits(hull: &mut SimplicialHull, positions: &[DVec3]) -> usize {
    let Ok(edges) = hull.edges() else {
        return 0;
    };
    let mut incident = incidence(hull);
    // Candidates, most opposed end normals first.
    let mut slits: Vec<(f64, [u32; 2])> = edges
        .iter()
        .filter(|e| e.faces[1] != u32::MAX)
        .filter(|e| on_face(hull, e.v[0]) && on_face(hull, e.v[1]))
        .map(|e| {
            let [a, b] = e.v.map(|i| hull.normals[i as usize]);
            (a.dot(b), e.v)
        })
        .filter(|&(c, _)| c < SLIT_COS)
        .collect();
    slits.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut flips = 0;
    for (_, [v0, v1]) in slits {
        let Some(quad) = pseudo_centroid_quad(hull, &incident, positions, [v0, v1]) else {
            continue;
        };
        let ([f0, f1], c, d) = (quad.f, quad.c, quad.d);
        let old_tris = [hull.triangles[f0], hull.triangles[f1]];
        // Both triangles lie across the slit: each faces against one of the edge's ends.
        let across = |t: [u32; 3]| {
            unit_normal(hull, t).is_none_or(|n| {
                [v0, v1]
                    .iter()
                    .any(|&i| n.dot(hull.normals[i as usize]) < 0.0)
            })
        };
        if !old_tris.iter().all(|&t| across(t)) {
            continue;
        }
        let (_, _, before_bad) = local_quality(hull, &incident, [c, d]);
        let around = |hull: &SimplicialHull, incident: &[Vec<usize>]| -> Vec<[u32; 3]> {
            let mut ts: Vec<usize> = [c, d]
                .iter()
                .flat_map(|&p| incident[p as usize].iter().copied())
                .filter(|&t| t != f0 && t != f1)
                .collect();
            ts.sort_unstable();
            ts.dedup();
            ts.iter().map(|&t| hull.triangles[t]).collect()
        };
        let before_against = against(hull, &around(hull, &incident));
        let flipped = quad.try_flip(hull, &mut incident, cuts(), |hull, incident| {
            let new_tris = [hull.triangles[f0], hull.triangles[f1]];
            let (_, _, bad) = local_quality(hull, incident, [c, d]);
            // No new nonconvex edge (Lemma 4.1), every new triangle facing all its normals,
            // and no triangle round c or d turned against one of its normals by the move.
            if bad > before_bad
                || !facing_all(hull, &new_tris)
                || against(hull, &around(hull, incident)) > before_against
            {
                return false;
            }
            let Some(new_apexes) = new_tris
                .iter()
                .map(|&t| slit_apexes(hull, t))
                .collect::<Option<Vec<_>>>()
            else {
                return false;
            };
            hull.apexes[f0] = new_apexes[0];
            hull.apexes[f1] = new_apexes[1];
            // Every other triangle at c or d gets apexes over its moved base where it can.
            let _ = place_apexes(hull, incident, [c, d], [usize::MAX; 2]);
            true
        });
        flips += usize::from(flipped);
    }
    flips
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A slit along the x axis (its bottom from c = (0, 0, 0) to d = (1, 0, 0), both normals
    /// −y, pointing out of the slit): the lower wall through the bottom and v0 = (0.5, −0.6,
    /// −0.1), the upper wall through the bottom and v1 = (0.5, −0.3, 0.1), each point's normal
    /// its wall's (facing into the slit; 152° apart). Step (5) joins them as [v0 v1 c] and
    /// [v1 v0 d], which lie across the slit and both face against v1's normal. `upper` is v1's
    /// normal (the upper wall's for the slit).
    fn slit(upper: DVec3) -> (SimplicialHull, Vec<DVec3>) {
        let points = vec![
            DVec3::new(0.5, -0.6, -0.1), // 0 v0, lower wall
            DVec3::new(0.5, -0.3, 0.1),  // 1 v1, upper wall
            DVec3::ZERO,                 // 2 c
            DVec3::X,                    // 3 d
        ];
        let normals = vec![
            DVec3::new(0.0, -0.1, 0.6).normalize(),
            upper,
            DVec3::NEG_Y,
            DVec3::NEG_Y,
        ];
        let origins = vec![
            PointOrigin::Centroid { face: 0 },
            PointOrigin::Centroid { face: 1 },
            PointOrigin::PseudoCentroid { vertex: 0 },
            PointOrigin::PseudoCentroid { vertex: 1 },
        ];
        let triangles = vec![[0, 1, 2], [1, 0, 3]];
        let hull = SimplicialHull {
            points,
            normals,
            origins,
            apexes: vec![[Some(DVec3::new(0.3, -0.3, 0.5)), None]; 2],
            element: vec![0, 1],
            triangles,
        };
        // The polyhedron's corners behind the pseudo-centroids (at the slit's bottom).
        (
            hull,
            vec![DVec3::new(0.0, 0.05, 0.0), DVec3::new(1.0, 0.05, 0.0)],
        )
    }

    /// The edge across the slit becomes its bottom: the two new triangles lie on the walls and
    /// face all their vertex normals, the quad's edges still run opposite ways in their two
    /// triangles, the points stay where they were (the new edge is zero convex as it is), and
    /// the face tetrahedra are on the sides the new triangles' edges ask for.
    #[test]
    fn edge_across_a_slit_is_flipped_to_its_bottom() {
        let upper = DVec3::new(0.0, -0.1, -0.3).normalize();
        let (mut hull, corners) = slit(upper);
        let before = hull.points.clone();
        assert!(against(&hull, &hull.triangles.clone()) >= 2);
        assert_eq!(flip_slits(&mut hull, &corners), 1);
        assert_eq!(hull.triangles, vec![[2, 0, 3], [3, 1, 2]]);
        assert_eq!(hull.points, before);
        assert!(facing_all(&hull, &hull.triangles.clone()));
        // The lower wall's triangle faces like v0's normal, the upper one like v1's.
        let n0 = unit_normal(&hull, hull.triangles[0]).unwrap();
        let n1 = unit_normal(&hull, hull.triangles[1]).unwrap();
        assert!(n0.dot(hull.normals[0]) > 0.999, "{n0}");
        assert!(n1.dot(upper) > 0.999, "{n1}");
        let edges = hull.edges().unwrap();
        let bottom = edges
            .iter()
            .find(|e| e.v == [2, 3] || e.v == [3, 2])
            .unwrap();
        assert!(
            bottom.faces[1] != u32::MAX,
            "the bottom is shared by both triangles"
        );
        for (t, tri) in hull.triangles.iter().enumerate() {
            let req = required_sides(&hull, *tri);
            let base = tri.map(|i| hull.points[i as usize]);
            let nn = (base[1] - base[0]).cross(base[2] - base[0]);
            for (side, sign) in [(0, 1.0), (1, -1.0)] {
                if req[side] {
                    let q = hull.apexes[t][side].expect("a required side has its apex");
                    assert!(sign * nn.dot(q - base[0]) > 0.0, "triangle {t} side {side}");
                }
            }
        }
        // Nothing lies across the slit any more.
        assert_eq!(flip_slits(&mut hull, &corners), 0);
    }

    /// Where the normals at the edge's ends are less than 120° apart (no slit: the "upper
    /// wall"'s normal turned to within 60° of the lower one's), nothing is flipped.
    #[test]
    fn no_flip_without_a_slit() {
        let lower = DVec3::new(0.0, -0.1, 0.6).normalize();
        let turned = (lower + DVec3::new(0.0, -0.9, 0.0)).normalize();
        assert!(lower.dot(turned) > SLIT_COS);
        let (mut hull, corners) = slit(turned);
        let triangles = hull.triangles.clone();
        assert_eq!(flip_slits(&mut hull, &corners), 0);
        assert_eq!(hull.triangles, triangles);
    }
}

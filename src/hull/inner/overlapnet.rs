//! Flat nets for the merged regions whose triangles of T overlap (Appendix B, Algorithm 3,
//! driven by [`super::verify`]).
//!
//! Why: [`super::flatnet`] decides before T exists which merged flat regions get a corner
//! guard per corner and a zero coplanar group, from the region's shape (far corners, folded
//! fans, diagonals passing beside an edge at a nearly flat corner). Some regions pass those
//! tests and still overlap: fandisk's 9-corner strips along its 90° edges (input faces 8463,
//! 10573), whose one centroid sees the strip's end edges at a grazing angle, so Algorithm 1's
//! two triangles over such an edge, [C_0(V), G, C'] and [C_0(W), C', G], fold into a valley
//! (their normals 77–80° apart) and their outer tetrahedra overlap. The nut's side strips
//! have the same shape (the same misses, one valley fold of 81°) and their hull verifies, so
//! no shape test separates them. The overlap itself does: after a build whose hull has flat
//! nets and fails [`super::verify`] with `Intersecting` tetrahedra, the input faces of the
//! points of the triangles named get flat nets too, one region at a time (most often named
//! first), and T is rebuilt; a region is kept only when the rebuilt hull has fewer
//! violations ([`force_nets`]).
//!
//! Hulls without flat nets (every model but fandisk among `scenes/models`) and hulls that
//! verify are built once and do not change.

use super::verify::{verify, HullViolation, ViolationKind};
use super::InnerReport;
use crate::error::Result;
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use std::collections::{BTreeMap, BTreeSet};

/// Most passes over the regions named by the violations left.
pub const ROUNDS: usize = 3;

/// Most rebuilds in all (each one a build and a [`verify`] of the whole hull).
pub const MAX_TRIALS: usize = 24;

/// Gives flat nets, one region at a time, to the merged regions whose triangles of T overlap
/// in `hull` (module docs), keeping each only when the rebuilt hull has fewer violations.
/// `build` builds the hull with the regions of the given input faces forced to flat nets.
/// Candidates are the regions that can take a net (`report.flat_net_candidates`) named by
/// the `Intersecting` violations, most often named first; a round ends at the first that does
/// not lower the count, and the next ranks the regions named by the violations left. A
/// rebuild that fails is skipped.
pub fn force_nets<F>(
    hull: SimplicialHull,
    report: InnerReport,
    mut build: F,
) -> (SimplicialHull, InnerReport)
where
    F: FnMut(&BTreeSet<u32>) -> Result<(SimplicialHull, InnerReport)>,
{
    let mut violations = verify(&hull);
    let mut best = (hull, report);
    let mut forced = BTreeSet::new();
    let mut tried = BTreeSet::new();
    for _ in 0..ROUNDS {
        let eligible: BTreeSet<u32> = best.1.flat_net_candidates.iter().copied().collect();
        let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
        for v in &violations {
            for f in overlapping_faces(&best.0, std::slice::from_ref(v)) {
                if eligible.contains(&f) && !tried.contains(&f) {
                    *counts.entry(f).or_insert(0) += 1;
                }
            }
        }
        let mut ranked: Vec<(u32, usize)> = counts.into_iter().collect();
        ranked.sort_by_key(|&(f, n)| (std::cmp::Reverse(n), f));
        let mut improved = false;
        for (f, _) in ranked {
            if tried.len() >= MAX_TRIALS {
                break;
            }
            tried.insert(f);
            let mut trial = forced.clone();
            trial.insert(f);
            let Ok((h, r)) = build(&trial) else { continue };
            let v = verify(&h);
            if v.len() >= violations.len() {
                // The less often named regions did not help on fandisk (5 references each
                // against 12-32 for the ones that did): the round ends at the first miss.
                break;
            }
            forced = trial;
            best = (h, r);
            violations = v;
            improved = true;
        }
        if !improved || violations.is_empty() {
            break;
        }
    }
    best
}

/// The triangles of T an `Intersecting` violation names: its `triangle`, and every
/// "triangle N" of its message (verify names both tetrahedra of a pair there: "… face
/// tetrahedron of triangle N (element E)", "… edge tetrahedron at edge (a, b) beside triangle
/// N (element E)").
#[must_use]
pub fn named_triangles(v: &HullViolation) -> Vec<u32> {
    let mut out: Vec<u32> = v.triangle.into_iter().collect();
    let mut rest = v.message.as_str();
    while let Some(i) = rest.find("triangle ") {
        rest = &rest[i + "triangle ".len()..];
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        if let Ok(t) = rest[..digits].parse() {
            out.push(t);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The input faces (`PointOrigin` faces: centroids and corner guards) of the points of every
/// triangle named by an `Intersecting` violation of `violations` ([`named_triangles`]).
#[must_use]
pub fn overlapping_faces(hull: &SimplicialHull, violations: &[HullViolation]) -> BTreeSet<u32> {
    let mut out = BTreeSet::new();
    for v in violations {
        if v.kind != ViolationKind::Intersecting {
            continue;
        }
        for t in named_triangles(v) {
            let Some(tri) = hull.triangles.get(t as usize) else {
                continue;
            };
            for &p in tri {
                if let Some(PointOrigin::Centroid { face } | PointOrigin::CornerGuard { face }) =
                    hull.origins.get(p as usize)
                {
                    out.insert(*face);
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

    /// Only `Intersecting` violations count, and only centroids' and guards' faces.
    #[test]
    fn faces_of_overlapping_triangles() {
        let hull = SimplicialHull {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            normals: vec![DVec3::Z; 4],
            origins: vec![
                PointOrigin::Centroid { face: 7 },
                PointOrigin::CornerGuard { face: 9 },
                PointOrigin::PseudoCentroid { vertex: 3 },
                PointOrigin::Centroid { face: 11 },
            ],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            apexes: vec![[None, None]; 2],
            element: vec![0, 1],
        };
        let v = |kind, t| HullViolation {
            kind,
            triangle: Some(t),
            message: String::new(),
        };
        let faces = overlapping_faces(
            &hull,
            &[
                v(ViolationKind::Intersecting, 0),
                v(ViolationKind::Degenerate, 1),
            ],
        );
        assert_eq!(faces.into_iter().collect::<Vec<_>>(), vec![7, 9]);
        // The second triangle of a pair is named in the message only.
        let pair = HullViolation {
            kind: ViolationKind::Intersecting,
            triangle: None,
            message: "Outer face tetrahedron of triangle 0 (element 0) overlaps Outer edge \
                      tetrahedron at edge (1, 2) beside triangle 1 (element 1) (depth 1e-2)"
                .into(),
        };
        assert_eq!(named_triangles(&pair), vec![0, 1]);
        let faces = overlapping_faces(&hull, &[pair]);
        assert_eq!(faces.into_iter().collect::<Vec<_>>(), vec![7, 9, 11]);
    }
}

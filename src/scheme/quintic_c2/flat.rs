//! Zero coplanar groups made exact (Appendix B (5'')(ii); opt-in `zero_groups`).
//!
//! Why: where adjacent triangles of T are coplanar beyond isolated pairs, the C1/C2 conditions
//! relate all their bottom weights (Appendix B), and the quintic's systems are consistent only
//! when the data on the group are those of one plane: F is the plane's signed distance there,
//! so every point of the group has the plane's normal and a Hessian without tangential part
//! (the paper's "set the bottom weights to zero" for a zero coplanar group). A polyhedron with
//! float32 coordinates (the nut) has faces of one plane 1e-6 rad apart that
//! [`crate::hull::inner::coplanar`] does not merge: its T holds coplanar groups of up to 146
//! triangles whose points' normals and positions agree with the plane only to that noise, so
//! the edges' convexity classes and the estimated Hessians there are noise, and every star
//! system of the nut was inconsistent.
//!
//! [`zero_coplanar_groups`] finds the coplanar groups of T (edge-adjacent triangles whose fourth
//! point lies within [`COPLANAR_TOL`] of the neighbour's plane) whose points' normals all lie
//! within [`NORMAL_NOISE`] of the group's plane normal, and returns a hull whose points of such
//! groups lie on the plane, with its normal, plus the list of those points (their Hessians are
//! then set to zero). Points shared by two groups of different planes are left as they are, and
//! with them their groups.

use crate::hull::simplicial::SimplicialHull;
use glam::DVec3;
use std::collections::{HashMap, HashSet};

/// Largest distance of a triangle's fourth point from its edge-neighbour's plane, relative to
/// the distance of that point from the shared edge's first point, for the two to count as
/// coplanar: the nut's float32 rounding puts group points up to 9e-6 off (edges ≥ 1).
pub const COPLANAR_TOL: f64 = 1e-5;

/// Largest difference of a point's unit normal from its group plane's for the group to be
/// made a zero coplanar group: the nut's groups agree to 3e-6 (measured); real features are
/// far above it.
pub const NORMAL_NOISE: f64 = 1e-5;

/// The hull with its zero coplanar groups made exact, and the points moved onto their planes
/// (module docs). The hull is returned unchanged (a clone) with no points when T has no such
/// group.
#[must_use]
pub fn zero_coplanar_groups(hull: &SimplicialHull) -> (SimplicialHull, Vec<u32>) {
    let mut out = hull.clone();
    let Ok(edges) = hull.edges() else {
        return (out, Vec::new());
    };
    let nt = hull.triangles.len();
    let pts = |t: usize| hull.triangles[t].map(|i| hull.points[i as usize]);
    let area = |t: usize| {
        let [a, b, c] = pts(t);
        (b - a).cross(c - a)
    };
    let mut parent: Vec<usize> = (0..nt).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for e in &edges {
        if e.faces[1] == u32::MAX {
            continue;
        }
        let [f, g] = e.faces.map(|f| f as usize);
        let Some(nf) = area(f).try_normalize() else {
            continue;
        };
        let Some(&o) = hull.triangles[g]
            .iter()
            .find(|&&i| i != e.v[0] && i != e.v[1])
        else {
            continue;
        };
        let a = hull.points[e.v[0] as usize];
        let d = hull.points[o as usize] - a;
        if nf.dot(d).abs() <= COPLANAR_TOL * d.length() && nf.dot(area(g)) > 0.0 {
            let (rf, rg) = (find(&mut parent, f), find(&mut parent, g));
            if rf != rg {
                parent[rf] = rg;
            }
        }
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    for t in 0..nt {
        let r = find(&mut parent, t);
        groups.entry(r).or_default().push(t);
    }
    let mut groups: Vec<Vec<usize>> = groups.into_values().filter(|g| g.len() > 2).collect();
    groups.sort_unstable();
    // Per point: the plane it is moved to (normal, point on it), or a conflict.
    let mut plane_of: HashMap<u32, Option<(DVec3, DVec3)>> = HashMap::new();
    for g in &groups {
        let Some(n) = g.iter().map(|&t| area(t)).sum::<DVec3>().try_normalize() else {
            continue;
        };
        let mut members: Vec<u32> = g.iter().flat_map(|&t| hull.triangles[t]).collect();
        members.sort_unstable();
        members.dedup();
        let noisy = members
            .iter()
            .all(|&i| (hull.normals[i as usize].normalize() - n).length() <= NORMAL_NOISE);
        if !noisy {
            continue;
        }
        let c = members
            .iter()
            .map(|&i| hull.points[i as usize])
            .sum::<DVec3>()
            / members.len() as f64;
        for i in members {
            let e = plane_of.entry(i).or_insert(Some((n, c)));
            if e.is_some_and(|(m, _)| (m - n).length() > NORMAL_NOISE) {
                *e = None;
            }
        }
    }
    let mut moved: Vec<u32> = plane_of.iter().filter_map(|(&i, p)| p.map(|_| i)).collect();
    moved.sort_unstable();
    for &i in &moved {
        let (n, c) = plane_of[&i].expect("kept");
        let p = hull.points[i as usize];
        out.points[i as usize] = p - n.dot(p - c) * n;
        out.normals[i as usize] = n;
    }
    (out, moved)
}

/// The triangles of T on a zero coplanar group of `hull` (as returned by
/// [`zero_coplanar_groups`], with its `moved` points): all three points moved, with one plane
/// normal, which the triangle's own normal matches. F vanishes on their face tetrahedra's
/// bases, so the base itself is the sheet there and the level-1 weights must keep the apex's
/// sign ([`super::signs`]).
#[must_use]
pub fn zero_triangles(hull: &SimplicialHull, moved: &[u32]) -> HashSet<u32> {
    let moved: HashSet<u32> = moved.iter().copied().collect();
    (0..hull.triangles.len() as u32)
        .filter(|&t| {
            let tri = hull.triangles[t as usize];
            if !tri.iter().all(|i| moved.contains(i)) {
                return false;
            }
            let n = hull.normals[tri[0] as usize];
            let [a, b, c] = tri.map(|i| hull.points[i as usize]);
            tri.iter().all(|&i| hull.normals[i as usize] == n)
                && (b - a).cross(c - a).try_normalize().is_some_and(|m| {
                    (m - n).length() <= NORMAL_NOISE || (m + n).length() <= NORMAL_NOISE
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;

    /// A flat fan of four triangles round a centre, normals and heights perturbed by 1e-6
    /// (float32 noise): all points land on one plane with its normal; a fan with one normal
    /// tilted by 0.1 (a real feature) is left alone.
    #[test]
    fn noisy_flat_fan_becomes_exact() {
        let ring = [
            DVec3::new(1.0, 0.0, 1e-6),
            DVec3::new(0.0, 1.0, -1e-6),
            DVec3::new(-1.0, 0.0, 2e-6),
            DVec3::new(0.0, -1.0, 0.0),
        ];
        let mut points = vec![DVec3::new(0.0, 0.0, 1e-6)];
        points.extend(ring);
        let noisy = |k: usize| DVec3::new(1e-6 * k as f64, -1e-6, 1.0).normalize();
        let hull = SimplicialHull {
            normals: (0..5).map(noisy).collect(),
            points,
            origins: vec![PointOrigin::Other; 5],
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
            apexes: vec![[Some(DVec3::Z), None]; 4],
            element: vec![0; 4],
        };
        let (flat, moved) = zero_coplanar_groups(&hull);
        assert_eq!(moved, vec![0, 1, 2, 3, 4]);
        let n = flat.normals[0];
        for i in 0..5 {
            assert_eq!(flat.normals[i], n);
            // On one plane through the first point, to rounding of O(1) coordinates.
            assert!(n.dot(flat.points[i] - flat.points[0]).abs() < 1e-15);
            // Moved by the noise only.
            assert!((flat.points[i] - hull.points[i]).length() < 1e-5);
        }
        let zero = zero_triangles(&flat, &moved);
        assert_eq!(
            zero.len(),
            4,
            "every triangle of the fan is on the zero group"
        );
        // The last point left out of the moved list: its two triangles are not zero bases.
        let zero = zero_triangles(&flat, &moved[..4]);
        assert_eq!(zero, HashSet::from([0, 1]));
        let mut tilted = hull.clone();
        tilted.normals[2] = DVec3::new(0.1, 0.0, 1.0).normalize();
        let (same, moved) = zero_coplanar_groups(&tilted);
        assert!(moved.is_empty());
        assert_eq!(same.points, tilted.points);
        assert!(zero_triangles(&same, &moved).is_empty());
    }
}

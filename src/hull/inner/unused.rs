//! Points of T that no triangle of T uses are dropped at the end of the build.
//!
//! Every convex piece of a polygon becomes a point of T (its centroid or corner guard) before
//! the corners are built, but in a corner guard net ([`super::guardnet`]) each region corner
//! gets ONE guard, and a piece whose guard the assignment gives no corner has no triangle:
//! mpi_poly's needle face 35 had such a guard at (0, 1.43, 4.01). A point of T is a point the
//! surface must pass through with its normal (the schemes interpolate T's points), but a point
//! no triangle has as a corner is a corner of no tetrahedron, so no patch is built to pass
//! through it, and where it lies inside another point's tetrahedron the surface misses it
//! (`apatch check`: vertex value 1.9e-3, normal 0.37 there). Such a point is no vertex of T
//! at all (T is the union of its triangles), so it is removed and the triangles renumbered.

use crate::hull::simplicial::SimplicialHull;

/// Removes the points of T that no triangle names, keeping the others in order, and renumbers
/// the triangles. Returns the old indices of the removed points. `renumber` maps old to new
/// indices for the caller's own lists (`None` for a removed point).
pub fn drop_unused_points(hull: &mut SimplicialHull) -> (Vec<u32>, Vec<Option<u32>>) {
    let n = hull.points.len();
    let mut used = vec![false; n];
    for t in &hull.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    let mut map = vec![None; n];
    let mut dropped = Vec::new();
    let mut next = 0u32;
    for (i, &u) in used.iter().enumerate() {
        if u {
            map[i] = Some(next);
            next += 1;
        } else {
            dropped.push(i as u32);
        }
    }
    if dropped.is_empty() {
        return (dropped, map);
    }
    keep_used(&mut hull.points, &used);
    keep_used(&mut hull.normals, &used);
    keep_used(&mut hull.origins, &used);
    for t in &mut hull.triangles {
        for i in t.iter_mut() {
            *i = map[*i as usize].expect("a triangle's point is used");
        }
    }
    (dropped, map)
}

/// Keeps the entries of `v` whose flag in `used` is set, in order.
fn keep_used<T>(v: &mut Vec<T>, used: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        i += 1;
        used[i - 1]
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::simplicial::PointOrigin;
    use glam::DVec3;

    #[test]
    fn unused_points_drop_and_triangles_renumber() {
        let p = |x: f64| DVec3::new(x, x * x, 1.0);
        let mut hull = SimplicialHull {
            points: (0..5).map(|i| p(i as f64)).collect(),
            normals: (0..5).map(|i| DVec3::new(0.0, 0.0, i as f64)).collect(),
            origins: (0..5).map(|i| PointOrigin::Centroid { face: i }).collect(),
            triangles: vec![[0, 2, 4], [4, 2, 3]],
            apexes: vec![[Some(DVec3::ZERO), None]; 2],
            element: vec![7, 8],
        };
        let before: Vec<[DVec3; 3]> = hull
            .triangles
            .iter()
            .map(|t| t.map(|i| hull.points[i as usize]))
            .collect();
        let (dropped, map) = drop_unused_points(&mut hull);
        assert_eq!(dropped, vec![1]);
        assert_eq!(map, vec![Some(0), None, Some(1), Some(2), Some(3)]);
        assert_eq!(hull.points.len(), 4);
        assert_eq!(hull.normals.len(), 4);
        assert_eq!(hull.origins[1], PointOrigin::Centroid { face: 2 });
        assert_eq!(hull.normals[1], DVec3::new(0.0, 0.0, 2.0));
        // The triangles name the same positions as before.
        for (t, b) in hull.triangles.iter().zip(&before) {
            assert_eq!(t.map(|i| hull.points[i as usize]), *b);
        }
        // Nothing to drop: nothing changes.
        let again = hull.clone();
        let (dropped, _) = drop_unused_points(&mut hull);
        assert!(dropped.is_empty());
        assert_eq!(hull.points, again.points);
        assert_eq!(hull.triangles, again.triangles);
    }
}

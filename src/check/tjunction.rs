//! T-junctions: boundary faces (faces of one patch only) that overlap another boundary face lying
//! in the same plane on the other side, i.e. two tetrahedra meet along a face without sharing its
//! vertices.
//!
//! Cheap, not exhaustive: boundary faces are grouped by their plane (unit normal and offset
//! rounded to [`PLANE_QUANTUM`]; faces whose rounded plane falls on different sides of a rounding
//! boundary are missed), and only groups with faces facing both ways are tested pairwise.

use super::eval::PatchEval;
use super::Location;
use glam::{DVec2, DVec3};

/// Relative resolution of the plane grouping (unit normals, offsets over the model size).
pub const PLANE_QUANTUM: f64 = 1e-8;

/// Relative overlap slack: triangles that only touch along an edge (to this fraction of their
/// size) do not overlap.
const TOUCH_SLACK: f64 = 1e-9;

/// A boundary face: patch index and the tetrahedron-local index of the opposite vertex.
pub(super) type BoundaryFace = (u32, u8);

/// Counts overlapping pairs of opposite boundary faces; an example location.
pub(super) fn overlapping_pairs(
    evals: &[PatchEval<'_>],
    faces: &[BoundaryFace],
) -> (usize, Option<Location>) {
    let scale = model_size(evals).max(f64::MIN_POSITIVE);
    struct Planar {
        key: [i64; 4],
        outward_positive: bool,
        pts: [DVec3; 3],
        patch: u32,
        drop_axis: usize,
    }
    let mut planar: Vec<Planar> = faces
        .iter()
        .filter_map(|&(patch, opposite)| {
            let v = evals[patch as usize].patch.tet_points();
            let idx: Vec<usize> = (0..4).filter(|&k| k != usize::from(opposite)).collect();
            let pts = [v[idx[0]], v[idx[1]], v[idx[2]]];
            let n = (pts[1] - pts[0]).cross(pts[2] - pts[0]).try_normalize()?;
            // Canonical sign: the first component of magnitude ≥ ½ is positive (one exists
            // because the largest is ≥ 1/√3, and its sign is immune to rounding).
            let lead = (0..3).find(|&k| n[k].abs() >= 0.5)?;
            let canon = if n[lead] > 0.0 { n } else { -n };
            let towards_opposite = (v[usize::from(opposite)] - pts[0]).dot(canon);
            let d = canon.dot(pts[0]) / scale;
            let q = |x: f64| (x / PLANE_QUANTUM).round() as i64;
            Some(Planar {
                key: [q(canon.x), q(canon.y), q(canon.z), q(d)],
                outward_positive: towards_opposite < 0.0,
                pts,
                patch,
                drop_axis: canon.abs().max_position(),
            })
        })
        .collect();
    planar.sort_by(|a, b| a.key.cmp(&b.key).then(a.patch.cmp(&b.patch)));

    let mut count = 0;
    let mut at = None;
    let mut start = 0;
    for i in 1..=planar.len() {
        if i < planar.len() && planar[i].key == planar[start].key {
            continue;
        }
        let group = &planar[start..i];
        start = i;
        if group.iter().all(|f| f.outward_positive) || !group.iter().any(|f| f.outward_positive) {
            continue;
        }
        // Both sides present: project to 2D and sweep the negative side by bounding box in x.
        let axis = group[0].drop_axis;
        let flat = |f: &Planar| {
            let (u, v) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            f.pts.map(|p| DVec2::new(p[u], p[v]))
        };
        let bbox = |t: &[DVec2; 3]| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        let mut neg: Vec<(&Planar, [DVec2; 3], DVec2, DVec2)> = group
            .iter()
            .filter(|f| !f.outward_positive)
            .map(|f| {
                let t = flat(f);
                let (lo, hi) = bbox(&t);
                (f, t, lo, hi)
            })
            .collect();
        neg.sort_by(|a, b| a.2.x.total_cmp(&b.2.x));
        for a in group.iter().filter(|f| f.outward_positive) {
            let ta = flat(a);
            let (alo, ahi) = bbox(&ta);
            let end = neg.partition_point(|n| n.2.x < ahi.x);
            for (b, tb, blo, bhi) in &neg[..end] {
                if bhi.x <= alo.x || bhi.y <= alo.y || blo.y >= ahi.y {
                    continue;
                }
                if triangles_overlap(&ta, tb) {
                    count += 1;
                    if at.is_none() {
                        let c = (a.pts[0] + a.pts[1] + a.pts[2]) / 3.0;
                        let pair = [&evals[a.patch as usize], &evals[b.patch as usize]];
                        at = Some(Location::new(&pair, c.to_array(), None));
                    }
                }
            }
        }
    }
    (count, at)
}

fn model_size(evals: &[PatchEval<'_>]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for e in evals {
        for v in e.patch.tet_points() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (hi - lo).max_element()
}

/// True when the interiors of two triangles intersect (separating-axis test over the six edge
/// normals; touching along an edge or at a point is not overlap).
fn triangles_overlap(a: &[DVec2; 3], b: &[DVec2; 3]) -> bool {
    let size = a
        .iter()
        .chain(b)
        .fold(0.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()))
        .max(f64::MIN_POSITIVE);
    let slack = TOUCH_SLACK * size;
    for tri in [a, b] {
        for i in 0..3 {
            let e = tri[(i + 1) % 3] - tri[i];
            let axis = DVec2::new(-e.y, e.x);
            let len = axis.length();
            if len == 0.0 {
                continue;
            }
            let axis = axis / len;
            let proj = |t: &[DVec2; 3]| {
                t.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                        let d = axis.dot(*p);
                        (lo.min(d), hi.max(d))
                    })
            };
            let (alo, ahi) = proj(a);
            let (blo, bhi) = proj(b);
            if ahi <= blo + slack || bhi <= alo + slack {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_cases() {
        let t = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let half = [DVec2::ZERO, DVec2::new(0.5, 0.0), DVec2::new(0.0, 0.5)];
        let beside = [DVec2::X, DVec2::Y, DVec2::ONE];
        let far = [
            DVec2::splat(2.0),
            DVec2::new(3.0, 2.0),
            DVec2::new(2.0, 3.0),
        ];
        assert!(triangles_overlap(&t, &half));
        assert!(!triangles_overlap(&t, &beside), "touching along an edge");
        assert!(!triangles_overlap(&t, &far));
    }
}

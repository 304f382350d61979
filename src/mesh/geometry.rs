//! Per-face geometry: area vectors (Newell), planarity, corner angles.

use glam::DVec3;

/// The area vector of a polygon (Newell's method): its direction is the polygon's normal
/// (counter-clockwise vertices give the right-hand normal) and its length the area for a planar
/// polygon. Computed about the first vertex to limit cancellation.
#[must_use]
pub fn area_vector(positions: &[DVec3], face: &[u32]) -> DVec3 {
    let o = positions[face[0] as usize];
    let mut s = DVec3::ZERO;
    for k in 1..face.len().saturating_sub(1) {
        let a = positions[face[k] as usize] - o;
        let b = positions[face[k + 1] as usize] - o;
        s += a.cross(b);
    }
    0.5 * s
}

/// The length of the bounding-box diagonal of `positions` (0 when empty): the scale relative
/// tolerances (`model.clean`, `scheme.merge_close`) are measured in.
#[must_use]
pub fn bbox_diagonal(positions: &[DVec3]) -> f64 {
    let Some(&first) = positions.first() else {
        return 0.0;
    };
    let (lo, hi) = positions
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (hi - lo).length()
}

/// The largest distance from the first vertex to another vertex of the face (a length scale).
#[must_use]
pub fn face_size(positions: &[DVec3], face: &[u32]) -> f64 {
    let o = positions[face[0] as usize];
    face.iter()
        .map(|&v| (positions[v as usize] - o).length())
        .fold(0.0, f64::max)
}

/// Largest distance of a vertex from the plane through the face's centroid normal to its area
/// vector, divided by the face size. 0 for triangles; `None` for a zero-area face.
#[must_use]
pub fn planarity_deviation(positions: &[DVec3], face: &[u32]) -> Option<f64> {
    let n = area_vector(positions, face).try_normalize()?;
    let size = face_size(positions, face);
    if face.len() == 3 {
        return Some(0.0);
    }
    let c = face.iter().map(|&v| positions[v as usize]).sum::<DVec3>() / face.len() as f64;
    let d = face
        .iter()
        .map(|&v| (positions[v as usize] - c).dot(n).abs())
        .fold(0.0, f64::max);
    Some(d / size)
}

/// The interior angle of the face at its `k`-th vertex, in [0, 2π): reflex corners of a
/// non-convex polygon (turning against `normal`, the face's area vector) get 2π − θ.
/// 0 for a degenerate corner.
#[must_use]
pub fn corner_angle(positions: &[DVec3], face: &[u32], k: usize, normal: DVec3) -> f64 {
    let n = face.len();
    let p = positions[face[k] as usize];
    let a = positions[face[(k + 1) % n] as usize] - p;
    let b = positions[face[(k + n - 1) % n] as usize] - p;
    let (la, lb) = (a.length(), b.length());
    if la == 0.0 || lb == 0.0 {
        return 0.0;
    }
    // atan2 of |a×b| and a·b is accurate for small and near-π angles alike.
    let x = a.cross(b);
    let theta = x.length().atan2(a.dot(b));
    if face.len() > 3 && x.dot(normal) < 0.0 {
        std::f64::consts::TAU - theta
    } else {
        theta
    }
}

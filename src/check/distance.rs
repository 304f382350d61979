//! Distance of a surface to the polyhedron it approximates (1994 schemes cut corners): surface
//! points are sampled per patch along its promised single-sheet lines (from the j-vertex
//! through a lattice of the opposite face, or between lattices of the j-edge and the opposite
//! edge; the first root of F on each), and each point's distance to the triangulated polyhedron
//! is the least over all its triangles (found by branch and bound in a box tree). Largest and mean, relative to the polyhedron's bounding-box
//! diagonal.

use crate::bb::uni;
use crate::complex::PatchComplex;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

/// Largest number of (sample, triangle) pairs measured; beyond it every k-th sample is used
/// (deterministic stride), so large models stay within seconds.
pub const MAX_PAIRS: usize = 200_000_000;

/// The distance measures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DistanceStats {
    /// Surface points measured.
    pub samples: usize,
    /// Largest distance / bounding-box diagonal.
    pub max: f64,
    /// Mean distance / bounding-box diagonal.
    pub mean: f64,
    /// The bounding-box diagonal of the polyhedron.
    pub diagonal: f64,
    /// The surface point farthest from the polyhedron.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_at: Option<[f64; 3]>,
}

/// Surface points of every patch with a j-vertex or j-edge: the first root of F in (0, 1)
/// on lines through `res` lattice steps per edge (at least 3, and 4 across a face so it has an
/// interior point: the lattice of the sheet check).
#[must_use]
pub fn surface_samples(complex: &PatchComplex, res: usize) -> Vec<DVec3> {
    let res = res.max(3);
    complex
        .patches
        .par_iter()
        .flat_map_iter(|p| {
            let v = p.tet_points();
            let (from, to) = super::sheets::j_line_ends(p, res).unwrap_or_default();
            let mut pts = Vec::new();
            for a in &from {
                for b in &to {
                    let mut c = [0.0; 16];
                    let mut len = p.segment_poly_bary(*a, *b, &mut c);
                    if len == 0 {
                        continue;
                    }
                    let scale = c[..len].iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    // A root at the start (the j-vertex on the surface) is not a sample: 1e-12
                    // is far above weight round-off and far below any weight set on purpose.
                    while len > 1 && c[0].abs() <= 1e-12 * scale {
                        len = uni::deflate_at_zero(&mut c, len);
                    }
                    if let Some(t) = uni::first_root(&c[..len]) {
                        let alpha: [f64; 4] = std::array::from_fn(|k| (1.0 - t) * a[k] + t * b[k]);
                        pts.push((0..4).map(|k| alpha[k] * v[k]).sum::<DVec3>());
                    }
                }
            }
            pts
        })
        .collect()
}

/// Distance from `x` to the triangle [a b c] (closest point by regions, Ericson §5.1.5).
#[must_use]
pub fn point_triangle_distance(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, x - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = x - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (x - (a + v * ab)).length();
    }
    let cp = x - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (x - (a + w * ac)).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (x - (b + w * (c - b))).length();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (x - (a + ab * v + ac * w)).length()
}

/// Distance measures of `complex`'s surface to the polyhedron (`positions`, `triangles`),
/// sampled with `res` lattice steps per patch edge.
#[must_use]
pub fn distance_to_polyhedron(
    complex: &PatchComplex,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    res: usize,
) -> DistanceStats {
    let (lo, hi) = positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let diagonal = (hi - lo).length();
    let all = surface_samples(complex, res);
    let stride = (all.len() * triangles.len()).div_ceil(MAX_PAIRS).max(1);
    let tree = TriangleTree::new(positions, triangles);
    let d: Vec<(f64, DVec3)> = all
        .par_iter()
        .step_by(stride)
        .map(|&x| (tree.distance(x), x))
        .collect();
    if d.is_empty() || diagonal.is_nan() || diagonal <= 0.0 {
        return DistanceStats {
            diagonal,
            ..DistanceStats::default()
        };
    }
    let (max, at) = d
        .iter()
        .copied()
        .fold((0.0, DVec3::ZERO), |m, x| if x.0 > m.0 { x } else { m });
    DistanceStats {
        samples: d.len(),
        max: max / diagonal,
        mean: d.iter().map(|x| x.0).sum::<f64>() / d.len() as f64 / diagonal,
        diagonal,
        max_at: Some(at.to_array()),
    }
}

/// Triangles in at most this many per leaf of [`TriangleTree`].
const LEAF: usize = 4;

/// The polyhedron's triangles in a tree of bounding boxes (median splits), for the distance
/// from a point to the nearest triangle by branch and bound: a box is skipped when even its
/// nearest point is farther than the best distance found (with a relative margin of 1e-9, far
/// above the rounding of either distance), so the result is the brute-force minimum over all
/// triangles, bit for bit, at a small fraction of the cost.
struct TriangleTree {
    /// Corners of each triangle.
    tris: Vec<[DVec3; 3]>,
    /// Triangle indices, each leaf's a contiguous run.
    order: Vec<usize>,
    /// Nodes, the root first.
    nodes: Vec<TreeNode>,
}

/// A box of [`TriangleTree`]: `count > 0` is a leaf holding `order[first..first + count]`,
/// else the children are the nodes `first` and `first + 1`.
struct TreeNode {
    lo: DVec3,
    hi: DVec3,
    first: usize,
    count: usize,
}

impl TriangleTree {
    fn new(positions: &[DVec3], triangles: &[[u32; 3]]) -> Self {
        let tris: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|k| positions[k as usize]))
            .collect();
        let mut tree = TriangleTree {
            order: (0..tris.len()).collect(),
            tris,
            nodes: Vec::new(),
        };
        if !tree.tris.is_empty() {
            tree.nodes.push(TreeNode {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
                first: 0,
                count: 0,
            });
            tree.split(0, 0, tree.tris.len());
        }
        tree
    }

    /// Makes node `at` the box of `order[start..end]`, and splits it at the median centroid
    /// along the longest axis of the centroids' box while more than [`LEAF`] remain.
    fn split(&mut self, at: usize, start: usize, end: usize) {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        for &t in &self.order[start..end] {
            let [a, b, c] = self.tris[t];
            lo = lo.min(a.min(b).min(c));
            hi = hi.max(a.max(b).max(c));
            let m = (a + b + c) / 3.0;
            clo = clo.min(m);
            chi = chi.max(m);
        }
        self.nodes[at].lo = lo;
        self.nodes[at].hi = hi;
        if end - start <= LEAF {
            self.nodes[at].first = start;
            self.nodes[at].count = end - start;
            return;
        }
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let tris = &self.tris;
        let key = |t: &usize| {
            let [a, b, c] = tris[*t];
            (a[axis] + b[axis] + c[axis], *t)
        };
        let mid = start + (end - start) / 2;
        self.order[start..end].select_nth_unstable_by(mid - start, |p, q| {
            let (kp, kq) = (key(p), key(q));
            kp.0.total_cmp(&kq.0).then(kp.1.cmp(&kq.1))
        });
        let child = self.nodes.len();
        for _ in 0..2 {
            self.nodes.push(TreeNode {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
                first: 0,
                count: 0,
            });
        }
        self.nodes[at].first = child;
        self.split(child, start, mid);
        self.split(child + 1, mid, end);
    }

    /// Distance from `x` to node `n`'s box (0 inside).
    fn box_distance(&self, n: usize, x: DVec3) -> f64 {
        let node = &self.nodes[n];
        (node.lo - x).max(x - node.hi).max(DVec3::ZERO).length()
    }

    /// Distance from `x` to the nearest triangle (infinite without triangles).
    fn distance(&self, x: DVec3) -> f64 {
        let mut best = f64::INFINITY;
        if self.nodes.is_empty() {
            return best;
        }
        let mut stack = vec![(0usize, self.box_distance(0, x))];
        while let Some((n, near)) = stack.pop() {
            if near > best * (1.0 + 1e-9) {
                continue;
            }
            let node = &self.nodes[n];
            if node.count > 0 {
                for &t in &self.order[node.first..node.first + node.count] {
                    let [a, b, c] = self.tris[t];
                    best = best.min(point_triangle_distance(x, a, b, c));
                }
            } else {
                let (l, r) = (node.first, node.first + 1);
                let (dl, dr) = (self.box_distance(l, x), self.box_distance(r, x));
                // The nearer child is searched first (popped first).
                if dl <= dr {
                    stack.push((r, dr));
                    stack.push((l, dl));
                } else {
                    stack.push((l, dl));
                    stack.push((r, dr));
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree's distance is the minimum over all triangles, bit for bit (what the brute-force
    /// loop computed before): a seeded soup of 600 small triangles in a box (some degenerate:
    /// a repeated corner; some repeated whole), and points inside the box, near it and far off;
    /// also a single triangle and none.
    #[test]
    fn tree_distance_is_the_brute_force_minimum() {
        let mut seed = 1994u64;
        let mut r = move || crate::fixtures::splitmix(&mut seed);
        let mut positions = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for k in 0..600u32 {
            if k % 50 == 49 {
                triangles.push(triangles[(k / 2) as usize]);
                continue;
            }
            let base = DVec3::new(r(), r(), r()) * 4.0 - 2.0;
            let n = positions.len() as u32;
            for _ in 0..3 {
                positions.push(base + DVec3::new(r(), r(), r()) * 0.3);
            }
            triangles.push(if k % 37 == 0 {
                [n, n + 1, n]
            } else {
                [n, n + 1, n + 2]
            });
        }
        let brute = |x: DVec3, tris: &[[u32; 3]]| {
            tris.iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| positions[k as usize]);
                    point_triangle_distance(x, a, b, c)
                })
                .fold(f64::INFINITY, f64::min)
        };
        let tree = TriangleTree::new(&positions, &triangles);
        let one = TriangleTree::new(&positions, &triangles[..1]);
        let none = TriangleTree::new(&positions, &[]);
        for k in 0..400 {
            let scale = [1.0, 3.0, 50.0][k % 3];
            let x = (DVec3::new(r(), r(), r()) * 2.0 - 1.0) * scale;
            assert_eq!(
                tree.distance(x).to_bits(),
                brute(x, &triangles).to_bits(),
                "{x}"
            );
            assert_eq!(
                one.distance(x).to_bits(),
                brute(x, &triangles[..1]).to_bits()
            );
            assert_eq!(none.distance(x), f64::INFINITY);
        }
    }

    /// The region formula against brute-force sampling of the triangle.
    #[test]
    fn point_triangle_distance_matches_sampling() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.5, 0.4),
        );
        for x in [
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(3.0, 0.0, 0.2),
            DVec3::new(1.5, 1.5, -0.5),
            DVec3::new(0.2, 2.5, 0.4),
        ] {
            let n = 400;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    best = best.min((x - (a + u * (b - a) + v * (c - a))).length());
                }
            }
            let d = point_triangle_distance(x, a, b, c);
            // The 400-step grid is within ~2/400 of the closest point; distances are ≥ 0.3.
            assert!(d <= best + 1e-12 && best - d < 5e-3, "{x}: {d} vs {best}");
        }
    }
}

//! The outer face/edge hull of Xu, Huang and Bajaj (2001), §3.
//!
//! Every edge and face of the triangulation is classified from the unit vertex normals
//! ([`Convexity`]); every face that is not zero convex gets a positive face tetrahedron
//! [p_i p_j p_k u_ijk] and/or a negative one [p_i p_j p_k v_ijk]; every edge that is not zero
//! convex and has two such faces gets edge tetrahedra [p_i p_j u_ijk u_ijl] / [p_i p_j v_ijk v_ijl].
//!
//! Edge numbering (used as the `element` of edge patches): triangles are scanned in order, and
//! each triangle's corners (0,1), (1,2), (2,0) in turn; an undirected edge gets the next index the
//! first time it is met. [`Edge::v`] keeps the orientation of that first meeting, and
//! [`Edge::faces`]`[0]` is the triangle of that first meeting.
//!
//! Deviations from the paper, all documented: t_max is at least ε and t_min at most −ε (the
//! paper's 0 can give a degenerate tetrahedron), and ε = `epsilon` × the face's longest edge
//! (scale-aware; default 0.05).

pub mod refine;

use crate::error::{Error, Result};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// No face: marks the missing second face of a boundary edge.
pub const NO_FACE: u32 = u32::MAX;

/// Classification of an edge or face from its vertex normals (§3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Convexity {
    /// (p_j−p_i)·n_j ≥ 0, (p_i−p_j)·n_i ≥ 0, one of them > 0 (for faces: all edges ≥ 0, one > 0).
    Positive,
    /// Both numbers zero (faces: all three edges zero convex): the face is its own plane.
    Zero,
    /// Both ≤ 0, one < 0 (faces: all edges nonpositive, one negative).
    Negative,
    /// Opposite signs (faces: every other case).
    Nonconvex,
}

impl Convexity {
    /// Whether tetrahedra on the positive side (towards the normals) are built.
    #[must_use]
    pub fn has_positive(self) -> bool {
        matches!(self, Convexity::Positive | Convexity::Nonconvex)
    }
    /// Whether tetrahedra on the negative side are built.
    #[must_use]
    pub fn has_negative(self) -> bool {
        matches!(self, Convexity::Negative | Convexity::Nonconvex)
    }
    /// Lowercase name for reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Convexity::Positive => "positive",
            Convexity::Zero => "zero",
            Convexity::Negative => "negative",
            Convexity::Nonconvex => "nonconvex",
        }
    }
}

/// Relative tolerance under which (p_j − p_i)·n_j / |p_j − p_i| counts as zero.
pub const ZERO_TOL: f64 = 1e-9;

/// Classifies the edge [p_i p_j] with unit normals n_i, n_j (§3, Fig. 5).
#[must_use]
pub fn edge_convexity(pi: DVec3, pj: DVec3, ni: DVec3, nj: DVec3) -> Convexity {
    let len = (pj - pi).length();
    let zero = |x: f64| if x.abs() <= ZERO_TOL * len { 0.0 } else { x };
    let a = zero((pj - pi).dot(nj));
    let b = zero((pi - pj).dot(ni));
    if a == 0.0 && b == 0.0 {
        Convexity::Zero
    } else if a >= 0.0 && b >= 0.0 {
        Convexity::Positive
    } else if a <= 0.0 && b <= 0.0 {
        Convexity::Negative
    } else {
        Convexity::Nonconvex
    }
}

/// Classifies a face from the classes of its three edges (§3).
#[must_use]
pub fn face_convexity(edges: [Convexity; 3]) -> Convexity {
    use Convexity::*;
    let pos = edges.iter().filter(|&&e| e == Positive).count();
    let neg = edges.iter().filter(|&&e| e == Negative).count();
    let zero = edges.iter().filter(|&&e| e == Zero).count();
    if zero == 3 {
        Zero
    } else if pos + zero == 3 {
        Positive
    } else if neg + zero == 3 {
        Negative
    } else {
        Nonconvex
    }
}

/// One undirected mesh edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// Its vertices, oriented as in `faces[0]`.
    pub v: [u32; 2],
    /// The one or two triangles containing it ([`NO_FACE`] for a boundary edge).
    pub faces: [u32; 2],
    /// Its class.
    pub class: Convexity,
}

impl Edge {
    /// True when the edge has only one triangle.
    #[must_use]
    pub fn is_boundary(&self) -> bool {
        self.faces[1] == NO_FACE
    }
}

/// The hull data of one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceHull {
    /// Its class.
    pub class: Convexity,
    /// Unit face normal n_ijk on the positive side (the side of the vertex normals).
    pub normal: DVec3,
    /// Centroid c = (p_i + p_j + p_k)/3.
    pub centroid: DVec3,
    /// u_ijk = c + t_max n_ijk, when a positive face tetrahedron is built.
    pub top: Option<DVec3>,
    /// v_ijk = c + t_min n_ijk, when a negative face tetrahedron is built.
    pub bottom: Option<DVec3>,
    /// The ε used for this face (absolute length).
    pub epsilon: f64,
    /// t_max of §3.1 (at least ε), computed for every face that is not zero convex.
    pub t_max: f64,
    /// t_min of §3.1 (at most −ε), computed for every face that is not zero convex.
    pub t_min: f64,
}

/// The outer simplicial hull Σ of a triangulation.
#[derive(Clone, Debug, PartialEq)]
pub struct OuterHull {
    /// One entry per triangle.
    pub faces: Vec<FaceHull>,
    /// The unique edges, numbered as described in the module docs.
    pub edges: Vec<Edge>,
    /// For each triangle, the indices of its edges (p0p1, p1p2, p2p0).
    pub face_edges: Vec<[u32; 3]>,
}

/// Settings of the hull construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HullOptions {
    /// ε of §3.1 relative to the face's longest edge (default 0.05).
    pub epsilon: f64,
}

impl Default for HullOptions {
    fn default() -> Self {
        HullOptions { epsilon: 0.05 }
    }
}

/// One raw edge: its vertices and its one or two triangles.
pub type RawEdge = ([u32; 2], [u32; 2]);

/// The unique edges of a triangle list and each triangle's edge indices (numbering as in the
/// module docs). Errors on an edge shared by more than two triangles, or a degenerate index.
pub fn edge_map(nverts: usize, triangles: &[[u32; 3]]) -> Result<(Vec<RawEdge>, Vec<[u32; 3]>)> {
    let mut map: HashMap<u64, u32, EdgeKeyHash> =
        HashMap::with_capacity_and_hasher(triangles.len() * 2, EdgeKeyHash);
    let mut edges: Vec<RawEdge> = Vec::with_capacity(triangles.len() * 3 / 2 + 3);
    let mut face_edges = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            if v as usize >= nverts {
                return Err(Error::Invalid(format!(
                    "triangle {t}: vertex index {v} out of range ({nverts} vertices)"
                )));
            }
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(Error::Invalid(format!(
                "triangle {t}: repeated vertex {tri:?}"
            )));
        }
        let mut fe = [0u32; 3];
        for c in 0..3 {
            let (a, b) = (tri[c], tri[(c + 1) % 3]);
            let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            let id = *map.entry(key).or_insert_with(|| {
                edges.push(([a, b], [t as u32, NO_FACE]));
                (edges.len() - 1) as u32
            });
            let e = &mut edges[id as usize];
            if e.1[0] != t as u32 {
                if e.1[1] != NO_FACE {
                    return Err(Error::Invalid(format!(
                        "edge ({a}, {b}) is shared by more than two triangles (triangles {}, {}, {t})",
                        e.1[0], e.1[1]
                    )));
                }
                e.1[1] = t as u32;
            }
            fe[c] = id;
        }
        face_edges.push(fe);
    }
    Ok((edges, face_edges))
}

/// A fast, deterministic hash for the packed vertex pair keys of [`edge_map`] (the default
/// SipHash was a visible serial cost on 100k-triangle meshes; the keys are not adversarial).
#[derive(Clone, Copy, Default)]
struct EdgeKeyHash;

impl std::hash::BuildHasher for EdgeKeyHash {
    type Hasher = EdgeKeyHasher;
    fn build_hasher(&self) -> EdgeKeyHasher {
        EdgeKeyHasher(0)
    }
}

/// The hasher of [`EdgeKeyHash`]: a multiplicative mix of one u64 (high and low bits folded,
/// since the table uses both).
struct EdgeKeyHasher(u64);

impl std::hash::Hasher for EdgeKeyHasher {
    fn finish(&self) -> u64 {
        let h = self.0.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        h ^ (h >> 29)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x100_0000_01B3);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 ^= x;
    }
}

/// Checks that every normal is finite and of unit length (within 1e-6).
pub fn validate_normals(positions: &[DVec3], normals: &[DVec3]) -> Result<()> {
    if positions.len() != normals.len() {
        return Err(Error::Invalid(format!(
            "{} vertices but {} normals",
            positions.len(),
            normals.len()
        )));
    }
    for (i, (p, n)) in positions.iter().zip(normals).enumerate() {
        if !p.is_finite() {
            return Err(Error::Invalid(format!(
                "vertex {i}: position is not finite"
            )));
        }
        if !n.is_finite() || (n.length() - 1.0).abs() > 1e-6 {
            return Err(Error::Invalid(format!(
                "vertex {i}: normal {n} is not a finite unit vector"
            )));
        }
    }
    Ok(())
}

/// Builds the outer hull (§3.1, §3.2) without the intersection test (see [`refine`]).
///
/// Errors: a degenerate triangle, a vertex normal that does not point to the positive side of
/// one of its triangles (n_ijk · n_l ≤ 0, which makes t_l of §3.1 meaningless).
pub fn build(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    opts: &HullOptions,
) -> Result<OuterHull> {
    validate_normals(positions, normals)?;
    let (raw_edges, face_edges) = edge_map(positions.len(), triangles)?;
    // Per edge and per face independent work: in parallel (indexed, so the order and the
    // results are those of the sequential loop on any number of threads).
    let edges: Vec<Edge> = raw_edges
        .par_iter()
        .map(|&(v, faces)| {
            let (a, b) = (v[0] as usize, v[1] as usize);
            Edge {
                v,
                faces,
                class: edge_convexity(positions[a], positions[b], normals[a], normals[b]),
            }
        })
        .collect();
    let faces: Vec<Result<FaceHull>> = triangles
        .par_iter()
        .enumerate()
        .map(|(t, tri)| {
            let class = face_convexity(face_edges[t].map(|e| edges[e as usize].class));
            face_hull(t, positions, tri, normals, class, opts)
        })
        .collect();
    // The first error in triangle order, as the sequential loop would report it.
    let faces = faces.into_iter().collect::<Result<Vec<FaceHull>>>()?;
    Ok(OuterHull {
        faces,
        edges,
        face_edges,
    })
}

/// The positive unit normal of a triangle: the right-hand normal flipped to the side of the
/// vertex normals. Errors when the triangle is degenerate or a vertex normal is on the other side.
pub fn face_normal(t: usize, p: [DVec3; 3], n: [DVec3; 3]) -> Result<DVec3> {
    let cross = (p[1] - p[0]).cross(p[2] - p[0]);
    let longest = (p[1] - p[0])
        .length()
        .max((p[2] - p[1]).length())
        .max((p[0] - p[2]).length());
    if cross.length().is_nan() || cross.length() <= 1e-12 * longest * longest {
        return Err(Error::Invalid(format!(
            "triangle {t}: degenerate (zero area)"
        )));
    }
    let mut nf = cross.normalize();
    if nf.dot(n[0] + n[1] + n[2]) < 0.0 {
        nf = -nf;
    }
    for (l, nl) in n.iter().enumerate() {
        if nf.dot(*nl) <= 1e-9 {
            return Err(Error::Invalid(format!(
                "triangle {t}: the normal of its corner {l} points to the other side of the \
                 triangle (or along it) relative to the other corners' normals"
            )));
        }
    }
    Ok(nf)
}

/// α(c, p_m, p_l) of (3.1).
#[must_use]
pub fn alpha(c: DVec3, pm: DVec3, pl: DVec3) -> f64 {
    (2.0 * (c - pl) + (c - pm)).dot(pm - pl) / (pm - pl).length_squared()
}

/// The mid-edge gradient data of the edge [p_a p_b] used by Steps 3–4 (see the scheme docs):
/// the cubic's blossom value b(p_a, p_b, w) for any point w is `f_ab + (w − p_a)·g1 / 3`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeBlossom {
    /// p_a.
    pub pa: DVec3,
    /// f_ab = (p_b − p_a)·n_a / 3, the weight next to p_a on the edge.
    pub fab: f64,
    /// Middle Bernstein coefficient of the (quadratic) gradient of F along the edge.
    pub g1: DVec3,
}

impl EdgeBlossom {
    /// Builds the data from the edge's end points and unit normals. Along the edge, ∇F is the
    /// quadratic with end values n_a, n_b whose mid value has the component across the edge
    /// (n_a + n_b)/2 (the directional derivatives of Steps 3–4) and the component along the edge
    /// from the Hermite cubic of F on the edge.
    #[must_use]
    pub fn new(pa: DVec3, pb: DVec3, na: DVec3, nb: DVec3) -> Self {
        let e = pb - pa;
        let e2 = e.length_squared();
        let mean = 0.5 * (na + nb);
        let along = -(e.dot(na) + e.dot(nb)) / 4.0;
        let gmid = mean - e * (mean.dot(e) / e2) + e * (along / e2);
        EdgeBlossom {
            pa,
            fab: e.dot(na) / 3.0,
            g1: 2.0 * gmid - mean,
        }
    }

    /// b(p_a, p_b, w).
    #[inline]
    #[must_use]
    pub fn at(&self, w: DVec3) -> f64 {
        self.fab + (w - self.pa).dot(self.g1) / 3.0
    }
}

fn face_hull(
    t: usize,
    positions: &[DVec3],
    tri: &[u32; 3],
    normals: &[DVec3],
    class: Convexity,
    opts: &HullOptions,
) -> Result<FaceHull> {
    let p = tri.map(|i| positions[i as usize]);
    let n = tri.map(|i| normals[i as usize]);
    let nf = face_normal(t, p, n)?;
    let c = (p[0] + p[1] + p[2]) / 3.0;
    let longest = (p[1] - p[0])
        .length()
        .max((p[2] - p[1]).length())
        .max((p[0] - p[2]).length());
    let eps = opts.epsilon * longest;
    if class == Convexity::Zero {
        return Ok(FaceHull {
            class,
            normal: nf,
            centroid: c,
            top: None,
            bottom: None,
            epsilon: eps,
            t_max: 0.0,
            t_min: 0.0,
        });
    }
    // t_l: c + t_l n lies on the tangent plane at p_l.
    let tl: [f64; 3] = std::array::from_fn(|l| (p[l] - c).dot(n[l]) / nf.dot(n[l]));
    // t_lm: the number 3 weight b_lm(c + t n) of the edge [p_l p_m] vanishes.
    let mut tlm = [0.0; 3];
    for (k, (l, m)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
        let eb = EdgeBlossom::new(p[l], p[m], n[l], n[m]);
        tlm[k] = -3.0 * eb.at(c) / nf.dot(eb.g1);
    }
    let mut tmax = eps;
    let mut tmin = -eps;
    for l in 0..3 {
        tmax = tmax.max(tl[l] + eps).max(tlm[l]);
        tmin = tmin.min(tl[l] - eps).min(tlm[l]);
    }
    Ok(FaceHull {
        class,
        normal: nf,
        centroid: c,
        top: class.has_positive().then_some(c + tmax * nf),
        bottom: class.has_negative().then_some(c + tmin * nf),
        epsilon: eps,
        t_max: tmax,
        t_min: tmin,
    })
}

/// Whether two tetrahedra overlap in more than a set of measure zero (separating axis test
/// with an absolute tolerance `tol`: touching along shared faces, edges or vertices is fine).
#[must_use]
pub fn tets_overlap(a: &[DVec3; 4], b: &[DVec3; 4], tol: f64) -> bool {
    const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    const EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
    let separated = |axis: DVec3| -> bool {
        let len = axis.length();
        if len < 1e-300 {
            return false;
        }
        let ax = axis / len;
        let (mut amin, mut amax, mut bmin, mut bmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for k in 0..4 {
            let x = a[k].dot(ax);
            amin = amin.min(x);
            amax = amax.max(x);
            let y = b[k].dot(ax);
            bmin = bmin.min(y);
            bmax = bmax.max(y);
        }
        amax <= bmin + tol || bmax <= amin + tol
    };
    for t in [a, b] {
        for f in FACES {
            if separated((t[f[1]] - t[f[0]]).cross(t[f[2]] - t[f[0]])) {
                return false;
            }
        }
    }
    for ea in EDGES {
        for eb in EDGES {
            let axis = (a[ea[1]] - a[ea[0]]).cross(b[eb[1]] - b[eb[0]]);
            // Skip near-parallel edge pairs: their cross product is numerically meaningless.
            let scale = (a[ea[1]] - a[ea[0]]).length() * (b[eb[1]] - b[eb[0]]).length();
            if axis.length() > 1e-9 * scale && separated(axis) {
                return false;
            }
        }
    }
    true
}

/// Signed volume of a tetrahedron (×6).
#[must_use]
pub fn tet_volume6(t: &[DVec3; 4]) -> f64 {
    (t[1] - t[0]).dot((t[2] - t[0]).cross(t[3] - t[0]))
}

impl OuterHull {
    /// The positive (`top = true`) or negative face tetrahedron [p_i p_j p_k u|v] of triangle t.
    #[must_use]
    pub fn face_tet(
        &self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        t: usize,
        top: bool,
    ) -> Option<[DVec3; 4]> {
        let f = &self.faces[t];
        let apex = if top { f.top } else { f.bottom }?;
        let tri = triangles[t];
        Some([
            positions[tri[0] as usize],
            positions[tri[1] as usize],
            positions[tri[2] as usize],
            apex,
        ])
    }

    /// Edges whose two same-side face tetrahedra overlap, or whose edge tetrahedron would be
    /// degenerate (§3.1: these edges are refined).
    #[must_use]
    pub fn bad_edges(&self, positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<u32> {
        // In parallel; `filter_map` + `collect` keeps the edge order.
        let bad_edge = |edge: &Edge| -> bool {
            if edge.is_boundary() {
                return false;
            }
            let [f0, f1] = edge.faces.map(|f| f as usize);
            let scale = (positions[edge.v[1] as usize] - positions[edge.v[0] as usize]).length();
            let mut is_bad = false;
            for top in [true, false] {
                let (Some(a), Some(b)) = (
                    self.face_tet(positions, triangles, f0, top),
                    self.face_tet(positions, triangles, f1, top),
                ) else {
                    continue;
                };
                if tets_overlap(&a, &b, 1e-9 * scale) {
                    is_bad = true;
                }
                let et = [
                    positions[edge.v[0] as usize],
                    positions[edge.v[1] as usize],
                    a[3],
                    b[3],
                ];
                if edge.class != Convexity::Zero
                    && tet_volume6(&et).abs() <= 1e-9 * scale * scale * scale
                {
                    is_bad = true;
                }
            }
            is_bad
        };
        self.edges
            .par_iter()
            .enumerate()
            .filter_map(|(e, edge)| bad_edge(edge).then_some(e as u32))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_classes() {
        let (pi, pj) = (DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        let up = DVec3::Z;
        let out_i = DVec3::new(-1.0, 0.0, 1.0).normalize();
        let out_j = DVec3::new(1.0, 0.0, 1.0).normalize();
        assert_eq!(edge_convexity(pi, pj, out_i, out_j), Convexity::Positive);
        assert_eq!(edge_convexity(pi, pj, out_j, out_i), Convexity::Negative);
        assert_eq!(edge_convexity(pi, pj, up, up), Convexity::Zero);
        assert_eq!(edge_convexity(pi, pj, out_i, out_i), Convexity::Nonconvex);
        use Convexity::*;
        assert_eq!(face_convexity([Positive, Zero, Positive]), Positive);
        assert_eq!(face_convexity([Zero, Zero, Zero]), Zero);
        assert_eq!(face_convexity([Negative, Zero, Negative]), Negative);
        assert_eq!(face_convexity([Negative, Positive, Zero]), Nonconvex);
    }

    #[test]
    fn overlap_test() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        // Mirror image across the plane x+y+z... share face [X Y Z]: touching only.
        let b = [DVec3::ONE, DVec3::X, DVec3::Y, DVec3::Z];
        assert!(!tets_overlap(&a, &b, 1e-12));
        let c = [DVec3::splat(0.1), DVec3::X, DVec3::Y, DVec3::Z];
        assert!(tets_overlap(&a, &c, 1e-12));
        let d = [
            DVec3::splat(5.0),
            DVec3::splat(6.0),
            DVec3::new(5.0, 6.0, 5.0),
            DVec3::new(6.0, 5.0, 5.0),
        ];
        assert!(!tets_overlap(&a, &d, 1e-12));
    }

    #[test]
    fn t_lm_matches_paper_formula() {
        // The paper's closed form of t_lm (§3.1) against ours (the number 3 weight vanishes).
        let p = [
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.3, 4.0, -1.0),
        ];
        let n = [
            DVec3::new(-1.0, 0.2, 1.0).normalize(),
            DVec3::new(1.0, 0.1, 1.0).normalize(),
            DVec3::new(0.0, 1.0, 1.5).normalize(),
        ];
        let nf = face_normal(0, p, n).unwrap();
        let c = (p[0] + p[1] + p[2]) / 3.0;
        for (l, m) in [(0, 1), (1, 2), (2, 0)] {
            let (pl, pm, nl, nm) = (p[l], p[m], n[l], n[m]);
            let den = (nl + nm).dot(nf);
            let paper = (pl - c + alpha(c, pl, pm) * (pl - pm)).dot(nl) / den
                + (pm - c + alpha(c, pm, pl) * (pm - pl)).dot(nm) / den;
            let eb = EdgeBlossom::new(pl, pm, nl, nm);
            let ours = -3.0 * eb.at(c) / nf.dot(eb.g1);
            // Both are closed forms of the same root; only rounding separates them.
            assert!(
                (paper - ours).abs() < 1e-12,
                "edge ({l},{m}): paper {paper} ours {ours}"
            );
        }
    }
}

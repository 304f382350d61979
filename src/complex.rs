//! The patch complex: the contract between surface construction and every consumer
//! (tracer, checker, exporters, library users).
//!
//! A [`PatchComplex`] is plain data: the vertices and normals the surface interpolates (or
//! approximates) and one [`Patch`] per tetrahedron of the hull. Its JSON form (`apatch export
//! patches`) is:
//!
//! ```text
//! {"format":"apatch-patches","version":1,"scheme":"…","vertices":[[x,y,z],…],"normals":[[x,y,z],…],
//!  "patches":[{"tet":[[x,y,z]×4],"degree":n,"weights":[… C(n+3,3) numbers …],
//!              "rational":[{"index":[k1,k2,k3,k4],"terms":[[w,[m1,m2,m3,m4]],…]}],   (omitted when none)
//!              "sheet":{"rule":"shooting","base":[…],"top":[…]},                      (omitted when "any")
//!              "role":"face|edge|…","element":id,
//!              "jvertex":j,                                                           (omitted when none)
//!              "jedge":[a,b]}]}                                                       (omitted when none)
//! ```
//!
//! meaning F(α) = Σ w_λ·n!/(λ1!λ2!λ3!λ4!)·α^λ + Σ_r (Σ_m w_m α^μm)/(Σ_m α^μm)·B^n_κr(α),
//! weights in the crate's multi-index order (decreasing lexicographic).

use crate::bb::{poly, rational, Tet};
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

/// Identifies the file format in JSON.
pub const FORMAT: &str = "apatch-patches";
/// Current JSON format version.
pub const VERSION: u32 = 1;

/// A whole piecewise-polynomial implicit surface: one patch per hull tetrahedron.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PatchComplex {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] for files this crate writes.
    pub version: u32,
    /// The scheme that built it: `rational-c1`, `cubic-c1`, `quintic-c2`, or a test name.
    pub scheme: String,
    /// Continuity the scheme promises (1 or 2); when absent it follows from `scheme`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuity: Option<u8>,
    /// Points the surface passes through (mesh vertices for interpolating schemes).
    pub vertices: Vec<[f64; 3]>,
    /// Unit normals the surface has at `vertices` (same length, or empty).
    pub normals: Vec<[f64; 3]>,
    /// One entry per tetrahedron.
    pub patches: Vec<Patch>,
}

/// One A-patch: a BB polynomial (plus optional rational terms) on one tetrahedron.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Patch {
    /// The tetrahedron [v1 v2 v3 v4]; barycentric αi belongs to `tet[i]`.
    pub tet: [[f64; 3]; 4],
    /// Polynomial degree n (1..=7).
    pub degree: u8,
    /// C(n+3,3) BB weights in the crate's multi-index order.
    pub weights: Vec<f64>,
    /// Rational corrections (2001 scheme); empty for polynomial patches.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rational: Vec<RationalTerm>,
    /// Which roots inside the tetrahedron belong to the surface.
    #[serde(default, skip_serializing_if = "SheetRule::is_any")]
    pub sheet: SheetRule,
    /// The hull role of the tetrahedron (face, edge, vertex, planar, …).
    pub role: Role,
    /// Index of the mesh element (face, edge or vertex) the tetrahedron belongs to.
    pub element: u32,
    /// 1994 schemes: the j-vertex (tetrahedron-local index) of a triangular j-patch
    /// (Definition 2.1): every segment from it to a point of the opposite face meets the
    /// surface at most once (a root at the j-vertex itself, when it lies on the surface, not
    /// counted). `None` when the scheme promises no such vertex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jvertex: Option<u8>,
    /// 1994 schemes: an edge (two tetrahedron-local indices) such that every segment from a
    /// point of it to a point of the opposite edge meets the surface at most once (the
    /// edge-tetrahedron form of Theorem 2.1; roots at the segment's ends not counted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jedge: Option<[u8; 2]>,
}

/// The rational term (Σ_m w_m α^μm)/(Σ_m α^μm) · B^n_κ(α) added to a patch.
///
/// `index` is κ (|κ| = n); each term is (w_m, μ_m). The denominator Σ α^μm is positive inside
/// the tetrahedron except where it vanishes on an edge, where the term is defined by continuity
/// (B^n_κ vanishes faster there).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RationalTerm {
    /// κ, the multi-index of the Bernstein polynomial the blended weight multiplies.
    pub index: [u8; 4],
    /// (w_m, μ_m) pairs: the weights blended by the monomials α^μm.
    pub terms: Blend,
}

/// The (w_m, μ_m) pairs of a [`RationalTerm`]: up to [`Blend::INLINE`] stored inline (the 2001
/// scheme's terms have two or three; a build of a 100k-triangle model writes ~500k of them),
/// more on the heap. Dereferences to `[(f64, [u8; 4])]`; its JSON form is an array of pairs,
/// exactly as a `Vec<(f64, [u8; 4])>`'s. Made with `.into()` from a `Vec` or an array.
#[derive(Clone)]
pub struct Blend(BlendRepr);

#[derive(Clone)]
enum BlendRepr {
    Inline {
        len: u8,
        items: [(f64, [u8; 4]); Blend::INLINE],
    },
    Heap(Vec<(f64, [u8; 4])>),
}

impl Blend {
    /// How many pairs are stored without a heap allocation.
    pub const INLINE: usize = 3;

    /// Appends a pair (moving to the heap past [`Blend::INLINE`]).
    pub fn push(&mut self, t: (f64, [u8; 4])) {
        match &mut self.0 {
            BlendRepr::Inline { len, items } if usize::from(*len) < Blend::INLINE => {
                items[usize::from(*len)] = t;
                *len += 1;
            }
            BlendRepr::Inline { len, items } => {
                let mut v = items[..usize::from(*len)].to_vec();
                v.push(t);
                self.0 = BlendRepr::Heap(v);
            }
            BlendRepr::Heap(v) => v.push(t),
        }
    }
}

impl Default for Blend {
    fn default() -> Self {
        Blend(BlendRepr::Inline {
            len: 0,
            items: [(0.0, [0; 4]); Blend::INLINE],
        })
    }
}

impl std::ops::Deref for Blend {
    type Target = [(f64, [u8; 4])];
    fn deref(&self) -> &Self::Target {
        match &self.0 {
            BlendRepr::Inline { len, items } => &items[..usize::from(*len)],
            BlendRepr::Heap(v) => v,
        }
    }
}

impl std::ops::DerefMut for Blend {
    fn deref_mut(&mut self) -> &mut Self::Target {
        match &mut self.0 {
            BlendRepr::Inline { len, items } => &mut items[..usize::from(*len)],
            BlendRepr::Heap(v) => v,
        }
    }
}

impl From<Vec<(f64, [u8; 4])>> for Blend {
    fn from(v: Vec<(f64, [u8; 4])>) -> Self {
        if v.len() > Blend::INLINE {
            return Blend(BlendRepr::Heap(v));
        }
        let mut b = Blend::default();
        for t in v {
            b.push(t);
        }
        b
    }
}

impl<const N: usize> From<[(f64, [u8; 4]); N]> for Blend {
    fn from(a: [(f64, [u8; 4]); N]) -> Self {
        if N > Blend::INLINE {
            return Blend(BlendRepr::Heap(a.to_vec()));
        }
        let mut b = Blend::default();
        for t in a {
            b.push(t);
        }
        b
    }
}

impl<'a> IntoIterator for &'a Blend {
    type Item = &'a (f64, [u8; 4]);
    type IntoIter = std::slice::Iter<'a, (f64, [u8; 4])>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl PartialEq for Blend {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for Blend {
    /// As the slice of pairs.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

impl Serialize for Blend {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

impl<'de> Deserialize<'de> for Blend {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Blend;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "an array of [weight, [m1, m2, m3, m4]] pairs")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<Blend, A::Error> {
                let mut b = Blend::default();
                while let Some(t) = seq.next_element::<(f64, [u8; 4])>()? {
                    b.push(t);
                }
                Ok(b)
            }
        }
        d.deserialize_seq(V)
    }
}

/// How to pick the surface among the zeros of F inside a tetrahedron.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "lowercase")]
pub enum SheetRule {
    /// Single-sheeted A-patch: every zero inside the tetrahedron is on the surface.
    #[default]
    Any,
    /// 2001 scheme, (4.5)–(4.7): a point p is on the surface only if, on the shooting line
    /// through p from the base simplex (tetrahedron vertices `base`) to the top simplex
    /// (vertices `top`), p is the zero with the smallest parameter t ∈ [0, 1)
    /// (t = Σ_{i∈top} αi at p; q and u are the normalised base and top parts of α), and F at
    /// the base point q does not have the strict sign of the weight at a top vertex (the top
    /// weights of one patch share their sign: > 0 on the positive side, < 0 on the negative).
    Shooting {
        /// Tetrahedron-local vertex indices spanning the base (a face: 3, an edge: 2).
        base: TetVerts,
        /// Tetrahedron-local vertex indices spanning the top (a vertex: 1, an edge: 2).
        top: TetVerts,
    },
}

/// At most four tetrahedron-local vertex indices, stored inline (no heap allocation: a build
/// of a 100k-triangle model writes ~600k sheet rules). Dereferences to `[u8]`; its JSON form is
/// an array of numbers, exactly as a `Vec<u8>`'s.
#[derive(Clone, Copy, Default, Eq)]
pub struct TetVerts {
    len: u8,
    ix: [u8; 4],
}

impl TetVerts {
    /// Most indices a [`TetVerts`] holds.
    pub const CAPACITY: usize = 4;

    /// The indices of `s`; `None` when there are more than [`TetVerts::CAPACITY`].
    #[must_use]
    pub fn from_slice(s: &[u8]) -> Option<Self> {
        if s.len() > Self::CAPACITY {
            return None;
        }
        let mut ix = [0; 4];
        ix[..s.len()].copy_from_slice(s);
        Some(TetVerts {
            len: s.len() as u8,
            ix,
        })
    }
}

impl<const N: usize> From<[u8; N]> for TetVerts {
    /// # Panics
    /// When N > [`TetVerts::CAPACITY`] (a programming error: a tetrahedron has four vertices).
    fn from(a: [u8; N]) -> Self {
        TetVerts::from_slice(&a).expect("at most four tetrahedron vertices")
    }
}

impl std::ops::Deref for TetVerts {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.ix[..usize::from(self.len)]
    }
}

impl<'a> IntoIterator for &'a TetVerts {
    type Item = &'a u8;
    type IntoIter = std::slice::Iter<'a, u8>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl PartialEq for TetVerts {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::hash::Hash for TetVerts {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (**self).hash(h);
    }
}

impl std::fmt::Debug for TetVerts {
    /// As the slice (`[0, 1, 2]`), which is how error messages show it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

impl Serialize for TetVerts {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

impl<'de> Deserialize<'de> for TetVerts {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = TetVerts;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "an array of at most 4 tetrahedron vertex indices")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<TetVerts, A::Error> {
                let mut v = TetVerts::default();
                while let Some(k) = seq.next_element::<u8>()? {
                    if usize::from(v.len) == TetVerts::CAPACITY {
                        return Err(serde::de::Error::invalid_length(
                            TetVerts::CAPACITY + 1,
                            &self,
                        ));
                    }
                    v.ix[usize::from(v.len)] = k;
                    v.len += 1;
                }
                Ok(v)
            }
        }
        d.deserialize_seq(V)
    }
}

impl SheetRule {
    /// True for [`SheetRule::Any`] (used to omit it from JSON).
    #[must_use]
    pub fn is_any(&self) -> bool {
        matches!(self, SheetRule::Any)
    }
}

/// The hull role of a tetrahedron, for shading by patch type and for error messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Face tetrahedron (2001: [p_i p_j p_k u_ijk] or with v_ijk; 1994: face tetrahedron).
    Face,
    /// Edge tetrahedron between two face tetrahedra across a mesh edge.
    Edge,
    /// Vertex tetrahedron (1994 inner hull, around a mesh vertex).
    Vertex,
    /// A zero-convex face reproduced as its own plane.
    Planar,
    /// Anything else (test complexes).
    Other,
}

impl Role {
    /// The lowercase name used in JSON and reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Role::Face => "face",
            Role::Edge => "edge",
            Role::Vertex => "vertex",
            Role::Planar => "planar",
            Role::Other => "other",
        }
    }
}

impl PatchComplex {
    /// An empty complex for `scheme`.
    #[must_use]
    pub fn new(scheme: &str) -> Self {
        PatchComplex {
            format: FORMAT.to_string(),
            version: VERSION,
            scheme: scheme.to_string(),
            continuity: None,
            vertices: Vec::new(),
            normals: Vec::new(),
            patches: Vec::new(),
        }
    }

    /// The continuity the complex promises: the explicit field, else from the scheme's name
    /// (`quintic-c2` → 2, anything else → 1).
    #[must_use]
    pub fn promised_continuity(&self) -> u8 {
        self.continuity
            .unwrap_or(if self.scheme.contains("c2") { 2 } else { 1 })
    }
}

impl Patch {
    /// The tetrahedron's vertices as vectors.
    #[must_use]
    pub fn tet_points(&self) -> [DVec3; 4] {
        self.tet.map(DVec3::from_array)
    }

    /// The tetrahedron with its barycentric map; `None` when it is degenerate.
    #[must_use]
    pub fn tet(&self) -> Option<Tet> {
        Tet::new(self.tet_points())
    }

    /// F at barycentric `a`, rational terms included (0 where their denominator vanishes).
    ///
    /// # Panics
    /// When `weights` does not hold C(n+3,3) numbers.
    #[must_use]
    pub fn value_bary(&self, a: [f64; 4]) -> f64 {
        let n = usize::from(self.degree);
        let mut f = poly::eval(n, &self.weights, a);
        for term in &self.rational {
            f += rational::term_value(term, n, a);
        }
        f
    }

    /// ∂F/∂αi (the four barycentric coordinates treated as independent), rational terms
    /// included exactly.
    #[must_use]
    pub fn gradient_bary(&self, a: [f64; 4]) -> [f64; 4] {
        let n = usize::from(self.degree);
        let mut g = poly::gradient_bary(n, &self.weights, a);
        for term in &self.rational {
            let (_, gt, _) = rational::term_jet(term, n, a);
            for i in 0..4 {
                g[i] += gt[i];
            }
        }
        g
    }

    /// ∂²F/∂αi∂αj, rational terms included exactly.
    #[must_use]
    pub fn hessian_bary(&self, a: [f64; 4]) -> [[f64; 4]; 4] {
        let n = usize::from(self.degree);
        let mut h = poly::hessian_bary(n, &self.weights, a);
        for term in &self.rational {
            let (_, _, ht) = rational::term_jet(term, n, a);
            for i in 0..4 {
                for j in 0..4 {
                    h[i][j] += ht[i][j];
                }
            }
        }
        h
    }

    /// F at world point `p` (NaN when the tetrahedron is degenerate).
    #[must_use]
    pub fn value(&self, p: DVec3) -> f64 {
        match self.tet() {
            Some(t) => self.value_bary(t.bary(p)),
            None => f64::NAN,
        }
    }

    /// World-space ∇F at `p`, rational terms included exactly (finite on the tetrahedron's
    /// edges); NaN when the tetrahedron is degenerate.
    #[must_use]
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        match self.tet() {
            Some(t) => t.world_gradient(self.gradient_bary(t.bary(p))),
            None => DVec3::NAN,
        }
    }

    /// World-space Hessian of F at `p`; NaN when the tetrahedron is degenerate.
    #[must_use]
    pub fn hessian(&self, p: DVec3) -> DMat3 {
        match self.tet() {
            Some(t) => t.world_hessian(self.hessian_bary(t.bary(p))),
            None => DMat3::NAN,
        }
    }

    /// Degree of [`Patch::segment_poly`]'s output: n plus the degrees of the distinct rational
    /// denominators. Loaders should reject patches where this exceeds 15.
    #[must_use]
    pub fn segment_degree(&self) -> usize {
        rational::segment_degree(usize::from(self.degree), &self.rational)
    }

    /// Univariate Bernstein coefficients in s ∈ \[0, 1\] of F((1−s)·x0 + s·x1) times the
    /// (positive inside the tetrahedron) rational denominators; returns their number,
    /// [`Patch::segment_degree`] + 1, or 0 when the tetrahedron is degenerate. Inside the
    /// tetrahedron its roots and signs are those of F. No heap allocation.
    ///
    /// # Panics
    /// When `weights` has the wrong length or the cleared degree exceeds 15.
    pub fn segment_poly(&self, x0: DVec3, x1: DVec3, out: &mut [f64; 16]) -> usize {
        let Some(t) = self.tet() else {
            return 0;
        };
        self.segment_poly_bary(t.bary(x0), t.bary(x1), out)
    }

    /// [`Patch::segment_poly`] for a segment given by the barycentric coordinates of its ends
    /// (for callers that keep the tetrahedron's barycentric map).
    ///
    /// # Panics
    /// As [`Patch::segment_poly`].
    pub fn segment_poly_bary(&self, a0: [f64; 4], a1: [f64; 4], out: &mut [f64; 16]) -> usize {
        rational::segment_poly(
            usize::from(self.degree),
            &self.weights,
            &self.rational,
            a0,
            a1,
            out,
        )
    }
}

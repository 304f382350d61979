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
    pub terms: Vec<(f64, [u8; 4])>,
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
        base: Vec<u8>,
        /// Tetrahedron-local vertex indices spanning the top (a vertex: 1, an edge: 2).
        top: Vec<u8>,
    },
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
